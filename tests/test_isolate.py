"""Readers of untrusted files run in a child that cannot hang or crash the caller
(fibril_hpc.io.isolate): results and exceptions come back as they were; a child that stops
reading (a loop inside libhdf5 on a damaged file) or dies is one DamagedFileError line."""

from __future__ import annotations

import os
import signal
import time

import pytest

from fibril_hpc.errors import ConfigError, DamagedFileError, StoreError
from fibril_hpc.io import isolate

pytestmark = pytest.mark.skipif(not isolate.can_isolate(), reason="no fork here")


def _value(x, y=0):
    return {"sum": x + y, "pid": os.getpid()}


def _raises():
    raise StoreError("f.h5: a one-line reason")


def _raises_unpicklable():
    raise ConfigError("field", 1, "an allowed range")          # three-argument constructor


def _loops():
    while True:                       # reads nothing, like libhdf5 looping on a zeroed heap
        pass


def _crashes():
    os.kill(os.getpid(), signal.SIGSEGV)


def _reads_slowly(path):
    """A legitimate slow reader: keeps reading, longer than the stall limit in all."""
    end = time.monotonic() + 1.5
    n = 0
    while time.monotonic() < end:
        with open(path, "rb") as fh:
            n += len(fh.read())
        time.sleep(0.05)
    return n


def test_result_comes_back_from_a_child():
    got = isolate.run_isolated(_value, 2, y=3, what="f.h5")
    assert got["sum"] == 5 and got["pid"] != os.getpid()


def test_exceptions_come_back_as_raised():
    with pytest.raises(StoreError, match="a one-line reason"):
        isolate.run_isolated(_raises, what="f.h5")
    with pytest.raises(StoreError, match="field: got 1"):     # rebuilt as text when needed
        isolate.run_isolated(_raises_unpicklable, what="f.h5")


def test_a_child_that_reads_nothing_is_stopped_in_one_line():
    t = time.monotonic()
    with pytest.raises(DamagedFileError) as err:
        isolate.run_isolated(_loops, what="bad.h5", stall_s=0.5)
    assert time.monotonic() - t < 10
    assert "bad.h5" in str(err.value) and "\n" not in str(err.value)


def test_a_child_that_crashes_is_reported():
    with pytest.raises(DamagedFileError, match="crashed reading it .signal SIGSEGV"):
        isolate.run_isolated(_crashes, what="bad.h5")


def test_a_reader_that_keeps_reading_is_not_cut_short(tmp_path):
    p = tmp_path / "data.bin"
    p.write_bytes(b"x" * 4096)
    assert isolate.run_isolated(_reads_slowly, str(p), what=str(p), stall_s=0.5) > 0


def test_nested_and_mpi_readers_run_in_process(monkeypatch):
    monkeypatch.setenv("FIBRIL_ISOLATED_CHILD", "1")
    assert not isolate.can_isolate()
    assert isolate.run_isolated(_value, 1, what="f.h5")["pid"] == os.getpid()
