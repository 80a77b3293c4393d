"""``fibril-bench``: the performance benchmarks of fibril-hpc, one table and one JSON file.

Everything runs on one thread (FFT threads, numba, BLAS): the bench re-runs itself in a child
process with ``OMP_NUM_THREADS=OPENBLAS_NUM_THREADS=MKL_NUM_THREADS=NUMBA_NUM_THREADS=1`` and every
scene uses ``fft_threads=1``. Sections (``--only`` picks some):

``fft``
    Per padded size m: the *floor*, a plain pyFFTW ``rfft2`` + ``irfft2`` pair on the full m x m
    grid (aligned buffers, one thread, the FFTW planner flag stated), and fibril's row-pruned pair
    (:class:`~fibril_hpc.fft.FFTPair`) and operator product (scatter + pair + gather).
``cg``
    Per grid size (18 x 18 default brush, the pitch sets N and m): time per CG iteration inside a
    solve on a fixed attached set (each iteration is one operator product) over the floor, and the
    all-in cost of a fixed-d contact solve (``PathDriver.solve_at``: every pass, set update and
    preconditioner rebuild included) per CG iteration; scaling with N against m^2 log m.
``curves``
    The default 18 x 18 pull-off curve (``F_P = 4``) at each accuracy preset: wall time, CG
    iterations, solves, FFT pairs, events, F_A (``accurate`` only with ``--accurate``: it is long).
``memory``
    In a fresh process, after imports and JIT: growth of the peak resident set (VmHWM, reset
    through /proc/self/clear_refs) while a model is built and a contact solve runs, against the
    bytes of the arrays the solve must hold (listed and counted).
``campaign``
    Jobs per hour of a small campaign grid: ``fibril-campaign --serial``, ``mpirun -n 2``
    (one worker) and ``mpirun -n 3`` (two workers).
``peers``
    Side by side in one process, on the peers' ground (non-adhesive rigid flat punches, 18 x 18,
    Gaussian heights, phi = 0.16, fixed plate displacement): fibril ``solve_at(d)``,
    ContactMechanics (``FreeFFTElasticHalfSpace`` + ``constrained_conjugate_gradients(offset=d)``)
    and tamaas (non-periodic Boussinesq operator, ``PolonskyKeerRey`` under load control at the
    force fibril reaches); answers compared, ratios taken run by run, medians reported. Skipped
    (and said so) when a peer is not installed (``pip install "fibril-hpc[bench]"``).

``--quick`` runs every section on small grids in seconds (a smoke test, not a measurement).
Results: ``<out>/bench-<UTC date-time>.json`` (default out: ``benchmarks/results``).
"""

from __future__ import annotations

import argparse
import contextlib
import datetime as _dt
import json
import math
import os
import platform
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

SECTIONS = ("fft", "cg", "curves", "memory", "campaign", "peers")
#: sections run only when named in --only
EXTRA_SECTIONS = ("opts",)
PIN_ENV = {"OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1", "MKL_NUM_THREADS": "1",
           "NUMBA_NUM_THREADS": "1"}
_CHILD_FLAG = "FIBRIL_BENCH_PINNED"
PHI = 0.16

#: (n_side, pitches) of the grid-size sweep; pitch p gives N = n_side p, m = padded_size(N)
FULL = {"n_side": 18, "pitches": (9, 15, 17, 29, 35), "peer_pitches": (15, 29), "runs": 3,
        "peer_runs": 3, "d_tilde": 1.5}
QUICK = {"n_side": 6, "pitches": (7, 9), "peer_pitches": (9,), "runs": 2, "peer_runs": 2,
         "d_tilde": 1.5}

_FLAG = {"estimate": "FFTW_ESTIMATE", "measure": "FFTW_MEASURE"}

#: which clock the derived numbers (ratios, per-iteration costs) use: "cpu" (this process's CPU
#: time, robust on a shared machine) or "wall"; both are always recorded.
CLOCK = {"name": "cpu"}


class Stopwatch:
    """Wall and CPU seconds of a block; ``.t`` is the one the bench's clock selects."""

    def __enter__(self):
        self._w, self._c = time.perf_counter(), time.process_time()
        return self

    def __exit__(self, *exc):
        self.wall = time.perf_counter() - self._w
        self.cpu = time.process_time() - self._c
        self.t = self.cpu if CLOCK["name"] == "cpu" else self.wall
        return False


# ------------------------------------------------------------------------------ utilities
def epd_for_pitch(pitch: int, phi: float = PHI) -> float:
    """An ``elements_per_diameter`` whose pitch (nearest odd whole number) is ``pitch``."""
    from .grid import pitch_elements

    e = pitch / math.sqrt(math.pi / (4.0 * phi))
    if pitch_elements(phi, e) != pitch:     # pragma: no cover - guards the formula
        raise ValueError(f"no elements_per_diameter gives pitch {pitch}")
    return e


def time_call(fn, runs: int = 5, min_s: float = 0.05) -> dict:
    """Seconds per call of ``fn`` over ``runs`` batches of >= ``min_s``: median and min of the
    wall clock, and median of this process's CPU time (robust when the machine is shared)."""
    fn()                                      # warm (page faults, caches)
    t0 = time.process_time()
    fn()
    one = max(time.process_time() - t0, 1e-6)
    k = max(1, int(min_s / one))
    per, cpu = [], []
    for _ in range(runs):
        t0, c0 = time.perf_counter(), time.process_time()
        for _ in range(k):
            fn()
        per.append((time.perf_counter() - t0) / k)
        cpu.append((time.process_time() - c0) / k)
    out = {"wall_median_s": statistics.median(per), "wall_min_s": min(per), "wall_samples_s": per,
           "cpu_median_s": statistics.median(cpu), "cpu_samples_s": cpu, "calls_per_sample": k}
    out["median_s"] = out["cpu_median_s" if CLOCK["name"] == "cpu" else "wall_median_s"]
    return out


def loadavg() -> list:
    try:
        return [round(x, 2) for x in os.getloadavg()]
    except OSError:  # pragma: no cover
        return []


def _scene(n_side, pitch, **kw):
    from .scene import Scene

    solver = {"fft_threads": 1}
    solver.update(kw.pop("solver", {}))
    return Scene(n_side=n_side, phi=PHI, elements_per_diameter=epd_for_pitch(pitch),
                 solver=solver, **kw)


class FloorCache:
    """The measured floor pair per padded size (measured once per run of the bench)."""

    def __init__(self, planner: str, runs: int):
        self.planner = planner
        self.runs = runs
        self.data: dict = {}

    def get(self, m: int) -> dict:
        if m not in self.data:
            self.data[m] = floor_pair(m, self.planner, self.runs)
        return self.data[m]

    def seconds(self, m: int) -> float:
        return self.get(m)["median_s"]


