"""The ``campaign`` section: jobs per hour of a small grid, serial and under mpirun."""

from __future__ import annotations

import os
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

import yaml

from fibril_hpc import load_campaign

from .timing import PIN_ENV, loadavg


def campaign_grid(c: dict) -> dict:
    """The throughput grid of the section's configuration ``c``."""
    return {"description": "fibril-bench throughput grid", "output": "bench.h5",
            "scene": {"n_side": c["n_side"], "phi": 0.16, "elements_per_diameter": c["epd"],
                      "solver": {"fft_threads": 1}},
            "k_tilde": c["k_tilde"], "sigma_tilde": c["sigma_tilde"], "F_P": c["F_P"],
            "seeds": c["seeds"], "group_preloads": True}


def _campaign_run(cmd, out, env, timeout):
    if os.path.exists(out):
        os.remove(out)
    for ext in (".journal", ".lock"):
        for p in (out + ext,):
            if os.path.exists(p):
                os.remove(p)
    ru0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    proc = subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=timeout)
    wall = time.perf_counter() - t0
    ru1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (ru1.ru_utime - ru0.ru_utime) + (ru1.ru_stime - ru0.ru_stime)
    if proc.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} exited {proc.returncode}: {proc.stderr[-500:]}")
    c = load_campaign(out, curves=False)
    done = [j for j in c.jobs if j["status"] == "done"]
    job_wall = sum(j["wall_s"] / max(1, j.get("group_size", 1)) for j in done)
    return {"wall_s": wall, "jobs_done": len(done), "jobs_per_hour": 3600.0 * len(done) / wall,
            "sum_job_wall_s": job_wall, "cpu_s_all_ranks": cpu,
            "cores_used": cpu / wall, "jobs_per_cpu_hour": 3600.0 * len(done) / max(cpu, 1e-9)}


def section_campaign(cfg, floors, log):
    """Jobs per hour of a small grid: serial, ``mpirun -n 2`` and ``mpirun -n 3``."""
    tmp = tempfile.mkdtemp(prefix="fibril-bench-campaign-")
    try:
        c = cfg["campaign"]
        grid = os.path.join(tmp, "grid.yaml")
        with open(grid, "w") as fh:
            yaml.safe_dump(campaign_grid(c), fh)
        out = os.path.join(tmp, "bench.h5")
        exe = shutil.which("fibril-campaign", path=os.path.dirname(sys.executable)) or \
            shutil.which("fibril-campaign")
        base = [exe] if exe else [sys.executable, "-m", "fibril_hpc.cli.campaign"]
        run = base + ["run", grid, "--output", out, "--no-progress", "--checkpoint-s", "5"]
        mpirun = shutil.which("mpirun", path=os.path.dirname(sys.executable)) or \
            shutil.which("mpirun")
        env = dict(os.environ, **PIN_ENV)
        modes = [("serial", run + ["--serial"], 1)]
        try:
            import mpi4py  # noqa: F401
            have_mpi = mpirun is not None
        except ImportError:
            have_mpi = False
        if have_mpi and c.get("mpi", True):
            modes += [("mpirun -n 2", [mpirun, "-n", "2"] + run, 1),
                      ("mpirun -n 3", [mpirun, "-n", "3"] + run, 2)]
        results = {name: [] for name, _, _ in modes}
        for rep in range(c["reps"]):
            order = modes if rep % 2 == 0 else modes[::-1]   # alternate to spread drifts in load
            for name, cmd, workers in order:
                r = _campaign_run(cmd, out, env, timeout=c["timeout_s"])
                r["workers"] = workers
                r["load"] = loadavg()
                results[name].append(r)
                log(f"campaign {name}: {r['jobs_done']} jobs in {r['wall_s']:.1f} s = "
                    f"{r['jobs_per_hour']:.0f} jobs/h")
        rows = []
        for name, _, workers in modes:
            rs = results[name]
            rows.append({"mode": name, "workers": workers,
                         "jobs": rs[0]["jobs_done"],
                         "wall_s_median": statistics.median(r["wall_s"] for r in rs),
                         "jobs_per_hour_median": statistics.median(r["jobs_per_hour"] for r in rs),
                         "sum_job_wall_s_median": statistics.median(r["sum_job_wall_s"]
                                                                    for r in rs),
                         "cores_used_median": statistics.median(r["cores_used"] for r in rs),
                         "jobs_per_cpu_hour_median": statistics.median(r["jobs_per_cpu_hour"]
                                                                      for r in rs),
                         "runs": rs})
        by = {r["mode"]: r for r in rows}
        if "mpirun -n 2" in by and "mpirun -n 3" in by:
            by["mpirun -n 3"]["speedup_vs_n2"] = (by["mpirun -n 3"]["jobs_per_hour_median"]
                                                  / by["mpirun -n 2"]["jobs_per_hour_median"])
        return {"grid": c, "modes": rows, "mpi": have_mpi}
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
