"""Parameter campaigns: grid YAML -> jobs -> one resumable HDF5 file (serial or MPI).

Modules: :mod:`.spec` (grid -> jobs with stable keys), :mod:`.journal` + :mod:`.store` (crash-safe
HDF5 file), :mod:`.runner` (writer, serial runner, signals, progress), :mod:`.mpi` (master/worker,
the only mpi4py import), :mod:`.data` (:func:`load_campaign`), :mod:`.report`, :mod:`.cli`.
"""

from .data import CampaignData, load_campaign
from .spec import CampaignSpec, load_spec, spec_from_dict

__all__ = ["load_campaign", "CampaignData", "CampaignSpec", "load_spec", "spec_from_dict"]