def floor_pair(m: int, planner: str = "estimate", runs: int = 5) -> dict:
    """A plain pyFFTW rfft2 + irfft2 pair on an m x m float64 grid, one thread."""
    import pyfftw

    a = pyfftw.empty_aligned((m, m), dtype=np.float64)
    spec = pyfftw.empty_aligned((m, m // 2 + 1), dtype=np.complex128)
    b = pyfftw.empty_aligned((m, m), dtype=np.float64)
    t0 = time.perf_counter()
    fwd = pyfftw.FFTW(a, spec, axes=(0, 1), flags=(_FLAG[planner],), threads=1)
    inv = pyfftw.FFTW(spec, b, axes=(0, 1), direction="FFTW_BACKWARD",
                      flags=(_FLAG[planner], "FFTW_DESTROY_INPUT"), threads=1)
    plan_s = time.perf_counter() - t0
    a[...] = np.random.default_rng(0).standard_normal((m, m))

    def pair():
        fwd.execute()
        inv.execute()

    out = time_call(pair, runs)
    out.update({"m": m, "planner": _FLAG[planner], "threads": 1, "plan_s": plan_s,
                "what": "pyFFTW rfft2 + irfft2 (FFTW r2c + c2r, full m x m, unnormalised)"})
    return out


# ------------------------------------------------------------------------------ sections
def section_fft(cfg, floors, log):
    from .model import build_scene_model

    rows = []
    for pitch in cfg["pitches"]:
        model = build_scene_model(_scene(cfg["n_side"], pitch,
                                         solver={"fft_planner": floors.planner}))
        op = model.operator
        pair = op.pair
        m = op.m
        fl = floors.get(m)
        rng = np.random.default_rng(1)
        pair.real_in[...] = rng.standard_normal(pair.real_in.shape)
        pruned = time_call(lambda: pair.convolve(op.kernel_hat), cfg["runs"])
        p = rng.standard_normal(model.geometry.n_active)
        u = np.empty_like(p)
        apply = time_call(lambda: op.apply(p, u), cfg["runs"])
        row = {"pitch": pitch, "N": model.geometry.n, "m": m, "R": len(pair.rows),
               "R_over_m": len(pair.rows) / m, "n_active": model.geometry.n_active,
               "floor_ms": 1e3 * fl["median_s"], "floor_plan_s": fl["plan_s"],
               "pruned_pair_ms": 1e3 * pruned["median_s"],
               "operator_apply_ms": 1e3 * apply["median_s"],
               "pruned_over_floor": pruned["median_s"] / fl["median_s"],
               "apply_over_floor": apply["median_s"] / fl["median_s"],
               "floor_wall_ms": 1e3 * fl["wall_median_s"],
               "pruned_pair_wall_ms": 1e3 * pruned["wall_median_s"],
               "samples": {"floor": fl, "pruned": pruned, "apply": apply}}
        log(f"fft m={m}: floor {row['floor_ms']:.2f} ms, pruned {row['pruned_pair_ms']:.2f} ms, "
            f"apply {row['operator_apply_ms']:.2f} ms")
        rows.append(row)
    return rows


def section_cg(cfg, floors, log):
    from .loading import PathDriver
    from .model import build_scene_model

    rows = []
    for pitch in cfg["pitches"]:
        model = build_scene_model(_scene(cfg["n_side"], pitch,
                                         solver={"fft_planner": floors.planner}))
        m = model.operator.m
        drv = PathDriver(model)
        d = cfg["d_tilde"] * model.scaling.d_c
        sv = model.solver
        walls, cpus, iters, pairs, solves = [], [], [], [], []
        for _ in range(cfg["runs"]):
            i0, p0, s0 = sv.iterations, model.fft_pairs, sv.solves
            with Stopwatch() as w:
                drv.solve_at(d)
            walls.append(w.t)
            cpus.append((w.wall, w.cpu))
            iters.append(sv.iterations - i0)
            pairs.append(model.fft_pairs - p0)
            solves.append(sv.solves - s0)
        # in-loop cost: re-solve on the final attached set from zero (fixed set, no set updates)
        att = drv.att.copy()
        b = d - model.geometry.z0
        x = np.zeros(model.geometry.n_active)
        u = np.zeros_like(x)
        per_product, loop_its = [], []
        for _ in range(max(3, cfg["runs"])):
            x[:] = 0.0
            p0 = model.fft_pairs
            with Stopwatch() as w:
                its = sv.solve(att, b, x, u)
            per_product.append(w.t / (model.fft_pairs - p0))
            loop_its.append(its)
        fl = floors.seconds(m)
        t_it = statistics.median(per_product)
        wall = statistics.median(walls[1:] if len(walls) > 1 else walls)
        row = {"pitch": pitch, "N": model.geometry.n, "m": m,
               "n_active": model.geometry.n_active, "n_attached": int(att.sum()),
               "d_tilde": cfg["d_tilde"], "floor_ms": 1e3 * fl,
               "cg_iteration_ms": 1e3 * t_it, "cg_iteration_over_floor": t_it / fl,
               "cg_its_fixed_set_from_zero": loop_its[0],
               "solve_at_s_first": walls[0], "solve_at_s_median_warm": wall,
               "solve_at_cg_iterations": iters[-1], "solve_at_fft_pairs": pairs[-1],
               "solve_at_cg_solves": solves[-1],
               "solve_at_per_iteration_over_floor": wall / iters[-1] / fl,
               "solve_at_per_pair_over_floor": wall / pairs[-1] / fl,
               "samples": {"solve_at_s": walls, "solve_at_wall_cpu_s": cpus,
                           "per_product_s": per_product}}
        log(f"cg m={m}: {row['cg_iteration_ms']:.2f} ms/iteration = "
            f"{row['cg_iteration_over_floor']:.2f} floor; solve_at {wall:.3f} s, "
            f"{iters[-1]} its, {pairs[-1]} pairs")
        rows.append(row)
    # scaling: cost per iteration against m^2 log m, normalised to the smallest grid
    if rows:
        ref = rows[0]
        law = lambda m: m * m * math.log(m)  # noqa: E731
        for r in rows:
            r["law_m2logm_ratio"] = law(r["m"]) / law(ref["m"])
            r["measured_iteration_ratio"] = r["cg_iteration_ms"] / ref["cg_iteration_ms"]
            r["measured_floor_ratio"] = r["floor_ms"] / ref["floor_ms"]
        if len(rows) >= 2:
            lm = np.log([r["m"] for r in rows])
            for key in ("cg_iteration_ms", "floor_ms"):
                slope = float(np.polyfit(lm, np.log([r[key] for r in rows]), 1)[0])
                for r in rows:
                    r[f"fitted_exponent_{key}"] = slope
            law_slope = float(np.polyfit(lm, np.log([law(r["m"]) for r in rows]), 1)[0])
            for r in rows:
                r["fitted_exponent_m2logm"] = law_slope
    return rows


def section_curves(cfg, floors, log, presets):
    from .api import simulate
    from .scene import Scene

    rows = []
    simulate(Scene(n_side=2, solver={"fft_threads": 1}))     # warm-up: JIT / cache loads
    for name, cap in presets:
        solver = {"fft_threads": 1, "fft_planner": floors.planner}
        if cap:
            solver["max_wall_s"] = cap
        scene = Scene(n_side=cfg["curve_n_side"], preset=name, solver=solver)
        with Stopwatch() as w:
            r = simulate(scene)
        wall = w.t
        st = dict(r.stats)
        m = r.discretisation["fft_size"]
        fl = floors.seconds(m)
        row = {"preset": name, "n_side": scene.n_side,
               "elements_per_diameter": scene.elements_per_diameter,
               "N": r.discretisation["grid_side"], "m": m, "status": r.status,
               "message": r.message, "time_s": wall, "cg_iterations": st["cg_iterations"],
               "cg_solves": st["cg_solves"], "fft_pairs": st["fft_pairs"],
               "events": st["events"], "cap_s": cap, "wall_clock_s": w.wall, "cpu_s": w.cpu,
               "F_A": r.main.F_A if r.status == "ok" else None,
               "floor_ms": 1e3 * fl, "wall_over_pairs_floor": wall / max(1, st["fft_pairs"]) / fl,
               "fft_pairs_per_cg_iteration": st["fft_pairs"] / max(1, st["cg_iterations"])}
        log(f"curve {name}: {r.status} {wall:.1f} s, {st['cg_iterations']} its, "
            f"{st['fft_pairs']} pairs, {st['events']} events, F_A {row['F_A']}")
        rows.append(row)
    return rows


_MEMORY_CHILD = r"""
import json, sys, numpy as np
def status():
    d = {}
    for line in open("/proc/self/status"):
        if line.startswith(("VmRSS", "VmHWM")):
            k, v = line.split(":"); d[k] = int(v.split()[0]) * 1024
    return d
from fibril_hpc.bench import _scene, memory_arrays
from fibril_hpc.model import build_scene_model
from fibril_hpc.loading import PathDriver
n_side, pitch, d_tilde = int(sys.argv[1]), int(sys.argv[2]), float(sys.argv[3])
planner = sys.argv[4]
# JIT / cache load and imports on a tiny model first
m0 = build_scene_model(_scene(2, 5, solver={"fft_planner": planner}))
PathDriver(m0).solve_at(1.0 * m0.scaling.d_c)
del m0
before = status()
open("/proc/self/clear_refs", "w").write("5")        # reset the peak (VmHWM) to the current RSS
reset = status()
model = build_scene_model(_scene(n_side, pitch, solver={"fft_planner": planner}))
drv = PathDriver(model)
built = status()
open("/proc/self/clear_refs", "w").write("5")
built_reset = status()
drv.solve_at(d_tilde * model.scaling.d_c)
after = status()
arrays = memory_arrays(model, drv)
print(json.dumps({"before": before, "reset": reset, "built": built, "built_reset": built_reset,
                  "after": after, "arrays": arrays,
                  "N": model.geometry.n, "m": model.operator.m,
                  "n_active": model.geometry.n_active, "n_attached": int(drv.att.sum())}))
"""


def memory_arrays(model, drv) -> dict:
    """Bytes of the arrays a solve must hold, by category (counts stated)."""
    op, sv, pc, g = model.operator, model.solver, model.solver.precond, model.geometry
    pair = op.pair
    fft = [a for a in (getattr(pair, n, None) for n in
                       ("real_in", "_rows_hat", "_full", "_spec", "_rows_back", "real_out",
                        "_padded")) if isinstance(a, np.ndarray)]
    vec_solver = [sv._r, sv._z, sv._d, sv._kd, sv._q]
    vec_driver = [getattr(drv, n) for n in ("p", "u", "g", "p1", "u1", "g1", "_b", "_ones",
                                            "p_ref", "p1_ref") if hasattr(drv, n)]
    small = [drv.att, drv.f, drv.f1, drv.counts, drv._dl, op._idx, g.iy, g.ix, g.z0, g.starts]
    pre = []
    if hasattr(pc, "full_inv"):
        pre = [pc.block, pc.full_inv, pc._zg, pc._att]
        pre += [inv for (_, inv) in pc._cache.values()]
    cats = {
        "fft_buffers": fft,
        "kernel_transform": [op.kernel_hat],
        "real_space_kernel_table": [t for t in [getattr(op, "_table", None)]
                                    if isinstance(t, np.ndarray)],
        "active_length_float_vectors": vec_solver + vec_driver,
        "index_and_small_vectors": small,
        "preconditioner_blocks": pre,
    }
    out = {k: {"count": len(v), "bytes": int(sum(a.nbytes for a in v))} for k, v in cats.items()}
    out["total_bytes"] = int(sum(c["bytes"] for c in out.values()))
    if hasattr(pc, "_cache"):
        out["preconditioner_blocks"]["cached_partial_inverses"] = len(pc._cache)
        out["preconditioner_blocks"]["block_elements"] = int(pc.m)
    return out


def section_memory(cfg, floors, log):
    rows = []
    env = dict(os.environ, **PIN_ENV)
    for pitch in cfg["memory_pitches"]:
        proc = subprocess.run([sys.executable, "-c", _MEMORY_CHILD, str(cfg["n_side"]),
                               str(pitch), str(cfg["d_tilde"]), floors.planner],
                              capture_output=True, text=True, env=env, timeout=1800)
        if proc.returncode != 0:
            rows.append({"pitch": pitch, "error": proc.stderr.strip().splitlines()[-1:]})
            log(f"memory pitch {pitch}: failed: {proc.stderr.strip()[-300:]}")
            continue
        r = json.loads(proc.stdout.strip().splitlines()[-1])
        # peak over the process after imports and JIT: max of the build peak and the solve peak
        growth = max(r["built"]["VmHWM"], r["after"]["VmHWM"]) - r["reset"]["VmRSS"]
        solve_growth = r["after"]["VmHWM"] - r["reset"]["VmRSS"]
        need = r["arrays"]["total_bytes"]
        row = {"pitch": pitch, "N": r["N"], "m": r["m"], "n_active": r["n_active"],
               "n_attached": r["n_attached"],
               "rss_after_imports_jit_MB": r["before"]["VmRSS"] / 2**20,
               "peak_growth_MB": growth / 2**20, "arrays_MB": need / 2**20,
               "growth_over_arrays": growth / need, "arrays": r["arrays"],
               "build_peak_growth_MB": (r["built"]["VmHWM"] - r["reset"]["VmRSS"]) / 2**20,
               "solve_peak_growth_MB": solve_growth / 2**20,
               "solve_peak_over_arrays": solve_growth / need,
               "rss_after_build_MB": r["built"]["VmRSS"] / 2**20,
               "rss_end_MB": r["after"]["VmRSS"] / 2**20}
        log(f"memory m={r['m']}: peak growth {row['peak_growth_MB']:.1f} MB vs arrays "
            f"{row['arrays_MB']:.1f} MB ({row['growth_over_arrays']:.2f}x)")
        rows.append(row)
    return rows


_CAMPAIGN_YAML = """\
description: fibril-bench throughput grid
output: bench.h5
scene:
  n_side: {n_side}
  phi: 0.16
  elements_per_diameter: {epd}
  solver:
    fft_threads: 1
k_tilde: {k_tilde}
sigma_tilde: {sigma_tilde}
F_P: {F_P}
seeds: {seeds}
group_preloads: true
"""


def _campaign_run(cmd, out, env, timeout):
    from .campaign.data import load_campaign

    if os.path.exists(out):
        os.remove(out)
    for ext in (".journal", ".lock"):
        for p in (out + ext,):
            if os.path.exists(p):
                os.remove(p)
    import resource

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
    tmp = tempfile.mkdtemp(prefix="fibril-bench-campaign-")
    try:
        c = cfg["campaign"]
        grid = os.path.join(tmp, "grid.yaml")
        with open(grid, "w") as fh:
            fh.write(_CAMPAIGN_YAML.format(**c))
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


# ------------------------------------------------------------------------------ peers
@contextlib.contextmanager
def _capture_fds(path):
    """Redirect the C-level stdout and stderr (fds 1, 2) into ``path`` (tamaas logs there)."""
    sys.stdout.flush()
    sys.stderr.flush()
    saved = [os.dup(1), os.dup(2)]
    fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC)
    os.dup2(fd, 1)
    os.dup2(fd, 2)
    try:
        yield
    finally:
        sys.stdout.flush()
        sys.stderr.flush()
        os.dup2(saved[0], 1)
        os.dup2(saved[1], 2)
        for f in saved + [fd]:
            os.close(f)


def peer_availability() -> dict:
    out = {}
    for mod, name in (("ContactMechanics", "contactmechanics"), ("tamaas", "tamaas")):
        try:
            m = __import__(mod)
            out[name] = getattr(m, "__version__", "") or "installed"
        except Exception as exc:  # noqa: BLE001 - any import failure means: skip this peer
            out[name] = None
            out[name + "_error"] = f"{type(exc).__name__}: {exc}"
    return out


class _FibrilPeer:
    def __init__(self, n_side, pitch, tol, planner):
        from .loading import PathDriver
        from .model import build_scene_model

        self.scene = _scene(n_side, pitch, k_tilde=math.inf, sigma_tilde=0.5, adhesion=False,
                            solver={"cg_tol": tol, "fft_planner": planner})
        self.model = build_scene_model(self.scene)
        self.drv = PathDriver(self.model)

    def solve(self, d):
        m, sv = self.model, self.model.solver
        i0, p0 = sv.iterations, m.fft_pairs
        with Stopwatch() as w:
            self.drv.solve_at(d)
        wall = w.t
        g = m.geometry
        p = np.zeros((g.n, g.n))
        p[g.iy, g.ix] = np.where(self.drv.att != 0, self.drv.p, 0.0)
        return {"time_s": wall, "clocks": (w.wall, w.cpu), "iterations": sv.iterations - i0,
                "fft_pairs": m.fft_pairs - p0, "force": self.drv.force(),
                "area": int(np.count_nonzero(p > 0)), "p": p}


class _CMPeer:
    """ContactMechanics: FreeFFTElasticHalfSpace (grid 2N x 2N) + constrained CG at fixed offset."""

    def __init__(self, geometry, tol, d):
        from ContactMechanics import FreeFFTElasticHalfSpace

        g = geometry
        self.g, self.tol = g, tol
        n, h = g.n, g.h
        self.sub = FreeFFTElasticHalfSpace((n, n), 1.0, physical_sizes=(n * h, n * h))
        self.calls = 0
        orig = self.sub.evaluate_disp

        def counted(f):
            self.calls += 1
            return orig(f)

        self.sub.evaluate_disp = counted
        big = 1e3 * (float(g.z0.max()) + abs(d) + 1.0)
        self.heights = np.full((n, n), -big)      # off the pillars: never reached
        self.heights[g.iy, g.ix] = -g.z0
        self.grid = tuple(int(s) for s in self.sub.nb_subdomain_grid_pts)

    def solve(self, d):
        from ContactMechanics.Optimization import constrained_conjugate_gradients

        g, n, h = self.g, self.g.n, self.g.h
        f0 = np.zeros(self.grid)
        pen = np.zeros((n, n), bool)
        pen[g.iy, g.ix] = (d - g.z0) > 0
        f0[:n, :n][pen] = -1e-3 * h * h * d        # small initial forces (platform.md)
        self.calls = 0
        with Stopwatch() as w:
            res = constrained_conjugate_gradients(self.sub, self.heights, offset=d,
                                                  initial_forces=f0, pentol=self.tol * d,
                                                  forcetol=1e-12, thermotol=self.tol,
                                                  maxiter=100000)
        wall = w.t
        p = np.asarray(res.jac) / (h * h)
        return {"time_s": wall, "clocks": (w.wall, w.cpu), "iterations": int(res.nit),
                "fft_pairs": self.calls, "force": float(res.jac.sum()),
                "area": int(np.count_nonzero(p > 0)), "p": p,
                "converged": bool(res.success), "message": str(res.message)}


class _TamaasPeer:
    """tamaas: basic_2d model, non-periodic Boussinesq operator, PolonskyKeerRey, load control."""

    def __init__(self, geometry, tol, d, logdir):
        import tamaas as tm

        g = geometry
        self.tm, self.g, self.tol, self.logdir = tm, g, tol, logdir
        n, h = g.n, g.h
        self.L = n * h
        big = 10.0 * (float(g.z0.max()) + abs(d) + 1.0)
        self.surface = np.full((n, n), -big)
        self.surface[g.iy, g.ix] = -g.z0
        tm.set_log_level(tm.LogLevel.info)
        self.model = tm.ModelFactory.createModel(tm.model_type.basic_2d, [self.L, self.L], [n, n])
        self.model.E = 1.0          # E* = E / (1 - nu^2) = 1, fibril's internal unit
        self.model.nu = 0.0
        tm.ModelFactory.registerNonPeriodic(self.model, "nonperiodic")
        self.solver = tm.PolonskyKeerRey(self.model, self.surface, tol)
        self.solver.setIntegralOperator("nonperiodic")
        self.solver.max_iter = 100000

    def solve(self, force):
        g, h = self.g, self.g.h
        logf = os.path.join(self.logdir, "tamaas.log")
        self.model.traction[...] = 0.0
        with _capture_fds(logf):
            with Stopwatch() as w:
                err = self.solver.solve(force / (self.L * self.L))
        wall = w.t
        its = None
        with open(logf) as fh:
            for line in fh:
                parts = line.split()
                if len(parts) == 3 and parts[0].isdigit():
                    its = int(parts[0])
        p = np.array(self.model.traction, dtype=float).reshape(g.n, g.n)
        return {"time_s": wall, "clocks": (w.wall, w.cpu), "iterations": its,
                "force": float(p.sum() * h * h),
                "area": int(np.count_nonzero(p > 0)), "p": p, "error": float(err)}


def section_peers(cfg, floors, log):
    avail = peer_availability()
    out = {"available": avail, "sizes": [], "tol": cfg["peer_tol"]}
    tmp = tempfile.mkdtemp(prefix="fibril-bench-peers-")
    try:
        for pitch in cfg["peer_pitches"]:
            fib = _FibrilPeer(cfg["n_side"], pitch, cfg["peer_tol"], floors.planner)
            g = fib.model.geometry
            d = cfg["d_tilde"] * fib.model.scaling.d_c
            m = fib.model.operator.m
            fl = floors.seconds(m)
            peers = {}
            if avail.get("contactmechanics"):
                peers["contactmechanics"] = _CMPeer(g, cfg["peer_tol"], d)
            if avail.get("tamaas"):
                peers["tamaas"] = _TamaasPeer(g, cfg["peer_tol"], d, tmp)
            fib.solve(d)        # warm: JIT, block inverses of this grid
            runs = []
            for rep in range(cfg["peer_runs"]):
                r = {"fibril": fib.solve(d)}
                F = r["fibril"]["force"]
                for name, peer in peers.items():
                    r[name] = peer.solve(d) if name == "contactmechanics" else peer.solve(F)
                for v in r.values():
                    v["load"] = loadavg()
                runs.append(r)
                log(f"peers m={m} run {rep}: " + ", ".join(
                    f"{k} {v['time_s']:.2f} s/{v['iterations']} its" for k, v in r.items()))
            size = {"pitch": pitch, "N": g.n, "m": m, "n_active": g.n_active, "d_tilde":
                    cfg["d_tilde"], "floor_ms": 1e3 * fl, "codes": {}}
            ref = runs[-1]["fibril"]
            for name in ["fibril"] + list(peers):
                rs = [r[name] for r in runs]
                t = statistics.median(x["time_s"] for x in rs)
                its = rs[-1]["iterations"]
                c = {"time_s_median": t, "time_s": [x["time_s"] for x in rs],
                     "wall_and_cpu_s": [x["clocks"] for x in rs],
                     "wall_clock_s_median": statistics.median(x["clocks"][0] for x in rs),
                     "iterations": its, "force": rs[-1]["force"],
                     "contact_elements": rs[-1]["area"],
                     "per_iteration_ms": None if not its else 1e3 * t / its,
                     "per_iteration_floor_pairs": None if not its else t / its / fl}
                if "fft_pairs" in rs[-1]:
                    c["fft_pairs"] = rs[-1]["fft_pairs"]
                for k in ("converged", "message", "error"):
                    if k in rs[-1]:
                        c[k] = rs[-1][k]
                if name != "fibril":
                    pr = rs[-1]["p"]
                    c["force_rel_diff"] = rs[-1]["force"] / ref["force"] - 1.0
                    c["contact_elements_diff"] = rs[-1]["area"] - ref["area"]
                    c["contact_set_mismatch"] = int(np.count_nonzero((pr > 0) != (ref["p"] > 0)))
                    c["pressure_rel_l2_diff"] = float(np.linalg.norm(pr - ref["p"])
                                                      / np.linalg.norm(ref["p"]))
                    ratios = [r[name]["time_s"] / r["fibril"]["time_s"] for r in runs]
                    c["ratio_wall_vs_fibril_median"] = statistics.median(ratios)
                    c["ratio_wall_vs_fibril_runs"] = ratios
                if name == "contactmechanics":
                    c["fft_grid"] = list(peers[name].grid)
                    if c["fft_grid"][0] != m:
                        c["floor_ms_own_grid"] = 1e3 * floors.seconds(c["fft_grid"][0])
                size["codes"][name] = c
            out["sizes"].append(size)
        return out
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


# ------------------------------------------------------------------------------ opts
def _curve_stats(scene):
    from .api import simulate

    with Stopwatch() as w:
        r = simulate(scene)
    st = r.stats
    return {"status": r.status, "F_A": r.main.F_A if r.status == "ok" else None,
            "time_s": w.t, "wall_s": w.wall, "cpu_s": w.cpu, "cg_iterations": st["cg_iterations"],
            "cg_solves": st["cg_solves"], "fft_pairs": st["fft_pairs"], "events": st["events"],
            "m": r.discretisation["fft_size"], "N": r.discretisation["grid_side"]}


def _forget_wisdom():
    import pyfftw

    pyfftw.forget_wisdom()


def _smooth(k: int, primes) -> bool:
    for p in primes:
        while k % p == 0:
            k //= p
    return k == 1


def section_opts(cfg, floors, log):
    """Before/after pairs of the optimisations in benchmarks/NOTES.md, side by side."""
    from . import halfspace as hs
    from .fft import FFTPair
    from .loading import PathDriver
    from .model import build_scene_model
    from .scene import Scene

    q = cfg["n_side"] < 18
    runs = max(3, cfg["runs"])
    out = {}
    # (1) exact block-Jacobi pillar preconditioner vs the diagonal (Sherman-Morrison) one
    n1 = 3 if q else 8
    pre = {}
    for kind in ("diagonal", "block"):      # warm-up: JIT / cache loads are not timed
        _curve_stats(Scene(n_side=2, solver={"fft_threads": 1, "preconditioner": kind}))
    for kind in ("diagonal", "block"):
        pre[kind] = _curve_stats(Scene(n_side=n1, solver={"fft_threads": 1,
                                                          "preconditioner": kind}))
        log(f"opts precond {kind}: {pre[kind]}")
    pre["F_A_rel_diff"] = pre["block"]["F_A"] / pre["diagonal"]["F_A"] - 1
    pre["scene"] = f"{n1}x{n1} default preset, F_P=4"
    out["preconditioner"] = pre
    # (3) event batching: event_merge 1e-4 (default) vs 1e-6, on a full 18 x 18 brush at a
    #     coarse pitch (many pillars: near-simultaneous events exist)
    n3, p3 = (3, 7) if q else (18, 9)
    ev = {}
    for em in (1e-6, 1e-4):
        ev[str(em)] = _curve_stats(_scene(n3, p3, solver={"event_merge": em}))
        log(f"opts event_merge {em}: {ev[str(em)]}")
    ev["F_A_rel_diff"] = ev["0.0001"]["F_A"] / ev["1e-06"]["F_A"] - 1
    ev["scene"] = f"{n3}x{n3}, pitch {p3}, default knobs, F_P=4"
    out["event_merge"] = ev
    # (4) loose tolerance inside detachment cascades: relax_tol 1e-5 (default) vs = cg_tol
    rx = {}
    for rt in (1e-8, 1e-5):
        rx[str(rt)] = _curve_stats(_scene(n3, p3, solver={"relax_tol": rt}))
        log(f"opts relax_tol {rt}: {rx[str(rt)]}")
    rx["F_A_rel_diff"] = rx["1e-05"]["F_A"] / rx["1e-08"]["F_A"] - 1
    rx["scene"] = ev["scene"]
    out["relax_tol"] = rx
    # (5) padded FFT size: the smallest 7-smooth m >= 2N-1 vs the smallest even 2^a 5^b one
    #     (odd sizes such as 625 = 5^4 are slow in FFTW's r2c/c2r)
    cases = {}
    orig = hs.padded_size
    for pitch, label, bump, planner in [(p, lab, bump, pl) for p in ((9,) if q else (17, 35))
                                        for lab, bump in (("smallest 7-smooth", False),
                                                          ("even 2^a 5^b", True))
                                        for pl in ("estimate", "measure")]:
        def chosen(n, bump=bump):
            m = orig(n)
            if bump:
                m = next(k for k in range(m, 2 * m) if k % 2 == 0 and _smooth(k, (2, 5)))
            return m
        hs.padded_size = chosen
        _forget_wisdom()        # no plan may profit from an earlier MEASURE of the same size
        try:
            model = build_scene_model(_scene(cfg["n_side"], pitch,
                                             solver={"fft_planner": planner}))
        finally:
            hs.padded_size = orig
        drv = PathDriver(model)
        d = cfg["d_tilde"] * model.scaling.d_c
        drv.solve_at(d)
        att, b = drv.att.copy(), d - model.geometry.z0
        x, u = np.zeros(model.geometry.n_active), np.zeros(model.geometry.n_active)
        per = []
        for _ in range(runs):
            x[:] = 0
            p0 = model.fft_pairs
            with Stopwatch() as w:
                model.solver.solve(att, b, x, u)
            per.append(w.t / (model.fft_pairs - p0))
        key = f"N={model.geometry.n} {label} {planner}"
        cases[key] = {"pitch": pitch, "m": model.operator.m, "N": model.geometry.n,
                      "rule": label, "planner": planner,
                      "cg_iteration_ms": 1e3 * statistics.median(per), "force": drv.force()}
        log(f"opts padded size {key}: {cases[key]}")
    for r in cases.values():
        base = cases[f"N={r['N']} smallest 7-smooth estimate"]
        r["speedup_vs_default"] = base["cg_iteration_ms"] / r["cg_iteration_ms"]
        r["force_rel_diff"] = r["force"] / base["force"] - 1
    out["padded_size"] = cases
    # (6) FFTW planner: ESTIMATE (fibril's default) vs MEASURE for fibril's pruned pair
    pl = {}
    for pitch in ((9,) if q else (15, 17, 35)):
        model = build_scene_model(_scene(cfg["n_side"], pitch))
        rows, m = model.operator.pair.rows, model.operator.m
        r = {"m": m}
        for planner in ("estimate", "measure"):
            _forget_wisdom()
            with Stopwatch() as w:
                pair = FFTPair(m, rows, threads=1, planner=planner)
            pair.real_in[...] = np.random.default_rng(2).standard_normal(pair.real_in.shape)
            t = time_call(lambda: pair.convolve(model.operator.kernel_hat), runs)
            _forget_wisdom()
            r[planner] = {"pair_ms": 1e3 * t["median_s"], "plan_s": w.t,
                          "floor_ms": 1e3 * floor_pair(m, planner, runs)["median_s"]}
        gain = 1e-3 * (r["estimate"]["pair_ms"] - r["measure"]["pair_ms"])
        r["pair_speedup"] = r["estimate"]["pair_ms"] / r["measure"]["pair_ms"]
        r["break_even_pairs"] = ((r["measure"]["plan_s"] - r["estimate"]["plan_s"]) / gain
                                 if gain > 0 else None)
        log(f"opts planner m={m}: {r}")
        pl[str(m)] = r
    out["planner"] = pl
    return out


# ------------------------------------------------------------------------------ table
def _fmt(x, spec=".3g"):
    if x is None:
        return "-"
    if isinstance(x, float):
        return format(x, spec)
    return str(x)


def table_rows(res: dict) -> list:
    rows = []
    add = lambda *a: rows.append(tuple(str(x) for x in a))  # noqa: E731
    pl = res["meta"]["fftw_planner"]
    for r in res.get("fft", []):
        add("fft", f"N={r['N']} m={r['m']} R={r['R']}", f"floor pair ({pl}, 1 thread)",
            f"{r['floor_ms']:.2f} ms")
        add("fft", f"N={r['N']} m={r['m']}", "row-pruned pair / floor",
            f"{r['pruned_pair_ms']:.2f} ms = {r['pruned_over_floor']:.2f}x")
    for r in res.get("cg", []):
        add("cg", f"N={r['N']} m={r['m']}", "CG iteration / floor pair",
            f"{r['cg_iteration_ms']:.2f} ms = {r['cg_iteration_over_floor']:.2f}x")
        add("cg", f"N={r['N']} m={r['m']}", "solve_at: time, CG its, FFT pairs, all-in per it",
            f"{r['solve_at_s_median_warm']:.3f} s, {r['solve_at_cg_iterations']}, "
            f"{r['solve_at_fft_pairs']}, {r['solve_at_per_iteration_over_floor']:.2f}x floor")
        add("scaling", f"N={r['N']} m={r['m']}", "t_it / t_it(smallest) vs m^2 log m law",
            f"{r['measured_iteration_ratio']:.2f} vs {r['law_m2logm_ratio']:.2f} "
            f"(floor {r['measured_floor_ratio']:.2f})")
    cg = res.get("cg", [])
    if len(cg) >= 2 and "fitted_exponent_cg_iteration_ms" in cg[0]:
        add("scaling", f"m={cg[0]['m']}..{cg[-1]['m']}", "fitted exponent of m: CG it, floor, law",
            f"{cg[0]['fitted_exponent_cg_iteration_ms']:.2f}, "
            f"{cg[0]['fitted_exponent_floor_ms']:.2f}, {cg[0]['fitted_exponent_m2logm']:.2f}")
    for r in res.get("curves", []):
        add("curve", f"{r['preset']} {r['n_side']}x{r['n_side']} N={r['N']} m={r['m']}",
            "time, CG its, FFT pairs, events, F_A",
            f"{r['time_s']:.1f} s{'' if r['status'] == 'ok' else ' (' + r['status'] + ')'}, "
            f"{r['cg_iterations']}, {r['fft_pairs']}, {r['events']}, {_fmt(r['F_A'], '.4f')}")
        add("curve", f"{r['preset']}", "time per FFT pair / floor",
            f"{r['wall_over_pairs_floor']:.2f}x")
    for r in res.get("memory", []):
        if "error" in r:
            add("memory", f"pitch {r['pitch']}", "failed", r["error"])
            continue
        a = r["arrays"]
        add("memory", f"N={r['N']} m={r['m']}", "peak RSS growth (build+solve) / arrays held",
            f"{r['peak_growth_MB']:.1f} MB / {r['arrays_MB']:.1f} MB = "
            f"{r['growth_over_arrays']:.2f}x")
        add("memory", f"N={r['N']} m={r['m']}", "peak RSS growth of the solve alone / arrays",
            f"{r['solve_peak_growth_MB']:.1f} MB = {r['solve_peak_over_arrays']:.2f}x "
            f"(build peak {r['build_peak_growth_MB']:.1f} MB)")
        add("memory", f"N={r['N']} m={r['m']}", "arrays counted",
            f"{a['fft_buffers']['count']} FFT buffers, 1 kernel transform, "
            f"{a['active_length_float_vectors']['count']} active-length vectors, "
            f"{a['preconditioner_blocks']['count']} block arrays")
    camp = res.get("campaign")
    if camp:
        for r in camp["modes"]:
            extra = f" ({r['speedup_vs_n2']:.2f}x -n 2)" if "speedup_vs_n2" in r else ""
            add("campaign", f"{r['mode']} ({r['workers']} worker{'s' if r['workers'] > 1 else ''})",
                f"jobs/hour ({r['jobs']} jobs); cores used; jobs/CPU-hour",
                f"{r['jobs_per_hour_median']:.0f}{extra}; {r['cores_used_median']:.2f}; "
                f"{r['jobs_per_cpu_hour_median']:.0f}")
    peers = res.get("peers")
    if peers:
        for name in ("contactmechanics", "tamaas"):
            if not peers["available"].get(name):
                add("peers", name, "not installed", "skipped")
        for s in peers["sizes"]:
            for name, c in s["codes"].items():
                ratio = ""
                if "ratio_wall_vs_fibril_median" in c:
                    ratio = f" = {c['ratio_wall_vs_fibril_median']:.1f}x fibril"
                add("peers", f"{name} N={s['N']} m={s['m']}",
                    "solve time, CG its, FFT pairs, per it in floor pairs",
                    f"{c['time_s_median']:.3f} s{ratio}, {c['iterations']}, "
                    f"{c.get('fft_pairs', '-')}, {_fmt(c['per_iteration_floor_pairs'], '.1f')}")
                if name != "fibril":
                    add("peers", f"{name} N={s['N']}", "agreement: force, contact set, p (L2)",
                        f"{c['force_rel_diff']:.1e}, {c['contact_set_mismatch']} elements, "
                        f"{c['pressure_rel_l2_diff']:.1e}")
    o = res.get("opts")
    if o:
        p = o["preconditioner"]
        add("opts", f"preconditioner ({p['scene']})", "diagonal -> block: CG its, pairs, time",
            f"{p['diagonal']['cg_iterations']} -> {p['block']['cg_iterations']}, "
            f"{p['diagonal']['fft_pairs']} -> {p['block']['fft_pairs']}, "
            f"{p['diagonal']['time_s']:.1f} -> {p['block']['time_s']:.1f} s "
            f"(F_A rel diff {p['F_A_rel_diff']:.1e})")
        e = o["event_merge"]
        add("opts", f"event_merge 1e-6 -> 1e-4 ({e['scene']})", "solves, time, F_A rel diff",
            f"{e['1e-06']['cg_solves']} -> {e['0.0001']['cg_solves']}, "
            f"{e['1e-06']['time_s']:.1f} -> {e['0.0001']['time_s']:.1f} s, "
            f"{e['F_A_rel_diff']:.1e}")
        x = o["relax_tol"]
        add("opts", f"relax_tol 1e-8 -> 1e-5 ({x['scene']})", "CG its, time, F_A rel diff",
            f"{x['1e-08']['cg_iterations']} -> {x['1e-05']['cg_iterations']}, "
            f"{x['1e-08']['time_s']:.1f} -> {x['1e-05']['time_s']:.1f} s, {x['F_A_rel_diff']:.1e}")
        for r in o["padded_size"].values():
            add("opts", f"N={r['N']} m={r['m']} ({r['rule']}), FFTW {r['planner']}",
                "CG iteration time (vs 7-smooth, ESTIMATE)",
                f"{r['cg_iteration_ms']:.2f} ms ({r['speedup_vs_default']:.2f}x, "
                f"force rel diff {r['force_rel_diff']:.0e})")
        for m, r in o["planner"].items():
            add("opts", f"FFTW ESTIMATE -> MEASURE m={m}", "pruned pair, planning, break-even",
                f"{r['estimate']['pair_ms']:.2f} -> {r['measure']['pair_ms']:.2f} ms "
                f"({r['pair_speedup']:.2f}x), {r['measure']['plan_s']:.1f} s, "
                f"{_fmt(r['break_even_pairs'], '.0f')} pairs")
    return rows


def format_table(rows) -> str:
    head = ("section", "case", "quantity", "value")
    w = [max(len(r[i]) for r in list(rows) + [head]) for i in range(4)]
    line = lambda r: " | ".join(s.ljust(w[i]) for i, s in enumerate(r)).rstrip()  # noqa: E731
    sep = "-+-".join("-" * x for x in w)
    return "\n".join([line(head), sep] + [line(r) for r in rows])


# ------------------------------------------------------------------------------ driver
def _git_state() -> dict:
    """Commit and the modified tracked files of the checkout the bench runs from (if any)."""
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    try:
        head = subprocess.run(["git", "rev-parse", "HEAD"], cwd=root, capture_output=True,
                              text=True, timeout=30).stdout.strip()
        dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"],
                               cwd=root, capture_output=True, text=True, timeout=30).stdout
        return {"commit": head, "modified": [ln[3:] for ln in dirty.splitlines()]}
    except (OSError, subprocess.SubprocessError):
        return {}


