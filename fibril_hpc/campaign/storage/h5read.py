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

from ...errors import DamagedFileError, StoreError, UnknownLayoutError
from ...io import h5check, isolate
from . import integrity
from .grids import GridIndex, grid_matches
from .rootcheck import root_problem
from .record import BRANCHES, CURVE_KEYS, CURVE_KINDS, OPTIONAL_CURVE_KEYS, layout_problem

log = logging.getLogger(__name__)

PROGRAM = "fibril-hpc campaign"
#: the layout version this code writes and the newest it reads (``format_version``)
FORMAT_VERSION = 1
#: root dataset of object references to every job group (written by :mod:`.store`)
REFS = "job_refs"


def damaged_error(path: str, exc) -> DamagedFileError:
    """The one-line error of a file whose HDF5 structure cannot be read (points to salvage)."""
    return DamagedFileError(
        f"{path}: the HDF5 structure is damaged ({type(exc).__name__}: "
        f"{str(exc).splitlines()[0][:160] if str(exc) else ''}); "
        f"`fibril-campaign salvage {path} -o NEW.h5` copies every readable, verified record")


def read_root(path: str) -> dict:
    """Root attributes of a campaign file (StoreError if it is not one). Read in a child
    process that cannot hang the caller (:mod:`fibril_hpc.io.isolate`); a FIFO, device or
    folder is refused at once."""
    h5check.check_regular_file(path)
    return isolate.run_isolated(_read_root, path, what=path)


def check_layout_version(root: dict, path: str) -> None:
    """Refuse (:class:`UnknownLayoutError`, one line) a file whose ``format_version`` is not a
    layout this code knows (newer, or not a whole number); a root without one (damaged, or
    salvaged from a lost root) is left to the other checks."""
    v = root.get("format_version")
    if v is None:
        return
    try:
        ok = int(v) == v and 1 <= int(v) <= FORMAT_VERSION
    except (TypeError, ValueError, OverflowError):
        ok = False
    if not ok:
        raise UnknownLayoutError(
            f"{path}: layout version (format_version) {str(v)[:40]!s} is not one this "
            f"fibril-hpc reads (1 to {FORMAT_VERSION}); read it with the fibril-hpc that wrote "
            "it, or a newer one")


def _read_root(path: str) -> dict:
    try:
        with h5py.File(path, "r") as fh:
            attrs = h5check.read_attrs(fh)
    except StoreError as exc:
        raise StoreError(f"{path}: {exc}") from None
    except FileNotFoundError:
        raise StoreError(f"cannot open {path}: no such file") from None
    except Exception as exc:  # noqa: BLE001
        if _is_hdf5(path):
            raise damaged_error(path, exc) from None
        raise StoreError(f"cannot open {path} as HDF5: {exc}") from None
    if attrs.get("program") != PROGRAM:
        raise StoreError(f"{path} is not a fibril-hpc campaign file")
    check_layout_version(attrs, path)
    return attrs


def root_whole(root: dict) -> bool:
    """Whether root attributes read from a file can be trusted as they are: they say it is a
    campaign file, and its grid rebuilds to its campaign hash."""
    return root.get("program") == PROGRAM and grid_matches(root)


def _is_hdf5(path: str) -> bool:
    """Whether ``path`` starts like an HDF5 file (signature at offset 0)."""
    try:
        with open(path, "rb") as fh:
            return fh.read(8) == b"\x89HDF\r\n\x1a\n"
    except OSError:
        return False


def _read_group(g) -> dict:
    """One job group through the checked path (:mod:`fibril_hpc.h5check`): hard links only,
    data in the file, the layout's dtypes and shapes (StoreError / ForeignError otherwise)."""
    rec = h5check.read_attrs(g)
    for branch in BRANCHES:
        bg = h5check.member(g, branch, h5py.Group)
        rec[branch] = None if bg is None else {
            k: v for k in CURVE_KEYS + OPTIONAL_CURVE_KEYS
            if (v := h5check.read_dataset(bg, k, CURVE_KINDS[k])) is not None}
    problem = layout_problem(rec)
    if problem:
        raise StoreError(f"{g.name}: not the layout ({problem})")
    return rec


