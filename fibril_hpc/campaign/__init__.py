"""Parameter campaigns: grid YAML -> jobs -> one resumable HDF5 file (serial or MPI).

Modules, one job each:

- inputs: :mod:`.spec` (grid -> jobs with stable keys), :mod:`.estimate` (cost model);
- records: :mod:`.record` (:class:`JobRecord`, the one field list), :mod:`.journal` +
  :mod:`.store` (the crash-safe HDF5 file), :mod:`.writer` (the single writer);
- running: :mod:`.execute` (one task), :mod:`.runner` (serial), :mod:`.mpi` (master/worker, the
  only mpi4py import), :mod:`.launcher` (launcher detection), :mod:`.control` (stop signals),
  :mod:`.progress`;
- reading: :mod:`.data` (:func:`load_campaign`), :mod:`.status`, :mod:`.merge`, :mod:`.export`,
  :mod:`.report`.

The command line (``fibril-campaign``) is :mod:`fibril_hpc.cli.campaign`.
"""

from .data import CampaignData, load_campaign
from .record import JobRecord
from .spec import CampaignSpec, load_spec, spec_from_dict

__all__ = ["load_campaign", "CampaignData", "JobRecord", "CampaignSpec", "load_spec", "spec_from_dict"]
