"""The campaign HDF5 file (with :mod:`fibril_hpc.io.store`, the only h5py importers).

Layout (open it with h5py; every number is dimensionless, see the ``definitions`` attribute)::

    /  attrs: program, format_version, fibril_hpc_version, campaign_yaml (the resolved grid),
              campaign_hash (SHA-256 of the sorted job keys), key_definition, definitions (JSON:
              every normalisation), versions (JSON), layout (this text), created, updated,
              n_jobs (jobs of the grid), extended_from (JSON list of earlier grids' hashes and
              YAML), merged_from (JSON, after ``merge``), units (JSON, a grid given in physical
              units only: the SI value of every unit of its base scene, docs/units.md)
    /jobs/<key>/  attrs: key, record_id, campaign_hash, k_tilde, sigma_tilde, preload_kind,
                         preload, seed, status ("done" or "failed"), message (the error),
                         F_P, F_A, d_tilde_max, d_tilde_at_F_A, n_pillars_in_contact_max, events,
                         wall_s, cg_iterations, cg_solves, fft_pairs (of the simulate call that
                         computed the job; shared by its group_size jobs of one loading path),
                         group_size, rank, host, finished (UTC), scene_yaml, discretisation (JSON),
                         checksum ("sha256:..." of the record; absent in records written before
                         checksums existed, see fibril_hpc/campaign/storage/integrity.py);
                         only with a compliant machine (k_machine < inf; absent otherwise and in
                         older records): k_machine, jumps, F_jump (tension at the jump-off of the
                         final separation), d_machine_tilde_at_F_A; only with
                         solver.confirm: local: confirmed_local, confirmed_global (relaxations
                         of the simulate call ended each way), force_bound_tilde
        loading/{d_tilde, F_tilde, contact_fraction, n_pillars_in_contact}   (load to F_P)
        unloading/{d_tilde, F_tilde, contact_fraction, n_pillars_in_contact} (pull-off)
                  (+ d_machine_tilde, the machine's displacement, with a compliant machine)
    /job_refs     object references to every /jobs/<key> (a second way to each record that
                  survives damage to the link index of /jobs; used by ``salvage``)

Crash safety: the published file is never opened for writing. A checkpoint reads it, adds the
records to that image in memory (libhdf5 never writes to the disk), checks the free space,
writes a temporary file beside it, ``fsync``-s it, reads it back and verifies it, keeps the old
file as ``<file>.previous`` and renames the new one into place; records finished since the last
checkpoint live in ``<file>.journal`` and its mirror ``<file>.journal.mirror`` (see
:mod:`fibril_hpc.campaign.storage.durable`). So a SIGKILL at any moment leaves a file that opens,
plus a journal that the next run (or reader) replays, a full disk leaves the previous file, and
no single damaged or deleted file loses a finished record while the campaign runs (the journal
pair and ``<file>.previous`` are removed when it finishes). Readers never block the writer.
"""

from __future__ import annotations

import datetime as _dt
import glob
import io
import json
import logging
import os
from dataclasses import dataclass

import h5py
import numpy as np

from ..._version import __version__
from ...errors import ConfigError, StoreError
from ...geometry.grid import Lattice
from ...io import h5check
from ...io.results import json_safe, software_versions
from ..plan.keys import KEY_EXCLUDED_SOLVER
from . import durable, integrity
from . import journal as _journal
from .h5read import (
    FORMAT_VERSION,
    PROGRAM,
    REFS,
    H5Read,
    check_written,
    damaged_error,
    read_h5_checked,
    read_h5_records,
    read_h5_salvage,
    read_root,
    root_whole,
    warn_corrupt,
)
from .record import BRANCHES, CURVE_KEYS, OPTIONAL_CURVE_KEYS, SCALAR_KEYS
from .rootcheck import ROOT_LOST

log = logging.getLogger(__name__)

