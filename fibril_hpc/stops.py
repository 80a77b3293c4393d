"""Where a stop signal's exception may be raised, and how to deliver it later where it may not:
shared by the commands' guard (:mod:`fibril_hpc.cli.common`) and a running campaign's stop flag
(:mod:`fibril_hpc.campaign.run.control`)."""

from __future__ import annotations

import os
import threading

_LLVMLITE = f"{os.sep}llvmlite{os.sep}"

#: how long a stop signal that lands where raising is unsafe waits to be sent again (seconds)
UNSAFE_RETRY_S = 0.05


def unsafe(frame) -> bool:
    """Whether an exception raised in ``frame`` could come out as another one or corrupt what
    runs below it: inside Python's import machinery (a module body, a class body created while
    importing), or in llvmlite's Python code (callbacks that LLVM calls while numba compiles and
    caches a kernel: one aborted there is swallowed with an "Exception ignored ... Traceback",
    or leaves numba without its compiled object, and a later "RuntimeError: no compiled object
    yet" or a crash)."""
    if _LLVMLITE in frame.f_code.co_filename:
        return True
    while frame is not None:
        if frame.f_code.co_filename.startswith("<frozen importlib"):
            return True
        frame = frame.f_back
    return False


def send_again(signum: int, delay: float) -> None:
    """Send stop signal ``signum`` to this process again after ``delay`` seconds, from a
    short-lived thread (sent from a handler, it would be handled inside that handler)."""
    again = threading.Timer(delay, os.kill, (os.getpid(), signum))
    again.daemon = True
    again.start()


__all__ = ["UNSAFE_RETRY_S", "send_again", "unsafe"]
