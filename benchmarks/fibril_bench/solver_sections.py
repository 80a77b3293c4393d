"""Solver sections of the benchmark: ``fft``, ``cg``, ``curves`` and the ``opts`` experiments.

Each section is ``section_<name>(cfg, floors, log)`` and returns JSON-able rows; ``cfg["clock"]``
selects the clock of the reported times.
"""

from __future__ import annotations

import math
import statistics

import numpy as np
import pyfftw

from fibril_hpc import Scene, simulate
from fibril_hpc.elastic.fft import FFTPair
from fibril_hpc.elastic.greens import padded_size
from fibril_hpc.model import build_scene_model, scene_lattice
from fibril_hpc.path.loading import PathDriver

from .timing import Stopwatch, bench_scene, floor_pair, time_call


def scene_grid_side(scene) -> int:
    """Grid side N (elements) of a scene: n_side pillars of ``pitch`` elements."""
    return scene_lattice(scene).grid_side


def section_fft(cfg, floors, log):
    """Floor pair, fibril's pruned pair and operator product per padded size."""
    rows = []
    for pitch in cfg["pitches"]:
        model = build_scene_model(bench_scene(cfg["n_side"], pitch,
                                         solver={"fft_planner": floors.planner}))
        op = model.operator
        pair = op.pair
        m = op.m
        fl = floors.get(m)
        rng = np.random.default_rng(1)
        pair.real_in[...] = rng.standard_normal(pair.real_in.shape)
        pruned = time_call(pair.convolve, cfg["runs"], clock=cfg["clock"])
        p = rng.standard_normal(model.geometry.n_active)
        u = np.empty_like(p)
        apply = time_call(lambda op=op, p=p, u=u: op.apply(p, u), cfg["runs"], clock=cfg["clock"])
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
    """Cost per CG iteration and of a fixed-d contact solve per grid size."""
    rows = []
    for pitch in cfg["pitches"]:
        model = build_scene_model(bench_scene(cfg["n_side"], pitch,
                                         solver={"fft_planner": floors.planner}))
        m = model.operator.m
        drv = PathDriver(model)
        d = cfg["d_tilde"] * model.scaling.d_c
        sv = model.solver
        walls, cpus, iters, pairs, solves = [], [], [], [], []
        for _ in range(cfg["runs"]):
            i0, p0, s0 = sv.iterations, model.fft_pairs, sv.solves
            with Stopwatch(cfg["clock"]) as w:
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
            with Stopwatch(cfg["clock"]) as w:
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


def section_curves(cfg, floors, log):
    """The default pull-off curve at each accuracy preset of ``cfg['presets']``."""
    presets = cfg["presets"]
    rows = []
    simulate(Scene(n_side=2, solver={"fft_threads": 1}))     # warm-up: JIT / cache loads
    for name, cap in presets:
        solver = {"fft_threads": 1, "fft_planner": floors.planner}
        if cap:
            solver["max_wall_s"] = cap
        scene = Scene(n_side=cfg["curve_n_side"], preset=name, solver=solver)
        with Stopwatch(cfg["clock"]) as w:
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


def _curve_stats(scene, clock):
    with Stopwatch(clock) as w:
        r = simulate(scene)
    st = r.stats
    return {"status": r.status, "F_A": r.main.F_A if r.status == "ok" else None,
            "time_s": w.t, "wall_s": w.wall, "cpu_s": w.cpu, "cg_iterations": st["cg_iterations"],
            "cg_solves": st["cg_solves"], "fft_pairs": st["fft_pairs"], "events": st["events"],
            "m": r.discretisation["fft_size"], "N": r.discretisation["grid_side"]}


def _forget_wisdom():
    pyfftw.forget_wisdom()


def _smooth(k: int, primes) -> bool:
    for p in primes:
        while k % p == 0:
            k //= p
    return k == 1


