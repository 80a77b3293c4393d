"""SIGKILL at random moments, stop signals (exit 75), readers while writing, locking, launcher
mismatch. Every subprocess has a timeout; nothing asserts timings."""

import glob
import os
import random
import signal
import time

import h5py
import pytest
from campaign_helpers import env, results_by_key, run, start, write_grid

from fibril_hpc import load_campaign


def _wait_records(path, n, proc, timeout=120):
    t0 = time.monotonic()
    while time.monotonic() - t0 < timeout:
        if proc.poll() is not None:
            return False
        if os.path.exists(path):
            try:
                if len(load_campaign(path, curves=False)) >= n:
                    return True
            except Exception:  # noqa: BLE001 - the file may not exist yet
                pass
        time.sleep(0.05)
    return False


def _finish(proc, timeout=120):
    try:
        out, err = proc.communicate(timeout=timeout)
    except Exception:
        proc.kill()
        proc.communicate()
        raise
    return proc.returncode, out, err


@pytest.mark.slow
def test_sigkill_at_random_moments_then_resume_exactly_once(tmp_path):
    grid = write_grid(tmp_path, group_preloads=False, seeds=8)     # 64 jobs
    out = str(tmp_path / "tiny.h5")
    rng = random.Random(20261122)
    seen: dict = {}            # key -> record_id of a done record seen after a kill
    kills = 0
    for _ in range(12):
        p = start([grid, "--checkpoint-s", "0", "--no-progress"])
        # a random moment *while it runs*: after a random number of new records (the solver's
        # speed, the machine's load and the JIT cache must not decide whether the kill lands),
        # plus a random fraction of a job
        _wait_records(out, len(seen) + rng.randint(1, 4), p)
        time.sleep(rng.uniform(0.0, 0.2))
        if p.poll() is None:
            p.send_signal(signal.SIGKILL)
            kills += 1
        p.communicate(timeout=120)
        if os.path.exists(out):
            with h5py.File(out, "r") as fh:          # always reopens, no h5clear
                assert fh.attrs["program"] == "fibril-hpc campaign"
            for k, r in results_by_key(out).items():
                if r["status"] == "done":
                    assert seen.setdefault(k, r["record_id"]) == r["record_id"], "recomputed"
        if len(seen) == 64 or kills >= 6:
            break
    assert kills >= 3
    r = run([grid, "--no-progress"], timeout=300)
    assert r.returncode == 0, r.stderr
    final = results_by_key(out)
    assert len(final) == 64 and {x["status"] for x in final.values()} == {"done"}
    assert all(final[k]["record_id"] == rid for k, rid in seen.items())
    with h5py.File(out, "r") as fh:
        assert sorted(fh["jobs"]) == sorted(final) and len(fh["jobs"]) == 64
    # finished: everything is in the file; the empty journal and the lock file are gone
    assert not os.path.exists(out + ".journal") and not os.path.exists(out + ".lock")
    assert glob.glob(str(tmp_path / ".tiny.h5.ckpt-*")) == []


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT, signal.SIGUSR1])
def test_stop_signal_exits_75_and_resumes(tmp_path, sig):
    grid = write_grid(tmp_path, group_preloads=False, seeds=4)     # 32 jobs
    out = str(tmp_path / "tiny.h5")
    p = start([grid, "--no-progress", "--checkpoint-s", "1000"])
    assert _wait_records(out, 1, p), "campaign produced no record"
    p.send_signal(sig)
    rc, _, err = _finish(p)
    assert rc == 75, err
    assert "interrupted" in err and "resume" in err and "Traceback" not in err
    done = results_by_key(out)
    assert 1 <= len(done) < 32
    assert not os.path.exists(out + ".journal")            # closed cleanly: all published
    r = run([grid, "--no-progress"])
    assert r.returncode == 0, r.stderr
    final = results_by_key(out)
    assert len(final) == 32
    assert all(final[k]["record_id"] == done[k]["record_id"] for k in done)


def test_readers_while_writing_never_block_or_corrupt(tmp_path):
    grid = write_grid(tmp_path, group_preloads=False)
    out = str(tmp_path / "tiny.h5")
    p = start([grid, "--no-progress", "--checkpoint-s", "0"])
    try:
        assert _wait_records(out, 1, p)
        held = h5py.File(out, "r")                      # a reader that keeps the file open
        counts = []
        while p.poll() is None:
            counts.append(len(load_campaign(out, curves=False)))
            s = run(["status", out], timeout=60)
            assert s.returncode == 0 and "done" in s.stdout, s.stderr
            time.sleep(0.1)
        held.close()
        rc, _, err = _finish(p)
    finally:
        if p.poll() is None:
            p.kill()
            p.communicate()
    assert rc == 0, err
    assert counts == sorted(counts)
    assert len(results_by_key(out)) == 16


def test_second_writer_is_refused(tmp_path):
    grid = write_grid(tmp_path, group_preloads=False)
    out = str(tmp_path / "tiny.h5")
    p = start([grid, "--no-progress"])
    try:
        assert _wait_records(out, 1, p)
        # Freeze the first writer mid-campaign, so it holds the lock for as long as the second
        # run takes (the tiny grid can finish before a second interpreter has even started).
        p.send_signal(signal.SIGSTOP)
        try:
            r = run([grid, "--no-progress"], timeout=120)
        finally:
            p.send_signal(signal.SIGCONT)
        assert r.returncode == 2 and "locked" in r.stderr, r.stderr
        assert "Traceback" not in r.stderr
        assert _finish(p)[0] == 0
    finally:
        if p.poll() is None:
            p.kill()
            p.communicate()
    assert len(results_by_key(out)) == 16


def test_launcher_mismatch_is_refused(tmp_path):
    pytest.importorskip("mpi4py", reason="mpi4py not installed (pip install '.[mpi]')")
    grid = write_grid(tmp_path)
    e = env()
    e["OMPI_COMM_WORLD_SIZE"] = "2"      # a launcher announcing 2 ranks; mpi4py sees a singleton
    r = run([grid, "--no-progress"], env=e, timeout=120)
    assert r.returncode == 2, r.stderr
    last = r.stderr.strip().splitlines()[-1]     # (mpi4py may warn before it, too)
    assert last.startswith("fibril-campaign: error: launcher:") and "OMPI_COMM_WORLD_SIZE=2" in last
    assert "Traceback" not in r.stderr
    assert os.listdir(tmp_path) == ["grid.yaml"]
