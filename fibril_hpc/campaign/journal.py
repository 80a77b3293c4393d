"""Append-only, checksummed journal of finished job records (no h5py, no MPI).

Why a journal: HDF5 (the h5py wheel, default or latest libver) is not crash-safe while a file is
open for writing; a writer killed mid-write can leave a file that does not open again. The
campaign therefore never writes the published ``results.h5`` in place. Each finished record is
appended here as one frame and ``fsync``-ed (cheap, and a torn last frame is detected and
dropped); from time to time the records are folded into a *copy* of the HDF5 file which then
atomically replaces it (see :mod:`fibril_hpc.campaign.store`). Readers (``status``,
``load_campaign``) read the journal first, then the HDF5 file, so they always see every finished
record and never hold anything the writer needs.

Frame: ``b"FJR1"``, payload length (uint64 LE), CRC-32 of the payload (uint32 LE), payload
(a pickled dict of Python scalars, strings and NumPy arrays written by this package).
"""

from __future__ import annotations

import os
import pickle
import struct
import zlib

MAGIC = b"FJR1"
_HEAD = struct.Struct("<4sQI")


def journal_path(output: str) -> str:
    """The journal beside the campaign file ``output``."""
    return output + ".journal"


def encode(record: dict) -> bytes:
    """One journal frame of ``record`` (see the module docstring for the format)."""
    payload = pickle.dumps(record, protocol=5)
    return _HEAD.pack(MAGIC, len(payload), zlib.crc32(payload)) + payload


def read(path: str) -> tuple[list, int]:
    """Records of a journal and the byte length of its valid prefix (a torn tail is ignored)."""
    try:
        with open(path, "rb") as fh:
            data = fh.read()
    except FileNotFoundError:
        return [], 0
    out, pos = [], 0
    while pos + _HEAD.size <= len(data):
        magic, n, crc = _HEAD.unpack_from(data, pos)
        end = pos + _HEAD.size + n
        if magic != MAGIC or end > len(data):
            break
        payload = data[pos + _HEAD.size:end]
        if zlib.crc32(payload) != crc:
            break
        try:
            out.append(pickle.loads(payload))
        except Exception:  # noqa: BLE001 - a damaged frame ends the valid prefix
            break
        pos = end
    return out, pos


class JournalWriter:
    """Appends records durably (one ``write`` + ``fsync`` per record)."""

    def __init__(self, path: str):
        self.path = path
        records, valid = read(path)
        if os.path.exists(path) and os.path.getsize(path) != valid:
            os.truncate(path, valid)        # drop a torn tail left by a killed writer
        self._fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_APPEND, 0o644)
        self.replayed = records

    def append(self, record: dict) -> None:
        """Append one record and ``fsync`` it before returning."""
        data = encode(record)
        view = memoryview(data)
        while view:
            n = os.write(self._fd, view)
            view = view[n:]
        os.fsync(self._fd)

    def reset(self) -> None:
        """Empty the journal (after its records are safely in the HDF5 file)."""
        os.ftruncate(self._fd, 0)
        os.fsync(self._fd)

    def close(self) -> None:
        """Close the journal file (idempotent)."""
        if self._fd is not None:
            os.close(self._fd)
            self._fd = None