def section_opts(cfg, floors, log):
    """Before/after pairs of the optimisations in benchmarks/NOTES.md, side by side."""
    q = cfg["n_side"] < 18
    runs = max(3, cfg["runs"])
    out = {}
    # (1) exact block-Jacobi pillar preconditioner vs the diagonal (Sherman-Morrison) one
    n1 = 3 if q else 8
    pre = {}
    for kind in ("diagonal", "block"):      # warm-up: JIT / cache loads are not timed
        _curve_stats(Scene(n_side=2, solver={"fft_threads": 1, "preconditioner": kind}),
                     cfg["clock"])
    for kind in ("diagonal", "block"):
        pre[kind] = _curve_stats(Scene(n_side=n1, solver={"fft_threads": 1,
                                                          "preconditioner": kind}), cfg["clock"])
        log(f"opts precond {kind}: {pre[kind]}")
    pre["F_A_rel_diff"] = pre["block"]["F_A"] / pre["diagonal"]["F_A"] - 1
    pre["scene"] = f"{n1}x{n1} default preset, F_P=4"
    out["preconditioner"] = pre
    # (3) event batching: event_merge 1e-4 (default) vs 1e-6, on a full 18 x 18 brush at a
    #     coarse pitch (many pillars: near-simultaneous events exist)
    n3, p3 = (3, 7) if q else (18, 9)
    ev = {}
    for em in (1e-6, 1e-4):
        ev[str(em)] = _curve_stats(bench_scene(n3, p3, solver={"event_merge": em}), cfg["clock"])
        log(f"opts event_merge {em}: {ev[str(em)]}")
    ev["F_A_rel_diff"] = ev["0.0001"]["F_A"] / ev["1e-06"]["F_A"] - 1
    ev["scene"] = f"{n3}x{n3}, pitch {p3}, default knobs, F_P=4"
    out["event_merge"] = ev
    # (4) loose tolerance inside detachment cascades: relax_tol 1e-5 (default) vs = cg_tol
    rx = {}
    for rt in (1e-8, 1e-5):
        rx[str(rt)] = _curve_stats(bench_scene(n3, p3, solver={"relax_tol": rt}), cfg["clock"])
        log(f"opts relax_tol {rt}: {rx[str(rt)]}")
    rx["F_A_rel_diff"] = rx["1e-05"]["F_A"] / rx["1e-08"]["F_A"] - 1
    rx["scene"] = ev["scene"]
    out["relax_tol"] = rx
    # (5) padded FFT size: the smallest 7-smooth m >= 2N-1 vs the smallest even 2^a 5^b one
    #     (odd sizes such as 625 = 5^4 are slow in FFTW's r2c/c2r)
    cases = {}
    for pitch, label, bump, planner in [(p, lab, bump, pl) for p in ((9,) if q else (17, 35))
                                        for lab, bump in (("smallest 7-smooth", False),
                                                          ("even 2^a 5^b", True))
                                        for pl in ("estimate", "measure")]:
        scene = bench_scene(cfg["n_side"], pitch, solver={"fft_planner": planner})
        m = padded_size(scene_grid_side(scene))
        if bump:
            m = next(k for k in range(m, 2 * m) if k % 2 == 0 and _smooth(k, (2, 5)))
        _forget_wisdom()        # no plan may profit from an earlier MEASURE of the same size
        model = build_scene_model(scene, m=m)
        drv = PathDriver(model)
        d = cfg["d_tilde"] * model.scaling.d_c
        drv.solve_at(d)
        att, b = drv.att.copy(), d - model.geometry.z0
        x, u = np.zeros(model.geometry.n_active), np.zeros(model.geometry.n_active)
        per = []
        for _ in range(runs):
            x[:] = 0
            p0 = model.fft_pairs
            with Stopwatch(cfg["clock"]) as w:
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
        model = build_scene_model(bench_scene(cfg["n_side"], pitch))
        rows, m = model.operator.pair.rows, model.operator.m
        r = {"m": m}
        for planner in ("estimate", "measure"):
            _forget_wisdom()
            with Stopwatch(cfg["clock"]) as w:
                pair = FFTPair(m, rows, threads=1, planner=planner)
            pair.real_in[...] = np.random.default_rng(2).standard_normal(pair.real_in.shape)
            t = time_call(lambda pair=pair, kh=model.operator.kernel_hat: pair.convolve(kh), runs,
                          clock=cfg["clock"])
            _forget_wisdom()
            r[planner] = {"pair_ms": 1e3 * t["median_s"], "plan_s": w.t,
                          "floor_ms": 1e3 * floor_pair(m, planner, runs, cfg["clock"])["median_s"]}
        gain = 1e-3 * (r["estimate"]["pair_ms"] - r["measure"]["pair_ms"])
        r["pair_speedup"] = r["estimate"]["pair_ms"] / r["measure"]["pair_ms"]
        r["break_even_pairs"] = ((r["measure"]["plan_s"] - r["estimate"]["plan_s"]) / gain
                                 if gain > 0 else None)
        log(f"opts planner m={m}: {r}")
        pl[str(m)] = r
    out["planner"] = pl
    return out
