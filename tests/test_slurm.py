"""A real, throwaway single-node Slurm (Debian slurmctld/slurmd/munge): submit a campaign with
slurm/campaign.sbatch, interrupt it with a signal (what Slurm sends before a time limit), and
check that the job, requeued with every option it was given, completes the file; run a grid as a
job array of shards (slurm/array.sbatch) and merge them into a serial run's records. Every
daemon is stopped by its PID."""

import os
import shutil
import socket
import subprocess
import sys
import tempfile
import time

import pytest
from campaign_helpers import env, results_by_key, same_numbers, write_grid

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BINARIES = ("slurmctld", "slurmd", "sbatch", "squeue", "scancel", "scontrol", "srun", "munged")
MISSING = [b for b in BINARIES if shutil.which(b) is None and not os.path.exists(f"/usr/sbin/{b}")]

pytestmark = [
    pytest.mark.slurm,
    pytest.mark.skipif(bool(MISSING), reason="Slurm test cluster needs " + ", ".join(MISSING)
                       + " (apt-get install slurmctld slurmd slurm-client munge)"),
    pytest.mark.skipif(os.geteuid() != 0, reason="the throwaway Slurm cluster runs as root"),
    pytest.mark.skipif(shutil.which("mpirun", path=os.path.dirname(sys.executable)) is None,
                       reason="no pip mpich in this environment (pip install '.[mpi]')"),
]


def _which(b):
    return shutil.which(b) or f"/usr/sbin/{b}"


def _free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _wait(pred, timeout, what):
    t0 = time.monotonic()
    while time.monotonic() - t0 < timeout:
        if pred():
            return
        time.sleep(0.2)
    raise AssertionError(f"timed out waiting for {what}")


