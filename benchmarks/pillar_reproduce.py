"""Does the measured sigma~_c reproduce with another seed set, on brushes made of whole pillars?

    python benchmarks/pillar_reproduce.py [--draws 20] [--n-boot 200] [--n-side 12] [--first-draw 0]

(``--first-draw`` starts at another draw, to split the draws over processes.)

Synthetic truth that looks like the real data near a loss (tests/synthetic_campaigns.py,
:func:`pillar_plateau`): a seed is one brush of n_side^2 standard normal heights, the same at
every sigma~; its plateau is the number of pillars within reach of the tallest (each a share,
the tallest a whole pillar), skewed and nearly discrete near the loss; the population's
seed-mean plateau crosses 3 pillars at sigma~_c = 1 exactly. The shipped search's settings
(``campaigns/critical_roughness.yaml``: sigma~ auto from 0.1, 0.4, 1.6, 6.4, bracket 1.1,
seeds auto 3 to 10 at width 0.2) place sigma~ and seeds through the real planner
(:mod:`fibril_hpc.campaign.plan.search`), once with seeds 0..9 and once with ``first: 10``.
Per draw (a fresh population sample) the report's study reads both; the table gives the rate
at which each interval holds the truth, and at which each set's interval and span hold the other
set's estimate (what a referee checks), with median widths. Writes
``benchmarks/results/pillar_reproduce-*``.
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
from fibril_hpc.campaign.laws import reading  # noqa: E402
from fibril_hpc.campaign.laws.study import study_k  # noqa: E402
from fibril_hpc.campaign.plan import search  # noqa: E402
from fibril_hpc.campaign.plan.spec import spec_from_dict  # noqa: E402
from synthetic_campaigns import pillar_plateau, pillar_truth  # noqa: E402

PRELOADS = (0.001, 0.004, 0.016, 0.064, 0.25, 1.0, 4.0, 16.0)
ALPHA, BETA = 1.0, 1.0


def spec(n_side: int, first: int):
    auto = {"start": 3, "max": 10, "width": 0.2}
    if first:
        auto["first"] = first
    return spec_from_dict({
        "output": "s.h5", "scene": {"n_side": n_side, "phi": 0.16}, "k_tilde": [1.0],
        "sigma_tilde": {"auto": {"start": [0.1, 0.4, 1.6, 6.4], "min": 0.01, "max": 50,
                                 "bracket": 1.1, "spacing": 2, "rounds": 12}},
        "F_P": list(PRELOADS), "seeds": {"auto": auto}})


class Brushes:
    """The synthetic population of one draw: seed s is brush s (its own heights), c follows
    alpha/sigma~ - beta where the population holds adhesion, the few pillars' creep after."""

    def __init__(self, n_side: int, draw: int):
        self.floor = reading.pillar_floor(n_side, 0.16)
        self.reach, self.pop = pillar_truth(n_side, 1.0)
        self.n_side, self.draw, self._gaps = n_side, draw, {}

    def gaps(self, seed: int):
        if seed not in self._gaps:
            rng = np.random.default_rng([self.draw, seed, 7])
            xi = rng.standard_normal(self.n_side * self.n_side)
            self._gaps[seed] = np.sort(xi.max() - xi)[:80]
        return self._gaps[seed]

    def __call__(self, path, p):
        _, s, seed = path[:3]
        rng = np.random.default_rng([self.draw, seed, int(round(s * 1e6))])
        P = self.floor * pillar_plateau(self.gaps(seed), s, self.reach)
        P = self.floor + (P - self.floor) * (1 + 0.02 * rng.standard_normal())
        held = self.pop(s) > reading.FEW_PILLARS and ALPHA / s > BETA
        c = (ALPHA / s - BETA) if held else 10.0 * self.floor * self.pop(s)
        c *= max(1 + 0.05 * np.random.default_rng([self.draw, seed, 3]).standard_normal(), 0.05)
        return p, min(max(self.floor, c * p), P)


def drive(sp, truth):
    """The planner's rounds on synthetic records: {path: {preload: (F_P, F_A)}}."""
    done, cache = {}, {}
    for _ in range(10000):
        todo = search.frontier_of(sp, done, {}, cache=cache)
        if not todo:
            return done
        for path, pre in todo:
            for p in pre:
                done.setdefault(path, {})[p] = truth(path, p)
    raise RuntimeError("the search never finished")


