"""The issue's corner grid under ``confirm: global`` (the reference) and a faster path
(``--path local``: ``confirm: local``; ``--path multipole``: ``far_field: multipole``;
``--path multipole-bound``: the same with ``far_refresh`` 10^6, so that only the held states'
force bound asks for exact products), scene by scene, with the curves compared point by point.

    python benchmarks/confirm_grid.py run --out DIR [--sides 18 36] [--presets fast default]
                                          [--jobs N] [--max-wall-s S] [--path multipole]
    python benchmarks/confirm_grid.py table DIR

``run`` simulates every corner (n_side x preset x k~ 10, 1, 0.01, 0.001 x sigma~ 0.01, 0.1, 0.5,
2.1; seed 0, F~_P = 4) under both confirmations, one process per (scene, confirmation) from a
pool of ``--jobs`` workers (the dearest first), each with one FFT thread, and writes one ``.npz``
per run into DIR as it finishes (F~_A, CPU seconds, the counters, the loading and unloading
curves), so a run cut short keeps what it finished. ``table`` pairs the runs of each scene and
prints, and writes as CSV beside them: F~_A of both, the relative and absolute difference, the
graph distance of the curves (:func:`benchmarks.common.graph_gap`, over the peak force and the
displacement span), the pair and CPU ratios, and whether the scene meets the issue's accuracy
(F~_A within 0.2 %, 1e-4 absolute where F~_A < 0.05; curves within 0.5 % of the peak force).
Nothing here asserts a time.
"""

from __future__ import annotations

import argparse
import csv
import glob
import os
import statistics
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))

from benchmarks.common import graph_gap  # noqa: E402

K_CORNERS = (10.0, 1.0, 0.01, 0.001)
SIGMA_CORNERS = (0.01, 0.1, 0.5, 2.1)
#: relative CPU of one run by (n_side, preset), to start the dearest first (rough, measured here)
_WEIGHT = {(18, "fast"): 1, (18, "default"): 3, (36, "fast"): 8, (36, "default"): 25}
#: the solver options of each path (``global`` is the reference)
PATHS = {"global": {}, "local": {"confirm": "local"}, "multipole": {"far_field": "multipole"},
         # the held states refreshed where their force bound asks only (path/confirm.py)
         "multipole-bound": {"far_field": "multipole", "far_refresh": 10**6}}


def _name(n, preset, k, s, confirm) -> str:
    return f"n{n}-{preset}-k{k:g}-s{s:g}-{confirm}"


def run_one(task) -> str:
    """One (scene, confirmation): simulate, write ``<name>.npz`` into the output folder."""
    import numpy as np

    from fibril_hpc import Scene, simulate

    n, preset, k, s, confirm, out, max_wall = task
    solver = {**PATHS[confirm], "fft_threads": 1}
    if max_wall:
        solver["max_wall_s"] = max_wall
    scene = Scene(n_side=n, k_tilde=k, sigma_tilde=s, F_P=(4.0,), seed=0, preset=preset,
                  solver=solver)
    t = time.process_time()
    r = simulate(scene)
    cpu = time.process_time() - t
    st, main = r.stats, r.main
    curves = {}
    for part in ("loading", "unloading"):
        c = getattr(main, part)
        if c is not None:
            curves[f"{part}_d"], curves[f"{part}_F"] = c.d_tilde, c.F_tilde
    np.savez(os.path.join(out, _name(n, preset, k, s, confirm) + ".npz"),
             F_A=main.F_A, cpu_s=cpu, fft_pairs=st["fft_pairs"], events=st["events"],
             confirmed_local=st.get("confirmed_local", 0),
             force_bound=st.get("force_bound_tilde", 0.0), status=r.status,
             held_certified=st.get("held_certified", 0), held_refreshes=st.get("held_refreshes", 0),
             held_uncertified=st.get("held_uncertified", 0),
             n_side=n, preset=preset, k=k, sigma=s, confirm=confirm, **curves)
    return f"{_name(n, preset, k, s, confirm)} {r.status} {cpu:.1f} s"


def cmd_run(a) -> int:
    import multiprocessing as mp

    os.makedirs(a.out, exist_ok=True)
    tasks = [(n, p, k, s, c, a.out, a.max_wall_s) for n in a.sides for p in a.presets
             for k in a.k for s in a.sigma for c in ("global", a.path)]
    if a.skip_existing:             # runs of an earlier call (e.g. the reference's) are kept
        tasks = [t for t in tasks
                 if not os.path.exists(os.path.join(a.out, _name(*t[:5]) + ".npz"))]
    tasks.sort(key=lambda t: -_WEIGHT.get((t[0], t[1]), t[0] ** 2 / 50))
    with mp.get_context("fork").Pool(a.jobs, maxtasksperchild=1) as pool:
        for line in pool.imap_unordered(run_one, tasks):
            print(line, flush=True)
    return 0


def _pairs(folder):
    import numpy as np

    runs = {}
    for path in sorted(glob.glob(os.path.join(folder, "*.npz"))):
        z = dict(np.load(path, allow_pickle=False))
        key = (int(z["n_side"]), str(z["preset"]), float(z["k"]), float(z["sigma"]))
        runs.setdefault(key, {})[str(z["confirm"])] = z
    return runs


