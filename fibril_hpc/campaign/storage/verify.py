"""Checking a whole campaign file (:func:`verify_file`) and rescuing a damaged one
(:func:`salvage_file`).

``verify`` reads every record of the HDF5 file and of its journal, checks each against its
checksum (see :mod:`.integrity`) and says what is wrong: corrupt or unreadable records (by key),
records without a checksum (*unchecked*), members of ``/jobs`` that live elsewhere or are no job
of the file's grids (*foreign*), damaged or foreign journal frames, or an HDF5 structure that
cannot be read at all. Anything but verified records is a finding (exit status 1).

``salvage`` copies every readable record that verifies (and the journal's intact records) into
a new file with the same root attributes, so that the campaign resumes from it (the grid and
its ``campaign_hash`` are kept); corrupt and unreadable records are left out and get recomputed
by the next run. Foreign members are never copied.

A file cut short, emptied or overwritten (while its campaign ran: the writer then stops with
exit status 75 and points here), or whose root attributes are damaged (a flipped byte), is
still salvaged: the records of ``/jobs`` that still read and verify, and every journal frame
whose own checksum verifies, whatever their campaign. Such records belong when their key is the
key of their own stored scene. The new file's root then holds only what the resume needs (the
campaign hash of the journal's records, or the most common one of the file's); the campaign's
next checkpoint writes the rest of it again. Unchecked records are copied only with
``keep_unchecked`` (nothing vouches for them, and a damaged file may hold zeros that read as
numbers), and then without a checksum: they stay unchecked in the new file.
"""

from __future__ import annotations

import os
from collections import Counter
from dataclasses import dataclass, field

from ...errors import ConfigError, DamagedFileError, StoreError, UnknownLayoutError
from . import durable, store
from . import journal as _journal
from .grids import GridIndex
from .rootcheck import repair, root_problem


@dataclass
class Verdict:
    """What :func:`verify_file` found."""

    path: str
    ok: int = 0
    unchecked: int = 0
    corrupt: dict = field(default_factory=dict)        # key -> why
    foreign: dict = field(default_factory=dict)        # name -> why
    in_journal: int = 0
    journal_problem: str = ""
    damaged: str = ""                                   # the HDF5 structure cannot be read
    #: what is wrong with the root attributes a reader relies on (see :mod:`.rootcheck`)
    root_problem: str = ""

    @property
    def clean(self) -> bool:
        """Whether every record is vouched for: nothing damaged, unchecked or foreign."""
        return not (self.corrupt or self.foreign or self.unchecked or self.journal_problem
                    or self.damaged or self.root_problem)

    def lines(self) -> list:
        """The report, one line per finding."""
        if self.damaged:
            return [self.damaged]
        out = [f"{self.path}: {self.ok} record(s) verified, {len(self.corrupt)} corrupt, "
               f"{self.unchecked} unchecked (no checksum), {len(self.foreign)} foreign, "
               f"{self.in_journal} in the journal"]
        if self.root_problem:
            out.append(f"  root attributes damaged: {self.root_problem}; repair: "
                       f"{repair(self.path)}")
        for k, why in sorted(self.corrupt.items()):
            out.append(f"  corrupt {k}: {why} (left out by every reader; resume recomputes it)")
        for k, why in sorted(self.foreign.items()):
            out.append(f"  foreign {k}: {why} (never counted, published or copied)")
        if self.unchecked:
            out.append(f"  {self.unchecked} unchecked record(s): no checksum vouches for them "
                       "(written before checksums, or stripped of theirs); left out of reports "
                       "and exports unless --include-unchecked, never given a checksum")
        if self.journal_problem:
            out.append("  " + self.journal_problem)
        if self.clean:
            out.append("  no damage found")
        return out


def verify_file(path: str) -> Verdict:
    """Check every record of the campaign file ``path`` and its journal."""
    v = Verdict(path)
    try:
        got = store.read_h5_checked(path, curves=True)
    except DamagedFileError as exc:
        v.damaged = str(exc)
        return v
    except UnknownLayoutError:
        raise
    except StoreError as exc:         # e.g. a flipped byte in the root's program attribute
        v.damaged = (f"{exc}; if it is a damaged campaign file, "
                     f"`fibril-campaign salvage {path} -o NEW.h5` copies every record that "
                     "reads and verifies")
        return v
    v.root_problem = root_problem(got.root)
    v.corrupt = dict(got.corrupt)
    v.foreign = dict(got.foreign)
    v.unchecked = got.unchecked
    v.ok = len(got.records) - got.unchecked
    jpath = _journal.journal_path(path)
    scan = _journal.scan_pair(jpath, store.accepted_hashes(got.root), got.index.belongs)
    v.in_journal = len(scan.records)
    v.journal_problem = scan.message(jpath)
    return v


