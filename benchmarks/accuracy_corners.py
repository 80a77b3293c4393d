"""The bias of every number the report reads, per preset, on the corners of the paper's space.

    python benchmarks/accuracy_corners.py [--presets fast default] [--seeds 0] [--out results/]

Corners: sigma~ in {0.01, 0.07, 2.1} x k~ in {10, 0.01, 0.001} on the paper's 18 x 18 brush
(phi 0.16), each at ``F_P: auto``'s first-round preloads (0.001 ... 4, x 4 apart) on one loading
path. The reference is ``default`` (8 elements per diameter) converged in everything but the
resolution: loading batches of at most 0.01 of the length spread (``load_merge_spread`` 0.01:
within 0.1 % of the unbatched path on sigma~ = 0.01 and 0.07, benchmarks/NOTES.md, "Loading
batches and the rise") and no batching while unloading (``event_merge`` 0). Against it the
``fast`` column is the bias of fast's batching and resolution (6 against 8 elements per
diameter) on each quantity; the resolution bias of ``default`` itself against the converged
reference of the default scene (+0.9 % on F~_A, benchmarks/NOTES.md §27b) is not in it: an
``accurate`` reference with the same batching cost more than 25 CPU min per corner beside a
campaign, and was stopped. Per preset and corner it reads, as the report does (floor: one pillar's
Kendall pull-off), the state, the plateau, c (eq. 15), c_stage, c_chord, c0 and F~_A at the two
smallest preloads, and prints the relative difference of each to the reference, with CPU seconds
and FFT pairs. Writes results/accuracy_corners-<stamp>.jsonl (one row per run, as it finishes).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
import time

START = (0.001, 0.004, 0.016, 0.064, 0.25, 1.0, 4.0)
SIGMAS = (0.01, 0.07, 2.1)
KS = (10.0, 0.01, 0.001)
QUANTITIES = ("plateau", "c", "c_stage", "c_chord", "c0", "F_A_0", "F_A_1")
REFERENCE = {"preset": "default", "solver": {"load_merge_spread": 0.01, "event_merge": 0.0}}


def run(k, s, seed, scene_extra):
    from fibril_hpc import scene_from_dict, simulate
    from fibril_hpc.campaign.laws.reading import pillar_floor, read_group

    solver = {"fft_threads": 1, **scene_extra.get("solver", {})}
    sc = scene_from_dict({"n_side": 18, "phi": 0.16, "k_tilde": k, "sigma_tilde": s,
                          "F_P": list(START), "seed": seed, "preset": scene_extra["preset"],
                          "solver": solver})
    t = time.process_time()
    r = simulate(sc)
    cpu = time.process_time() - t
    x = [p.F_P for p in r.results]
    y = [p.F_A for p in r.results]
    rd = read_group([seed] * len(x), list(START), x, y, floor=pillar_floor(18, 0.16))
    return {"k_tilde": k, "sigma_tilde": s, "seed": seed, "preset": scene_extra["preset"],
            "reference": scene_extra is REFERENCE, "cpu_s": round(cpu, 2),
            "fft_pairs": r.stats.get("fft_pairs"), "events": r.stats.get("events"),
            "state": rd.state, "plateau": rd.plateau, "c": rd.c, "c_stage": rd.c_stage,
            "c_chord": rd.c_chord, "c0": rd.c0, "c_lower": rd.c_lower, "F_A_0": y[0],
            "F_A_1": y[1], "F_P_0": x[0], "F_P": x, "F_A": y}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--presets", nargs="+", default=["fast", "default"],
                    help="presets compared with the reference (default: fast default)")
    ap.add_argument("--seeds", nargs="+", type=int, default=[0])
    ap.add_argument("--out", default=os.path.join(os.path.dirname(__file__), "results"))
    a = ap.parse_args(argv)
    os.makedirs(a.out, exist_ok=True)
    path = os.path.join(a.out, f"accuracy_corners-{time.strftime('%Y-%m-%d-%H%M%S')}.jsonl")
    rows = []
    with open(path, "w") as fh:
        for s in SIGMAS:
            for k in KS:
                for seed in a.seeds:
                    for extra in [REFERENCE] + [{"preset": p} for p in a.presets]:
                        row = run(k, s, seed, extra)
                        rows.append(row)
                        fh.write(json.dumps(row) + "\n")
                        fh.flush()
                        print(f"sigma~ {s:g} k~ {k:g} seed {seed} "
                              f"{'reference' if row['reference'] else row['preset']}: "
                              f"{row['state']}, plateau {row['plateau']:.4g}, c {row['c']:.4g}, "
                              f"F_A0 {row['F_A_0']:.4g} at {row['F_P_0']:.3g}; "
                              f"{row['cpu_s']} CPU s, {row['fft_pairs']} pairs", flush=True)
    print("\nrelative difference to the reference (state when it differs)")
    print("sigma~ | k~ | preset | " + " | ".join(QUANTITIES))
    for row in rows:
        if row["reference"]:
            ref = row
            continue
        cells = []
        for q in QUANTITIES:
            v, r = row[q], ref[q]
            cells.append(f"{100 * (v / r - 1):+.1f} %" if all(map(math.isfinite, (v, r))) and r
                         else ("0 = 0" if v == r == 0 else "—"))
        st = "" if row["state"] == ref["state"] else f" ({row['state']} vs {ref['state']})"
        print(f"{row['sigma_tilde']:g} | {row['k_tilde']:g} | {row['preset']}{st} | "
              + " | ".join(cells))
    print(f"rows: {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
