"""``solver.confirm: local`` against the reference ``confirm: global``, side by side.

    python benchmarks/confirm.py                                 # 18 x 18 and 36 x 36, `default`
    python benchmarks/confirm.py --sides 18 --presets fast default --repeat 3

For every brush side and preset the same scene (k~ = 0.01, sigma~ = 0.5, F~_P = 4, seed 0 unless
given; the growth table's scene) runs under both confirmations, each in a fresh child process
(``benchmarks/growth.py``'s ``run_child``), the two alternating within each repetition so that
both see the same machine state. Printed per row: CPU seconds (median over the repetitions),
FFT pairs, CG solves, events, the relaxations confirmed locally / globally, the directions kept
locally / solved globally, the largest certified force bound (F~), F~_A and its difference from
the reference; under each pair the CPU and pair ratios. Writes CSV and JSON into
``benchmarks/results/`` with the command, the commit and the load. Nothing here asserts a time.
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))

from benchmarks.common import write_results  # noqa: E402
from benchmarks.growth import run_child  # noqa: E402


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--sides", type=int, nargs="+", default=[18, 36])
    p.add_argument("--presets", nargs="+", default=["default"])
    p.add_argument("--confirm-tol", type=float, default=None,
                   help="solver.confirm_tol of the local runs (default: the option's)")
    p.add_argument("--repeat", type=int, default=1, help="runs of each (CPU: the median)")
    p.add_argument("--k", type=float, default=0.01, help="k_tilde")
    p.add_argument("--sigma", type=float, default=0.5, help="sigma_tilde")
    p.add_argument("--F-P", type=float, default=4.0, help="force preload")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--out", default=os.path.join(HERE, "results"))
    a = p.parse_args(argv)
    rows, lines = [], []
    hdr = (f"{'n':>4s} {'preset':>8s} {'confirm':>7s} {'CPU s':>7s} {'pairs':>6s} "
           f"{'solves':>6s} {'events':>6s} {'st loc/glob':>12s} {'dir loc/glob':>12s} "
           f"{'bound F~':>9s} {'F~_A':>11s} {'dF~_A':>9s}")
    lines.append(hdr)
    for n in a.sides:
        for preset in a.presets:
            runs = {"global": [], "local": []}
            for rep in range(a.repeat):
                order = ("global", "local") if rep % 2 == 0 else ("local", "global")
                for confirm in order:
                    row = run_child({"n_side": n, "preset": preset, "preconditioner": "auto",
                                     "threads": 1, "k": a.k, "sigma": a.sigma, "F_P": a.F_P,
                                     "seed": a.seed, "confirm": confirm,
                                     "confirm_tol": a.confirm_tol if confirm == "local"
                                     else None})
                    row["repetition"] = rep
                    rows.append(row)
                    runs[confirm].append(row)
                    print(f"  n_side {n} {preset} {confirm}: {row['fft_pairs']} pairs, "
                          f"{row['cpu_s']:.1f} CPU s, F~_A {row['F_A']:.8f} "
                          f"(load {row['load_1min']:.1f})", flush=True)
            ref = runs["global"][0]
            cpu = {c: statistics.median(r["cpu_s"] for r in runs[c]) for c in runs}
            for c in ("global", "local"):
                r = runs[c][0]
                loc = r.get("confirmed_local", 0)
                glob = r.get("confirmed_global", r["events"])
                dloc = r.get("directions_local", 0)
                dref = r.get("directions_refused", 0)
                lines.append(
                    f"{n:4d} {preset:>8s} {c:>7s} {cpu[c]:7.1f} {r['fft_pairs']:6d} "
                    f"{r['cg_solves']:6d} {r['events']:6d} {f'{loc}/{glob}':>12s} "
                    f"{(f'{dloc}/{dref}+' if c == 'local' else '-'):>12s} "
                    f"{r.get('force_bound_tilde', float('nan')):9.2e} {r['F_A']:11.8f} "
                    f"{r['F_A'] - ref['F_A']:9.1e}")
            loc = runs["local"][0]
            lines.append(f"     {n} x {n} {preset}: local / global CPU "
                         f"{cpu['local'] / cpu['global']:.2f}, FFT pairs "
                         f"{loc['fft_pairs'] / ref['fft_pairs']:.2f}, F~_A rel. diff "
                         f"{(loc['F_A'] - ref['F_A']) / ref['F_A']:.1e}")
    print("\n".join(lines))
    print("dir loc/glob: directions kept locally / refused by the bound (+ those solved "
          "globally without a local attempt: first contact, too large a change, a machine)")
    for r in rows:          # one set of columns: the reference confirms every event globally
        r.setdefault("confirmed_local", 0)
        r.setdefault("confirmed_global", r["events"])
        for key in ("certificates_refused", "directions_local", "directions_refused"):
            r.setdefault(key, 0)
        r.setdefault("force_bound_tilde", float("nan"))
    write_results(a.out, "confirm", rows, {
        "meta": {"command": " ".join(["confirm.py"] + (argv if argv is not None
                                                       else sys.argv[1:]))},
        "table": lines})
    return 0


if __name__ == "__main__":
    sys.exit(main())
