"""Measure the cost of campaigns/paper.yaml on a sample of its jobs and extrapolate to core-hours.

    python benchmarks/paper_cost.py                         # default sample (6 loading paths)
    python benchmarks/paper_cost.py --k 10,0.1,0.001 --sigma 0.07,0.384,2.1 --json cost.json
    python benchmarks/paper_cost.py --solver cascade=global,preconditioner=block,direction_tol=1e-8
                                   # the same paths on the reference path of the start of issue 8

Each sampled (k~, sigma~, seed) runs exactly as in the campaign: one ``simulate`` call with all
the grid's preloads (with ``F_P: auto``, every round the campaign would run),
``solver.fft_threads = 1`` (one core), one OperatorCache. The total is the
sum over every (k~, sigma~) of the grid of the wall time of the nearest sampled point (in
log k~, log sigma~), times the number of seeds. Costs are CPU seconds of the (single-threaded)
process, so that a busy shared machine does not inflate them (wall times are printed too);
with N MPI ranks add the master's core: core-hours x N/(N-1). Nothing here asserts a timing.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
import time

import yaml

HERE = os.path.dirname(os.path.abspath(__file__))


def _floats(text):
    return [float(x) for x in text.split(",") if x.strip()]


def _run_path(spec, path, simulate, ops):
    """Run one (k~, sigma~, seed) as the campaign would: one simulate call with the grid's
    preloads, or with ``F_P: auto`` every round the planner asks for. Returns the last result,
    the summed stats and the preloads run."""
    if spec.auto is None:
        task = [t for t in spec.tasks() if (t.jobs[0].k_tilde, t.jobs[0].sigma_tilde,
                                            t.jobs[0].seed) == path][0]
        r = simulate(task.scene, operators=ops)
        return r, r.stats, [j.preload for j in task.jobs]
    from fibril_hpc.campaign.plan.auto import path_todo

    results, run, total = {}, [], {"cg_iterations": 0, "fft_pairs": 0, "events": 0}
    r = None
    while True:
        todo, _ = path_todo(spec.auto, results)
        if not todo:
            return r, total, run
        task = spec.auto_task(path, todo)
        r = simulate(task.scene, operators=ops)
        for name in total:
            total[name] += r.stats[name]
        run += todo
        for p, x in zip(todo, r.results):
            if x.status == "ok":
                results[p] = (x.F_P, x.F_A)
        if r.status != "ok":
            return r, total, run


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--grid", default=os.path.join(HERE, "..", "campaigns", "paper.yaml"))
    p.add_argument("--k", default="1,0.001", help="k_tilde values to sample")
    p.add_argument("--sigma", default="0.07,0.587", help="sigma_tilde values to sample")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--max-wall", type=float, default=1800.0,
                   help="cap per sampled path in seconds (a capped path counts as >= the cap)")
    p.add_argument("--preset", default=None,
                   help="run the sample at this accuracy preset (fast, default, accurate) "
                        "instead of the grid's")
    p.add_argument("--solver", default="",
                   help="solver options to override, KEY=VALUE,... (e.g. cascade=global)")
    p.add_argument("--json", help="write the measurements here")
    args = p.parse_args(argv)

    from fibril_hpc import simulate
    from fibril_hpc.campaign import load_spec
    from fibril_hpc.campaign.plan.estimate import fft_pair_seconds, task_pairs, task_seconds
    from fibril_hpc.model import OperatorCache

    spec = load_spec(args.grid)
    if args.preset is not None:
        from fibril_hpc.inputs.presets import PRESET_NAMES, preset_values
        from fibril_hpc.inputs.options import SolverOptions

        if args.preset not in PRESET_NAMES:
            print(f"paper_cost: --preset must be one of {PRESET_NAMES}", file=sys.stderr)
            return 2
        spec.base = spec.base.replace(
            preset=args.preset,
            elements_per_diameter=preset_values(args.preset)["elements_per_diameter"],
            solver=SolverOptions.from_preset(args.preset))
    from fibril_hpc.errors import ConfigError

    try:
        over = {k.strip(): yaml.safe_load(v) for k, v in
                (kv.split("=", 1) for kv in args.solver.split(",") if kv.strip())}
        spec.base = spec.base.replace(solver=spec.base.solver.replace(
            fft_threads=1, max_wall_s=args.max_wall, **over))
    except (ValueError, TypeError, ConfigError) as e:
        print(f"paper_cost: --solver {args.solver!r}: KEY=VALUE,... of solver options ({e})",
              file=sys.stderr)
        return 2
    ks, ss = _floats(args.k), _floats(args.sigma)
    for v, allv, name in ((ks, spec.k_tilde, "k"), (ss, spec.sigma_tilde, "sigma")):
        bad = [x for x in v if x not in allv]
        if bad:
            print(f"paper_cost: --{name} {bad} not in the grid {list(allv)}", file=sys.stderr)
            return 2
    pair_s, m, epp = fft_pair_seconds(spec.base)
    print(f"grid {spec.base.n_side}^2 pillars, preset {spec.base.preset}, FFT {m}^2, {epp} elements/pillar, "
          f"{'F_P auto' if spec.auto else len(spec.preloads)} preloads per path; "
          f"{pair_s * 1e3:.2f} ms per FFT pair (1 thread); "
          f"load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} CPUs", flush=True)
    ops = OperatorCache()
    samples = []
    for k in ks:
        for s in ss:
            t0, c0 = time.perf_counter(), time.process_time()
            r, st, preloads = _run_path(spec, (k, s, args.seed), simulate, ops)
            wall, cpu = time.perf_counter() - t0, time.process_time() - c0
            samples.append({"k_tilde": k, "sigma_tilde": s, "wall_s": wall, "cpu_s": cpu,
                            "status": r.status, "preloads": preloads,
                            "message": r.message, "cg_iterations": st["cg_iterations"],
                            "fft_pairs": st["fft_pairs"], "events": st["events"],
                            "F_A": [x.F_A for x in r.results],
                            "load": os.getloadavg()[0]})
            print(f"  k~={k:g} sigma~={s:g}: {cpu:8.1f} s CPU ({wall:.1f} s wall)  {r.status:6s} "
                  f"{st['fft_pairs']} FFT pairs, {st['cg_iterations']} CG iterations, "
                  f"{st['events']} events, {wall / max(st['fft_pairs'], 1) * 1e3:.2f} ms/pair, "
                  f"{len(samples[-1]['preloads'])} preloads"
                  + (f"  ({r.message})" if r.status != "ok" else ""), flush=True)

    def nearest(k, s):
        return min(samples, key=lambda x: (math.log(x["k_tilde"] / k)) ** 2
                   + (math.log(x["sigma_tilde"] / s)) ** 2)

    total = sum(nearest(k, s)["cpu_s"] for k in spec.k_tilde for s in spec.sigma_tilde)
    total *= len(spec.seeds)
    capped = any(x["status"] != "ok" for x in samples)
    # the dry run's model for each sample: its preloads as one task (an F_P: auto path's later
    # rounds are small single-preload tasks; counted in with the first)
    for x in samples:
        kind = "d_tilde" if spec.auto is None and spec.base.F_P is None else "F_P"
        sc = spec.base.replace(**{kind: tuple(x["preloads"])})
        x["model_fft_pairs"] = task_pairs(sc, epp)
        x["model_cpu_s"] = task_seconds(sc, pair_s, epp)
    n_paths = len(spec.paths())
    dry_run = sum(x["model_cpu_s"] for x in samples) / len(samples)
    per_pillar = [x["fft_pairs"] / (spec.base.n_side ** 2 * math.sqrt(epp)) for x in samples]
    out = {"grid": os.path.abspath(args.grid), "preset": spec.base.preset, "jobs": len(spec.jobs),
           "solver": args.solver,
           "paths": n_paths, "samples": samples, "ms_per_fft_pair": pair_s * 1e3,
           "core_hours": total / 3600, "lower_bound": capped,
           "mean_path_cpu_s": sum(x["cpu_s"] for x in samples) / len(samples),
           "pairs_per_pillar_sqrt_element": sum(per_pillar) / len(per_pillar),
           "dry_run_path_cpu_s": dry_run,
           "fibril_hpc_commit": os.popen(f"git -C {HERE} rev-parse --short HEAD 2>/dev/null")
           .read().strip()}
    cap_note = " (at least: a sample hit the cap)" if capped else ""
    cheap, dear = (f(x["cpu_s"] for x in samples) * n_paths / 3600 for f in (min, max))
    out["core_hours_range"] = [cheap, dear]
    print(f"estimate: {out['core_hours']:.1f} core-hours{cap_note} ({cheap:.1f}-{dear:.1f} if "
          "every path cost the cheapest or the dearest sample) "
          f"for {len(spec.jobs) or 'auto'} jobs in {n_paths} loading paths "
          f"(mean sampled path {out['mean_path_cpu_s']:.0f} s CPU); with N ranks x N/(N-1) for the master; "
          f"FFT pairs per pillar per sqrt(element) {out['pairs_per_pillar_sqrt_element']:.1f}; "
          f"--dry-run's model: {dry_run:.0f} s per path "
          f"({dry_run / out['mean_path_cpu_s']:.2f}x the mean sampled path)")
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(out, fh, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
