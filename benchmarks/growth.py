"""How the cost of one loading curve grows with the brush: the growth table.

    python benchmarks/growth.py                                  # 12, 18, 24, 30, 36 at `default`
    python benchmarks/growth.py --sides 12 18 24 --preset fast
    python benchmarks/growth.py --sides 36 --threads 1 2          # one scene on one and two threads
    python benchmarks/growth.py --sides 36 --preconditioner block two_level
    python benchmarks/growth.py --sides 18 --floor               # per pair over the bare full pair
    python benchmarks/growth.py --sides 18 36 64 100 --preset fast --far-field multipole

One scene per brush side n (n x n pillars, k~ = 0.01, sigma~ = 0.5, F~_P = 4, seed 0 unless
given), each run in a fresh child process so that its peak memory is its own. Printed per row:
pillars N_p, the FFT side m, FFT pairs, CG solves, contact events, pairs per event, CPU and wall
seconds, peak resident memory, F~_A and the preconditioner that ``auto`` chose; under the table
the power laws fitted over the rows of one configuration (cost ~ N_p^b, least squares in log-log)
and, with two thread counts, the wall-time ratio per size. With ``--floor`` each child also times
the bare full pair on its own FFT side after the curve (a plain pyFFTW ``rfft2`` + ``irfft2`` of
m x m, one thread, CPU median of 7, with the engine's ``FFTW_ESTIMATE`` plans and with
``FFTW_MEASURE`` ones) and the table gains the curve's CPU per counted pair over each. Writes
CSV and JSON into ``benchmarks/results/`` with the command, the commit and the load. Nothing here
asserts a time.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))

from benchmarks.common import write_results  # noqa: E402


def child(args: dict) -> dict:
    """Run one scene (in this process) and return its row."""
    import resource

    from fibril_hpc import Scene, simulate

    solver = {"fft_threads": args["threads"]}
    if args["preconditioner"] != "auto":
        solver["preconditioner"] = args["preconditioner"]
    for key in ("confirm", "confirm_tol", "far_field", "max_wall_s"):   # confirm.py, options
        if args.get(key) is not None:
            solver[key] = args[key]
    scene = Scene(n_side=args["n_side"], k_tilde=args["k"], sigma_tilde=args["sigma"],
                  F_P=(args["F_P"],), seed=args["seed"], preset=args["preset"], solver=solver)
    t0, w0 = time.process_time(), time.perf_counter()
    r = simulate(scene)
    cpu, wall = time.process_time() - t0, time.perf_counter() - w0
    st = r.stats
    row = {"n_side": args["n_side"], "pillars": args["n_side"]**2, "preset": args["preset"],
           "preconditioner": args["preconditioner"], "chosen": st.get("preconditioner", ""),
           "threads": args["threads"], "fft_size": r.discretisation.get("fft_size"),
           "fft_pairs": st["fft_pairs"], "cg_solves": st["cg_solves"], "events": st["events"],
           "pairs_per_event": st["fft_pairs"] / max(st["events"], 1), "cpu_s": cpu,
           "wall_s": wall, "peak_rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,
           "F_A": r.main.F_A if r.main.F_A is not None else float("nan"), "F_P": r.main.F_P,
           "status": r.status,
           "load_1min": os.getloadavg()[0], "confirm": r.scene.solver.confirm,
           "far_field": r.scene.solver.far_field}
    for key in ("confirmed_local", "confirmed_global", "certificates_refused",
                "directions_local", "directions_refused", "force_bound_tilde"):
        if key in st:
            row[key] = float(st[key]) if key.endswith("_tilde") else int(st[key])
    if args.get("floor"):           # after the curve and its peak memory
        row.update(_floors(row["fft_size"], cpu, st["fft_pairs"]))
    return row


def _floors(m: int, cpu: float, pairs: int) -> dict:
    """The bare full pair on side ``m`` with either planner (ms, CPU median of 7), and the
    curve's CPU per counted pair over each."""
    from benchmarks.fibril_bench.timing import floor_pair

    out = {}
    for planner in ("estimate", "measure"):
        ms = floor_pair(m, planner, 7)["cpu_median_s"] * 1e3
        out[f"floor_{planner}_ms"] = ms
        out[f"per_pair_over_{planner}"] = cpu * 1e3 / max(pairs, 1) / ms
    return out


def run_child(args: dict) -> dict:
    env = dict(os.environ)
    for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
        env.setdefault(var, "1")
    code = ("import json, sys; from benchmarks.growth import child; "
            "print('ROW ' + json.dumps(child(json.loads(sys.argv[1]))))")
    p = subprocess.run([sys.executable, "-c", code, json.dumps(args)], capture_output=True,
                       text=True, env=env, cwd=os.path.dirname(HERE))
    rows = [ln[4:] for ln in p.stdout.splitlines() if ln.startswith("ROW ")]
    if p.returncode != 0 or not rows:
        raise SystemExit(f"growth: n_side {args['n_side']} failed:\n{p.stderr[-2000:]}")
    return json.loads(rows[-1])


