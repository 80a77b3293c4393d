"""The campaign HDF5 file (with :mod:`fibril_hpc.store`, the only h5py importers).

Layout (open it with h5py; every number is dimensionless, see the ``definitions`` attribute)::

    /  attrs: program, format_version, fibril_hpc_version, campaign_yaml (the resolved grid),
              campaign_hash (SHA-256 of the sorted job keys), key_definition, definitions (JSON:
              every normalisation), versions (JSON), layout (this text), created, updated,
              n_jobs (jobs of the grid), extended_from (JSON list of earlier grids' hashes and
              YAML), merged_from (JSON, after ``merge``)
    /jobs/<key>/  attrs: key, record_id, campaign_hash, k_tilde, sigma_tilde, preload_kind,
                         preload, seed, status ("done" or "failed"), message (the error),
                         F_P, F_A, d_tilde_max, d_tilde_at_F_A, n_pillars_in_contact_max, events,
                         wall_s, cg_iterations, cg_solves, fft_pairs (of the simulate call that
                         computed the job; shared by its group_size jobs of one loading path),
                         group_size, rank, host, finished (UTC), scene_yaml, discretisation (JSON)
        loading/{d_tilde, F_tilde, contact_fraction, n_pillars_in_contact}   (load to F_P)
        unloading/{d_tilde, F_tilde, contact_fraction, n_pillars_in_contact} (pull-off)

Crash safety: the published file is never opened for writing. A checkpoint copies it to a
temporary file beside it, adds the records, ``fsync``-s and renames it into place; records
finished since the last checkpoint live in ``<file>.journal`` (see
:mod:`fibril_hpc.campaign.journal`). So a SIGKILL at any moment leaves a file that opens, plus a
journal that the next run (or reader) replays. Readers never block the writer.
"""

from __future__ import annotations

import datetime as _dt
import glob
import json
import os
import shutil
import tempfile

import h5py
import numpy as np

from ..errors import StoreError
from ..files import discard_on_failure, fsync_dir
from . import journal as _journal
from .record import BRANCHES, CURVE_KEYS, SCALAR_KEYS
from .spec import KEY_EXCLUDED_SOLVER

PROGRAM = "fibril-hpc campaign"
FORMAT_VERSION = 1
KEY_DEFINITION = ("first 16 hex digits of SHA-256 of the job's single-preload scene as canonical "
                  "JSON (sorted keys) of k_tilde, sigma_tilde, seed, the preload and every field "
                  "that differs from its default, without "
                  + ", ".join("solver." + k for k in KEY_EXCLUDED_SOLVER))


def now() -> str:
    return _dt.datetime.now(_dt.UTC).isoformat(timespec="seconds")


def _attr(v):
    if isinstance(v, bytes):
        return v.decode()
    if isinstance(v, np.generic):
        return v.item()
    return v


def is_campaign_file(path: str) -> bool:
    """Whether ``path`` is an HDF5 file written by fibril-campaign."""
    try:
        with h5py.File(path, "r") as fh:
            return fh.attrs.get("program") == PROGRAM
    except OSError:
        return False


def read_root(path: str) -> dict:
    """Root attributes of a campaign file (StoreError if it is not one)."""
    try:
        with h5py.File(path, "r") as fh:
            attrs = {k: _attr(v) for k, v in fh.attrs.items()}
    except OSError as exc:
        raise StoreError(f"cannot open {path} as HDF5: {exc}") from None
    if attrs.get("program") != PROGRAM:
        raise StoreError(f"{path} is not a fibril-hpc campaign file")
    return attrs


def _read_group(g, curves: bool) -> dict:
    rec = {k: _attr(v) for k, v in g.attrs.items()}
    if curves:
        for branch in BRANCHES:
            if branch in g:
                rec[branch] = {k: g[branch][k][()] for k in CURVE_KEYS if k in g[branch]}
            else:
                rec[branch] = None
    return rec


def read_h5_records(path: str, curves: bool = True) -> tuple[dict, dict]:
    """(root attrs, {key: record}) from the HDF5 file alone."""
    if not os.path.exists(path):
        return {}, {}
    try:
        with h5py.File(path, "r") as fh:
            root = {k: _attr(v) for k, v in fh.attrs.items()}
            if root.get("program") != PROGRAM:
                raise StoreError(f"{path} is not a fibril-hpc campaign file")
            jobs = fh.get("jobs")
            recs = {} if jobs is None else {k: _read_group(jobs[k], curves) for k in jobs}
    except OSError as exc:
        raise StoreError(f"cannot open {path} as HDF5: {exc}") from None
    return root, recs