def _open_job(jobs, k: str):
    """The group ``jobs/<k>`` (hard link only; ForeignError / StoreError otherwise)."""
    g = h5check.member(jobs, k)
    if not isinstance(g, h5py.Group):
        raise StoreError(f"/jobs/{k} is not a group")
    return g


@dataclass
class H5Read:
    """What the HDF5 file holds: verified (or unchecked, older) records and the corrupt ones."""

    root: dict = field(default_factory=dict)
    records: dict = field(default_factory=dict)
    corrupt: dict = field(default_factory=dict)      # key -> why
    #: members of /jobs that nothing vouches for as this file's own: links to elsewhere,
    #: data stored elsewhere, keys that are no job of the file's grids (name -> why)
    foreign: dict = field(default_factory=dict)
    #: keys of ``records`` without a checksum (written before checksums, or stripped of it)
    unchecked_keys: set = field(default_factory=set)
    #: the file's grids (which keys belong)
    index: GridIndex = field(default_factory=GridIndex)

    @property
    def unchecked(self) -> int:
        """How many records carry no checksum."""
        return len(self.unchecked_keys)


def read_h5_checked(path: str, curves: bool = True, tolerant: bool = False) -> H5Read:
    """Every record of the HDF5 file, each checked against its checksum (see
    :mod:`.integrity`). A record that does not match, or cannot be read, is left out and listed
    in ``corrupt``; a damaged file structure raises :class:`DamagedFileError` (one line) unless
    ``tolerant`` (salvage: take whatever still reads, attribute by attribute). Read in a child
    process, so that a file that makes libhdf5 loop is a DamagedFileError, not a hang
    (:mod:`fibril_hpc.io.isolate`)."""
    if not os.path.exists(path):
        return H5Read()
    h5check.check_regular_file(path)   # a FIFO, device or folder: one line at once, no stall
    return isolate.run_isolated(_read_h5_checked, path, curves, tolerant, what=path)


def _read_h5_checked(path: str, curves: bool, tolerant: bool) -> H5Read:
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
        except h5check.ForeignError:
            raise
        except Exception as exc:  # noqa: BLE001
            raise damaged_error(path, exc) from None
        if out.root.get("program") != PROGRAM and not tolerant:
            raise StoreError(f"{path} is not a fibril-hpc campaign file")
        check_layout_version(out.root, path)
        # a damaged root (a flipped byte in its grid or hash) must not make the records
        # foreign; they then belong by their own stored scene, and still only when their
        # checksum verifies
        out.index = GridIndex.of_root(out.root, trusted=not root_problem(out.root))
        for k in keys:
            try:
                rec = _read_group(_open_job(jobs, k))
            except h5check.ForeignError as exc:
                out.foreign[k] = str(exc)
                continue
            except Exception as exc:  # noqa: BLE001 - a damaged group is one corrupt record
                out.corrupt[k] = _why(exc)
                continue
            _classify(out, k, rec, curves)
        if tolerant:
            _salvage_by_reference(fh, out, curves)
    return out


def _why(exc) -> str:
    if isinstance(exc, StoreError):
        return "unreadable (" + str(exc).split(": ", 1)[-1][:200] + ")"
    return f"unreadable ({type(exc).__name__})"


def _classify(out: H5Read, k: str, rec: dict, curves: bool) -> None:
    """File a record that reads: corrupt (checksum or name mismatch), foreign (not a job of
    the file's grids), else a record (unchecked when it carries no checksum)."""
    state = integrity.check(rec)
    if state == integrity.CORRUPT or rec.get("key") != k:
        out.corrupt[k] = "checksum mismatch" if state == integrity.CORRUPT else \
            "stored under another key's name"
        return
    if not out.index.belongs(rec):
        out.foreign[k] = "its key is no job of the file's grid(s)"
        return
    if state == integrity.UNCHECKED:
        out.unchecked_keys.add(k)
    if not curves:
        rec.pop("loading", None)
        rec.pop("unloading", None)
    out.records[k] = rec


