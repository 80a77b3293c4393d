"""Fault injection for the tests: make writes to chosen paths fail with ENOSPC or EDQUOT.

In-process: ``install(spec)``; in a subprocess: put this folder first on ``PYTHONPATH`` and set
``FIBRIL_TEST_FAULT`` (``sitecustomize.py`` here installs it at start-up). A spec is
``ERRNO:SUBSTRING[:SKIP]`` (e.g. ``ENOSPC:.journal:3``): every ``os.write``/``os.fsync`` on a file
whose path contains SUBSTRING, and every ``open`` of such a path for writing, fails with ERRNO
once SKIP such writes have succeeded. Only the operating-system calls are replaced; the code
under test is the shipped code.
"""

from __future__ import annotations

import builtins
import errno as _errno
import os

_state = {"spec": None, "seen": 0, "fired": 0}


def _path_of(fd: int) -> str:
    try:
        return os.readlink(f"/proc/self/fd/{fd}")
    except OSError:
        return ""


def _hit(path: str) -> bool:
    spec = _state["spec"]
    if spec is None or spec[1] not in str(path):
        return False
    _state["seen"] += 1
    if _state["seen"] <= spec[2]:
        return False
    _state["fired"] += 1
    return True


def _fail(path):
    code = _state["spec"][0]
    raise OSError(code, os.strerror(code), str(path))


def parse(text: str):
    parts = text.split(":")
    code = getattr(_errno, parts[0])
    return code, parts[1], int(parts[2]) if len(parts) > 2 else 0


def install(text: str) -> None:
    """Activate a fault (idempotent wrappers; ``uninstall`` restores the real calls)."""
    _state.update(spec=parse(text), seen=0, fired=0)
    if getattr(os.write, "_fault", False):
        return
    real_write, real_fsync, real_open = os.write, os.fsync, builtins.open

    def write(fd, data):
        if _state["spec"] and _hit(_path_of(fd)):
            _fail(_path_of(fd))
        return real_write(fd, data)

    def fsync(fd):
        fd_ = fd if isinstance(fd, int) else fd.fileno()
        if _state["spec"] and _hit(_path_of(fd_)):
            _fail(_path_of(fd_))
        return real_fsync(fd)

    def open_(file, mode="r", *a, **kw):
        if _state["spec"] and any(c in mode for c in "wax+") and isinstance(file, (str, bytes,
                                                                                   os.PathLike)):
            if _hit(os.fsdecode(file)):
                _fail(file)
        return real_open(file, mode, *a, **kw)

    for f in (write, fsync, open_):
        f._fault = True
    _state["real"] = (real_write, real_fsync, real_open)
    os.write, os.fsync, builtins.open = write, fsync, open_


def uninstall() -> None:
    _state["spec"] = None
    if "real" in _state:
        os.write, os.fsync, builtins.open = _state.pop("real")


def fired() -> int:
    return _state["fired"]
