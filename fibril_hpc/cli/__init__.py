"""The command-line wing (the only argparse of the package), thin on top of the library.

``fibril-run`` (:mod:`.run`), ``fibril-campaign`` (:mod:`.campaign`), ``fibril-accuracy``
(:mod:`fibril_hpc.accuracy`); shared parser and exit statuses in :mod:`.common`. A user mistake
is one line on stderr, exit status 2, nothing written.
"""

from .run import main as run_main

__all__ = ["run_main"]
