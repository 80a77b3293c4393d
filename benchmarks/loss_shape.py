"""Is the loss of adhesion sharp or a fade? The groups of a search campaign around the loss.

    python benchmarks/loss_shape.py campaigns/critical_roughness.h5 [more files]

For every line (k~, n_side) of a search campaign (``sigma_tilde: auto``): every sigma~ it ran with
its seeds, state, plateau and c with their seed intervals (the report's reading and the planner's
bootstrap, :func:`fibril_hpc.campaign.laws.precision.group_precision`; c's interval shown from 0,
as on the page), and the local log-slope
of the plateau, d ln P / d ln sigma~, between neighbouring sigma~. A *fade* keeps the slope it had
before the loss through the loss bracket (the plateau falls as a power of sigma~ through the
threshold of three pillars and on to one pillar's pull-off); a *sharp* loss steepens across the
bracket far beyond the slope before it, with c still well above 0 at the last sigma~ holding
adhesion. Prints one table per line and the slope before and across the bracket; writes
``benchmarks/results/loss_shape-*``.
"""

from __future__ import annotations

import argparse
import math
import os
import sys

import yaml

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

from benchmarks.common import write_results  # noqa: E402
from fibril_hpc.campaign.analysis.data import load_campaign  # noqa: E402
from fibril_hpc.campaign.laws.reading import LOST, pillar_floor  # noqa: E402
from fibril_hpc.campaign.plan import search  # noqa: E402
from fibril_hpc.campaign.plan.spec import spec_from_dict  # noqa: E402

OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "results")


def _slope(a, b) -> float:
    (s0, p0), (s1, p1) = a, b
    if min(p0, p1) <= 0:
        return math.nan
    return math.log(p1 / p0) / math.log(s1 / s0)


def _first_crossing(gs, thr: float) -> float:
    """The sigma~ where the seed-mean plateau of the groups ``gs`` (ascending sigma~) first falls
    to ``thr``, interpolated log-log between the two groups around it (NaN: it never does)."""
    pts = [(g.sigma, g.precision.plateau) for g in gs if g.precision.plateau > 0]
    for (s0, p0), (s1, p1) in zip(pts, pts[1:]):
        if p0 > thr >= p1:
            t = math.log(p0 / thr) / math.log(p0 / p1)
            return math.exp(math.log(s0) + t * math.log(s1 / s0))
    return math.nan


def rows_of(path: str) -> tuple[list, list]:
    """(one row per group, one summary per line) of the search campaign at ``path``."""
    c = load_campaign(path, curves=False)
    spec = spec_from_dict(dict(yaml.safe_load(c.meta["campaign_yaml"]),
                               output=os.path.abspath(path)))
    done, failed = search.results(spec, c.jobs)
    rows, lines = [], []
    for line in spec.lines():
        n_side = line[1] if len(line) > 1 else spec.base.n_side
        floor = pillar_floor(n_side, spec.base.phi)
        ln = search.replay_line(spec, line, done, failed)
        gs = [ln.groups[s] for s in sorted(ln.groups) if ln.groups[s].precision is not None]
        lo, hi = search.loss_bracket({g.sigma: g.state for g in gs})
        prev = None
        for g in gs:
            p = g.precision
            rows.append({"file": os.path.basename(path), "k_tilde": line[0], "n_side": n_side,
                         "sigma_tilde": g.sigma, "seeds": len(g.seeds), "state": g.state,
                         "plateau": p.plateau, "plateau_lo": p.plateau_ci[0],
                         "plateau_hi": p.plateau_ci[1], "plateau_pillars": p.plateau / floor,
                         "c": p.c, "c_lo": max(p.c_ci[0], 0.0), "c_hi": p.c_ci[1],
                         "slope_from_previous": (_slope(prev, (g.sigma, p.plateau))
                                                 if prev else math.nan),
                         "met": p.met, "short": " ".join(p.short)})
            prev = (g.sigma, p.plateau)
        summary = {"file": os.path.basename(path), "k_tilde": line[0], "n_side": n_side,
                   "bracket_lo": lo, "bracket_hi": hi,
                   # where the seed-mean plateau first falls to 2, 3, 5 pillars (log-log)
                   **{f"sigma_at_{m}_pillars": _first_crossing(gs, m * floor) for m in (2, 3, 5)}}
        if math.isfinite(lo) and math.isfinite(hi):
            by = {g.sigma: g for g in gs}
            alive = [g for g in gs if g.sigma <= lo and g.state != LOST]
            before = (_slope((alive[-2].sigma, alive[-2].precision.plateau),
                             (lo, by[lo].precision.plateau)) if len(alive) >= 2 else math.nan)
            across = _slope((lo, by[lo].precision.plateau), (hi, by[hi].precision.plateau))
            summary.update({
                "plateau_lo_pillars": by[lo].precision.plateau / floor,
                "plateau_hi_pillars": by[hi].precision.plateau / floor,
                "c_at_lo": by[lo].precision.c,
                "c_at_lo_ci": [max(by[lo].precision.c_ci[0], 0.0), by[lo].precision.c_ci[1]],
                "slope_before": before, "slope_across": across,
                "seeds_lo": len(by[lo].seeds), "seeds_hi": len(by[hi].seeds)})
        lines.append(summary)
    return rows, lines


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("files", nargs="+")
    args = ap.parse_args(argv)
    rows, lines = [], []
    for f in args.files:
        r, ln = rows_of(f)
        rows += r
        lines += ln
    for s in lines:
        print(f"\n{s['file']}: k~ = {s['k_tilde']:g}, {s['n_side']} x {s['n_side']}: loss bracket "
              f"({s['bracket_lo']:g}, {s['bracket_hi']:g}]")
        print(f"  {'sigma~':>8} {'seeds':>5} {'state':<18} {'plateau [seed CI]':<28} "
              f"{'pillars':>7} {'c [seed CI]':<26} {'dlnP/dlns':>9}")
        for r in rows:
            if (r["file"], r["k_tilde"], r["n_side"]) != (s["file"], s["k_tilde"], s["n_side"]):
                continue
            print(f"  {r['sigma_tilde']:>8.4g} {r['seeds']:>5} {r['state']:<18} "
                  f"{r['plateau']:.4g} [{r['plateau_lo']:.3g}, {r['plateau_hi']:.3g}]".ljust(66)
                  + f" {r['plateau_pillars']:>7.3g} "
                  + f"{r['c']:.3g} [{r['c_lo']:.3g}, {r['c_hi']:.3g}]".ljust(26)
                  + f" {r['slope_from_previous']:>9.3g}")
        print("  the plateau first falls to 2, 3, 5 pillars at sigma~ = "
              + ", ".join(f"{s[f'sigma_at_{m}_pillars']:.3g}" for m in (2, 3, 5)))
        if "slope_across" in s:
            print(f"  plateau {s['plateau_lo_pillars']:.3g} -> {s['plateau_hi_pillars']:.3g} "
                  f"pillars across the bracket; d ln P / d ln sigma~ {s['slope_before']:.3g} "
                  f"before it, {s['slope_across']:.3g} across it; c at lo {s['c_at_lo']:.3g} "
                  f"[{s['c_at_lo_ci'][0]:.3g}, {s['c_at_lo_ci'][1]:.3g}]")
    write_results(OUT, "loss_shape", rows, {"meta": {"files": args.files}, "lines": lines})
    return 0


if __name__ == "__main__":
    sys.exit(main())
