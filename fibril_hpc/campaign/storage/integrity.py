"""Checksums of published job records (no h5py, no MPI).

Every job group of a campaign file carries an attribute ``checksum``: ``"sha256:"`` + the
SHA-256 of a canonical serialisation of the record's attributes and curves (below). Every reader
recomputes it from what it read; a record whose checksum does not match is *corrupt*: it is
reported, never returned as a result, never copied into a new file, and resume recomputes it.

Canonical serialisation: for each attribute name in sorted order (``checksum`` itself and absent
or ``None`` values left out) the name, a type tag and the value (``i`` decimal integer, ``f`` the
8 IEEE-754 bytes of a float, so NaN and -0.0 are exact, ``s`` UTF-8 text); then for each of
``loading`` and ``unloading`` either ``none`` or, per curve array in sorted name order, its name,
dtype, shape and raw little-endian bytes. Each piece is length-prefixed so that no two different
records serialise alike.

Records written before checksums existed (older files of the same format_version 1) have
no ``checksum`` attribute: they are *unchecked*. They are read and resumed exactly as before,
and ``fibril-campaign verify`` counts them separately; nothing vouches for them.
"""

from __future__ import annotations

import hashlib
import struct

import numpy as np

ATTR = "checksum"
PREFIX = "sha256:"
CURVE_BRANCHES = ("loading", "unloading")

OK = "ok"
CORRUPT = "corrupt"
UNCHECKED = "unchecked"


def _piece(h, b: bytes) -> None:
    h.update(struct.pack("<Q", len(b)))
    h.update(b)


def _scalar(v) -> bytes:
    if isinstance(v, np.generic):
        v = v.item()
    if isinstance(v, (bool, int)):
        return b"i" + str(int(v)).encode()
    if isinstance(v, float):
        return b"f" + struct.pack("<d", v)
    if isinstance(v, bytes):
        v = v.decode("utf-8", "surrogateescape")
    if isinstance(v, str):
        return b"s" + v.encode("utf-8", "surrogateescape")
    return b"r" + repr(v).encode()


def record_checksum(rec: dict) -> str:
    """The checksum of a record (a dict of attributes plus ``loading``/``unloading`` curves)."""
    h = hashlib.sha256(b"fibril-hpc job record v1")
    for k in sorted(rec):
        v = rec[k]
        if k == ATTR or k in CURVE_BRANCHES or k == "type" or v is None:
            continue
        _piece(h, k.encode())
        _piece(h, _scalar(v))
    for branch in CURVE_BRANCHES:
        c = rec.get(branch)
        _piece(h, branch.encode())
        if c is None:
            _piece(h, b"none")
            continue
        for name in sorted(c):
            a = np.ascontiguousarray(c[name])
            a = a.astype(a.dtype.newbyteorder("<"), copy=False)
            _piece(h, name.encode())
            _piece(h, a.dtype.str.encode() + repr(tuple(a.shape)).encode())
            _piece(h, a.tobytes())
    return PREFIX + h.hexdigest()


def seal(rec: dict) -> dict:
    """``rec`` with its checksum attribute set (a new dict)."""
    out = dict(rec)
    out.pop(ATTR, None)
    out[ATTR] = record_checksum(out)
    return out


def check(rec: dict) -> str:
    """``ok``, ``corrupt`` or ``unchecked`` (no checksum: written before checksums existed)."""
    want = rec.get(ATTR)
    if want is None:
        return UNCHECKED
    if not isinstance(want, str) or not want.startswith(PREFIX):
        return CORRUPT
    try:
        return OK if record_checksum(rec) == want else CORRUPT
    except (TypeError, ValueError):
        return CORRUPT
