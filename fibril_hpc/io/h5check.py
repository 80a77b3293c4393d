"""Checked reading of HDF5 files that may come from anywhere: the ONE way every reader of
fibril-hpc (single-run files and campaign files) reaches a group, an attribute or a dataset.

Rules (each violation is a :class:`StoreError` of one line; :class:`ForeignError` when the data
lives outside the file):

- a member is reached only through a *hard* link: soft links (and so soft-link loops) and
  external links to other files are never followed;
- a dataset is read only when its raw data lives in the file: external raw storage (e.g. bytes
  of ``/etc/passwd``) and virtual datasets (data mapped from other files) are refused;
- a dataset's dtype kind and number of dimensions are checked, and its size against a cap,
  *before* it is read, so a crafted shape never becomes a huge allocation;
- an attribute is read only when it is a scalar number or a text (its dtype and shape are
  checked before reading).

Nothing here follows an object reference or recurses; the callers read a fixed layout.
"""

from __future__ import annotations

import os
import stat

import h5py
import numpy as np

from ..errors import StoreError

#: most elements a checked dataset may have (a curve of 10^7 points is 80 MB)
MAX_ELEMENTS = 10_000_000
#: most bytes of one text attribute (a stored scene with a measured height map stays far below)
MAX_TEXT = 64 << 20

#: dtype kinds by name: float, integer (signed or unsigned), numbers (both)
FLOAT = "f"
INT = "iu"
NUMBER = "fiub"


Group = h5py.Group
Dataset = h5py.Dataset


class ForeignError(StoreError):
    """The object or its data lives outside the file (external link, external storage, virtual
    dataset, soft link): nothing in this file vouches for it."""


#: what a path that is not a regular file is (``stat`` mode test -> words)
_KINDS = ((stat.S_ISFIFO, "a FIFO (named pipe)"), (stat.S_ISCHR, "a character device"),
          (stat.S_ISBLK, "a block device"), (stat.S_ISSOCK, "a socket"),
          (stat.S_ISDIR, "a folder"))


def check_regular_file(path: str) -> None:
    """Refuse, at once and in one :class:`StoreError` line, a ``path`` that exists and is not a
    regular file (after symlinks): a FIFO, a device, a socket or a folder, which libhdf5 would
    block on or read as a damaged file. A missing path passes (the callers say what that
    means)."""
    try:
        mode = os.stat(path).st_mode
    except FileNotFoundError:
        return
    except OSError as exc:
        raise StoreError(f"cannot open {path}: {exc.strerror}") from None
    if not stat.S_ISREG(mode):
        what = next((w for test, w in _KINDS if test(mode)), "not a file")
        raise StoreError(f"{path}: {what}, not a regular file: an HDF5 file is read from a "
                         "regular file")


def open_file(path: str) -> h5py.File:
    """Open ``path`` read-only; a missing or non-HDF5 file is one :class:`StoreError` line."""
    try:
        return h5py.File(path, "r")
    except FileNotFoundError:
        raise StoreError(f"cannot open {path}: no such file") from None
    except Exception as exc:  # noqa: BLE001 - whatever libhdf5 says about a hostile file
        raise StoreError(f"cannot open {path} as HDF5: {describe(exc)}") from None


def describe(exc: BaseException, limit: int = 160) -> str:
    """``Type: first line of the message`` of an exception, capped (for one-line errors)."""
    text = str(exc).splitlines()[0] if str(exc) else ""
    return f"{type(exc).__name__}: {text[:limit]}" if text else type(exc).__name__


def link_kind(group, name: str) -> str:
    """``hard``, ``soft``, ``external`` or ``other`` (never follows the link)."""
    try:
        link = group.get(name, getlink=True)
    except Exception:  # noqa: BLE001 - a user-defined or damaged link
        return "other"
    if isinstance(link, h5py.HardLink):
        return "hard"
    if isinstance(link, h5py.SoftLink):
        return "soft"
    if isinstance(link, h5py.ExternalLink):
        return "external"
    return "other"


def member(group, name: str, kind: type | None = None):
    """``group[name]`` reached through a hard link (ForeignError otherwise), checked to be a
    ``kind`` (``h5py.Group`` or ``h5py.Dataset``); None when there is no such member."""
    try:
        there = name in group
    except Exception as exc:  # noqa: BLE001
        raise StoreError(f"{_where(group)}: cannot look up {name!r} ({describe(exc)})") from None
    if not there:
        lk = link_kind(group, name) if _has_link(group, name) else None
        if lk in ("soft", "external", "other"):       # a dangling link: still not followed
            raise ForeignError(f"{_where(group)}/{name} is a {lk} link (not followed)")
        return None
    lk = link_kind(group, name)
    if lk != "hard":
        raise ForeignError(f"{_where(group)}/{name} is a {lk} link (not followed)")
    try:
        obj = group[name]
    except Exception as exc:  # noqa: BLE001
        raise StoreError(f"{_where(group)}/{name}: unreadable ({describe(exc)})") from None
    if kind is not None and not isinstance(obj, kind):
        want = "group" if kind is h5py.Group else "dataset"
        raise StoreError(f"{_where(group)}/{name} is not a {want}")
    return obj