def newer(new: dict, old: dict | None) -> bool:
    """Whether record ``new`` replaces ``old`` for the same key: a done record is final."""
    if old is None:
        return True
    if new.get("record_id") == old.get("record_id"):
        return False
    return old.get("status") != "done"


def read_records(path: str, curves: bool = True) -> tuple[dict, dict, int]:
    """(root attrs, {key: record}, number of records still only in the journal): what a reader
    sees while a campaign runs. The journal is read first so that a checkpoint that happens
    in between cannot hide a record."""
    jrecs, _ = _journal.read(_journal.journal_path(path))
    root, recs = read_h5_records(path, curves)
    pending = 0
    for r in jrecs:
        if r.get("type") != "job":
            continue
        r = dict(r)
        r.pop("type")
        if newer(r, recs.get(r["key"])):
            if not curves:
                r.pop("loading", None)
                r.pop("unloading", None)
            recs[r["key"]] = r
            pending += 1
    return root, recs, pending


def _write_record(jobs, rec: dict) -> None:
    key = rec["key"]
    if key in jobs:
        del jobs[key]
    g = jobs.create_group(key)
    for k in SCALAR_KEYS:
        if k in rec and rec[k] is not None:
            g.attrs[k] = rec[k]
    for branch in BRANCHES:
        c = rec.get(branch)
        if c is not None:
            cg = g.create_group(branch)
            for k in CURVE_KEYS:
                cg.create_dataset(k, data=np.asarray(c[k]))


def clean_temporaries(path: str) -> None:
    """Remove checkpoint temporaries left by a killed writer (call while holding the lock)."""
    folder = os.path.dirname(os.path.abspath(path)) or "."
    for tmp in glob.glob(os.path.join(folder, "." + os.path.basename(path) + ".ckpt-*")):
        try:
            os.unlink(tmp)
        except OSError:  # pragma: no cover
            pass


def checkpoint(path: str, root_attrs: dict, records) -> None:
    """Publish ``records`` into ``path`` atomically: copy, add, fsync, rename.

    ``root_attrs`` are (re)set on the root; an existing file's other content is kept.
    """
    folder = os.path.dirname(os.path.abspath(path)) or "."
    fd, tmp = tempfile.mkstemp(prefix="." + os.path.basename(path) + ".ckpt-", dir=folder)
    os.close(fd)
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(tmp, 0o666 & ~umask)
    with discard_on_failure(tmp, path):
        if os.path.exists(path):
            shutil.copyfile(path, tmp)
            mode = "a"
        else:
            mode = "w"
        with h5py.File(tmp, mode) as fh:
            if mode == "w":
                fh.attrs["created"] = now()
                fh.attrs["program"] = PROGRAM
            jobs = fh.require_group("jobs")
            for rec in records:
                _write_record(jobs, rec)
            for k, v in root_attrs.items():
                fh.attrs[k] = v
            fh.attrs["updated"] = now()
        with open(tmp, "rb+") as fh:
            os.fsync(fh.fileno())
        os.replace(tmp, path)
        fsync_dir(folder)


def root_attrs_for(spec, extended_from=None) -> dict:
    """Root attributes describing a campaign spec."""
    from .._version import __version__
    from ..grid import Lattice
    from ..results import json_safe, software_versions

    b = spec.base
    scaling = Lattice.of(b.n_side, b.phi, b.elements_per_diameter).scaling(b.work_of_adhesion)
    defs = dict(scaling.definitions())
    defs["F_A"] = "pull-off force: -min F over the unloading branch, / F_c"
    defs["F_P"] = "force at the end of loading (the preload reached), / F_c"
    defs["contact_fraction"] = "attached area / total pillar-tip area"
    return {
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


def write_merged(path: str, root_attrs: dict, records) -> None:
    """Write a new file (atomically) holding ``records`` (used by ``merge``)."""
    if os.path.exists(path):
        raise StoreError(f"{path} exists; choose a new output name")
    checkpoint(path, root_attrs, records)


__all__ = ["read_root", "read_records", "read_h5_records", "checkpoint", "root_attrs_for",
           "write_merged", "is_campaign_file", "clean_temporaries", "newer"]
