"""What the held states' certificate of ``far_field: multipole`` costs: the growth scene with the
check and with it off, side by side.

    python benchmarks/held_check_cost.py [--sides 18 36 64] [--presets fast default] [--repeats 2]

Each (n_side, preset) runs twice at once in fresh processes (so each pays its own imports and
table), once as shipped and once with ``PathDriver._held_certified`` replaced by "kept" (no
direction solved ahead, no bound), ``--repeats`` times. Printed and written per row: CPU seconds
of both, their ratio, the FFT pairs and F~_A of both (the same wherever the bound asks for no
refresh), the states certified, the refreshes asked for and the largest bound. Nothing here
asserts a time.
"""

from __future__ import annotations

import argparse
import multiprocessing as mp
import os
import statistics
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))

from benchmarks.common import write_results  # noqa: E402


def one(args) -> dict:
    n, preset, off = args
    from fibril_hpc import Scene, simulate

    if off:
        from fibril_hpc.path.confirm import ConfirmMixin
        ConfirmMixin._held_certified = lambda self: True
    scene = Scene(n_side=n, k_tilde=0.01, sigma_tilde=0.5, F_P=(4.0,), seed=0, preset=preset,
                  solver={"fft_threads": 1, "far_field": "multipole"})
    t = time.process_time()
    r = simulate(scene)
    st = r.stats
    return {"cpu_s": time.process_time() - t, "pairs": st["fft_pairs"], "F_A": r.main.F_A,
            "held_certified": st.get("held_certified", 0),
            "held_refreshes": st.get("held_refreshes", 0),
            "force_bound_tilde": st.get("force_bound_tilde", 0.0)}


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--sides", type=int, nargs="+", default=[18, 36, 64])
    p.add_argument("--presets", nargs="+", default=["fast", "default"])
    p.add_argument("--repeats", type=int, default=2)
    p.add_argument("--out", default=os.path.join(HERE, "results"))
    a = p.parse_args(argv)
    rows = []
    with mp.get_context("fork").Pool(2, maxtasksperchild=1) as pool:
        for n in a.sides:
            for preset in a.presets:
                for rep in range(a.repeats):
                    on, off = pool.map(one, [(n, preset, False), (n, preset, True)])
                    row = {"n_side": n, "preset": preset, "repeat": rep,
                           "cpu_on": on["cpu_s"], "cpu_off": off["cpu_s"],
                           "ratio": on["cpu_s"] / off["cpu_s"], "pairs_on": on["pairs"],
                           "pairs_off": off["pairs"], "F_A_on": on["F_A"], "F_A_off": off["F_A"],
                           "held_certified": on["held_certified"],
                           "held_refreshes": on["held_refreshes"],
                           "force_bound_tilde": on["force_bound_tilde"]}
                    rows.append(row)
                    print(f"n {n} {preset} #{rep}: CPU {row['cpu_on']:.2f} / {row['cpu_off']:.2f} s "
                          f"({row['ratio']:.3f}), pairs {row['pairs_on']}/{row['pairs_off']}, "
                          f"{row['held_certified']} certified, {row['held_refreshes']} refreshes, "
                          f"bound {row['force_bound_tilde']:.1e}", flush=True)
    for n in a.sides:
        for preset in a.presets:
            sel = [r["ratio"] for r in rows if r["n_side"] == n and r["preset"] == preset]
            print(f"n {n} {preset}: CPU ratio median {statistics.median(sel):.3f}")
    write_results(a.out, "held-check-cost", rows, {"args": vars(a)})
    return 0


if __name__ == "__main__":
    sys.exit(main())
