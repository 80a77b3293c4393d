"""Reading a file that may come from anywhere in a child process, so that it can never hang us.

A few damaged HDF5 files make libhdf5 itself loop forever: zeroing one 512-byte block of a
campaign file's global heap turns the read of a text attribute into a busy loop inside the
C library (measured: no file read, no allocation, no end), where no Python signal handler can
run. :func:`run_isolated` runs a reader in a forked child and hands back what it returned (or
raised). The parent watches the child's reads (``rchar`` of ``/proc/PID/io``): a child that has
read nothing for ``stall_s`` seconds is stopped and the file is reported as damaged in one
line; so is a child that dies (a crash inside the library). A legitimate read of a large file
keeps reading and is never cut short.

The child is not used where forking is unsafe or impossible: on systems without ``os.fork``,
inside an initialised MPI job (the campaign writer opening its own output; forking an MPI
process can upset the interconnect), and in a child of this module. There the reader runs in
process, as before.
"""

from __future__ import annotations

import os
import pickle
import signal
import sys
import time
import warnings

from ..errors import DamagedFileError, StoreError

#: seconds a reading child may go without reading a byte before it is taken for hung
STALL_S = 15.0
#: seconds between the parent's looks at the child
POLL_S = 0.05
#: environment variable of a forked child (nested readers run in process)
_CHILD_VAR = "FIBRIL_ISOLATED_CHILD"


def _mpi_initialised() -> bool:
    mpi = sys.modules.get("mpi4py.MPI")
    if mpi is None:
        return False
    try:
        return bool(mpi.Is_initialized()) and not bool(mpi.Is_finalized())
    except Exception:  # noqa: BLE001 - a broken MPI: do not fork
        return True


def can_isolate() -> bool:
    """Whether :func:`run_isolated` runs its reader in a child here."""
    return hasattr(os, "fork") and os.environ.get(_CHILD_VAR) != "1" and not _mpi_initialised()


def _read_count(pid: int):
    """Bytes the process has read so far (``rchar``), or None where /proc does not tell."""
    try:
        with open(f"/proc/{pid}/io") as fh:
            for line in fh:
                if line.startswith("rchar:"):
                    return int(line.split()[1])
    except (OSError, ValueError):
        return None
    return None


def _child(fn, args, kwargs, wfd: int) -> None:
    import faulthandler

    os.environ[_CHILD_VAR] = "1"
    faulthandler.disable()               # a crash is reported by the parent, in one line
    try:
        try:
            payload = ("ok", fn(*args, **kwargs))
        except BaseException as exc:  # noqa: BLE001 - handed to the parent as it was raised
            payload = ("raise", exc)
        try:
            data = pickle.dumps(payload, protocol=pickle.HIGHEST_PROTOCOL)
            pickle.loads(data)               # an exception that cannot be rebuilt is sent as text
        except Exception:  # noqa: BLE001
            kind, value = payload
            text = value if kind == "raise" else f"result not transferable ({type(value).__name__})"
            data = pickle.dumps(("raise", StoreError(str(text).splitlines()[0][:500]
                                                     if str(text) else type(text).__name__)))
        with os.fdopen(wfd, "wb") as out:
            out.write(data)
    finally:
        os._exit(0)


def run_isolated(fn, *args, what: str, stall_s: float | None = None, **kwargs):
    """``fn(*args, **kwargs)`` run in a forked child; its result is returned and its exception
    raised here. A child that reads nothing for ``stall_s`` seconds is killed and a child that
    dies is reported: both as one :class:`DamagedFileError` line naming ``what`` (the file);
    ``stall_s`` defaults to :data:`STALL_S`. Where :func:`can_isolate` is false, ``fn`` simply
    runs here."""
    stall_s = STALL_S if stall_s is None else stall_s
    if not can_isolate():
        return fn(*args, **kwargs)
    rfd, wfd = os.pipe()
    with warnings.catch_warnings():          # Python >= 3.12 warns about fork with threads
        warnings.simplefilter("ignore", DeprecationWarning)
        pid = os.fork()
    if pid == 0:                             # pragma: no cover - the child ends in os._exit
        os.close(rfd)
        _child(fn, args, kwargs, wfd)
    os.close(wfd)
    try:
        data = _collect(pid, rfd, what, stall_s)        # reaps the child whatever happens
    finally:
        os.close(rfd)
    kind, value = pickle.loads(data)
    if kind == "raise":
        raise value
    return value


def _collect(pid: int, rfd: int, what: str, stall_s: float) -> bytes:
    """Everything the child writes to ``rfd``, watching it for stalls. The child is reaped
    exactly once: waited for when it has written everything, killed and waited for on a stall or
    on anything raised here (a signal's exception included)."""
    import selectors

    chunks = []
    last_count, last_change = _read_count(pid), time.monotonic()
    sel = selectors.DefaultSelector()
    sel.register(rfd, selectors.EVENT_READ)
    try:
        while True:
            if sel.select(POLL_S):
                chunk = os.read(rfd, 1 << 20)
                if not chunk:
                    break
                chunks.append(chunk)
                last_change = time.monotonic()
                continue
            count = _read_count(pid)
            now = time.monotonic()
            if count is None or count != last_count:
                if count is not None:
                    last_count, last_change = count, now
                elif now - last_change > 20 * stall_s:      # no /proc: a plain deadline
                    raise _hung(what, 20 * stall_s)
                continue
            if now - last_change > stall_s:
                raise _hung(what, stall_s)
    except BaseException:
        _kill(pid)
        raise
    finally:
        sel.close()
    _, status = os.waitpid(pid, 0)
    if not chunks:
        sig = os.WTERMSIG(status) if os.WIFSIGNALED(status) else None
        why = f"signal {signal.Signals(sig).name}" if sig else f"status {os.waitstatus_to_exitcode(status)}"
        raise DamagedFileError(f"{what}: the HDF5 library crashed reading it ({why}); "
                               f"`fibril-campaign salvage` copies what still reads")
    return b"".join(chunks)


def _kill(pid: int) -> None:
    """SIGKILL our own child ``pid`` (not yet reaped, so its PID is still ours) and reap it."""
    os.kill(pid, signal.SIGKILL)
    os.waitpid(pid, 0)


def _hung(what: str, seconds: float) -> DamagedFileError:
    return DamagedFileError(f"{what}: the HDF5 structure is damaged (reading it made the HDF5 "
                            f"library loop: nothing read for {seconds:.0f} s, stopped)")


__all__ = ["run_isolated", "can_isolate", "STALL_S"]
