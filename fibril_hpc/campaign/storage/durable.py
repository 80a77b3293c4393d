"""Publishing a checkpoint so that no single damaged or deleted file loses a record (no h5py,
no MPI).

The campaign writer keeps every finished record in two files at every moment:

* records of the previous checkpoint: the published file ``<file>`` *and* its previous
  generation ``<file>.previous`` (the file as it was before the last checkpoint replaced it);
* records of the last checkpoint: ``<file>`` *and* the journal pair (see :mod:`.journal_writer`);
* records finished since: the journal *and* its mirror.

A checkpoint (:func:`publish`) follows what SQLite and HDF5's durability notes ask of a
rename-into-place writer: the new file is written beside the old one, ``fsync``-ed, read back and
verified (its bytes are the bytes meant, every record it must hold is there and the new ones
read whole and verify), and only then is the old file renamed to
``<file>.previous`` (a second name made with ``link`` then ``rename``: no copy) and the new one
renamed into place, and the folder is ``fsync``-ed. The journal is trimmed only after that.
A new file that does not read back whole is never published (:class:`CheckpointNotVerified`).
"""

from __future__ import annotations

import os
import shutil
import tempfile

from ...errors import FULL_ERRNOS, DiskFull, Interruption, StoreError
from ...io.files import write_bytes_atomically

#: suffix of the previous generation of a campaign file
PREVIOUS = ".previous"


def previous_path(path: str) -> str:
    """The previous generation of the campaign file ``path`` (beside its resolved path)."""
    return os.path.realpath(path) + PREVIOUS


def tmp_prefix(path: str) -> str:
    """Prefix of the temporaries a checkpoint writes beside ``path`` (removed by the next
    writer if a kill leaves one behind)."""
    return "." + os.path.basename(path) + ".ckpt-"


class CheckpointNotVerified(Interruption):
    """The new copy a checkpoint wrote did not read back whole: it is not published; the
    published file, its previous generation and the journal still hold every record."""

    def __init__(self, path, journal, detail):
        self.path = path
        super().__init__(
            f"the checkpoint copy of {path} did not read back whole ({detail}); {path} was not "
            f"replaced and every finished record is still in it or in {journal}: rerun the same "
            "command to resume")


def publish(path: str, data, verify=None, keep_previous: bool = False,
            operation: str = "checkpoint copy", exclusive: str | None = None) -> None:
    """Write ``data`` to a temporary file beside ``path``, ``fsync`` it, check it with
    ``verify`` (a callable taking the temporary path and returning "" or what is wrong:
    :class:`CheckpointNotVerified`), keep the old ``path`` as :func:`previous_path` when
    ``keep_previous``, rename the new file over ``path`` and ``fsync`` the folder.

    ENOSPC/EDQUOT at any step becomes :class:`DiskFull`; the temporary file is always removed
    on failure. ``exclusive``: see :func:`fibril_hpc.io.files.write_bytes_atomically` (a new
    file of ``merge`` or ``salvage``; never with ``verify`` or ``keep_previous``).
    """
    folder = os.path.dirname(os.path.abspath(path)) or "."

    def check(tmp: str) -> None:       # the written copy, before it gets the name
        problem = (_read_back(tmp, data) or verify(tmp)) if verify is not None else ""
        if problem:
            raise CheckpointNotVerified(path, path + ".journal", problem)
        if keep_previous and os.path.exists(path):
            _second_name(path, previous_path(path), folder)

    write_bytes_atomically(path, data, operation, tmp_prefix(path), exclusive,
                           before_publish=check)


def _read_back(tmp: str, data) -> str:
    """"" when the bytes of ``tmp`` on disk are ``data``, else what differs."""
    with open(tmp, "rb") as fh:
        got = fh.read()
    if got == bytes(data):
        return ""
    return f"{len(got)} bytes read back of {len(data)} written, or other bytes"


def keep_copy(path: str) -> None:
    """Make :func:`previous_path` a copy of ``path`` as it is now (a run starting on a file
    whose records so far have no other copy). A full disk is :class:`DiskFull`."""
    try:
        with open(path, "rb") as fh:
            data = fh.read()
    except OSError as exc:
        raise StoreError(f"cannot read {path}: {exc}") from None
    try:
        write_bytes_atomically(previous_path(path), data, "checkpoint copy", tmp_prefix(path))
    except DiskFull as exc:            # named as the campaign's checkpoint, which it is
        raise DiskFull(path, "checkpoint copy", exc.detail) from None


def remove_previous(path: str) -> None:
    """Delete the previous generation (the published file holds every record, verified)."""
    try:
        os.unlink(previous_path(path))
    except OSError:
        pass


def _second_name(path: str, previous: str, folder: str) -> None:
    """Give the file ``path`` the name ``previous`` too (atomically replacing an older one), so
    that renaming a new file over ``path`` keeps the old one whole. Where hard links are not
    supported, the old file is copied."""
    fd, tmp = tempfile.mkstemp(prefix=tmp_prefix(path), dir=folder)
    os.close(fd)
    os.unlink(tmp)
    try:
        os.link(path, tmp)
    except OSError as exc:
        if exc.errno in FULL_ERRNOS:
            raise
        shutil.copyfile(path, tmp)
        with open(tmp, "rb+") as fh:
            os.fsync(fh.fileno())
    try:
        os.replace(tmp, previous)
    except BaseException:
        if os.path.lexists(tmp):
            os.unlink(tmp)
        raise


__all__ = ["publish", "keep_copy", "remove_previous", "previous_path", "tmp_prefix",
           "CheckpointNotVerified", "PREVIOUS"]
