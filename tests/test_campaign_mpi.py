"""MPI master/worker runs equal serial runs bitwise; SIGTERM to mpirun exits 75 and resumes."""

import os
import shutil
import signal
import subprocess
import sys
import time

import pytest
from campaign_helpers import campaign_cmd, env, results_by_key, same_numbers, write_grid

from fibril_hpc.cli.campaign import main

MPIRUN = shutil.which("mpirun", path=os.path.dirname(sys.executable)) or shutil.which("mpirun")

try:
    import mpi4py  # noqa: F401
    HAVE_MPI4PY = True
except ImportError:  # pragma: no cover
    HAVE_MPI4PY = False

pytestmark = [
    pytest.mark.mpi,
    pytest.mark.skipif(MPIRUN is None, reason="no mpirun on PATH (pip install '.[mpi]')"),
    pytest.mark.skipif(not HAVE_MPI4PY, reason="mpi4py not installed (pip install '.[mpi]')"),
]


def _mpirun(n, args, timeout=300):
    return subprocess.run([MPIRUN, "-n", str(n)] + campaign_cmd() + list(args),
                          capture_output=True, text=True, timeout=timeout, env=env())


@pytest.fixture(scope="module")
def serial(tmp_path_factory):
    d = tmp_path_factory.mktemp("serial")
    grid = write_grid(d)
    assert main([grid, "--no-progress"]) == 0
    return results_by_key(str(d / "tiny.h5"))


@pytest.mark.parametrize("n", [2, 3])
def test_mpi_equals_serial_bitwise(tmp_path, serial, n):
    grid = write_grid(tmp_path)
    r = _mpirun(n, [grid, "--no-progress"])
    assert r.returncode == 0, r.stderr
    res = results_by_key(str(tmp_path / "tiny.h5"))
    assert len(res) == 16
    assert same_numbers(serial, res) == []
    ranks = {x["rank"] for x in res.values()}
    assert 0 not in ranks and ranks <= set(range(1, n))   # rank 0 only writes


def test_mpi_ungrouped_equals_serial_grouped(tmp_path, serial):
    grid = write_grid(tmp_path, group_preloads=False)
    r = _mpirun(3, [grid])                      # with the progress line (not a terminal: lines)
    assert r.returncode == 0, r.stderr
    assert same_numbers(serial, results_by_key(str(tmp_path / "tiny.h5"))) == []
    # its first line, as the two workers get their first job, counts them running (it said 0)
    lines = [x for x in r.stderr.splitlines() if " jobs (" in x]
    assert lines[0].startswith("fibril-campaign: 0/16 jobs (0 done, 0 failed, 2 running; "), lines
    assert lines[-1].startswith("fibril-campaign: 16/16 jobs (16 done, 0 failed, 0 running; ")


@pytest.mark.slow
def test_sigterm_to_mpirun_exits_75_then_resumes(tmp_path, serial):
    from fibril_hpc import load_campaign

    grid = write_grid(tmp_path, group_preloads=False, seeds=4)     # 32 jobs
    out = str(tmp_path / "tiny.h5")
    p = subprocess.Popen([MPIRUN, "-n", "2"] + campaign_cmd() + [grid, "--no-progress"],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env())
    try:
        t0 = time.monotonic()
        while time.monotonic() - t0 < 120 and p.poll() is None:
            try:
                if len(load_campaign(out, curves=False)) >= 1:
                    break
            except Exception:  # noqa: BLE001 - not created yet
                pass
            time.sleep(0.05)
        p.send_signal(signal.SIGTERM)
        _, err = p.communicate(timeout=120)
    finally:
        if p.poll() is None:
            p.kill()
            p.communicate()
    assert p.returncode == 75, err
    part = results_by_key(out)
    assert 1 <= len(part) < 32
    r = _mpirun(2, [grid, "--no-progress"])
    assert r.returncode == 0, r.stderr
    final = results_by_key(out)
    assert all(final[k]["record_id"] == part[k]["record_id"] for k in part)
    assert same_numbers(serial, final) == []


def test_bad_grid_under_mpirun_one_line_exit_2(tmp_path):
    grid = write_grid(tmp_path, k_tilde=[-1])
    r = _mpirun(2, [grid])
    assert r.returncode == 2, r.stderr
    assert r.stderr.count("fibril-campaign: error: k_tilde:") == 1, r.stderr
    assert os.listdir(tmp_path) == ["grid.yaml"]


def test_other_grid_refused_under_mpirun(tmp_path, serial):
    grid = write_grid(tmp_path, k_tilde=[1])
    assert main([grid, "--no-progress"]) == 0
    before = (tmp_path / "tiny.h5").read_bytes()
    grid = write_grid(tmp_path, k_tilde=[0.1])
    r = _mpirun(2, [grid, "--no-progress"])
    assert r.returncode == 2, r.stderr
    assert r.stderr.count("another grid") == 1
    assert (tmp_path / "tiny.h5").read_bytes() == before


@pytest.mark.slow
def test_mpi_auto_preloads_equal_serial(tmp_path):
    """F_P: auto under MPI: the master plans every path's rounds; same preloads and records."""
    from test_campaign_auto import AUTO

    ser = tmp_path / "ser"
    par = tmp_path / "par"
    ser.mkdir()
    par.mkdir()
    assert main([write_grid(ser, AUTO), "--no-progress", "--serial"]) == 0
    r = _mpirun(3, [write_grid(par, AUTO), "--no-progress"])
    assert r.returncode == 0, r.stderr
    a, b = results_by_key(str(ser / "auto.h5")), results_by_key(str(par / "auto.h5"))
    assert set(a) == set(b) and len(a) > 10
    assert same_numbers(a, b) == []


@pytest.mark.slow
def test_mpi_search_grid_equals_serial(tmp_path):
    """sigma_tilde: auto and seeds: auto under MPI: the master replays every line's rounds as
    paths come back in any order; the same sigma~, seeds and records as a serial run."""
    from test_campaign_search import SMALL

    ser = tmp_path / "ser"
    par = tmp_path / "par"
    ser.mkdir()
    par.mkdir()
    grid = dict(SMALL, k_tilde=[1, 0.01])
    assert main([write_grid(ser, grid), "--no-progress", "--serial"]) == 0
    r = _mpirun(3, [write_grid(par, grid), "--no-progress"])
    assert r.returncode == 0, r.stderr
    a, b = results_by_key(str(ser / "search.h5")), results_by_key(str(par / "search.h5"))
    assert set(a) == set(b) and len({j["sigma_tilde"] for j in a.values()}) > 4
    assert same_numbers(a, b) == []