def points(done) -> dict:
    rows: dict = {}
    for path, recs in done.items():
        _, s, seed = path[:3]
        for p, (fp, fa) in recs.items():
            rows.setdefault(float(s), []).append((seed, p, fp, fa))
    return {s: tuple(np.array(c, dtype=float) for c in zip(*r)) for s, r in rows.items()}


def one(n_side: int, draw: int, n_boot: int) -> dict:
    truth = Brushes(n_side, draw)
    st = {}
    for first in (0, 10):
        pts = points(drive(spec(n_side, first), truth))
        st[first] = study_k(1.0, pts, n_boot=n_boot, floor=truth.floor, rng_seed=draw)
    a, b = st[0].loss, st[10].loss

    def has(ci, v):
        if any(map(math.isnan, ci)) or not math.isfinite(v):
            return None
        return bool(ci[0] <= v <= ci[1])

    def width(ci):
        return ci[1] / ci[0] if ci[0] > 0 and math.isfinite(ci[1]) else math.nan

    return {"est_a": a.sigma, "est_b": b.sigma, "ci_a": a.ci, "ci_b": b.ci,
            "span_a": a.span, "span_b": b.span,
            "ci_truth": [has(a.ci, 1.0), has(b.ci, 1.0)],
            "span_truth": [has(a.span, 1.0), has(b.span, 1.0)],
            "ci_other": [has(a.ci, b.sigma), has(b.ci, a.sigma)],
            "span_other": [has(a.span, b.sigma), has(b.span, a.sigma)],
            "ci_ratio": [width(a.ci), width(b.ci)], "span_ratio": [width(a.span), width(b.span)],
            "n_groups": [len(st[0].groups), len(st[10].groups)],
            "another_other": [has(a.another, b.sigma), has(b.another, a.sigma)],
            "another_truth": [has(a.another, 1.0), has(b.another, 1.0)],
            "seeds_at_loss": [a.n_seeds, b.n_seeds]}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--draws", type=int, default=20)
    ap.add_argument("--n-boot", type=int, default=200)
    ap.add_argument("--n-side", type=int, default=12)
    ap.add_argument("--first-draw", type=int, default=0)
    a = ap.parse_args(argv)
    t0, res = time.time(), []
    for d in range(a.first_draw, a.first_draw + a.draws):
        r = one(a.n_side, d, a.n_boot)
        res.append(r)
        print(f"draw {d:2d}: {r['est_a']:.3f} {np.round(r['ci_a'], 3)} span {np.round(r['span_a'], 3)}"
              f" | {r['est_b']:.3f} {np.round(r['ci_b'], 3)} span {np.round(r['span_b'], 3)}",
              flush=True)

    def rate(key):
        v = [x for r in res for x in r[key] if x is not None]
        return f"{sum(v)}/{len(v)}" if v else "-"

    def med(key):
        v = [x for r in res for x in r[key] if math.isfinite(x)]
        return statistics.median(v) if v else math.nan

    print(f"n_side {a.n_side}, {a.draws} draws x 2 disjoint seed sets, truth sigma~_c = 1; "
          f"claimed 95 %")
    print(f"{'interval':>10} | {'holds truth':>11} | {'holds other set':>15} | median hi/lo")
    print(f"{'seed CI':>10} | {rate('ci_truth'):>11} | {rate('ci_other'):>15} | {med('ci_ratio'):.2f}")
    print(f"{'another':>10} | {rate('another_truth'):>11} | {rate('another_other'):>15} |")
    print(f"{'span':>10} | {rate('span_truth'):>11} | {rate('span_other'):>15} | {med('span_ratio'):.2f}")
    n_at = sorted(x for r in res for x in r["seeds_at_loss"])
    print(f"seeds at the loss bracket (the fewer of its two groups, as seeds: auto stopped): "
          f"median {statistics.median(n_at)}, range {n_at[0]}-{n_at[-1]}")
    ests = [x for r in res for x in (r["est_a"], r["est_b"]) if math.isfinite(x)]
    print(f"estimates: median {statistics.median(ests):.3f}, 2.5-97.5 % "
          f"{np.percentile(ests, 2.5):.3f}-{np.percentile(ests, 97.5):.3f}")
    base = write_results(os.path.join(HERE, "results"), "pillar_reproduce",
                         [dict(draw=a.first_draw + d, **{k: str(v) for k, v in r.items()})
                          for d, r in enumerate(res)],
                         {"draws": a.draws, "first_draw": a.first_draw, "n_boot": a.n_boot,
                          "n_side": a.n_side,
                          "wall_s": time.time() - t0})
    print(f"wrote {base}.csv/.json ({time.time() - t0:.0f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
