"""Work per curve of one scene, per preset and per cascade path (global reference vs local).

    python benchmarks/work_per_curve.py                          # default 18 x 18 scene, all presets
    python benchmarks/work_per_curve.py --presets default --repeat 1
    python benchmarks/work_per_curve.py --n-side 18 --k 1 --sigma 0.07 --F-P 6.5
    python benchmarks/work_per_curve.py --presets default --paths local local:two_level

A path is ``CASCADE``, ``CASCADE:PRECONDITIONER`` or ``CASCADE:PRECONDITIONER:DIRECTION_TOL``
(``exact``: the direction solved to ``cg_tol``; ``global:block:exact`` is the reference path of
the start of issue 8); differences and ratios are taken against the first path given.

For each preset (fast / default / accurate) and each path (``cascade: global``, the reference
with one global solve per cascade pass, and ``cascade: local``, the default) it runs the scene
through the public API (``fibril_hpc.simulate``) on one thread and prints FFT pairs, CG solves,
CG iterations and contact events per curve and per event, CPU seconds (median of ``--repeat``
runs, the two paths alternated so they see the same machine load), F~_A and F~_P and the relative
difference of the local path's F~_A, F~_P from the reference. Writes CSV and JSON into
``benchmarks/results/`` with the command, git commit, load averages and versions. Nothing here
asserts a timing.
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import os
import statistics
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("MKL_NUM_THREADS", "1")


def _git() -> dict:
    root = os.path.join(HERE, "..")
    try:
        head = subprocess.run(["git", "rev-parse", "HEAD"], cwd=root, capture_output=True,
                              text=True, check=True).stdout.strip()
        dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"],
                               cwd=root, capture_output=True, text=True).stdout.split("\n")
        return {"commit": head, "modified": [x[3:] for x in dirty if x.strip()]}
    except (OSError, subprocess.CalledProcessError):
        return {"commit": "", "modified": []}


def run_one(scene_kw: dict, preset: str, cascade: str) -> dict:
    from fibril_hpc import Scene, simulate

    # a path is "CASCADE[:PRECONDITIONER[:DIRECTION_TOL]]" (e.g. local:two_level,
    # global:block:exact; "exact" solves the direction to cg_tol, as before issue 8)
    casc, pc, dt = (cascade.split(":") + ["", ""])[:3]
    solver = {"fft_threads": 1, "cascade": casc}
    if pc:
        solver["preconditioner"] = pc
    if dt:
        from fibril_hpc.inputs.presets import preset_values

        solver["direction_tol"] = (preset_values(preset)["solver"]["cg_tol"] if dt == "exact"
                                   else float(dt))
    scene = Scene(**scene_kw, preset=preset, solver=solver)
    load0 = os.getloadavg()[0]
    t0 = time.process_time()
    r = simulate(scene)
    cpu = time.process_time() - t0
    if r.status != "ok":
        raise SystemExit(f"work_per_curve: {preset}/{cascade} failed: {r.message}")
    st = r.stats
    return {"preset": preset, "cascade": cascade, "cpu_s": cpu, "wall_s": st["wall_s"],
            "fft_pairs": st["fft_pairs"], "cg_solves": st["cg_solves"],
            "cg_iterations": st["cg_iterations"], "events": st["events"],
            "F_A": r.main.F_A, "F_P": r.main.F_P,
            "elements_per_diameter": r.discretisation.get("elements_per_diameter"),
            "fft_size": r.discretisation.get("fft_size"), "load_1min": load0}


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--presets", nargs="+", default=["fast", "default", "accurate"])
    p.add_argument("--repeat", type=int, default=1, help="runs per preset and path (median)")
    p.add_argument("--n-side", type=int, default=None)
    p.add_argument("--k", type=float, default=None, help="k_tilde (default: the Scene default)")
    p.add_argument("--sigma", type=float, default=None, help="sigma_tilde")
    p.add_argument("--F-P", type=float, nargs="+", default=None, help="force preload(s)")
    p.add_argument("--paths", nargs="+", default=["global", "local"],
                   help="cascade paths, each CASCADE or CASCADE:PRECONDITIONER")
    p.add_argument("--out", default=os.path.join(HERE, "results"))
    args = p.parse_args(argv)
    scene_kw = {}
    if args.n_side is not None:
        scene_kw["n_side"] = args.n_side
    if args.k is not None:
        scene_kw["k_tilde"] = args.k
    if args.sigma is not None:
        scene_kw["sigma_tilde"] = args.sigma
    if args.F_P is not None:
        scene_kw["F_P"] = tuple(args.F_P)

    rows = []
    for preset in args.presets:
        runs = {c: [] for c in args.paths}
        for _ in range(args.repeat):
            for cascade in args.paths:
                runs[cascade].append(run_one(scene_kw, preset, cascade))
                print(f"  {preset:8s} {cascade:6s} done: {runs[cascade][-1]['cpu_s']:.1f} s CPU "
                      f"(load {runs[cascade][-1]['load_1min']:.1f})", flush=True)
        for rs in runs.values():
            row = dict(rs[0])
            row["cpu_s"] = statistics.median(x["cpu_s"] for x in rs)
            row["wall_s"] = statistics.median(x["wall_s"] for x in rs)
            row["repeats"] = len(rs)
            rows.append(row)
    # differences and ratios are taken against the first path given (the global reference
    # by default)
    ref = {r["preset"]: r for r in rows if r["cascade"] == args.paths[0]}
    for r in rows:
        ev = max(r["events"], 1)
        r["pairs_per_event"] = r["fft_pairs"] / ev
        r["solves_per_event"] = r["cg_solves"] / ev
        r["iterations_per_event"] = r["cg_iterations"] / ev
        g = ref.get(r["preset"])
        for key in ("F_A", "F_P"):
            r[f"rel_diff_{key}"] = (abs(r[key] - g[key]) / abs(g[key])
                                    if g is not None and g[key] else math.nan)
        r["pairs_ratio_vs_global"] = g["fft_pairs"] / r["fft_pairs"] if g and r["fft_pairs"] else math.nan
        r["cpu_ratio_vs_global"] = g["cpu_s"] / r["cpu_s"] if g and r["cpu_s"] else math.nan

    hdr = (f"{'preset':8s} {'path':18s} {'el/D':>5s} {'m':>5s} {'pairs':>7s} {'solves':>6s} "
           f"{'iters':>7s} {'events':>6s} {'pairs/ev':>8s} {'sol/ev':>6s} {'it/ev':>6s} "
           f"{'CPU s':>7s} {'F~_A':>11s} {'F~_P':>9s} {'dF_A rel':>9s} {'dF_P rel':>9s} "
           f"{'pairs x':>7s} {'CPU x':>6s}")
    lines = [hdr]
    for r in rows:
        lines.append(
            f"{r['preset']:8s} {r['cascade']:18s} {r['elements_per_diameter']:5.1f} "
            f"{r['fft_size']:5d} {r['fft_pairs']:7d} {r['cg_solves']:6d} {r['cg_iterations']:7d} "
            f"{r['events']:6d} {r['pairs_per_event']:8.2f} {r['solves_per_event']:6.2f} "
            f"{r['iterations_per_event']:6.2f} {r['cpu_s']:7.1f} {r['F_A']:11.8f} "
            f"{r['F_P']:9.5f} {r['rel_diff_F_A']:9.1e} {r['rel_diff_F_P']:9.1e} "
            f"{r['pairs_ratio_vs_global']:7.2f} {r['cpu_ratio_vs_global']:6.2f}")
    print("\n".join(lines))
    os.makedirs(args.out, exist_ok=True)
    stamp = time.strftime("%Y-%m-%d-%H%M%S", time.gmtime())
    base = os.path.join(args.out, f"work_per_curve-{stamp}")
    with open(base + ".csv", "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    import numpy
    import pyfftw

    meta = {"command": " ".join([os.path.basename(sys.argv[0])] + (argv or sys.argv[1:])),
            "scene": scene_kw, "git": _git(), "utc": stamp,
            "load_end": list(os.getloadavg()), "cpus": os.cpu_count(),
            "versions": {"python": sys.version.split()[0], "numpy": numpy.__version__,
                         "pyfftw": getattr(pyfftw, "__version__", "")}}
    with open(base + ".json", "w") as fh:
        json.dump({"meta": meta, "rows": rows, "table": lines}, fh, indent=1)
    print(f"wrote {base}.csv and {base}.json")
    return 0


if __name__ == "__main__":
    sys.exit(main())
