"""Measure the cost of campaigns/paper.yaml on a sample of its jobs and extrapolate to core-hours.

    python benchmarks/paper_cost.py                         # default sample (6 loading paths)
    python benchmarks/paper_cost.py --k 10,0.1,0.001 --sigma 0.07,0.384,2.1 --json cost.json

Each sampled (k~, sigma~, seed) runs exactly as in the campaign: one ``simulate`` call with all
the grid's preloads, ``solver.fft_threads = 1`` (one core), one OperatorCache. The total is the
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

HERE = os.path.dirname(os.path.abspath(__file__))


def _floats(text):
    return [float(x) for x in text.split(",") if x.strip()]


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--grid", default=os.path.join(HERE, "..", "campaigns", "paper.yaml"))
    p.add_argument("--k", default="1,0.001", help="k_tilde values to sample")
    p.add_argument("--sigma", default="0.07,0.587", help="sigma_tilde values to sample")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--max-wall", type=float, default=1800.0,
                   help="cap per sampled path in seconds (a capped path counts as >= the cap)")
    p.add_argument("--json", help="write the measurements here")
    args = p.parse_args(argv)

    from fibril_hpc import simulate
    from fibril_hpc.campaign import load_spec
    from fibril_hpc.campaign.estimate import (PAIRS_PER_EXTRA_PRELOAD, fft_pair_seconds,
                                              task_seconds)
    from fibril_hpc.model import OperatorCache

    spec = load_spec(args.grid)
    spec.base = spec.base.replace(solver=spec.base.solver.replace(fft_threads=1,
                                                                  max_wall_s=args.max_wall))
    ks, ss = _floats(args.k), _floats(args.sigma)
    for v, allv, name in ((ks, spec.k_tilde, "k"), (ss, spec.sigma_tilde, "sigma")):
        bad = [x for x in v if x not in allv]
        if bad:
            print(f"paper_cost: --{name} {bad} not in the grid {list(allv)}", file=sys.stderr)
            return 2
    pair_s, m, epp = fft_pair_seconds(spec.base)
    print(f"grid {spec.base.n_side}^2 pillars, FFT {m}^2, {epp} elements/pillar, "
          f"{len(spec.preloads)} preloads per path; {pair_s * 1e3:.2f} ms per FFT pair (1 thread); "
          f"load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} CPUs", flush=True)
    ops = OperatorCache()
    samples = []
    for k in ks:
        for s in ss:
            task = [t for t in spec.tasks() if t.jobs[0].k_tilde == k
                    and t.jobs[0].sigma_tilde == s and t.jobs[0].seed == args.seed][0]
            t0, c0 = time.perf_counter(), time.process_time()
            r = simulate(task.scene, operators=ops)
            wall, cpu = time.perf_counter() - t0, time.process_time() - c0
            st = r.stats
            samples.append({"k_tilde": k, "sigma_tilde": s, "wall_s": wall, "cpu_s": cpu,
                            "status": r.status,
                            "message": r.message, "cg_iterations": st["cg_iterations"],
                            "fft_pairs": st["fft_pairs"], "events": st["events"],
                            "F_A": [x.F_A for x in r.results],
                            "load": os.getloadavg()[0]})
            print(f"  k~={k:g} sigma~={s:g}: {cpu:8.1f} s CPU ({wall:.1f} s wall)  {r.status:6s} "
                  f"{st['fft_pairs']} FFT pairs, {st['cg_iterations']} CG iterations, "
                  f"{st['events']} events, {wall / max(st['fft_pairs'], 1) * 1e3:.2f} ms/pair"
                  + (f"  ({r.message})" if r.status != "ok" else ""), flush=True)

    def nearest(k, s):
        return min(samples, key=lambda x: (math.log(x["k_tilde"] / k)) ** 2
                   + (math.log(x["sigma_tilde"] / s)) ** 2)

    total = sum(nearest(k, s)["cpu_s"] for k in spec.k_tilde for s in spec.sigma_tilde)
    total *= len(spec.seeds)
    capped = any(x["status"] != "ok" for x in samples)
    per_pillar = [x["fft_pairs"] / (spec.base.n_side ** 2 * math.sqrt(epp)
                                    * (1 + PAIRS_PER_EXTRA_PRELOAD * (len(spec.preloads) - 1)))
                  for x in samples]
    dry_run = task_seconds(spec.base, len(spec.preloads), pair_s, epp)
    out = {"grid": os.path.abspath(args.grid), "jobs": len(spec.jobs),
           "paths": len(spec.tasks()), "samples": samples, "ms_per_fft_pair": pair_s * 1e3,
           "core_hours": total / 3600, "lower_bound": capped,
           "mean_path_cpu_s": sum(x["cpu_s"] for x in samples) / len(samples),
           "pairs_per_pillar_element": sum(per_pillar) / len(per_pillar),
           "dry_run_path_cpu_s": dry_run,
           "fibril_hpc_commit": os.popen(f"git -C {HERE} rev-parse --short HEAD 2>/dev/null")
           .read().strip()}
    cap_note = " (at least: a sample hit the cap)" if capped else ""
    print(f"estimate: {out['core_hours']:.0f} core-hours{cap_note} "
          f"for {len(spec.jobs)} jobs in {len(spec.tasks())} loading paths "
          f"(mean sampled path {out['mean_path_cpu_s']:.0f} s CPU); with N ranks x N/(N-1) for the master; "
          f"FFT pairs per pillar per sqrt(element) {out['pairs_per_pillar_element']:.1f}; "
          f"--dry-run's model: {dry_run:.0f} s per path "
          f"({dry_run / out['mean_path_cpu_s']:.2f}x the mean sampled path)")
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(out, fh, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