@pytest.fixture(scope="module")
def cluster():
    base = tempfile.mkdtemp(prefix="fibril-slurm-", dir="/tmp")
    os.chmod(base, 0o755)
    procs = []
    node = socket.gethostname().split(".")[0]
    for d in ("state", "spool", "log", "munge"):
        os.makedirs(os.path.join(base, d))
    munge_dir = os.path.join(base, "munge")
    shutil.chown(munge_dir, "munge", "munge")
    os.chmod(munge_dir, 0o755)
    sock = os.path.join(munge_dir, "munge.socket")
    conf = os.path.join(base, "slurm.conf")
    with open(conf, "w") as fh:
        fh.write(f"""ClusterName=fibriltest
SlurmctldHost={node}(127.0.0.1)
SlurmctldPort={_free_port()}
SlurmdPort={_free_port()}
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket={sock}
StateSaveLocation={base}/state
SlurmdSpoolDir={base}/spool
SlurmctldPidFile={base}/slurmctld.pid
SlurmdPidFile={base}/slurmd.pid
SlurmctldLogFile={base}/log/slurmctld.log
SlurmdLogFile={base}/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/filetxt
JobCompLoc={base}/log/jobcomp.txt
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
MpiDefault=pmi2
SchedulerParameters=batch_sched_delay=0,sched_min_interval=0
ReturnToService=2
KillWait=10
NodeName={node} NodeAddr=127.0.0.1 CPUs=2 State=UNKNOWN
PartitionName=debug Nodes={node} Default=YES MaxTime=INFINITE State=UP
""")
    e = env()
    e["SLURM_CONF"] = conf
    e["PATH"] = os.path.dirname(sys.executable) + os.pathsep + e.get("PATH", "")
    try:
        procs.append(subprocess.Popen(
            ["runuser", "-u", "munge", "--", _which("munged"), "-F", f"--socket={sock}",
             f"--pid-file={munge_dir}/munged.pid", f"--log-file={munge_dir}/munged.log",
             f"--seed-file={munge_dir}/munged.seed"],
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
        _wait(lambda: os.path.exists(sock), 20, "munged")
        procs.append(subprocess.Popen([_which("slurmctld"), "-D", "-f", conf], env=e,
                                      stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
        procs.append(subprocess.Popen([_which("slurmd"), "-D", "-f", conf, "-N", node], env=e,
                                      stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))

        def idle():
            r = subprocess.run([_which("sinfo"), "-h", "-o", "%t"], env=e, capture_output=True,
                               text=True, timeout=20)
            return r.returncode == 0 and r.stdout.strip() in ("idle", "mix", "alloc")

        _wait(idle, 60, "the Slurm node to be idle")
        yield {"env": e, "base": base}
    finally:
        for p in reversed(procs):
            if p.poll() is None:
                p.terminate()
                try:
                    p.wait(timeout=15)
                except subprocess.TimeoutExpired:
                    p.kill()
                    p.wait(timeout=15)
        for pidfile in ("slurmd.pid", "slurmctld.pid", "munge/munged.pid"):
            try:                                   # daemons that forked: stop them by PID file
                pid = int(open(os.path.join(base, pidfile)).read().strip())
                os.kill(pid, 15)
            except (OSError, ValueError):
                pass
        shutil.rmtree(base, ignore_errors=True)


def _squeue(e):
    r = subprocess.run([_which("squeue"), "-h", "-o", "%i %T"], env=e, capture_output=True,
                       text=True, timeout=20)
    return r.stdout.split("\n") if r.stdout.strip() else []


def _sbatch(e, cwd, *args):
    r = subprocess.run([_which("sbatch"), "--parsable", *args], env=e, capture_output=True,
                       text=True, timeout=30, cwd=cwd)
    assert r.returncode == 0, r.stderr
    return r.stdout.strip().split(";")[0]


def _job_field(e, job, name):
    r = subprocess.run([_which("scontrol"), "show", "job", job], env=e, capture_output=True,
                       text=True, timeout=20)
    for word in r.stdout.split():
        if word.startswith(name + "="):
            return word.split("=", 1)[1]
    return None


def test_sbatch_campaign_interrupted_then_requeued_completes_with_every_option(cluster, tmp_path):
    from fibril_hpc import load_campaign

    e = cluster["env"]
    os.chmod(tmp_path, 0o755)
    grid = write_grid(tmp_path, group_preloads=False, seeds=4)          # 32 jobs
    out = str(tmp_path / "tiny.h5")
    # options campaign.sbatch never names: the requeued job must keep them
    first = _sbatch(e, tmp_path, "--ntasks=2", "--time=10", "--job-name=keepname",
                    "--comment=keep-this-comment", "--output", str(tmp_path / "slurm-%j.out"),
                    os.path.join(ROOT, "slurm", "campaign.sbatch"), grid, "--no-progress")

    def some_records():
        try:
            return len(load_campaign(out, curves=False)) >= 1
        except Exception:  # noqa: BLE001 - not created yet
            return False

    _wait(some_records, 180, "the first records")
    # what Slurm does before a time limit (--signal=USR1@...): SIGUSR1 to every rank
    s = subprocess.run([_which("scancel"), "--signal=USR1", first], env=e, capture_output=True,
                       text=True, timeout=30)
    assert s.returncode == 0, s.stderr
    _wait(lambda: _job_field(e, first, "Restarts") == "1", 120, "the requeue")
    assert _job_field(e, first, "JobName") == "keepname"
    assert _job_field(e, first, "Comment") == "keep-this-comment"
    assert _job_field(e, first, "TimeLimit") == "00:10:00"
    _wait(lambda: not _squeue(e), 400, "the requeued job to finish")
    logs = sorted(tmp_path.glob("*.out"))
    text = "\n".join(p.read_text() for p in logs)
    assert len(logs) == 1, text                      # one job, requeued, appending to its log
    assert "exited with 75" in text and "requeueing" in text and "exited with 0" in text, text
    final = results_by_key(out)
    assert len(final) == 32 and {x["status"] for x in final.values()} == {"done"}
    assert {x["rank"] for x in final.values()} == {1}        # computed by the MPI worker


def test_job_array_shards_merge_equal_to_a_serial_run(cluster, tmp_path):
    from fibril_hpc.cli.campaign import main

    e = cluster["env"]
    os.chmod(tmp_path, 0o755)
    grid = write_grid(tmp_path, seeds=3)                     # 24 jobs in 12 loading paths
    array = _sbatch(e, tmp_path, "--array=1-3", "--time=10", "--output",
                    str(tmp_path / "shard-%A_%a.out"),
                    os.path.join(ROOT, "slurm", "array.sbatch"), grid, "--no-progress")
    _wait(lambda: not _squeue(e), 300, "the array to finish")
    text = "\n".join(p.read_text() for p in sorted(tmp_path.glob("shard-*.out")))
    assert text.count("exited with 0") == 3, text
    shards = sorted(str(p) for p in tmp_path.glob("tiny.shard-*-of-3.h5"))
    assert len(shards) == 3, (array, text)
    merged = str(tmp_path / "merged.h5")
    assert main(["merge", *shards, "-o", merged]) == 0
    serial = str(tmp_path / "serial.h5")
    assert main([grid, "--output", serial, "--no-progress", "--serial"]) == 0
    a, b = results_by_key(serial), results_by_key(merged)
    assert len(a) == 24 and set(a) == set(b) and same_numbers(a, b) == []
