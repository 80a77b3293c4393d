"""Rates of benchmarks/pillar_reproduce.py's intervals from its results file, the span rebuilt
with another seed set's interval (the seed interval widened by a factor in log sigma~).

    python benchmarks/pillar_reproduce_table.py RESULTS.json [--factor 1.414]
"""
from __future__ import annotations

import argparse
import ast
import json
import math
import sys


def widen(s, ci, f):
    lo, hi = ci
    hi = math.inf if hi > 1e100 else hi        # an end the old percentile left huge
    if not (math.isfinite(s) and s > 0) or math.isnan(lo) or math.isnan(hi):
        return (math.nan, math.nan)
    lo2 = s * (lo / s) ** f if 0 < lo < s else min(lo, s)
    hi2 = s * (hi / s) ** f if s < hi < math.inf else max(hi, s)
    return lo2, hi2


def holds(ci, v):
    if any(map(math.isnan, ci)) or not math.isfinite(v):
        return None
    return ci[0] <= v <= ci[1]


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("results")
    ap.add_argument("--factor", type=float, default=math.sqrt(2))
    a = ap.parse_args(argv)
    rows = json.load(open(a.results))["rows"]
    tally = {}
    for r in rows:
        def ev(k, r=r):
            return ast.literal_eval(r[k].replace("inf", "1e999").replace("nan", "None"))

        est = {"a": float(r["est_a"]), "b": float(r["est_b"])}
        for me, other in (("a", "b"), ("b", "a")):
            ci = tuple(math.nan if v is None else float(v) for v in ev(f"ci_{me}"))
            span = tuple(math.nan if v is None else float(v) for v in ev(f"span_{me}"))
            an = widen(est[me], ci, a.factor)
            span2 = (min(span[0], an[0]) if not math.isnan(an[0]) else span[0],
                     max(span[1], an[1]) if not math.isnan(an[1]) else span[1])
            for name, iv in (("seed CI", ci), ("another", an), ("span", span2)):
                for what, v in (("truth", 1.0), ("other", est[other])):
                    h = holds(iv, v)
                    if h is not None:
                        t = tally.setdefault((name, what), [0, 0])
                        t[0] += h
                        t[1] += 1
    print(f"factor {a.factor:.3f}")
    for name in ("seed CI", "another", "span"):
        print(f"{name:>8} | truth {tally[(name, 'truth')][0]}/{tally[(name, 'truth')][1]} | "
              f"other {tally[(name, 'other')][0]}/{tally[(name, 'other')][1]}")


if __name__ == "__main__":
    sys.exit(main())