def exponents(rows: list) -> dict:
    """Least-squares exponents b of cost ~ N_p^b over ``rows`` (at least two sizes)."""
    if len({r["pillars"] for r in rows}) < 2:
        return {}
    x = np.log([r["pillars"] for r in rows])
    return {key: float(np.polyfit(x, np.log([max(r[key], 1e-12) for r in rows]), 1)[0])
            for key in ("cpu_s", "fft_pairs", "events", "pairs_per_event", "peak_rss_mb")}


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--sides", type=int, nargs="+", default=[12, 18, 24, 30, 36])
    p.add_argument("--preset", default="default")
    p.add_argument("--preconditioner", nargs="+", default=["auto"])
    p.add_argument("--threads", type=int, nargs="+", default=[1], help="fft_threads values")
    p.add_argument("--k", type=float, default=0.01, help="k_tilde")
    p.add_argument("--sigma", type=float, default=0.5, help="sigma_tilde")
    p.add_argument("--F-P", type=float, default=4.0, help="force preload")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--floor", action="store_true",
                   help="also time the bare full pair on each FFT side (both planners)")
    p.add_argument("--far-field", choices=["exact", "multipole"], default="exact",
                   help="solver.far_field of every scene (exact: the reference)")
    p.add_argument("--max-wall-s", type=float, default=None,
                   help="solver.max_wall_s of every scene: a capped curve stops (status failed) "
                        "and its row gives the CPU and FFT pairs per event up to there (the "
                        "power-law fits then mean nothing)")
    p.add_argument("--out", default=os.path.join(HERE, "results"))
    a = p.parse_args(argv)
    rows = []
    for n in a.sides:
        for pc in a.preconditioner:
            for th in a.threads:
                row = run_child({"n_side": n, "preset": a.preset, "preconditioner": pc,
                                 "threads": th, "k": a.k, "sigma": a.sigma, "F_P": a.F_P,
                                 "seed": a.seed, "floor": a.floor, "max_wall_s": a.max_wall_s,
                                 "far_field": None if a.far_field == "exact" else a.far_field})
                rows.append(row)
                print(f"  n_side {n} {pc} ({row['chosen']}) threads {th}: {row['fft_pairs']} pairs, "
                      f"{row['events']} events, {row['cpu_s']:.1f} CPU s, "
                      f"{row['wall_s']:.1f} wall s, {row['peak_rss_mb']:.0f} MB, "
                      f"F~_A {row['F_A']:.8f} ({row['status']}; load {row['load_1min']:.1f})",
                      flush=True)
    hdr = (f"{'n':>4s} {'N_p':>6s} {'precond':>10s} {'chosen':>10s} {'thr':>3s} {'m':>5s} "
           f"{'pairs':>7s} {'solves':>6s} {'events':>6s} {'pairs/ev':>8s} {'CPU s':>8s} "
           f"{'wall s':>8s} {'RSS MB':>7s} {'F~_A':>11s}")
    lines = [hdr]
    for r in rows:
        lines.append(f"{r['n_side']:4d} {r['pillars']:6d} {r['preconditioner']:>10s} "
                     f"{r['chosen']:>10s} {r['threads']:3d} {r['fft_size']:5d} "
                     f"{r['fft_pairs']:7d} {r['cg_solves']:6d} {r['events']:6d} "
                     f"{r['pairs_per_event']:8.2f} {r['cpu_s']:8.1f} {r['wall_s']:8.1f} "
                     f"{r['peak_rss_mb']:7.0f} {r['F_A']:11.8f}"
                     + (f"  per pair {r['per_pair_over_estimate']:.2f}x the bare pair "
                        f"({r['floor_estimate_ms']:.2f} ms ESTIMATE), "
                        f"{r['per_pair_over_measure']:.2f}x ({r['floor_measure_ms']:.2f} ms "
                        "MEASURE)" if "floor_estimate_ms" in r else ""))
    fits = {}
    for pc in a.preconditioner:
        for th in a.threads:
            sel = [r for r in rows if r["preconditioner"] == pc and r["threads"] == th]
            b = exponents(sel)
            if b:
                fits[f"{pc}/threads={th}"] = b
                lines.append(f"growth {pc}, {th} thread(s): " + ", ".join(
                    f"{k} ~ N_p^{v:.2f}" for k, v in b.items()))
    if len(a.threads) > 1:
        for n in a.sides:
            for pc in a.preconditioner:
                w = {r["threads"]: r["wall_s"] for r in rows
                     if r["n_side"] == n and r["preconditioner"] == pc}
                t1 = w.get(a.threads[0])
                lines.append(f"n_side {n} {pc}: wall " + ", ".join(
                    f"{th} threads {t1 / w[th]:.2f}x" for th in a.threads[1:] if t1 and w.get(th)))
    print("\n".join(lines))
    write_results(a.out, "growth", rows, {
        "meta": {"command": " ".join(["growth.py"] + (argv if argv is not None
                                                      else sys.argv[1:]))},
        "fits": fits, "table": lines})
    return 0


if __name__ == "__main__":
    sys.exit(main())
