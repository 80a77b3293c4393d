"""Append-only, checksummed journal of finished job records (no h5py, no MPI, no pickle).

Why a journal: HDF5 (the h5py wheel, default or latest libver) is not crash-safe while a file is
open for writing; a writer killed mid-write can leave a file that does not open again. The
campaign therefore never writes the published ``results.h5`` in place. Each finished record is
appended here as one frame and ``fsync``-ed; from time to time the records are folded into a
*copy* of the HDF5 file which then atomically replaces it (see :mod:`fibril_hpc.campaign.storage.store`).
Readers (``status``, ``load_campaign``) read the journal first, then the HDF5 file, so they
always see every finished record and never hold anything the writer needs.

The journal is data, never code. One frame::

    b"FJR2"                 magic
    uint32 LE               payload length n (at most MAX_PAYLOAD)
    32 bytes                campaign hash (SHA-256 digest) of the record's campaign
    uint32 LE               CRC-32 of the 40 bytes above
    n bytes                 payload: UTF-8 JSON object (one job record; arrays as
                            {"__nd__": [dtype, shape, base64 of the raw bytes]}, numeric dtypes only)
    uint32 LE               CRC-32 of the payload

The reader resynchronises: after a damaged stretch it looks for the next magic whose header
checksum holds, so intact frames before *and after* damage are kept. Damaged stretches are
reported (count and byte ranges, one line); frames of another campaign, frames whose key is
no job of the grid (*foreign*: never counted or published), and frames whose record carries no
checksum or one that does not verify (*unverified*, see :mod:`.integrity`: the CRCs only say that
the bytes are the bytes written, not that this code wrote the record), are refused (one line).
The writer (:class:`~.journal_writer.JournalWriter`) writes every frame to the journal and
to its mirror (``<journal>.mirror``: two copies of each record), and moves every damaged,
foreign or old-format stretch to ``<journal>.quarantine`` and keeps the intact frames, so
nothing is silently truncated away.

Old journals (magic ``FJR1``, written by fibril-hpc up to format 1) held pickled payloads;
unpickling a file runs code chosen by whoever wrote it, so they are never unpickled: their
frames are counted, reported and quarantined, and the jobs they held are recomputed.
"""

from __future__ import annotations

import base64
import hashlib
import json
import logging
import os
import struct
import zlib

import numpy as np

from . import integrity

log = logging.getLogger(__name__)

MAGIC = b"FJR2"
OLD_MAGIC = b"FJR1"
MAX_PAYLOAD = 1 << 28
_HEAD = struct.Struct("<4sI32s")            # magic, length, campaign hash
_CRC = struct.Struct("<I")
_OLD_HEAD = struct.Struct("<4sQI")
HEAD_SIZE = _HEAD.size + _CRC.size          # 44
#: NumPy dtypes a journal array may have (plain numbers only: never objects)
DTYPES = frozenset(np.dtype(t).str for t in ("f8", "f4", "i8", "i4", "i2", "i1", "u8", "u4",
                                             "u2", "u1", "b1"))


def journal_path(output: str) -> str:
    """The journal beside a campaign file (of its resolved path: symlinks are followed)."""
    return os.path.realpath(output) + ".journal"


def mirror_path(output_journal: str) -> str:
    """The journal's second copy: every frame is written to both files."""
    return output_journal + ".mirror"


def quarantine_path(output_journal: str) -> str:
    """Where the writer moves damaged, foreign and old-format stretches of a journal."""
    return output_journal + ".quarantine"


def hash_digest(campaign_hash) -> bytes:
    """32-byte digest standing for a campaign hash (its bytes when it is 64 hex digits)."""
    s = str(campaign_hash)
    if len(s) == 64:
        try:
            return bytes.fromhex(s)
        except ValueError:
            pass
    # a damaged root attribute reads back with surrogate escapes: hash its bytes as they are
    return hashlib.sha256(s.encode("utf-8", "surrogateescape")).digest()


# --------------------------------------------------------------------------- payload
def _to_json(obj):
    if isinstance(obj, np.ndarray):
        a = np.ascontiguousarray(obj)
        if a.dtype.str not in DTYPES:
            raise TypeError(f"journal arrays must be numeric, not {a.dtype}")
        return {"__nd__": [a.dtype.str, list(a.shape), base64.b64encode(a.tobytes()).decode()]}
    if isinstance(obj, np.generic):
        return obj.item()
    raise TypeError(f"cannot journal a {type(obj).__name__}")


