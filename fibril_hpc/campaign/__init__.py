"""Parameter campaigns: grid YAML -> jobs -> one resumable HDF5 file (serial or MPI).

Rooms, lowest first (each one's docstring says what it owns; ``lint-imports`` checks the order):

- :mod:`.laws`: the science of F~_A(F~_P): laws, the plateau, c, c0, alpha/beta, seed
  intervals; pure functions;
- :mod:`.plan`: the grid and its job keys, ``F_P: auto``, the ``--dry-run`` cost estimate;
- :mod:`.storage`: job records, the journal, checksums, the HDF5 file, the single writer,
  ``verify``/``salvage`` and ``merge``;
- :mod:`.run`: one task, the serial runner, the MPI master/worker, stop signals, progress;
- :mod:`.analysis`: :func:`load_campaign`, status, exports and the report.

The command line (``fibril-campaign``) is :mod:`fibril_hpc.cli.campaign`.
"""

from .analysis.data import CampaignData, load_campaign
from .plan.spec import CampaignSpec, load_spec, spec_from_dict
from .storage.record import JobRecord

__all__ = ["load_campaign", "CampaignData", "JobRecord", "CampaignSpec", "load_spec", "spec_from_dict"]
