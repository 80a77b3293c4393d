"""Reading a campaign HDF5 file record by record, each checked against its checksum.

With :mod:`.store` (writing) the only h5py importers of the campaign wing. A record that fails
its checksum or cannot be read is *corrupt*: left out and listed (see :class:`H5Read`); a file
whose structure cannot be read raises :class:`~fibril_hpc.errors.DamagedFileError` (one line).
``tolerant`` reading (for ``salvage``) takes whatever still reads, attribute by attribute, and
reaches records whose name is lost through the object references of ``/job_refs``.
"""

from __future__ import annotations

import logging
import os
from dataclasses import dataclass, field

import h5py
import numpy as np

from ...errors import DamagedFileError, StoreError
from . import integrity
from .record import BRANCHES, CURVE_KEYS, OPTIONAL_CURVE_KEYS

log = logging.getLogger(__name__)

PROGRAM = "fibril-hpc campaign"
#: root dataset of object references to every job group (written by :mod:`.store`)
REFS = "job_refs"


def _attr(v):
    if isinstance(v, bytes):
        return v.decode()
    if isinstance(v, np.generic):
        return v.item()
    return v


def damaged_error(path: str, exc) -> DamagedFileError:
    """The one-line error of a file whose HDF5 structure cannot be read (points to salvage)."""
    return DamagedFileError(
        f"{path}: the HDF5 structure is damaged ({type(exc).__name__}: "
        f"{str(exc).splitlines()[0][:160] if str(exc) else ''}); "
        f"`fibril-campaign salvage {path} -o NEW.h5` copies every readable, verified record")


def read_root(path: str) -> dict:
    """Root attributes of a campaign file (StoreError if it is not one)."""
    try:
        with h5py.File(path, "r") as fh:
            attrs = {k: _attr(v) for k, v in fh.attrs.items()}
    except FileNotFoundError:
        raise StoreError(f"cannot open {path}: no such file") from None
    except Exception as exc:  # noqa: BLE001
        if _is_hdf5(path):
            raise damaged_error(path, exc) from None
        raise StoreError(f"cannot open {path} as HDF5: {exc}") from None
    if attrs.get("program") != PROGRAM:
        raise StoreError(f"{path} is not a fibril-hpc campaign file")
    return attrs


def _is_hdf5(path: str) -> bool:
    """Whether ``path`` starts like an HDF5 file (signature at offset 0)."""
    try:
        with open(path, "rb") as fh:
            return fh.read(8) == b"\x89HDF\r\n\x1a\n"
    except OSError:
        return False


def _read_group(g) -> dict:
    rec = {k: _attr(v) for k, v in g.attrs.items()}
    for branch in BRANCHES:
        if branch in g:
            rec[branch] = {k: g[branch][k][()] for k in CURVE_KEYS + OPTIONAL_CURVE_KEYS
                           if k in g[branch]}
        else:
            rec[branch] = None
    return rec


@dataclass
class H5Read:
    """What the HDF5 file holds: verified (or unchecked, older) records and the corrupt ones."""

    root: dict = field(default_factory=dict)
    records: dict = field(default_factory=dict)
    corrupt: dict = field(default_factory=dict)      # key -> why
    unchecked: int = 0