KEY_DEFINITION = ("first 16 hex digits of SHA-256 of the job's single-preload scene as canonical "
                  "JSON (sorted keys) of k_tilde, sigma_tilde, seed, the preload and every field "
                  "that differs from its default, without "
                  + ", ".join("solver." + k for k in KEY_EXCLUDED_SOLVER))


def now() -> str:
    return _dt.datetime.now(_dt.UTC).isoformat(timespec="seconds")


def _write_references(fh, jobs) -> None:
    """(Re)write ``/job_refs``: one object reference per job group, a second way to every
    record that does not depend on the link index of ``/jobs``."""
    if REFS in fh:
        del fh[REFS]
    names = [k for k in jobs if h5check.link_kind(jobs, k) == "hard"]   # never follow a link
    refs = np.empty(len(names), dtype=h5py.ref_dtype)
    for i, k in enumerate(names):
        refs[i] = jobs[k].ref
    fh.create_dataset(REFS, data=refs, dtype=h5py.ref_dtype)


def newer(new: dict, old: dict | None) -> bool:
    """Whether record ``new`` replaces ``old`` for the same key: a done record is final."""
    if old is None:
        return True
    if new.get("record_id") == old.get("record_id"):
        return False
    return old.get("status") != "done"


def accepted_hashes(root: dict) -> set | None:
    """Campaign hashes whose journal frames belong to the file with root attributes ``root``
    (None when there is no file yet: the writer decides)."""
    if not root:
        return None
    out = {root.get("campaign_hash")}
    try:
        out |= {h.get("campaign_hash") for h in json.loads(root.get("extended_from", "[]"))}
    except (ValueError, TypeError, AttributeError):
        pass
    return {h for h in out if h}


@dataclass
class Snapshot:
    """What a reader sees: root attrs, {key: record} (the unchecked ones among them), records
    only in the journal, corrupt records of the HDF5 file, foreign members of ``/jobs``
    (name -> why), keys of the records without a checksum, the journal scan."""

    root: dict
    records: dict
    pending: int
    corrupt: dict
    unchecked_keys: set
    journal: object
    foreign: dict

    @property
    def unchecked(self) -> int:
        """How many records carry no checksum."""
        return len(self.unchecked_keys)


def read_snapshot(path: str, curves: bool = True) -> Snapshot:
    """Journal + HDF5 file, as a reader sees them while a campaign runs. The journal bytes are
    read first so that a checkpoint that happens in between cannot hide a record. Journal
    frames of another campaign, or whose key is no job of the file's grids, are left out."""
    jpath = _journal.journal_path(path)
    jdata = _journal.read_bytes(jpath), _journal.read_bytes(_journal.mirror_path(jpath))
    got = read_h5_checked(path, curves)
    warn_corrupt(path, got)
    scan = _journal.scan_bytes(*jdata, accept=accepted_hashes(got.root),
                               belongs=got.index.belongs)
    msg = scan.message(_journal.journal_path(path))
    if msg:
        log.warning("%s", msg)
    recs = got.records
    unchecked = set(got.unchecked_keys)
    pending = 0
    for _, _, r in scan.records:
        r = dict(r)
        r.pop("type", None)
        if newer(r, recs.get(r["key"])):
            if not curves:
                r.pop("loading", None)
                r.pop("unloading", None)
            recs[r["key"]] = r
            unchecked.discard(r["key"])
            pending += 1
    return Snapshot(got.root, recs, pending, got.corrupt, unchecked, scan, got.foreign)


def read_records(path: str, curves: bool = True) -> tuple[dict, dict, int]:
    """(root attrs, {key: record}, number of records still only in the journal)."""
    s = read_snapshot(path, curves)
    return s.root, s.records, s.pending


