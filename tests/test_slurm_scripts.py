"""The Slurm scripts' decisions, without Slurm: slurm/campaign.sbatch run by bash with a fake
`scontrol` that records what it is asked. A worker rank killed mid-run (what the out-of-memory
killer does) ends the MPI job with the runtime's own status; the script must see that the file
made progress and requeue, and the requeued run must complete the file as a serial run would.
A failure without progress must not requeue (it would repeat forever)."""

import os
import signal
import stat
import subprocess
import sys
import time

import pytest
from campaign_helpers import TINY, env, results_by_key, run, same_numbers, write_grid

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCRIPT = os.path.join(ROOT, "slurm", "campaign.sbatch")
BIN = os.path.dirname(sys.executable)
pytestmark = pytest.mark.skipif(not os.path.exists(os.path.join(BIN, "mpirun")),
                                reason="needs the pip mpich (the 'mpi' extra)")


def _fake_bin(folder, mpirun_exit=None):
    """A folder with a recording `scontrol` and a `fibril-campaign` that records its arguments
    before it runs the real one (and, if asked, an `mpirun` that fails at once)."""
    fake = folder / "fakebin"
    fake.mkdir()
    real = os.path.join(BIN, "fibril-campaign")
    tools = {"scontrol": f'echo "$@" >> {folder}/scontrol.log\n',
             "fibril-campaign": f'echo "$@" >> {folder}/campaign.log\nexec {real} "$@"\n'}
    if mpirun_exit is not None:
        tools["mpirun"] = f"exit {mpirun_exit}\n"
    for name, body in tools.items():
        p = fake / name
        p.write_text("#!/bin/bash\n" + body)
        p.chmod(p.stat().st_mode | stat.S_IXUSR)
    return str(fake)


def _script_env(folder, fake, restarts=0):
    e = env()
    e.update(PATH=f"{fake}:{BIN}:{e['PATH']}", FIBRIL_LAUNCHER="mpirun", SLURM_NTASKS="3",
             SLURM_JOB_ID="4242", SLURM_SUBMIT_DIR=str(folder),
             SLURM_RESTART_COUNT=str(restarts))
    return e


def _rank_pids(grid, rank):
    """PIDs of the fibril-campaign processes of ``grid`` with MPI rank ``rank``."""
    out = []
    for pid in os.listdir("/proc"):
        if not pid.isdigit():
            continue
        try:
            with open(f"/proc/{pid}/cmdline", "rb") as fh:
                cmd = fh.read().split(b"\0")
            with open(f"/proc/{pid}/environ", "rb") as fh:
                envs = fh.read().split(b"\0")
        except OSError:
            continue
        if grid.encode() in cmd and f"PMI_RANK={rank}".encode() in envs:
            out.append(int(pid))
    return out


def _records(path):
    try:
        return len(results_by_key(path))
    except Exception:                 # noqa: BLE001 - not written yet
        return 0


@pytest.mark.slow
def test_a_killed_worker_rank_is_resumed_by_requeue(tmp_path):
    grid = write_grid(tmp_path, {**TINY, "scene": {**TINY["scene"], "n_side": 3}},
                      group_preloads=False, seeds=6)                        # 48 jobs
    out = str(tmp_path / "tiny.h5")
    fake = _fake_bin(tmp_path)
    p = subprocess.Popen(["bash", SCRIPT, grid, "--no-progress", "--checkpoint-s", "1000"],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                         env=_script_env(tmp_path, fake), cwd=tmp_path)
    t0 = time.monotonic()
    while _records(out) < 3 and p.poll() is None and time.monotonic() - t0 < 240:
        time.sleep(0.05)
    victims = _rank_pids(grid, 2)
    assert p.poll() is None and victims, "the campaign ended before a worker could be killed"
    os.kill(victims[0], signal.SIGKILL)
    stdout, stderr = p.communicate(timeout=240)
    log = stdout + stderr
    assert p.returncode == 75, log
    assert "a rank died" in log and "treated as interrupted (75)" in log, log
    assert (tmp_path / "scontrol.log").read_text().split() == ["requeue", "4242"]
    done = _records(out)
    assert 3 <= done < 48
    # the requeued job: the same script again
    r = subprocess.run(["bash", SCRIPT, grid, "--no-progress"], capture_output=True, text=True,
                       timeout=300, env=_script_env(tmp_path, fake, restarts=1), cwd=tmp_path)
    assert r.returncode == 0, r.stdout + r.stderr
    final = results_by_key(out)
    assert len(final) == 48 and {x["status"] for x in final.values()} == {"done"}
    serial = str(tmp_path / "serial.h5")
    assert run([grid, "--serial", "--no-progress", "--output", serial],
               timeout=300).returncode == 0
    assert same_numbers(results_by_key(serial), final) == []


def test_a_failure_without_progress_is_not_requeued(tmp_path):
    grid = write_grid(tmp_path)
    fake = _fake_bin(tmp_path, mpirun_exit=9)
    r = subprocess.run(["bash", SCRIPT, grid, "--no-progress"], capture_output=True, text=True,
                       timeout=300, env=_script_env(tmp_path, fake), cwd=tmp_path)
    assert r.returncode == 9, r.stdout + r.stderr
    assert "finished no job in this run: not resuming" in r.stderr
    assert not (tmp_path / "scontrol.log").exists()
    # one dry run per job step (a 10^6-job grid's took 87 s); the counts after it come from
    # `status` of the file it named
    calls = (tmp_path / "campaign.log").read_text().splitlines()
    assert sum("--dry-run" in c for c in calls) == 1, calls