def _from_json(d):
    nd = d.get("__nd__") if len(d) == 1 else None
    if nd is None:
        return d
    dtype, shape, data = nd           # a malformed array raises, caught by the reader
    if dtype not in DTYPES or not all(isinstance(n, int) and n >= 0 for n in shape):
        raise ValueError("bad array")
    return np.frombuffer(base64.b64decode(data, validate=True),
                         dtype=np.dtype(dtype)).reshape(shape).copy()


def encode(record: dict) -> bytes:
    """One frame holding ``record`` (a dict with ``key`` and ``campaign_hash``)."""
    payload = json.dumps(record, default=_to_json, sort_keys=True).encode()
    head = _HEAD.pack(MAGIC, len(payload), hash_digest(record["campaign_hash"]))
    return (head + _CRC.pack(zlib.crc32(head)) + payload + _CRC.pack(zlib.crc32(payload)))


def _decode_payload(payload: bytes, digest: bytes):
    """The record of a checksummed payload, or None when it is not a well-formed job record."""
    try:
        rec = json.loads(payload.decode(), object_hook=_from_json)
    except (ValueError, TypeError, KeyError, UnicodeDecodeError, RecursionError):
        return None
    if not isinstance(rec, dict) or not isinstance(rec.get("key"), str) or not rec["key"]:
        return None
    if rec.get("type", "job") != "job" or hash_digest(rec.get("campaign_hash")) != digest:
        return None
    return rec


# --------------------------------------------------------------------------- reading
class Scan:
    """What a journal holds: the intact records, and the stretches that are not intact."""

    def __init__(self):
        self.records = []        # (start, end, record)
        self.damaged = []        # (start, end) byte ranges: corrupt, torn, malformed, unknown
        self.old = []            # (start, end) frames of the old pickle format (never unpickled)
        self.foreign = []        # (start, end) intact frames of another campaign
        #: (start, end) intact frames of this campaign whose key is no job of its grid(s)
        self.outside = []
        #: (start, end) intact frames whose record has no checksum, or one that does not verify
        #: (written by hand, by a version before journal checksums, or altered): never counted
        self.unverified = []
        #: (start, end) of an unfinished last frame: a write in progress (a reader racing the
        #: writer) or cut short by a kill; expected, so never reported as damage
        self.torn = None
        self.size = 0

    def _bad(self, start, end):
        if self.damaged and self.damaged[-1][1] == start:
            self.damaged[-1] = (self.damaged[-1][0], end)
        else:
            self.damaged.append((start, end))

    @property
    def clean(self) -> bool:
        """Whether every byte belongs to an intact record of an accepted campaign."""
        return not (self.damaged or self.old or self.foreign or self.outside or self.unverified
                    or self.torn)

    def message(self, path: str) -> str:
        """One line describing what is not intact ("" when everything is)."""
        parts = []
        if self.damaged:
            rng = ", ".join(f"{a}-{b}" for a, b in self.damaged[:4])
            more = f" and {len(self.damaged) - 4} more" if len(self.damaged) > 4 else ""
            parts.append(f"{len(self.damaged)} damaged stretch(es) (bytes {rng}{more}; the jobs "
                         "they held are recomputed)")
        if self.old:
            parts.append(f"{len(self.old)} old-format (pickle) frame(s), not read for safety "
                         "(their jobs are recomputed)")
        if self.foreign:
            parts.append(f"{len(self.foreign)} frame(s) of another campaign, refused")
        if self.unverified:
            parts.append(f"{len(self.unverified)} frame(s) whose record has no checksum or one "
                         "that does not verify, not counted (their jobs are recomputed)")
        if self.outside:
            parts.append(f"{len(self.outside)} frame(s) whose key is no job of the grid "
                         "(foreign), refused")
        if not parts:
            return ""
        return (f"journal {path}: {len(self.records)} intact record(s) kept; "
                + "; ".join(parts))


def scan(data: bytes, accept=None, belongs=None) -> Scan:
    """Parse journal bytes, resynchronising after damage. ``accept``: campaign hashes whose
    frames are returned (None: every campaign); ``belongs``: a predicate on a record (its key
    is a job of the grid; None: every key). Never raises on any input."""
    digests = None if accept is None else {hash_digest(h) for h in accept}
    out = Scan()
    out.size = n = len(data)
    pos = 0
    while pos < n:
        got = _frame_at(data, pos, digests, out, belongs)
        if got:
            pos = got
            continue
        if _unfinished(data, pos):
            out.torn = (pos, n)
            break
        nxt = _next_magic(data, pos + 1)
        out._bad(pos, nxt)
        pos = nxt
    return out