def _versions() -> dict:
    from .results import software_versions

    v = dict(software_versions())
    v["python"] = platform.python_version()
    for mod in ("ContactMechanics", "tamaas", "muGrid"):
        try:
            v[mod] = getattr(__import__(mod), "__version__", "")
        except Exception:  # noqa: BLE001
            v[mod] = None
    return v


def run(args, log=print) -> dict:
    CLOCK["name"] = args.clock
    cfg = dict(QUICK if args.quick else FULL)
    cfg["peer_tol"] = args.tol
    cfg["curve_n_side"] = 3 if args.quick else 18
    cfg["memory_pitches"] = (cfg["pitches"][-1],) if args.quick else (15, 29)
    cfg["campaign"] = ({"n_side": 2, "epd": 4, "k_tilde": "[1]", "sigma_tilde": "[0.5]",
                        "F_P": "[1]",
                        "seeds": 2, "reps": 1, "timeout_s": 300, "mpi": False}
                       if args.quick else
                       {"n_side": 6, "epd": 6, "k_tilde": "[1, 0.01]", "F_P": "[1, 3]",
                        "sigma_tilde": "[0.3, 1]", "seeds": 3, "reps": 2, "timeout_s": 900,
                        "mpi": True})
    if args.runs:
        cfg["runs"] = cfg["peer_runs"] = args.runs
    if args.pitches:
        cfg["pitches"] = tuple(args.pitches)
    if args.peer_pitches:
        cfg["peer_pitches"] = tuple(args.peer_pitches)
    sections = SECTIONS if not args.only else tuple(args.only.split(","))
    bad = [s for s in sections if s not in SECTIONS + EXTRA_SECTIONS]
    if bad:
        raise SystemExit(f"fibril-bench: unknown section {bad[0]!r} "
                         f"(known: {', '.join(SECTIONS + EXTRA_SECTIONS)})")
    floors = FloorCache(args.planner, max(3, cfg["runs"]))
    started = _dt.datetime.now(_dt.timezone.utc)
    res = {"meta": {"command": " ".join(["fibril-bench"] + list(args.argv)),
                    "mode": "quick" if args.quick else "full",
                    "started_utc": started.strftime("%Y-%m-%dT%H:%M:%SZ"),
                    "host": platform.node(), "cpus": os.cpu_count(),
                    "affinity": len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity")
                    else None,
                    "loadavg_start": loadavg(), "threads": PIN_ENV,
                    "fftw_planner": _FLAG[args.planner], "clock": args.clock, "config": cfg,
                    "versions": _versions(), "git": _git_state()}}
    presets = [("fast", None), ("default", None)]
    if args.accurate:
        presets.append(("accurate", args.accurate_cap))
    for s in sections:
        t0 = time.perf_counter()
        load0 = loadavg()
        if s == "curves":
            res[s] = section_curves(cfg, floors, log, presets)
        else:
            res[s] = globals()["section_" + s](cfg, floors, log)
        res["meta"].setdefault("section_wall_s", {})[s] = time.perf_counter() - t0
        res["meta"].setdefault("section_load", {})[s] = {"start": load0, "end": loadavg()}
    res["floors"] = {str(m): {k: v for k, v in f.items()} for m, f in floors.data.items()}
    res["meta"]["loadavg_end"] = loadavg()
    res["meta"]["finished_utc"] = _dt.datetime.now(_dt.timezone.utc).strftime(
        "%Y-%m-%dT%H:%M:%SZ")
    os.makedirs(args.out, exist_ok=True)
    path = os.path.join(args.out, f"bench-{started.strftime('%Y-%m-%d-%H%M%S')}"
                        f"{'-quick' if args.quick else ''}.json")
    tmp = path + ".tmp"
    with open(tmp, "w") as fh:
        json.dump(res, fh, indent=1, default=float)
    os.replace(tmp, path)
    res["meta"]["json"] = path
    return res


