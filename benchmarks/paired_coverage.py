"""Do the report's seed intervals hold the truth at the rate they claim, with seeds that are the
same brush at every sigma~ and a plateau that fades (not a clean step)?

    python benchmarks/paired_coverage.py [--draws 30] [--n-boot 100] [--sets 3 5 10 mixed]

(``--sets`` runs some seed counts only, e.g. one per process on a larger machine.)

Synthetic campaigns of known truth (tests/synthetic_campaigns.py: ``fade_campaign``): one k~,
eight sigma~ from 0.3 to 2 (x 1.31 apart), a plateau fading to the last pillar's pull-off
(each seed its own fade, sigma_h e^(0.15 z_s), the same z_s at every sigma~) whose seed-mean
crosses the 3-pillar threshold at sigma~_c = 1; c = 1/sigma~ - 1 where adhesion holds, with a
per-seed deviate (5 %) that is the same at every sigma~. Seed counts as ``seeds: auto`` stops at
them: 3, 5 and 10 at every sigma~, and *mixed* (3 seeds, 10 at the two sigma~ around the loss).
Per draw the report's study (:func:`fibril_hpc.campaign.laws.study.study_k`) gives the measured
sigma~_c with its seed interval (claims 95 %) and its span (the bracket widened by states not
certain and by that interval: claims at least 95 %), alpha and beta (95 %) and the line's zero
alpha/beta (95 %). Prints, per seed count, the rate each interval holds the truth and its median
width; writes ``benchmarks/results/paired_coverage-*``.
"""

from __future__ import annotations

import argparse
import math
import os
import statistics
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))
sys.path.insert(0, os.path.join(os.path.dirname(HERE), "tests"))

from benchmarks.common import write_results  # noqa: E402
from fibril_hpc.campaign.laws.study import study_k  # noqa: E402
from synthetic_campaigns import FLOOR, fade_campaign  # noqa: E402

SIGMAS = tuple(float(v) for v in np.geomspace(0.3, 2.0, 8))
SIGMA_C, ALPHA, BETA = 1.0, 1.0, 1.0


def seed_sets() -> dict:
    """The seed counts compared: equal at every sigma~, and mixed as seeds: auto leaves them."""
    near = {s: (10 if 0.8 < s < 1.2 else 3) for s in SIGMAS}
    return {"3": 3, "5": 5, "10": 10, "mixed 3/10": near}


def one(seeds, draw: int, n_boot: int) -> dict:
    """The intervals of one synthetic campaign and whether each holds its truth."""
    pts, _, _ = fade_campaign(SIGMA_C, SIGMAS, seeds, alpha=ALPHA, beta=BETA, rng=draw)
    st = study_k(1.0, pts, n_boot=n_boot, floor=FLOOR, rng_seed=draw)

    def holds(ci, truth):
        return bool(ci[0] <= truth <= ci[1]) if not any(map(math.isnan, ci)) else None

    def width(ci):
        return ci[1] - ci[0] if all(map(math.isfinite, ci)) else math.nan

    return {"sigma_c": st.sigma_loss, "sigma_c_ci": holds(st.sigma_loss_ci, SIGMA_C),
            "sigma_c_width": width(st.sigma_loss_ci),
            "span": holds(st.loss.span, SIGMA_C), "span_width": width(st.loss.span),
            "uncertain": len(st.loss.uncertain), "law": str(st.status),
            "alpha": holds(st.alpha_ci, ALPHA), "beta": holds(st.beta_ci, BETA),
            "zero": holds(st.sigma_c_ci, ALPHA / BETA), "zero_width": width(st.sigma_c_ci)}


def main(argv=None) -> int:
    """Run the coverage study and print its table."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--draws", type=int, default=30)
    ap.add_argument("--n-boot", type=int, default=100)
    ap.add_argument("--sets", nargs="+", choices=["3", "5", "10", "mixed"],
                    default=["3", "5", "10", "mixed"], help="the seed counts to run")
    a = ap.parse_args(argv)
    rows, t0 = [], time.time()
    print(f"{'seeds':>11} | {'sigma_c CI':>10} | {'span':>6} | {'alpha':>6} | {'beta':>6} | "
          f"{'alpha/beta':>10} | median widths (sigma_c CI, span) | states not certain")
    for name, seeds in seed_sets().items():
        if name.split()[0] not in a.sets:
            continue
        res = [one(seeds, d, a.n_boot) for d in range(a.draws)]

        def rate(key, res=res):
            v = [r[key] for r in res if r[key] is not None]
            return f"{sum(v)}/{len(v)}" if v else "—"

        def med(key, res=res):
            v = [r[key] for r in res if math.isfinite(r[key])]
            return statistics.median(v) if v else math.nan

        print(f"{name:>11} | {rate('sigma_c_ci'):>10} | {rate('span'):>6} | {rate('alpha'):>6} | "
              f"{rate('beta'):>6} | {rate('zero'):>10} | {med('sigma_c_width'):.3f}, "
              f"{med('span_width'):.3f} | {sum(r['uncertain'] > 0 for r in res)}/{len(res)}",
              flush=True)
        rows += [dict(seeds=name, draw=d, **r) for d, r in enumerate(res)]
    base = write_results(os.path.join(HERE, "results"), "paired_coverage", rows,
                         {"draws": a.draws, "n_boot": a.n_boot, "sigmas": SIGMAS,
                          "wall_s": time.time() - t0, "claimed": 0.95})
    print(f"wrote {base}.csv/.json ({time.time() - t0:.0f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