def read_h5_checked(path: str, curves: bool = True, tolerant: bool = False) -> H5Read:
    """Every record of the HDF5 file, each checked against its checksum (see
    :mod:`.integrity`). A record that does not match, or cannot be read, is left out and listed
    in ``corrupt``; a damaged file structure raises :class:`DamagedFileError` (one line) unless
    ``tolerant`` (salvage: take whatever still reads, attribute by attribute)."""
    out = H5Read()
    if not os.path.exists(path):
        return out
    try:
        fh = h5py.File(path, "r")
    except Exception as exc:  # noqa: BLE001
        if tolerant:
            return out
        if _is_hdf5(path):
            raise damaged_error(path, exc) from None
        raise StoreError(f"cannot open {path} as HDF5: {exc}") from None
    with fh:
        try:
            out.root = _root_attrs(fh, tolerant)
            jobs = _get(fh, "jobs", tolerant)
            keys = _job_names(jobs, tolerant)
        except Exception as exc:  # noqa: BLE001
            raise damaged_error(path, exc) from None
        if out.root.get("program") != PROGRAM and not tolerant:
            raise StoreError(f"{path} is not a fibril-hpc campaign file")
        for k in keys:
            try:
                rec = _read_group(jobs[k])
            except Exception as exc:  # noqa: BLE001 - a damaged group is one corrupt record
                out.corrupt[k] = f"unreadable ({type(exc).__name__})"
                continue
            state = integrity.check(rec)
            if state == integrity.CORRUPT or rec.get("key", k) != k:
                out.corrupt[k] = "checksum mismatch"
                continue
            out.unchecked += state == integrity.UNCHECKED
            if not curves:
                rec.pop("loading", None)
                rec.pop("unloading", None)
            out.records[k] = rec
        if tolerant:
            _salvage_by_reference(fh, out, curves)
    return out


def _get(fh, name: str, tolerant: bool):
    if not tolerant:
        return fh.get(name)
    try:
        return fh.get(name)
    except Exception:  # noqa: BLE001 - a damaged group: reach its members by reference
        return None


def _salvage_by_reference(fh, out: H5Read, curves: bool) -> None:
    """Records that their name no longer reaches (a damaged link index of ``/jobs``), opened
    through ``/job_refs`` (object references, i.e. addresses): only verified ones are taken."""
    try:
        refs = fh[REFS][()]
    except Exception:  # noqa: BLE001 - no index (older file) or a damaged one
        return
    for ref in refs:
        try:
            rec = _read_group(fh[ref])
        except Exception:  # noqa: BLE001
            continue
        key = rec.get("key")
        if not isinstance(key, str) or key in out.records:
            continue
        if integrity.check(rec) != integrity.OK:
            continue
        out.corrupt.pop(key, None)
        if not curves:
            rec.pop("loading", None)
            rec.pop("unloading", None)
        out.records[key] = rec


def _root_attrs(fh, tolerant: bool) -> dict:
    if not tolerant:
        return {k: _attr(v) for k, v in fh.attrs.items()}
    out = {}
    try:
        names = list(fh.attrs)
    except Exception:  # noqa: BLE001
        return out
    for k in names:
        try:
            out[k] = _attr(fh.attrs[k])
        except Exception:  # noqa: BLE001 - a damaged attribute is left out
            pass
    return out


def _job_names(jobs, tolerant: bool) -> list:
    if jobs is None:
        return []
    if not tolerant:
        return list(jobs)
    names = []
    try:
        n = jobs.id.get_num_objs()
    except Exception:  # noqa: BLE001
        return names
    for i in range(n):
        try:
            names.append(jobs.id.get_objname_by_idx(i).decode())
        except Exception:  # noqa: BLE001 - a damaged link is skipped
            pass
    return names


def read_h5_salvage(path: str) -> H5Read:
    """Whatever still reads and verifies in a damaged campaign file (see :mod:`.verify`)."""
    return read_h5_checked(path, curves=True, tolerant=True)


def warn_corrupt(path: str, got: H5Read) -> None:
    """One warning line naming the corrupt records of ``got`` (none when there are none)."""
    if got.corrupt:
        keys = sorted(got.corrupt)
        log.warning("%s: %d corrupt record(s) left out (%s%s); `fibril-campaign verify %s` lists "
                    "them, resuming recomputes them", path, len(keys), ", ".join(keys[:3]),
                    " ..." if len(keys) > 3 else "", path)


def read_h5_records(path: str, curves: bool = True) -> tuple[dict, dict]:
    """(root attrs, {key: record}) from the HDF5 file alone (corrupt records left out)."""
    got = read_h5_checked(path, curves)
    warn_corrupt(path, got)
    return got.root, got.records


__all__ = ["PROGRAM", "REFS", "H5Read", "damaged_error", "read_root",
           "read_h5_checked", "read_h5_salvage", "read_h5_records", "warn_corrupt"]
