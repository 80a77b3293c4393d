"""The only writer of a campaign file: :class:`CampaignWriter`.

It holds the lock, checks that the file belongs to this grid, replays the journal of a killed
run, appends each finished record to the journal and its mirror and folds them into the HDF5
file at checkpoints (see :mod:`.store`, :mod:`.journal` and :mod:`.durable`).

Two copies of every finished record at every moment of a run: the journal and its mirror
from the moment it finishes; the published file and the journal pair after the checkpoint
that publishes it (the pair is trimmed to that checkpoint's records only once the new file read
back whole); the published file and ``<file>.previous`` (the generation before) after the next
one. A run that starts on an existing file first copies it to ``<file>.previous``. When the run
finishes and the last checkpoint read back whole, the journal pair and ``<file>.previous`` are
removed: a finished campaign is its HDF5 file alone.
"""

from __future__ import annotations

import fcntl
import json
import logging
import os
import time

from ...errors import (
    FULL_ERRNOS,
    ConfigError,
    DamagedFileError,
    DiskFull,
    PublishedFileChanged,
    StoreError,
)
from ...io.files import check_writable
from . import durable, integrity, store
from . import journal as _journal
from .journal_writer import JournalWriter
from .record import layout_problem
from .rootcheck import repair, root_problem

log = logging.getLogger(__name__)

def _check_single_name(path: str) -> None:
    """Refuse a campaign file that has other names (hard links): the lock beside one name
    would not stop a writer through another, and a checkpoint (a new file renamed into place)
    would silently split the names into two diverging files."""
    try:
        st = os.stat(path)
    except FileNotFoundError:
        return
    except OSError as exc:
        raise ConfigError("output", path, f"a readable file ({exc.strerror})") from None
    if st.st_nlink > 1:
        raise ConfigError("output", path,
                          f"a file with one name (it has {st.st_nlink} hard links, device "
                          f"{st.st_dev} inode {st.st_ino}: another writer could reach it "
                          "under another name); copy it to a new name, or remove the other links")


def check_output(spec, extend: bool = False) -> list:
    """Whether a run of ``spec`` may write its output file, checked as the writer checks it
    before anything is written (and as ``--dry-run`` checks it, so that a dry run says what the
    run will do): a writable place, a file with one name, and a file (or a journal) of this
    grid, or of another one only with ``extend``. Returns the ``extended_from`` history the
    file will carry; a refusal is a one-line :class:`ConfigError` of field ``output``."""
    path = os.path.realpath(spec.output)
    check_writable(path, "output")
    _check_single_name(path)
    if os.path.exists(path):
        try:
            root = store.read_root(path)
        except StoreError as exc:
            if has_second_copies(path):     # a campaign file damaged: its copies are here
                raise ConfigError(
                    "output", path, f"a campaign file that reads ({str(exc).split('; ')[0]}); "
                    "its journal or previous generation is beside it: recover every record "
                    f"with `fibril-campaign salvage {path} -o NEW.h5`, then rerun with "
                    "--output NEW.h5") from None
            raise ConfigError("output", path,
                              f"a fibril-hpc campaign file or a new name ({exc})") from None
        prev = root.get("campaign_hash")
        history = []
        try:
            history = json.loads(root.get("extended_from", "[]"))
        except ValueError:
            history = []
        if prev != spec.campaign_hash:
            damaged = root_problem(root)
            if damaged:                # not another grid: a damaged root (--extend repairs
                raise ConfigError(     # nothing)
                    "output", path, f"a campaign file whose root reads whole: {damaged}; "
                    f"recover with {repair(path)}")
            if not extend:
                raise ConfigError(
                    "output", path,
                    f"a file of this grid: it holds campaign {str(prev)[:12]} from another grid"
                    f" (this grid is {spec.campaign_hash[:12]}); pass --extend to add "
                    "this grid's jobs to it, or choose another output")
            history.append({"campaign_hash": prev, "campaign_yaml": root.get("campaign_yaml")})
        return history
    previous = durable.previous_path(path)
    if os.path.exists(previous):
        raise ConfigError("output", path,
                          f"a campaign file that exists (it is missing, but its previous "
                          f"generation {previous} is here); recover every record with "
                          f"`fibril-campaign salvage {path} -o NEW.h5`, then rerun with "
                          "--output NEW.h5")
    jrecs, _ = _journal.read(_journal.journal_path(path))
    hashes = {r.get("campaign_hash") for r in jrecs if r.get("type") == "job"}
    other = hashes - {spec.campaign_hash} if hashes else set()   # the hash sorts every key
    if other and not extend:
        raise ConfigError("output", path,
                          "a file of this grid: its journal holds records of another grid; "
                          "pass --extend to keep them")
    return []


def has_second_copies(path: str) -> bool:
    """Whether the campaign file ``path`` has a journal, its mirror or a previous generation
    beside it (what ``salvage`` takes besides the file)."""
    jpath = _journal.journal_path(path)
    return any(os.path.isfile(p) and os.path.getsize(p) > 0
               for p in (jpath, _journal.mirror_path(jpath), durable.previous_path(path)))