def write_record(jobs, rec: dict, sign: bool = True) -> None:
    """Write one record as ``jobs/<key>``, replacing an older one: sealed with its checksum
    when ``sign`` (a record this code computed, or whose own checksum verifies: one that
    carries a checksum that does not verify is refused, StoreError), else as it is (an unchecked
    record copied by ``merge``/``salvage`` stays unchecked: nothing here vouches for it)."""
    key = rec["key"]
    if key in jobs:
        del jobs[key]
    stored = {k: rec[k] for k in SCALAR_KEYS if k in rec and rec[k] is not None}
    for branch in BRANCHES:
        c = rec.get(branch)
        stored[branch] = None if c is None else {
            k: np.asarray(c[k]) for k in CURVE_KEYS + OPTIONAL_CURVE_KEYS
            if k in CURVE_KEYS or c.get(k) is not None}
    if sign:
        if rec.get(integrity.ATTR) is not None and integrity.check(rec) != integrity.OK:
            raise StoreError(f"record {key}: its checksum does not verify; never re-signed")
        stored = integrity.seal(stored)
    elif "checksum" in rec:
        stored["checksum"] = rec["checksum"]
    g = jobs.create_group(key)
    for k, v in stored.items():
        if k not in BRANCHES:
            g.attrs[k] = v
    for branch in BRANCHES:
        c = stored[branch]
        if c is not None:
            cg = g.create_group(branch)
            for k in c:
                cg.create_dataset(k, data=c[k])


def clean_temporaries(path: str) -> None:
    """Remove checkpoint temporaries left by a killed writer (call while holding the lock)."""
    folder = os.path.dirname(os.path.abspath(path)) or "."
    for tmp in glob.glob(os.path.join(folder, glob.escape(durable.tmp_prefix(path)) + "*")):
        try:
            os.unlink(tmp)
        except OSError:  # pragma: no cover
            pass


def checkpoint(path: str, root_attrs: dict, records, drop=(), unsigned=(), verify=None,
               keep_previous: bool = False, exclusive: str | None = None) -> None:
    """Publish ``records`` into ``path`` atomically, leaving out the job groups ``drop``
    (corrupt ones: never republished); the records whose key is in ``unsigned`` are written
    without a new checksum (see :func:`write_record`). ``verify`` and ``keep_previous``: see
    :func:`.durable.publish` (the campaign writer reads the new copy back before publishing it,
    and keeps the old file as ``<file>.previous``). ``exclusive``: the option naming a
    ``path`` that must be new (see :func:`fibril_hpc.io.files.write_bytes_atomically`).

    The new file is built in memory (libhdf5 never writes to disk, so a full disk cannot crash
    it), then written to a temporary file beside ``path`` after a free-space check, ``fsync``-ed
    and renamed into place. ``root_attrs`` are (re)set; the file's other content is kept. A file
    whose records read but whose structure libhdf5 cannot add to (a damaged block elsewhere) is
    rebuilt from what reads and verifies (:func:`_rebuild`): its corrupt records are left out,
    to be recomputed. ENOSPC/EDQUOT becomes :class:`DiskFull`.
    """
    buf = io.BytesIO()
    try:
        if os.path.exists(path):
            with open(path, "rb") as fh:
                buf.write(fh.read())
        mode = "a" if buf.tell() else "w"
    except OSError as exc:
        raise StoreError(f"cannot read {path} for a checkpoint: {exc}") from None
    try:
        _add(buf, mode, root_attrs, records, drop, unsigned)
    except (OSError, RuntimeError, KeyError, ValueError) as exc:
        if mode != "a":
            raise damaged_error(path, exc) from None
        buf = _rebuild(path, root_attrs, records, drop, unsigned, exc)
    durable.publish(path, buf.getbuffer(), verify, keep_previous, exclusive=exclusive)


