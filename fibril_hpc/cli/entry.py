"""The console scripts' first code (pyproject ``[project.scripts]``): a stop signal is one line
from the first instant.

Importing a command pulls in numba, h5py and pyFFTW (0.5-3 s), exactly when a user who spotted
a typo presses Ctrl-C. This module imports nothing heavy (the package face loads its names
lazily): it answers SIGINT and SIGTERM with one line and the command's interrupted status
before it imports the command, whose own guard (:func:`.common.interruptible`) takes over once
``main`` runs. Nothing has been read or written before that.
"""

from __future__ import annotations

import os
import signal
import sys

from ..errors import EXIT_INTERRUPTED

__all__ = ["fibril_run", "fibril_campaign", "fibril_accuracy"]


def _starting(prog: str, code: int | None) -> None:
    """Until the command's guard takes over: a stop signal ends the process at once with one
    line and ``code`` (None: 128 + the signal). Signals the caller ignores stay ignored."""

    def stop(signum, frame):  # noqa: ARG001 - the signal handler's signature
        name = signal.Signals(signum).name
        os.write(2, f"{prog}: interrupted ({name}) while starting: nothing was read or written; "
                    "rerun the command\n".encode())
        os._exit(128 + signum if code is None else code)

    for s in (signal.SIGINT, signal.SIGTERM):
        if signal.getsignal(s) is not signal.SIG_IGN:
            signal.signal(s, stop)


def _quiet_exit() -> None:
    """The command has returned its status: a late signal no longer changes it."""
    for s in (signal.SIGINT, signal.SIGTERM):
        signal.signal(s, signal.SIG_IGN)


def fibril_run() -> int:
    """``fibril-run`` (Ctrl-C: exit 130, SIGTERM: 143)."""
    _starting("fibril-run", None)
    from .run import main

    code = main()
    _quiet_exit()
    return code


def fibril_campaign() -> int:
    """``fibril-campaign`` (a stop signal: exit 75, the interrupted campaign's status)."""
    _starting("fibril-campaign", EXIT_INTERRUPTED)
    from .campaign import main

    code = main()
    _quiet_exit()
    return code


def fibril_accuracy() -> int:
    """``fibril-accuracy`` (Ctrl-C: exit 130, SIGTERM: 143)."""
    _starting("fibril-accuracy", None)
    from .accuracy import main

    code = main()
    _quiet_exit()
    return code


if __name__ == "__main__":  # pragma: no cover
    sys.exit(fibril_run())