def salvage_file(path: str, output: str, keep_unchecked: bool = False) -> dict:
    """Copy every readable, verified record of ``path`` (and its journal) into the new file
    ``output``. Returns counts: copied, corrupt, unchecked_left_out, from_journal."""
    if os.path.lexists(output):
        raise ConfigError("--output", output, "a new file name (it exists)")
    got = _read_any(path)
    prev = _read_any(durable.previous_path(path)) if os.path.exists(
        durable.previous_path(path)) else store.H5Read()
    if not store.root_whole(got.root) and store.root_whole(prev.root):
        got.root = prev.root          # the previous generation's root, whole: the grid
        got.index = prev.index
    whole = store.root_whole(got.root)
    root = dict(got.root) if whole else {}
    recs = {}
    left_unchecked = 0
    for k, r in got.records.items():
        if k in got.unchecked_keys and not keep_unchecked:
            left_unchecked += 1
            continue
        recs[k] = r
    for k, r in prev.records.items():     # the generation before the last checkpoint
        if (k not in prev.unchecked_keys or keep_unchecked) and store.newer(r, recs.get(k)):
            recs[k] = r
            got.corrupt.pop(k, None)
            if k in prev.unchecked_keys:
                got.unchecked_keys.add(k)
    # a lost root names no grid: a frame belongs by its own stored scene (see GridIndex)
    index = got.index if whole else GridIndex.of_root({}, trusted=False)
    scan = _journal.scan_pair(_journal.journal_path(path),
                              store.accepted_hashes(root) if whole else None, index.belongs)
    if not whole:
        if not (recs or scan.records or got.corrupt):
            raise ConfigError("file", path, "a campaign file, or what is left of one (no record "
                              "under /jobs verifies and no journal frame does)")
        root = _lost_root(got.root, recs, scan)
    from_journal = 0
    journal_keys = set()
    for _, _, r in scan.records:
        r = dict(r)
        r.pop("type", None)
        if store.newer(r, recs.get(r["key"])):
            recs[r["key"]] = r
            journal_keys.add(r["key"])
            from_journal += 1
    root.pop("created", None)
    root.pop("updated", None)
    root.setdefault("program", store.PROGRAM)
    # an HDF5 text attribute is UTF-8: a name that is not is kept with backslash escapes
    root["salvaged_from"] = os.fsencode(os.path.abspath(path)).decode("utf-8", "backslashreplace")
    unsigned = {k for k in got.unchecked_keys if k in recs} - journal_keys
    store.write_merged(output, root, list(recs.values()), unsigned=unsigned)
    return {"copied": len(recs), "corrupt": len(got.corrupt), "foreign": len(got.foreign),
            "unchecked_left_out": left_unchecked, "from_journal": from_journal}


def _read_any(path: str) -> store.H5Read:
    """Every record of ``path`` that reads and verifies (checked; tolerant when it is damaged,
    cut short, overwritten or its root is damaged). A newer layout is refused."""
    try:
        return store.read_h5_checked(path, curves=True)
    except UnknownLayoutError:
        raise
    except StoreError:
        return store.read_h5_salvage(path)


def _lost_root(damaged: dict, recs: dict, scan) -> dict:
    """Root attributes for the salvage of a file whose root is lost or damaged: what resuming
    needs (the campaign hash of the journal's records, else the most common of the file's)."""
    hashes = Counter(r.get("campaign_hash") for _, _, r in scan.records) \
        or Counter(r.get("campaign_hash") for r in recs.values())
    out = {"program": store.PROGRAM, "format_version": store.FORMAT_VERSION,
           "root_lost": "the root attributes of the salvaged file did not read whole; the "
                        "campaign's next checkpoint writes them again"}
    if hashes:
        out["campaign_hash"] = hashes.most_common(1)[0][0]
    return out


__all__ = ["verify_file", "salvage_file", "Verdict"]