def _default_out() -> str:
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    if os.path.isdir(os.path.join(root, "benchmarks")):
        return os.path.join(root, "benchmarks", "results")
    return os.path.join("benchmarks", "results")


def parse_args(argv):
    ap = argparse.ArgumentParser(prog="fibril-bench", description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="small grids, seconds (smoke run)")
    ap.add_argument("--out", default=_default_out(), metavar="DIR",
                    help="folder of the JSON file (default: benchmarks/results of the source "
                         "checkout, else of the current folder)")
    ap.add_argument("--only", default=None, metavar="S1,S2",
                    help="sections to run, of: " + ", ".join(SECTIONS) + " (default: all), "
                         "and 'opts' (optimisation experiments of benchmarks/NOTES.md, "
                         "minutes; only when named)")
    ap.add_argument("--planner", choices=tuple(_FLAG), default="estimate",
                    help="FFTW planner flag of the floor and of fibril's plans (default estimate, "
                         "fibril's default)")
    ap.add_argument("--clock", choices=("cpu", "wall"), default="cpu",
                    help="clock of the reported times and ratios: this process's CPU time "
                         "(default; robust on a shared machine) or wall time (both recorded)")
    ap.add_argument("--runs", type=int, default=None, help="repetitions (median reported)")
    ap.add_argument("--pitches", type=int, nargs="+", default=None,
                    help="pitches (elements) of the grid-size sweep (odd)")
    ap.add_argument("--peer-pitches", type=int, nargs="+", default=None)
    ap.add_argument("--tol", type=float, default=1e-8,
                    help="tolerance given to every code in the peer comparison (default 1e-8)")
    ap.add_argument("--accurate", action="store_true",
                    help="also the 'accurate' preset curve (long; capped by --accurate-cap)")
    ap.add_argument("--accurate-cap", type=float, default=1800.0, metavar="S")
    ap.add_argument("--no-pin", action="store_true",
                    help="do not re-run in a child with one thread per library")
    args = ap.parse_args(argv)
    args.argv = list(argv)
    return args


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else list(argv)
    args = parse_args(argv)
    if not args.no_pin and os.environ.get(_CHILD_FLAG) != "1":
        env = dict(os.environ, **PIN_ENV)
        env[_CHILD_FLAG] = "1"
        return subprocess.call([sys.executable, "-m", "fibril_hpc.bench"] + argv, env=env)
    try:
        import numba

        numba.set_num_threads(1)
    except Exception:  # noqa: BLE001 - numba without threading layer
        pass
    log = lambda msg: print(f"[{time.strftime('%H:%M:%S')}] {msg}", file=sys.stderr,  # noqa: E731
                            flush=True)
    res = run(args, log)
    m = res["meta"]
    print(f"fibril-bench ({m['mode']}), {m['started_utc']} - {m['finished_utc']}, "
          f"{m['cpus']} CPUs, load average {m['loadavg_start']} -> {m['loadavg_end']}, "
          f"one thread per library, FFTW {m['fftw_planner']}, times are {m['clock']} "
          f"{'(CPU time of the bench process)' if m['clock'] == 'cpu' else 'time'}")
    print(format_table(table_rows(res)))
    print(f"JSON: {m['json']}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