def _unfinished(data: bytes, pos: int) -> bool:
    """Whether ``data[pos:]`` is the beginning of a frame that has not been written to its end
    (a magic prefix, or a header whose checksum holds and whose frame runs past the end)."""
    rest = len(data) - pos
    if rest < len(MAGIC):
        return MAGIC.startswith(data[pos:])
    if not data.startswith(MAGIC, pos):
        return False
    if rest < HEAD_SIZE:
        return True
    _, length, _ = _HEAD.unpack_from(data, pos)
    (hcrc,) = _CRC.unpack_from(data, pos + _HEAD.size)
    return (zlib.crc32(data[pos:pos + _HEAD.size]) == hcrc and length <= MAX_PAYLOAD
            and pos + HEAD_SIZE + length + _CRC.size > len(data))


def _next_magic(data: bytes, start: int) -> int:
    a, b = data.find(MAGIC, start), data.find(OLD_MAGIC, start)
    cands = [x for x in (a, b) if x >= 0]
    return min(cands) if cands else len(data)


def _frame_at(data: bytes, pos: int, digests, out: Scan, belongs=None) -> int:
    """End of a whole frame starting at ``pos`` (recorded in ``out``), or 0."""
    n = len(data)
    if data.startswith(OLD_MAGIC, pos) and pos + _OLD_HEAD.size <= n:
        _, length, crc = _OLD_HEAD.unpack_from(data, pos)
        end = pos + _OLD_HEAD.size + length
        if end <= n and zlib.crc32(data[pos + _OLD_HEAD.size:end]) == crc:
            out.old.append((pos, end))
            return end
        return 0
    if not data.startswith(MAGIC, pos) or pos + HEAD_SIZE > n:
        return 0
    _, length, digest = _HEAD.unpack_from(data, pos)
    (hcrc,) = _CRC.unpack_from(data, pos + _HEAD.size)
    if zlib.crc32(data[pos:pos + _HEAD.size]) != hcrc or length > MAX_PAYLOAD:
        return 0
    end = pos + HEAD_SIZE + length + _CRC.size
    if end > n:
        return 0
    payload = data[pos + HEAD_SIZE:end - _CRC.size]
    if zlib.crc32(payload) != _CRC.unpack_from(data, end - _CRC.size)[0]:
        return 0
    rec = _decode_payload(payload, digest)
    if rec is None:
        return 0
    if digests is not None and digest not in digests:
        out.foreign.append((pos, end))
    elif integrity.check(rec) != integrity.OK:
        out.unverified.append((pos, end))
    elif belongs is not None and not belongs(rec):
        out.outside.append((pos, end))
    else:
        out.records.append((pos, end, rec))
    return end


def read_bytes(path: str) -> bytes:
    """The bytes of a journal (empty when there is none)."""
    try:
        with open(path, "rb") as fh:
            return fh.read()
    except FileNotFoundError:
        return b""


def scan_pair(path: str, accept=None, belongs=None) -> Scan:
    """The scan of the journal ``path``, with the intact records of its mirror that the journal
    lacks added (a journal deleted, cut or damaged loses nothing its mirror holds). The
    positions and the damage reported are the journal's own."""
    return scan_bytes(read_bytes(path), read_bytes(mirror_path(path)), accept, belongs)


def scan_bytes(journal: bytes, mirror: bytes, accept=None, belongs=None) -> Scan:
    """:func:`scan_pair` of the bytes of a journal and of its mirror."""
    s = scan(journal, accept, belongs)
    have = {(r.get("key"), r.get("record_id")) for _, _, r in s.records}
    for a, b, r in scan(mirror, accept, belongs).records:
        if (r.get("key"), r.get("record_id")) not in have:
            have.add((r.get("key"), r.get("record_id")))
            s.records.append((a, b, r))
    return s


def read(path: str, accept=None, belongs=None) -> tuple[list, Scan]:
    """(records, scan) of a journal and its mirror (:func:`scan_pair`); a one-line warning is
    logged when something is not intact. Read-only: a reader never changes the journal (the
    writer quarantines)."""
    s = scan_pair(path, accept, belongs)
    msg = s.message(path)
    if msg:
        log.warning("%s", msg)
    return [r for _, _, r in s.records], s