class CampaignWriter:
    """The only writer of a campaign file: lock, identity check, journal replay, checkpoints.

    Parameters
    ----------
    spec : CampaignSpec
    extend : bool
        Accept a file written from another grid; its records are kept and this grid's jobs added.
    checkpoint_s : float
        Fold the journal into the HDF5 file at most this often (and at the end).
    """

    def __init__(self, spec, *, extend: bool = False, checkpoint_s: float = 30.0):
        self.spec = spec
        # the resolved path: a second writer through a symlink (or another spelling) meets
        # the same lock, and a checkpoint replaces the file, not the symlink
        self.path = os.path.realpath(spec.output)
        self.checkpoint_s = checkpoint_s
        extended_from = check_output(spec, extend)     # before anything is written
        self._lock_fd = os.open(self.path + ".lock", os.O_RDWR | os.O_CREAT, 0o644)
        try:
            fcntl.flock(self._lock_fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            os.close(self._lock_fd)
            raise ConfigError("output", self.path,
                              "a file that no other running campaign is writing (it is locked)") \
                from None
        if not _same_file(self._lock_fd, self.path + ".lock"):
            # the writer before us removed the lock file as it finished, after we opened it:
            # our lock is on a file nobody else can see
            self._unlock()
            raise ConfigError("output", self.path, "a file that no other campaign is writing "
                              "(one was finishing as this one started: rerun the command)")
        try:
            self._open(spec, extend, extended_from)
        except BaseException:
            if getattr(self, "journal", None) is not None:
                self.journal.close()
            for side in (_journal.journal_path(self.path),        # a refused run leaves
                         _journal.mirror_path(_journal.journal_path(self.path))):   # nothing
                _remove_if_empty(side)
            self._unlock(remove=True)
            raise

    def _open(self, spec, extend, extended_from):
        store.clean_temporaries(self.path)
        self.root_attrs = store.root_attrs_for(spec, extended_from)
        got = store.read_h5_checked(self.path, curves=False)
        self.records = {k: {"status": r.get("status"), "record_id": r.get("record_id")}
                        for k, r in got.records.items()}
        #: corrupt records of the file: recomputed, and left out of every checkpoint
        self.corrupt = set(got.corrupt)
        corrupt = sorted(self.corrupt)
        accept = store.accepted_hashes(got.root)
        if accept is not None:
            accept.add(spec.campaign_hash)
        elif not extend:
            accept = {spec.campaign_hash}
        index = got.index
        index.add_spec(spec)               # frames whose key is no job of a grid: foreign
        belongs = index.belongs
        if extend and not got.root:        # a journal of another grid kept by --extend
            def belongs(rec):
                return not layout_problem(rec)
        jpath = _journal.journal_path(self.path)
        try:
            self.journal = JournalWriter(jpath, accept, belongs)
        except OSError as exc:            # e.g. no room to quarantine a damaged stretch
            if exc.errno in FULL_ERRNOS:
                raise DiskFull(jpath, "opening the journal", exc.strerror) from None
            raise StoreError(f"cannot open the journal {jpath}: {exc}") from None
        self._unpublished = []
        for r in self.journal.replayed:
            if r.get("type") == "job":
                self._remember(r)
        self.journal.replayed = None
        self._last_ckpt = time.monotonic()
        #: the PublishedFileChanged met, if any: from then on records go to the journal only
        self.changed = None
        self._seen = _fingerprint(self.path)
        # publishes the replayed journal and drops the corrupt records (or fails: one line);
        # a finished file with nothing to add is left untouched (bitwise)
        if (self._unpublished or self.corrupt or not os.path.exists(self.path)
                or root_problem(got.root)):          # a damaged root is written again
            self.checkpoint(force=True)
        else:                      # the file's records get their second copy before any work
            try:
                durable.keep_copy(self.path)
            except StoreError as exc:
                if isinstance(exc, DiskFull):
                    raise
                raise StoreError(f"cannot keep a copy of {self.path}: {exc}") from None
        if corrupt:
            log.warning("%s: %d corrupt record(s) (%s%s) will be recomputed; they were not "
                        "republished", self.path, len(corrupt), ", ".join(corrupt[:3]),
                        " ..." if len(corrupt) > 3 else "")

    def _remember(self, rec):
        old = self.records.get(rec["key"])
        if store.newer(rec, old):
            self.records[rec["key"]] = {"status": rec["status"], "record_id": rec["record_id"]}
            self._unpublished.append(rec)

    # -------------------------------------------------------------- queries
    def keys_to_run(self, retry_failed: bool) -> list:
        """Keys of the grid's jobs without a record (and, with ``retry_failed``, the failed ones)."""
        out = []
        for j in self.spec.jobs:
            r = self.records.get(j.key)
            if r is None or (retry_failed and r["status"] != "done"):
                out.append(j.key)
        return out

    def counts(self) -> dict:
        """Jobs of the grid: total, done, failed and pending."""
        keys = {j.key for j in self.spec.jobs}
        done = sum(1 for k in keys if self.records.get(k, {}).get("status") == "done")
        failed = sum(1 for k in keys if self.records.get(k, {}).get("status") == "failed")
        return {"jobs": len(keys), "done": done, "failed": failed,
                "pending": len(keys) - done - failed}

    # -------------------------------------------------------------- writing
    def add(self, records) -> None:
        """Journal ``records`` (durably) and checkpoint when due. A full disk raises
        :class:`~fibril_hpc.errors.DiskFull` naming the journal."""
        for rec in records:
            rec = integrity.seal(rec)      # computed here: the frame carries its checksum
            try:
                self.journal.append(rec)
            except OSError as exc:
                if exc.errno in FULL_ERRNOS:
                    raise DiskFull(self.journal.path, "appending to the journal",
                                   exc.strerror) from None
                raise StoreError(f"cannot append to {self.journal.path}: {exc}") from None
            self._remember(rec)
        self.checkpoint()

    def checkpoint(self, force: bool = False) -> None:
        """Fold the journal into the HDF5 file (at most every ``checkpoint_s`` unless ``force``)."""
        if self.changed is not None:      # journal only: the file is no longer ours to replace
            return
        if not force and (not self._unpublished
                          or time.monotonic() - self._last_ckpt < self.checkpoint_s):
            return
        now = _fingerprint(self.path)
        if now != self._seen:
            self._changed("size " + ("gone" if now is None else f"{now[2]} bytes") + ", was "
                          + ("none" if self._seen is None else f"{self._seen[2]} bytes"))
        recs = []
        for r in self._unpublished:
            r = dict(r)
            r.pop("type", None)
            recs.append(r)
        t0 = time.monotonic()
        expect = {k: r["record_id"] for k, r in self.records.items()}
        try:
            store.checkpoint(self.path, self.root_attrs, recs, drop=self.corrupt,
                             verify=_verifier(expect, [r["key"] for r in recs]),
                             keep_previous=True)
        except DamagedFileError as exc:
            if _fingerprint(self.path) == self._seen:      # damaged before this run: salvage
                raise
            self._changed(f"no longer reads: {str(exc)[:120]}")   # changed just now
        self._seen = _fingerprint(self.path)
        self.corrupt = set()
        # the previous generation holds what was published before: the journal pair keeps
        # this checkpoint's records only (their other copy is the file just published)
        self.journal.keep(r["record_id"] for r in self._unpublished)
        self._unpublished = []
        self._last_ckpt = time.monotonic()
        # a checkpoint copies the file: keep its cost below ~10 % of the run however big it gets
        self.checkpoint_s = max(self.checkpoint_s, 10.0 * (self._last_ckpt - t0))

    def _changed(self, detail: str):
        """Stop publishing (the journal keeps every record) and raise PublishedFileChanged."""
        self.changed = PublishedFileChanged(self.path, self.journal.path, detail)
        log.info("%s", self.changed)
        raise self.changed

    def close(self) -> None:
        """Publish what is left, then release the journal and the lock (always, even when the
        last checkpoint fails: its records stay safe in the journal). Once everything is in
        the file, the then empty journal and the lock file are removed: a finished campaign
        leaves its HDF5 file alone beside the grid."""
        published = False
        try:
            self.checkpoint(force=bool(self._unpublished or self.corrupt))
            if self.changed is not None:
                raise self.changed
            if _fingerprint(self.path) != self._seen:       # never drop the second copies
                now = _fingerprint(self.path)               # of a file changed under us
                self._changed("size " + ("gone" if now is None else f"{now[2]} bytes"))
            published = True
        finally:
            if published:
                self.journal.remove()
                durable.remove_previous(self.path)
            else:
                self.journal.close()
            self._unlock(remove=published)

    def _unlock(self, remove: bool = False) -> None:
        if self._lock_fd is None:
            return
        try:
            if remove:              # while still holding it: see the check in __init__
                _remove_if_same(self._lock_fd, self.path + ".lock")
            fcntl.flock(self._lock_fd, fcntl.LOCK_UN)
        finally:
            os.close(self._lock_fd)
            self._lock_fd = None


def _verifier(expect: dict, added):
    """A check of a new checkpoint copy: every record of ``expect`` ({key: record_id}) is in
    it, and the records ``added`` read whole and verify ("" when so, else what is wrong)."""

    def verify(tmp: str) -> str:
        return store.check_written(tmp, expect, added)
    return verify


def _fingerprint(path: str):
    """(device, inode, size, mtime) of the published file (None when there is none): what
    tells the writer that another program changed it since its last checkpoint."""
    try:
        st = os.stat(path)
    except OSError:
        return None
    return (st.st_dev, st.st_ino, st.st_size, st.st_mtime_ns)


def _same_file(fd: int, path: str) -> bool:
    try:
        a, b = os.fstat(fd), os.stat(path)
    except OSError:
        return False
    return (a.st_dev, a.st_ino) == (b.st_dev, b.st_ino)


def _remove_if_same(fd: int, path: str) -> None:
    if _same_file(fd, path):
        try:
            os.unlink(path)
        except OSError:
            pass


def _remove_if_empty(path: str) -> None:
    try:
        if os.path.getsize(path) == 0:
            os.unlink(path)
    except OSError:
        pass


__all__ = ["CampaignWriter", "check_output", "has_second_copies"]
