"""What each lab-scene effect (issue 11) changes on a scene and what it costs.

    python -m benchmarks.lab_effects [--n-side 18] [--epd 8] [--repeats 1]

Runs the scene as given (default: the package's default scene) and one variant per effect, each
in this one process, one after the other, and prints F~_A, F~_P and the work (CG solves, FFT
pairs, events, jumps) beside the wall time (median of ``--repeats``). Writes
benchmarks/results/lab_effects-<date>.json.
"""

from __future__ import annotations

import argparse
import datetime as _dt
import json
import os
import statistics
import time

from fibril_hpc import Scene, simulate

from .common import ROOT, git_state

VARIANTS = [
    ("default", {}),
    ("heights: exponential", {"heights": "exponential"}),
    ("heights: uniform", {"heights": "uniform"}),
    ("lattice: hexagonal", {"lattice": "hexagonal"}),
    ("tip: sphere R/D=2", {"tip": "sphere", "tip_radius": 2.0}),
    ("tip: rounded rho/D=0.1", {"tip": "rounded", "tip_radius": 0.1}),
    ("k_machine: 1", {"k_machine": 1.0}),
    ("k_machine: 0.01", {"k_machine": 0.01}),
    ("k_law: lognormal 0.3", {"k_law": "lognormal", "k_spread": 0.3}),
    ("k_law: one, global cascade", {"solver": {"fft_threads": 1, "cascade": "global"}}),
]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n-side", type=int, default=18)
    ap.add_argument("--epd", type=float, default=8)
    ap.add_argument("--repeats", type=int, default=1)
    ap.add_argument("--only", default="", help="comma-separated variant numbers (0-based)")
    args = ap.parse_args(argv)
    base = {"n_side": args.n_side, "elements_per_diameter": args.epd,
            "solver": {"fft_threads": 1}}
    pick = [int(i) for i in args.only.split(",")] if args.only else range(len(VARIANTS))
    rows = []
    print(f"{'variant':26s} {'F~_A':>9s} {'F~_P':>6s} {'F_jump':>7s} {'solves':>7s} "
          f"{'FFT pairs':>9s} {'events':>7s} {'jumps':>6s} {'wall s':>7s}", flush=True)
    for i in pick:
        name, extra = VARIANTS[i]
        walls = []
        for _ in range(args.repeats):
            t = time.perf_counter()
            r = simulate(Scene(**{**base, **extra}))
            walls.append(time.perf_counter() - t)
        m = r.main
        row = {"variant": name, "fields": extra, "status": r.status, "F_A": m.F_A, "F_P": m.F_P,
               "F_jump": m.F_jump, "phi_discrete": r.discretisation["phi_discrete"],
               "cg_solves": r.stats["cg_solves"], "fft_pairs": r.stats["fft_pairs"],
               "events": r.stats["events"], "jumps": r.stats.get("jumps", 0),
               "wall_s_median": statistics.median(walls), "repeats": args.repeats}
        rows.append(row)
        fj = "" if m.F_jump is None else f"{m.F_jump:.4f}"
        print(f"{name:26s} {m.F_A:9.5f} {m.F_P:6.3f} {fj:>7s} {row['cg_solves']:7d} "
              f"{row['fft_pairs']:9d} {row['events']:7d} {row['jumps']:6d} "
              f"{row['wall_s_median']:7.1f}", flush=True)
    out = os.path.join(ROOT, "benchmarks", "results",
                       f"lab_effects-{_dt.datetime.now(_dt.UTC):%Y-%m-%d-%H%M%S}.json")
    with open(out, "w") as fh:
        json.dump({"scene": base, "rows": rows, "git": git_state(),
                   "load_1min": os.getloadavg()[0]}, fh, indent=1)
    print("wrote", out)


if __name__ == "__main__":
    main()