def compare(ref, new) -> dict:
    """The accuracy of ``new`` against ``ref`` (two runs' arrays) by the issue's measures."""
    import numpy as np

    fa, fb = float(ref["F_A"]), float(new["F_A"])
    tol = 1e-4 if abs(fa) < 0.05 else 2e-3 * abs(fa)
    gap = 0.0
    for part in ("loading", "unloading"):
        if f"{part}_d" not in ref or f"{part}_d" not in new:
            continue
        ad, aF, bd, bF = (ref[f"{part}_d"], ref[f"{part}_F"], new[f"{part}_d"], new[f"{part}_F"])
        peak = max(np.abs(aF).max(), np.abs(bF).max(), 1e-12)
        span = max(np.ptp(ad), np.ptp(bd), 1e-12)
        gap = max(gap, graph_gap(bd, bF, ad, aF, span, peak), graph_gap(ad, aF, bd, bF, span, peak))
    return {"F_A_ref": fa, "F_A_local": fb, "rel": (fb - fa) / fa if fa else float("nan"),
            "abs": fb - fa, "F_A_ok": abs(fb - fa) <= tol, "curve_gap": gap,
            "curve_ok": gap <= 5e-3}


def cmd_table(a) -> int:
    rows = []
    for (n, preset, k, s), pair in sorted(_pairs(a.folder).items()):
        other = sorted(set(pair) - {"global"})
        if "global" not in pair or len(other) != 1:
            print(f"n {n} {preset} k~ {k:g} sigma~ {s:g}: runs {sorted(pair)}")
            continue
        ref, new = pair["global"], pair[other[0]]
        path = other[0]
        row = {"n_side": n, "preset": preset, "path": path, "k_tilde": k, "sigma_tilde": s,
               "status": f"{ref['status']}/{new['status']}", **compare(ref, new),
               "pairs_ref": int(ref["fft_pairs"]), "pairs_local": int(new["fft_pairs"]),
               "cpu_ref": float(ref["cpu_s"]), "cpu_local": float(new["cpu_s"]),
               "events_ref": int(ref["events"]), "events_local": int(new["events"]),
               "confirmed_local": int(new["confirmed_local"]),
               "force_bound": float(new["force_bound"]),
               **{k: int(new[k]) if k in new else 0          # far_field: multipole's states
                  for k in ("held_certified", "held_refreshes", "held_uncertified")}}
        row["pair_ratio"] = row["pairs_local"] / max(row["pairs_ref"], 1)
        row["cpu_ratio"] = row["cpu_local"] / max(row["cpu_ref"], 1e-9)
        rows.append(row)
    if not rows:
        print("no complete pair of runs in", a.folder)
        return 1
    print(f"{'n':>3s} {'preset':>7s} {'k~':>6s} {'sig~':>5s} {'F~_A ref':>11s} {'rel':>9s} "
          f"{'abs':>9s} {'gap':>8s} {'ok':>3s} {'pairs':>13s} {'CPU s':>13s} {'cpu x':>6s}")
    for r in rows:
        ok = "yes" if r["F_A_ok"] and r["curve_ok"] else "NO"
        print(f"{r['n_side']:3d} {r['preset']:>7s} {r['k_tilde']:6g} {r['sigma_tilde']:5g} "
              f"{r['F_A_ref']:11.8f} {r['rel']:9.1e} {r['abs']:9.1e} {r['curve_gap']:8.1e} "
              f"{ok:>3s} {r['pairs_ref']:6d}/{r['pairs_local']:6d} "
              f"{r['cpu_ref']:6.1f}/{r['cpu_local']:6.1f} {r['cpu_ratio']:6.2f}")
    for n in sorted({r["n_side"] for r in rows}):
        for preset in sorted({r["preset"] for r in rows}):
            sel = [r for r in rows if r["n_side"] == n and r["preset"] == preset]
            if sel:
                bad = sum(not (r["F_A_ok"] and r["curve_ok"]) for r in sel)
                print(f"n {n} {preset}: {len(sel)} scenes, {bad} outside the accuracy; median "
                      f"ratio pairs {statistics.median(r['pair_ratio'] for r in sel):.2f}, CPU "
                      f"{statistics.median(r['cpu_ratio'] for r in sel):.2f}; largest |rel| "
                      f"{max(abs(r['rel']) for r in sel):.1e}, gap "
                      f"{max(r['curve_gap'] for r in sel):.1e}")
    path = os.path.join(a.folder, "confirm_grid.csv")
    with open(path, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    print("wrote", path)
    return 0


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = p.add_subparsers(dest="cmd", required=True)
    r = sub.add_parser("run")
    r.add_argument("--out", required=True)
    r.add_argument("--sides", type=int, nargs="+", default=[18, 36])
    r.add_argument("--presets", nargs="+", default=["fast", "default"])
    r.add_argument("--k", type=float, nargs="+", default=list(K_CORNERS), help="k~ corners")
    r.add_argument("--sigma", type=float, nargs="+", default=list(SIGMA_CORNERS),
                   help="sigma~ corners")
    r.add_argument("--jobs", type=int, default=os.cpu_count() or 1)
    r.add_argument("--path", choices=sorted(set(PATHS) - {"global"}), default="local",
                   help="the path run beside the reference")
    r.add_argument("--skip-existing", action="store_true",
                   help="do not rerun a (scene, path) whose .npz is already in --out")
    r.add_argument("--max-wall-s", type=float, default=None,
                   help="solver.max_wall_s of every run (a run past it is recorded as failed)")
    t = sub.add_parser("table")
    t.add_argument("folder")
    a = p.parse_args(argv)
    return cmd_run(a) if a.cmd == "run" else cmd_table(a)


if __name__ == "__main__":
    sys.exit(main())