def _get(fh, name: str, tolerant: bool):
    try:
        return h5check.member(fh, name, h5py.Group)
    except h5check.ForeignError as exc:   # /jobs itself elsewhere: nothing here is this file's
        if tolerant:
            return None
        raise h5check.ForeignError(f"{fh.filename}: {exc}; not a campaign file of its own") \
            from None
    except Exception:  # noqa: BLE001 - a damaged group: reach its members by reference
        if tolerant:
            return None
        raise


def _salvage_by_reference(fh, out: H5Read, curves: bool) -> None:
    """Records that their name no longer reaches (a damaged link index of ``/jobs``), opened
    through ``/job_refs`` (object references, i.e. addresses): only verified ones are taken."""
    try:
        ds = h5check.member(fh, REFS, h5py.Dataset)
        h5check.check_dataset(ds, "O", 1)
        refs = ds[()]
    except Exception:  # noqa: BLE001 - no index (older file) or a damaged one
        return
    for ref in refs:
        try:
            g = fh[ref]
            if not isinstance(g, h5py.Group):     # an address in this file (never a link)
                continue
            rec = _read_group(g)
        except Exception:  # noqa: BLE001
            continue
        key = rec.get("key")
        if not isinstance(key, str) or key in out.records:
            continue
        if integrity.check(rec) != integrity.OK or not out.index.belongs(rec):
            continue
        out.corrupt.pop(key, None)
        if not curves:
            rec.pop("loading", None)
            rec.pop("unloading", None)
        out.records[key] = rec


def _root_attrs(fh, tolerant: bool) -> dict:
    if not tolerant:
        return h5check.read_attrs(fh)
    out = {}
    try:
        names = list(fh.attrs)
    except Exception:  # noqa: BLE001
        return out
    for k in names:
        try:
            out[k] = h5check.read_attr(fh, k)
        except Exception:  # noqa: BLE001 - a damaged attribute is left out
            pass
    return out


def _job_names(jobs, tolerant: bool) -> list:
    if jobs is None:
        return []
    if not tolerant:
        return h5check.names(jobs)
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


def check_written(path: str, expect: dict, full) -> str:
    """What is wrong with a campaign file just written ("" when nothing): every key of
    ``expect`` ({key: record_id}) must be a job group with that ``record_id``, and the records
    of the keys ``full`` (the ones just added) must read whole and verify. Cheap: the other
    records are checked by their ``record_id`` only (their bytes were copied unchanged, and the
    caller compares the file's bytes with what it meant to write)."""
    try:
        with h5py.File(path, "r") as fh:
            jobs = h5check.member(fh, "jobs", h5py.Group)
            for k, rid in expect.items():
                g = _open_job(jobs, k)
                if h5check.read_attr(g, "record_id") != rid:
                    return f"record {k} is not the one expected"
            for k in full:
                rec = _read_group(_open_job(jobs, k))
                if integrity.check(rec) == integrity.CORRUPT or rec.get("key") != k:
                    return f"record {k} does not verify"
    except Exception as exc:  # noqa: BLE001 - anything unreadable is the finding
        return f"{type(exc).__name__}: {str(exc).splitlines()[0][:120] if str(exc) else ''}"
    return ""


def read_h5_records(path: str, curves: bool = True) -> tuple[dict, dict]:
    """(root attrs, {key: record}) from the HDF5 file alone (corrupt records left out)."""
    got = read_h5_checked(path, curves)
    warn_corrupt(path, got)
    return got.root, got.records


__all__ = ["PROGRAM", "FORMAT_VERSION", "REFS", "check_layout_version", "root_whole", "H5Read",
           "check_written",
           "damaged_error", "read_root",
           "read_h5_checked", "read_h5_salvage", "read_h5_records", "warn_corrupt"]
