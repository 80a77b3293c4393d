"""How should groups that lost adhesion (c = 0) enter the alpha/beta fit? Four ways against
synthetic truth.

    python benchmarks/lost_groups.py [--draws 20] [--n-boot 40]

Synthetic campaigns of known truth (tests/synthetic_campaigns.py: ``loss_campaign``): one k~,
sigma~ = 0.2 ... 1.6 (eight, x 1.35 apart), 5 seeds, a plateau fading through the 3-pillar
threshold at sigma~ = 1. Two truths of c where adhesion holds: *law* (c = 1/sigma~ - 1, the
line's zero at the loss) and *levels off* (c = 4/sigma~ - 1, still > 0 where adhesion is lost,
as the real files show it); the lost groups either *creep* (from one pillar's pull-off to their
plateau, slope 10 x it) or are *flat* (each seed's F~_A its plateau at every preload: c_sd = 0,
as sigma~ = 2.1 of tests/data/real18_k1.h5). Each campaign
is read once by the report's study; its c, seed sd and seed counts are then fitted four ways
(:data:`fibril_hpc.campaign.laws.alphabeta.LOST_MODES`): ``out`` (lost groups left out),
``floor`` (c = 0 with the smallest sd of the rising groups), ``censored`` (the line held at or
below 0 from the first lost sigma~ on) and ``own`` (each with its own sd: the weighting before
issue 34). Prints per truth, lost shape and mode the median relative error of alpha and beta, the
rate of fits flagged poor, and the weight (1/sd) a lost group would have by its own sd over the
median rising group's; writes ``benchmarks/results/lost_groups-*``.
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))
sys.path.insert(0, os.path.join(os.path.dirname(HERE), "tests"))

from benchmarks.common import write_results  # noqa: E402
from fibril_hpc.campaign.laws.alphabeta import LOST_MODES, fit_alpha_beta  # noqa: E402
from fibril_hpc.campaign.laws.study import study_k  # noqa: E402
from synthetic_campaigns import FLOOR, LOSS, loss_campaign  # noqa: E402

SIGMAS = tuple(float(v) for v in np.geomspace(0.2, 1.6, 8))
TRUTHS = {"law": (1.0, 1.0), "levels off": (4.0, 1.0)}
LOST = ("creep", "flat")


def flatten(pts: dict) -> dict:
    """The same campaign with every lost group flat: each seed's F~_A its largest at every
    preload (no creep)."""
    out = {}
    for s, (seed, pre, x, y) in pts.items():
        y = np.asarray(y, dtype=float).copy()
        if y.max() <= LOSS:
            for lab in np.unique(seed):
                y[seed == lab] = y[seed == lab].max()
        out[s] = (seed, pre, x, y)
    return out


def points(st):
    """(sigma~, c, sd, n_seeds) the study hands to the fit, and the lost groups' sd alone."""
    use = [g for g in st.groups if g.in_fit]
    sd = [float(np.hypot(max(g.c_sd, g.reading.c_detect),
                         g.reading.c_res if np.isfinite(g.reading.c_res) else 0.0)) for g in use]
    return ([g.sigma_tilde for g in use], [g.reading.c for g in use], sd,
            [g.n_seeds for g in use])


def main(argv=None) -> int:
    """Run the comparison and print its table."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--draws", type=int, default=20)
    ap.add_argument("--n-boot", type=int, default=40)
    a = ap.parse_args(argv)
    rows, t0 = [], time.time()
    for truth, (alpha, beta) in TRUTHS.items():
        for shape in LOST:
            for d in range(a.draws):
                pts, _ = loss_campaign(1.0, SIGMAS, 5, alpha=alpha, beta=beta, rng=d)
                pts = flatten(pts) if shape == "flat" else pts
                st = study_k(1.0, pts, n_boot=a.n_boot, floor=FLOOR, rng_seed=d)
                s, c, sd, ns = points(st)
                lost_sd = [x for x, y in zip(sd, c) if y == 0]
                rise_sd = [x for x, y in zip(sd, c) if y > 0]
                for mode in LOST_MODES:
                    f = fit_alpha_beta(s, c, sd, lost=mode, n_seeds=ns)
                    rows.append({"truth": truth, "lost": shape, "mode": mode, "draw": d,
                                 "alpha": f.alpha, "beta": f.beta,
                                 "alpha_err": abs(f.alpha / alpha - 1),
                                 "beta_err": abs(f.beta / beta - 1), "poor": f.poor,
                                 "enough": f.enough, "chi2_red": f.chi2_red,
                                 "n_active": f.n_active,
                                 "own_weight_ratio": statistics.median(rise_sd) / min(lost_sd)
                                 if lost_sd and rise_sd else float("nan")})
    print(f"{'truth':>10} | {'lost':>5} | {'mode':>8} | alpha err (median) | beta err (median) "
          f"| poor | own weight of a lost group / rising (1/sd, median)")
    for truth in TRUTHS:
        for shape in LOST:
            for mode in LOST_MODES:
                r = [x for x in rows if (x["truth"], x["lost"], x["mode"]) == (truth, shape, mode)]
                print(f"{truth:>10} | {shape:>5} | {mode:>8} | "
                      f"{statistics.median(x['alpha_err'] for x in r):18.3f} | "
                      f"{statistics.median(x['beta_err'] for x in r):17.3f} | "
                      f"{sum(x['poor'] for x in r):2d}/{len(r)} | "
                      f"{statistics.median(x['own_weight_ratio'] for x in r):.3g}")
    # does the fit change with the lost groups' shape alone (same draw, creep vs flat)?
    print("largest change of alpha between creeping and flat lost groups, same draw:")
    for truth in TRUTHS:
        for mode in LOST_MODES:
            key = {(x["lost"], x["draw"]): x["alpha"] for x in rows
                   if x["truth"] == truth and x["mode"] == mode}
            dev = max(abs(key[("creep", d)] / key[("flat", d)] - 1) for d in range(a.draws))
            print(f"  {truth:>10} {mode:>8}: {dev:.3g}")
    base = write_results(os.path.join(HERE, "results"), "lost_groups", rows,
                         {"draws": a.draws, "n_boot": a.n_boot, "sigmas": SIGMAS,
                          "truths": TRUTHS, "wall_s": time.time() - t0})
    print(f"wrote {base}.csv/.json ({time.time() - t0:.0f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
