"""The writer of the journal and of its mirror: :class:`JournalWriter` (no h5py, no MPI).

Every finished record is appended, as one frame (see :mod:`.journal`), to ``<file>.journal``
and to ``<file>.journal.mirror`` and both are ``fsync``-ed before the record counts as
finished: a record has two copies from the moment it exists, so no single damaged or deleted
file loses it. The campaign writer trims both files only to what the published HDF5 file and
its previous generation already hold twice (see :mod:`.writer`).
"""

from __future__ import annotations

import logging
import os

from ...io.files import fsync_dir
from .journal import Scan, encode, mirror_path, quarantine_path, read_bytes, scan

log = logging.getLogger(__name__)


def _write_all(fd: int, data: bytes) -> None:
    view = memoryview(data)
    while view:
        view = view[os.write(fd, view):]


def _rewrite(path: str, data: bytes) -> None:
    """Replace ``path`` by ``data`` (temporary file, ``fsync``, rename, folder ``fsync``)."""
    tmp = path + ".rewrite"
    fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o644)
    try:
        _write_all(fd, data)
        os.fsync(fd)
    finally:
        os.close(fd)
    os.replace(tmp, path)
    fsync_dir(os.path.dirname(path) or ".")


def _record_id(rec: dict):
    return rec.get("record_id")


class JournalWriter:
    """Appends records durably to the journal *and* its mirror (one ``write`` + ``fsync`` per
    record and file), so that each record has two copies before the HDF5 file has any.

    On opening, the intact frames of both files are read (a journal deleted or damaged is
    rebuilt from the other); a stretch that is not intact is appended to ``<file>.quarantine``
    (with a one-line warning naming it) and both files are rewritten (temporary file + rename)
    with the intact frames only. ``replayed`` holds the intact records of the accepted campaigns.
    :meth:`keep` trims both files to the records not yet in two other files (see
    :class:`~fibril_hpc.campaign.storage.writer.CampaignWriter`).
    """

    def __init__(self, path: str, accept=None, belongs=None):
        self.path = path
        self.mirror = mirror_path(path)
        self.replayed = []
        self._frames = []              # (record_id, frame bytes): what both files hold
        seen = set()
        scans = []
        for p in (path, self.mirror):
            data = read_bytes(p)
            s = scan(data, accept, belongs)
            scans.append((p, data, s))
            for a, b, rec in s.records:
                if data[a:b] not in seen:
                    seen.add(data[a:b])
                    self._frames.append((_record_id(rec), data[a:b]))
                    self.replayed.append(rec)
        self.scan = scans[0][2]
        for p, data, s in scans:
            if not s.clean:
                _quarantine(p, data, s)
        self._fds = {}
        good = b"".join(f for _, f in self._frames)
        for p, data, _ in scans:
            if data != good:
                _rewrite(p, good)
            self._fds[p] = os.open(p, os.O_WRONLY | os.O_CREAT | os.O_APPEND, 0o644)

    def _ensure(self) -> None:
        """Rebuild a file of the pair that was deleted or replaced under the writer."""
        for p, fd in list(self._fds.items()):
            try:
                a, b = os.fstat(fd), os.stat(p)
                same = (a.st_dev, a.st_ino) == (b.st_dev, b.st_ino)
            except OSError:
                same = False
            if not same:
                log.warning("journal %s was removed or replaced while the campaign ran; "
                            "rebuilt from the writer's copy", p)
                os.close(fd)
                _rewrite(p, b"".join(f for _, f in self._frames))
                self._fds[p] = os.open(p, os.O_WRONLY | os.O_APPEND, 0o644)

    def append(self, record: dict) -> None:
        """Append one frame holding ``record`` (sealed with its checksum by the caller: a frame
        without one is never counted) to both files and ``fsync`` them; on failure (a full
        disk) the torn frame is cut off again where possible and the ``OSError`` propagates."""
        data = encode(record)
        self._ensure()
        sizes = {p: os.fstat(fd).st_size for p, fd in self._fds.items()}
        try:
            for fd in self._fds.values():
                _write_all(fd, data)
                os.fsync(fd)
        except OSError:
            for p, fd in self._fds.items():
                try:
                    os.ftruncate(fd, sizes[p])
                except OSError:  # pragma: no cover - the reader resynchronises past it
                    pass
            raise
        self._frames.append((_record_id(record), data))

    def keep(self, record_ids) -> None:
        """Trim both files to the frames of the records ``record_ids`` (those whose only
        other copy is the HDF5 file). A failure is harmless: replaying records that are
        already in the file changes nothing."""
        keep = set(record_ids)
        frames = [(i, f) for i, f in self._frames if i in keep]
        if len(frames) == len(self._frames):
            return
        try:
            for p in list(self._fds):
                os.close(self._fds.pop(p))
                _rewrite(p, b"".join(f for _, f in frames))
                self._fds[p] = os.open(p, os.O_WRONLY | os.O_APPEND, 0o644)
        except OSError as exc:
            log.info("could not trim %s (%s); its records are replayed harmlessly", self.path,
                     exc)
            for p in (self.path, self.mirror):
                if p not in self._fds:
                    self._fds[p] = os.open(p, os.O_WRONLY | os.O_APPEND | os.O_CREAT, 0o644)
            return
        self._frames = frames

    def reset(self) -> None:
        """Empty both files (every record is safely in two other files)."""
        self.keep(())

    def close(self) -> None:
        """Close both files (idempotent)."""
        for p in list(self._fds):
            os.close(self._fds.pop(p))

    def remove(self) -> None:
        """Close and delete both files (every record is in the published file, verified)."""
        self.close()
        for p in (self.path, self.mirror):
            try:
                os.unlink(p)
            except OSError:
                pass


def _quarantine(path: str, data: bytes, s: Scan) -> None:
    """Append the stretches of ``data`` (the bytes of journal ``path``) that are not intact
    to its quarantine file, and say so in one line."""
    qpath = quarantine_path(path)
    bad = sorted(s.damaged + s.old + s.foreign + s.outside + s.unverified
                 + ([s.torn] if s.torn else []))
    with open(qpath, "ab") as q:
        q.writelines(data[a:b] for a, b in bad)
        q.flush()
        os.fsync(q.fileno())
    msg = s.message(path)
    moved = sum(b - a for a, b in bad)
    if msg:
        log.warning("%s; %d byte(s) moved to %s", msg, moved, qpath)
    else:        # only the unfinished frame of a killed writer (its job is recomputed)
        log.info("journal %s: an unfinished last frame (%d bytes) moved to %s", path, moved,
                 qpath)


__all__ = ["JournalWriter"]