def _add(buf, mode: str, root_attrs: dict, records, drop=(), unsigned=(), old=()) -> None:
    """Add ``records`` (and ``old`` ones, copied with the checksum they have) to the HDF5 image
    in ``buf``; see :func:`checkpoint`."""
    with h5py.File(buf, mode) as fh:
        if mode == "w":
            fh.attrs["created"] = now()
            fh.attrs["program"] = PROGRAM
        jobs = fh.require_group("jobs")
        for key in drop:
            if key in jobs:
                del jobs[key]
        for rec in old:
            write_record(jobs, rec, sign=False)
        for rec in records:
            write_record(jobs, rec, sign=rec["key"] not in unsigned)
        _write_references(fh, jobs)
        for k, v in root_attrs.items():
            fh.attrs[k] = v
        if "campaign_yaml" in root_attrs and ROOT_LOST in fh.attrs:   # written again whole
            del fh.attrs[ROOT_LOST]
        fh.attrs["updated"] = now()


def _rebuild(path: str, root_attrs: dict, records, drop, unsigned, exc) -> io.BytesIO:
    """A new image of ``path`` holding every record of it that reads and verifies (or is
    unchecked), each with the checksum it has, its other root attributes, and ``records``: what
    a checkpoint publishes when libhdf5 cannot add to the damaged file itself. A file whose
    structure does not read at all is :class:`DamagedFileError` (``salvage`` it)."""
    got = read_h5_checked(path, curves=True)
    new = {r["key"] for r in records}
    log.warning("%s: its HDF5 structure could not be added to (%s); rebuilt from the %d "
                "record(s) that read and verify, %d corrupt left out to be recomputed", path,
                type(exc).__name__, len(got.records), len(got.corrupt))
    keep = {k: v for k, v in got.root.items() if k not in root_attrs and k != "updated"}
    buf = io.BytesIO()
    try:
        _add(buf, "w", {**keep, **root_attrs}, records, unsigned=unsigned,
             old=[r for k, r in got.records.items() if k not in new and k not in drop])
    except (OSError, RuntimeError, KeyError, ValueError) as err:
        raise damaged_error(path, err) from None
    return buf


def root_attrs_for(spec, extended_from=None) -> dict:
    """Root attributes describing a campaign spec."""
    b = spec.base
    lattice = Lattice.of(b.n_side, b.phi, b.elements_per_diameter, b.lattice)
    scaling = lattice.scaling(b.work_of_adhesion)
    defs = dict(scaling.definitions())
    defs["F_A"] = "pull-off force: -min F over the unloading branch, / F_c"
    defs["F_P"] = "force at the end of loading (the preload reached), / F_c"
    defs["contact_fraction"] = "attached area / total pillar-tip area"
    units = {} if b.physical is None else {   # only for a grid in physical units
        "units": json.dumps(json_safe(b.physical.si(lattice)), sort_keys=True)}
    return {
        **units,
        "program": PROGRAM,
        "format_version": FORMAT_VERSION,
        "fibril_hpc_version": __version__,
        "campaign_yaml": spec.resolved_yaml(),
        "campaign_hash": spec.campaign_hash,
        "key_definition": KEY_DEFINITION,
        "definitions": json.dumps(json_safe(defs), sort_keys=True),
        "versions": json.dumps(json_safe(software_versions()), sort_keys=True),
        "layout": __doc__,
        "n_jobs": len(spec.jobs),
        "extended_from": json.dumps(extended_from or []),
    }


def write_merged(path: str, root_attrs: dict, records, unsigned=(), field: str = "--output") \
        -> None:
    """Write a new file (atomically) holding ``records`` (used by ``merge`` and ``salvage``);
    the records of ``unsigned`` keep having no checksum. ``path`` must be new, checked
    atomically as it is written (a file that appeared meanwhile: ConfigError naming
    ``field``)."""
    if os.path.lexists(path):
        raise ConfigError(field, path, "a new file name (it exists)")
    checkpoint(path, root_attrs, records, unsigned=unsigned, exclusive=field)


__all__ = ["read_root", "read_records", "read_h5_records", "read_h5_checked", "read_h5_salvage",
           "read_snapshot", "checkpoint", "root_attrs_for", "write_merged", "write_record",
           "clean_temporaries", "newer", "accepted_hashes", "H5Read", "check_written",
           "Snapshot", "PROGRAM", "REFS", "FORMAT_VERSION", "root_whole"]
