"""How each candidate definition of the adhesion coefficient c depends on the preload sampling,
and how well c = alpha/sigma~ - beta then fits, on a real campaign file.

    python benchmarks/c_definitions.py CAMPAIGN.h5 [--n-boot 100] [--out results/]

Candidates (the report's columns, :mod:`fibril_hpc.campaign.laws.reading`):

* ``c``       - eq. 15: the secant through the origin to where F~_A first reaches half the
  plateau (log F~_P interpolation);
* ``c_stage`` - the least-squares slope through the origin over the linear-stage levels;
* ``c_chord`` - the chord over the first half of the rise from the smallest level (the report's
  c before issue 28);
* ``sec70``, ``sec90`` - the secant through the origin to 70 % and 90 % of the plateau
  (benchmarks/paper_table.py: readings nearer the plateau, less steep).

Sampling variants of every (k~, sigma~) group (only groups whose rise is resolved in full):

* ``start``  - only the preloads of ``F_P: auto``'s first round (0.001 ... 4, x 4 apart);
* ``sparse`` - every other level (x 16 apart where the round had x 4);
* ``no_low`` - the smallest level dropped;
* ``low``    - a level added below the smallest, on the first-contact floor (F~_A of the
  smallest level, F~_P / 4): what a finer preload list would add below the rise.

Prints per candidate the median and 90th percentile of |c_variant / c_full - 1| over groups, and
per k~ the weighted chi^2/dof of the alpha/beta fit (seed-bootstrap sd as weights), the share of
k~ whose fit is not poor, and writes the table as CSV and JSON (results/).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
import time

import numpy as np

CANDIDATES = ("c", "c_stage", "c_chord", "sec70", "sec90")
VARIANTS = ("start", "sparse", "no_low", "low")
SECANTS = {"sec70": 0.7, "sec90": 0.9}
START = (0.001, 0.004, 0.016, 0.064, 0.25, 1.0, 4.0)


def _variant(pts, name):
    seed, pre, x, y = pts
    levels = np.unique(pre)
    if name == "start":
        keep = np.isin(pre, [p for p in levels if any(math.isclose(p, s) for s in START)])
    elif name == "sparse":
        keep = np.isin(pre, levels[::2])
    elif name == "no_low":
        keep = pre != levels[0]
    else:                                   # "low": a floor level below the smallest
        sel = pre == levels[0]
        return (np.concatenate([seed, seed[sel]]), np.concatenate([pre, pre[sel] / 4]),
                np.concatenate([x, x[sel] / 4]), np.concatenate([y, y[sel]]))
    return seed[keep], pre[keep], x[keep], y[keep]


def main(argv=None) -> int:
    from fibril_hpc import load_campaign
    from fibril_hpc.campaign.analysis.report_data import campaign_floor, points_by_group
    from fibril_hpc.campaign.laws.alphabeta import fit_alpha_beta
    from fibril_hpc.campaign.laws.intervals import replicate_sd, seed_replicates
    from fibril_hpc.campaign.laws.reading import LOST, RESOLVED, read_group
    from fibril_hpc.campaign.laws.study import _resample  # noqa: PLC2701 - a study of the study

    from fibril_hpc.campaign.laws.reading import levels, read_levels, secant

    def value(rr, pts, name):
        """``name`` of a reading ``rr`` of ``pts``: 0 for a lost group, else its value."""
        if rr.state == LOST:
            return 0.0
        if name in SECANTS:
            return (secant(read_levels(levels(*pts)), rr.plateau, SECANTS[name])
                    if rr.state == RESOLVED else math.nan)
        return getattr(rr, name)

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("campaign")
    ap.add_argument("--n-boot", type=int, default=100)
    ap.add_argument("--out", default=os.path.join(os.path.dirname(__file__), "results"))
    a = ap.parse_args(argv)
    t0 = time.time()
    c = load_campaign(a.campaign, curves=False)
    done = [j for j in c.jobs if j.get("status") == "done"]
    floor, _ = campaign_floor(c.meta, done)
    points = points_by_group(done)
    sens = {k: {v: [] for v in VARIANTS} for k in CANDIDATES}
    by_k: dict = {}
    for (k, s), pts in points.items():
        r = read_group(*pts, floor=floor)
        by_k.setdefault(k, []).append((s, pts, r))
        if r.state != RESOLVED or r.plateau_state != "reached":
            continue
        for v in VARIANTS:
            pv = _variant(pts, v)
            rv = read_group(*pv, floor=floor)
            if rv.state != RESOLVED:
                continue
            for name in CANDIDATES:
                full, var = value(r, pts, name), value(rv, pv, name)
                if math.isfinite(full) and math.isfinite(var) and full > 0:
                    sens[name][v].append(abs(var / full - 1))
    fits = {name: {} for name in CANDIDATES}
    for k, groups in sorted(by_k.items(), reverse=True):
        use = [(s, pts, r) for s, pts, r in groups if s > 0 and r.state in (RESOLVED, LOST)
               and r.plateau_state != "not reached"]
        if len(use) < 3:
            continue
        labels = sorted(set().union(*(set(p[0].tolist()) for _, p, _ in use)))

        def stat(picked, use=use):
            out = []
            for _, pts, _ in use:
                pr = _resample(pts, picked)
                rr = read_group(*pr, floor=floor)
                out += [value(rr, pr, n) if rr.state in (RESOLVED, LOST) else math.nan
                        for n in CANDIDATES]
            return np.array(out)

        reps = seed_replicates(labels, stat, a.n_boot, 0)
        for j, name in enumerate(CANDIDATES):
            cs = [value(r, pts, name) for _, pts, r in use]
            sd = [max(replicate_sd(reps[len(CANDIDATES) * i + j]), r.c_detect)
                  if reps is not None else math.nan for i, (_, _, r) in enumerate(use)]
            ok = [math.isfinite(v) for v in cs]
            f = fit_alpha_beta([s for (s, _, _), o in zip(use, ok) if o],
                               [v for v, o in zip(cs, ok) if o], [v for v, o in zip(sd, ok) if o])
            fits[name][k] = {"alpha": f.alpha, "beta": f.beta, "chi2_red": f.chi2_red,
                             "poor": f.poor, "n": f.n_points, "n_zero": f.n_zero}
    rows = []
    print(f"{a.campaign}: {len(points)} groups, floor {floor:.4g}; {time.time() - t0:.1f} s")
    print("candidate | " + " | ".join(f"{v}: median / p90 |dc/c|" for v in VARIANTS)
          + " | fits not poor | median chi2/dof")
    for name in CANDIDATES:
        cells = []
        row = {"candidate": name}
        for v in VARIANTS:
            d = np.array(sens[name][v])
            med, p90 = (float(np.median(d)), float(np.percentile(d, 90))) if d.size else (math.nan,) * 2
            row[f"{v}_median"], row[f"{v}_p90"], row[f"{v}_n"] = med, p90, int(d.size)
            cells.append(f"{100 * med:.1f} % / {100 * p90:.1f} % (n {d.size})")
        fk = fits[name]
        chi = [f["chi2_red"] for f in fk.values() if math.isfinite(f["chi2_red"])]
        row["fits"], row["not_poor"] = len(fk), sum(not f["poor"] for f in fk.values())
        row["chi2_median"] = float(np.median(chi)) if chi else math.nan
        row["per_k"] = {repr(k): f for k, f in fk.items()}
        rows.append(row)
        print(f"{name} | " + " | ".join(cells) + f" | {row['not_poor']} of {row['fits']} | "
              f"{row['chi2_median']:.3g}")
    for name in CANDIDATES:
        print(f"{name}: " + "; ".join(f"k~ {k:g}: alpha {f['alpha']:.3g} beta {f['beta']:.3g} "
                                       f"chi2/dof {f['chi2_red']:.3g}"
                                       for k, f in fits[name].items()))
    os.makedirs(a.out, exist_ok=True)
    stamp = time.strftime("%Y-%m-%d-%H%M%S")
    with open(os.path.join(a.out, f"c_definitions-{stamp}.json"), "w") as fh:
        json.dump({"campaign": os.path.basename(a.campaign), "rows": rows}, fh, indent=1,
                  default=float)
    return 0


if __name__ == "__main__":
    sys.exit(main())