def _has_link(group, name: str) -> bool:
    try:
        return group.id.links.exists(name.encode())
    except Exception:  # noqa: BLE001
        return False


def names(group) -> list:
    """Names of the members of ``group`` (links of any kind; :func:`member` checks each)."""
    try:
        return [n.decode() if isinstance(n, bytes) else n for n in group]
    except Exception as exc:  # noqa: BLE001
        raise StoreError(f"{_where(group)}: cannot list members ({describe(exc)})") from None


def _where(obj) -> str:
    try:
        return obj.name or "?"
    except Exception:  # noqa: BLE001
        return "?"


def check_dataset(ds, kinds: str, ndim: int | None = 1, max_elements: int = MAX_ELEMENTS) -> None:
    """Check a dataset before reading it: in-file storage, dtype kind in ``kinds``, ``ndim``
    dimensions (None: any), at most ``max_elements`` elements."""
    where = _where(ds)
    try:
        plist = ds.id.get_create_plist()
        layout = plist.get_layout()
        n_external = plist.get_external_count()
        dtype, shape = ds.dtype, ds.shape
    except Exception as exc:  # noqa: BLE001
        raise StoreError(f"{where}: unreadable dataset ({describe(exc)})") from None
    if layout == h5py.h5d.VIRTUAL:
        raise ForeignError(f"{where} is a virtual dataset (data mapped from elsewhere)")
    if n_external:
        raise ForeignError(f"{where} stores its data in an external file")
    if dtype.kind not in kinds or dtype.fields is not None or dtype.subdtype is not None:
        raise StoreError(f"{where}: dtype {dtype} is not one of the layout's ({kinds!r} kinds)")
    if shape is None or (ndim is not None and len(shape) != ndim):
        raise StoreError(f"{where}: shape {shape} has not {ndim} dimension(s)")
    n = int(np.prod(shape, dtype=np.float64)) if shape else 1
    if n > max_elements:
        raise StoreError(f"{where}: {n} elements, more than the {max_elements} a reader accepts")


def read_dataset(group, name: str, kinds: str, ndim: int | None = 1,
                 max_elements: int = MAX_ELEMENTS):
    """A checked dataset's values (None when there is no ``name``)."""
    ds = member(group, name, h5py.Dataset)
    if ds is None:
        return None
    check_dataset(ds, kinds, ndim, max_elements)
    try:
        return ds[()]
    except Exception as exc:  # noqa: BLE001 - a damaged chunk, an unknown filter
        raise StoreError(f"{_where(ds)}: unreadable data ({describe(exc)})") from None


def attr_names(obj) -> list:
    """Names of the attributes of ``obj``."""
    try:
        return list(obj.attrs)
    except Exception as exc:  # noqa: BLE001
        raise StoreError(f"{_where(obj)}: cannot list attributes ({describe(exc)})") from None


def read_attr(obj, name: str):
    """One attribute as a Python ``int``, ``float``, ``bool`` or ``str`` (a text stored as bytes
    is decoded); anything else (arrays, compound or reference types) is a :class:`StoreError`."""
    where = f"{_where(obj)}@{name}"
    try:
        aid = h5py.h5a.open(obj.id, name.encode())
        shape, dtype = aid.shape, aid.dtype
    except Exception as exc:  # noqa: BLE001
        raise StoreError(f"{where}: unreadable attribute ({describe(exc)})") from None
    if shape not in ((), None) and shape != (1,):
        raise StoreError(f"{where}: an array attribute (shape {shape}), not a scalar")
    is_text = dtype.kind in "SUO" and h5py.check_string_dtype(dtype) is not None
    if dtype.kind not in "fiub" and not is_text:
        raise StoreError(f"{where}: dtype {dtype} is neither a number nor a text")
    if is_text and dtype.kind == "S" and dtype.itemsize > MAX_TEXT:
        raise StoreError(f"{where}: a text of {dtype.itemsize} bytes")
    try:
        v = obj.attrs[name]
    except Exception as exc:  # noqa: BLE001
        raise StoreError(f"{where}: unreadable attribute ({describe(exc)})") from None
    if isinstance(v, np.ndarray):
        v = v.reshape(-1)[0] if v.size == 1 else v
    if isinstance(v, (bytes, np.bytes_)):
        try:
            v = bytes(v).decode()
        except UnicodeDecodeError:
            raise StoreError(f"{where}: text that is not UTF-8") from None
    if isinstance(v, np.generic):
        v = v.item()
    if isinstance(v, str) and len(v) > MAX_TEXT:
        raise StoreError(f"{where}: a text of {len(v)} characters")
    if not isinstance(v, (bool, int, float, str)):
        raise StoreError(f"{where}: a {type(v).__name__}, not a number or a text")
    return v


def read_attrs(obj) -> dict:
    """Every attribute of ``obj`` through :func:`read_attr`."""
    return {k: read_attr(obj, k) for k in attr_names(obj)}


__all__ = ["Group", "Dataset", "ForeignError", "check_regular_file", "open_file", "describe",
           "link_kind", "member", "names", "check_dataset", "read_dataset", "read_attr",
           "read_attrs", "MAX_ELEMENTS", "MAX_TEXT", "FLOAT", "INT", "NUMBER"]
