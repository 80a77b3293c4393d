"""alpha, beta and alpha/beta per reading of c, on a campaign file, beside the paper's Table 1.

    python benchmarks/paper_table.py CAMPAIGN.h5 [--n-boot 200] [--k-ref 1] [--out results/]
                                     [--against OTHER.h5]

He, Li & Popov (J. Adhesion 2021) read c as the slope of the linear stage of F~_A against F~_P
and fit c = alpha/sigma~ - beta per k~ (their Table 1: benchmarks/he_li_popov_2021_table1.csv).
A simulated rise is concave over decades, so "the slope of the linear stage" is a choice of
secant; this script fits the law to each candidate reading on the same groups and prints, per
reading and k~: alpha with its seed interval, the ratio alpha(k~)/alpha(k~_ref) (paired over
seeds), beta, alpha/beta, the law's chi^2/dof, and the paper's alpha, ratio, beta and sigma~_c.
It also prints the plateau where the paper quotes one (sigma~ = 0.07 and 2.1).

Readings (``READINGS``), all on the groups whose rise the report resolves with its plateau
reached (the groups the report's fit uses; lost groups stay out, as in the report):

* ``c``       - the report's c: secant through the origin to half the plateau;
* ``sec70``, ``sec90`` - the same secant to 70 % and 90 % of the plateau;
* ``c_chord`` - the chord over the first half of the rise from the smallest level;
* ``c_stage`` - the least-squares slope through the origin over the stage.

Weights: each group's seed-bootstrap sd of the reading (at least the smallest c its scatter can
tell from 0), the same rule for every reading. Intervals: percentile intervals of the fits to
the bootstrap replicates, resampling seed labels paired across every group of the file (a seed
is one brush at every sigma~ and k~), widened for the fewest seeds in a fit as the report does.

``--against OTHER.h5``: per reading, how far each group's value moves between the two files on
the groups both resolve (e.g. one made with the old loading batches, one with today's): the
robustness of a reading to the first-contact overshoot.

Writes results/paper_table-<stamp>.json (and .csv, one row per reading and k~).
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import os
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
PAPER_CSV = os.path.join(HERE, "he_li_popov_2021_table1.csv")
READINGS = ("c", "sec70", "sec90", "c_chord", "c_stage")
FRACTIONS = {"c": 0.5, "sec70": 0.7, "sec90": 0.9}
#: sigma~ where the paper quotes a plateau
PLATEAU_SIGMAS = (0.07, 2.1)


def paper_table(path: str = PAPER_CSV) -> list[dict]:
    """The paper's Table 1 rows: k_tilde_min, k_tilde_max, alpha, beta, sigma_c (floats)."""
    with open(path) as fh:
        rows = csv.DictReader(line for line in fh if not line.startswith("#"))
        return [{k: float(v) for k, v in r.items()} for r in rows]


def paper_row(k: float, table: list[dict]) -> dict | None:
    """The paper's column that covers ``k`` (``k~ >= 0.55`` is one column), or None."""
    for r in table:
        if (r["k_tilde_min"] <= k <= r["k_tilde_max"]) or math.isclose(k, r["k_tilde_min"]):
            return r
    return None


def values(pts, floor) -> tuple[object, dict]:
    """(the report's reading, {reading: value}) of one group; every value NaN where the report
    leaves the group out of its fit (rise not resolved, plateau not reached, lost)."""
    from fibril_hpc.campaign.laws.reading import RESOLVED, levels, read_group, read_levels, secant

    r = read_group(*pts, floor=floor)
    if r.state != RESOLVED or r.plateau_state != "reached":
        return r, dict.fromkeys(READINGS, math.nan)
    lv = read_levels(levels(*pts))
    out = {name: secant(lv, r.plateau, f) for name, f in FRACTIONS.items()}
    out["c_chord"], out["c_stage"] = r.c_chord, r.c_stage
    return r, out


def _fit(s, c, sd, ns):
    from fibril_hpc.campaign.laws.alphabeta import fit_alpha_beta

    ok = [math.isfinite(v) for v in c]
    return fit_alpha_beta([x for x, o in zip(s, ok) if o], [v for v, o in zip(c, ok) if o],
                          [v for v, o in zip(sd, ok) if o], n_seeds=[n for n, o in zip(ns, ok) if o])


def analyse(points: dict, floor: float, n_boot: int, k_ref: float | None = None) -> dict:
    """Per reading and k~: alpha, beta, alpha/beta with seed intervals, chi^2/dof, and the
    ratio alpha(k~)/alpha(k_ref) (``k_ref``: 1 where present, else the largest k~)."""
    from fibril_hpc.campaign.laws.intervals import (expanded, paired_replicates,
                                                    percentile_interval, replicate_sd)
    from fibril_hpc.campaign.laws.study import _resample  # noqa: PLC2701 - a study of the study

    keys = sorted(points)
    pts = {g: tuple(np.asarray(a) for a in points[g]) for g in keys}
    base = {g: values(pts[g], floor) for g in keys}
    sets = [sorted(set(pts[g][0].tolist())) for g in keys]
    nr = len(READINGS)

    def stat(picks):
        out = []
        for g, pick in zip(keys, picks):
            out += list(values(_resample(pts[g], pick), floor)[1].values())
        return np.array(out)

    reps = paired_replicates(sets, stat, n_boot, 0)
    ks = sorted({k for k, _ in keys}, reverse=True)
    if k_ref is None:
        k_ref = 1.0 if any(math.isclose(k, 1.0) for k in ks) else ks[0]
    res: dict = {"k_ref": k_ref, "fits": {}, "plateaus": {}}
    for k, s in keys:
        if any(math.isclose(s, p) for p in PLATEAU_SIGMAS):
            res["plateaus"][(k, s)] = base[(k, s)][0].plateau
    nb = 0 if reps is None else reps.shape[1]
    for name in READINGS:
        j = READINGS.index(name)
        per_k, ab_reps = {}, {}
        for k in ks:
            idx = [i for i, g in enumerate(keys) if g[0] == k and g[1] > 0
                   and math.isfinite(base[g][1][name])]
            s = [keys[i][1] for i in idx]
            c = [base[keys[i]][1][name] for i in idx]
            ns = [len(sets[i]) for i in idx]
            sd = [max(replicate_sd(reps[nr * i + j]), base[keys[i]][0].c_detect)
                  if reps is not None else math.nan for i in idx]
            f = _fit(s, c, sd, ns)
            fr = np.full((3, nb), math.nan)
            for b in range(nb):
                fb = _fit(s, [reps[nr * i + j, b] for i in idx], sd, ns)
                fr[:, b] = (fb.alpha, fb.beta,
                            fb.alpha / fb.beta if fb.beta > 0 and fb.alpha > 0 else
                            (math.inf if fb.ok else math.nan))
            ab_reps[k] = fr
            n_l = min(ns) if ns else 0
            zero = f.alpha / f.beta if f.ok and f.alpha > 0 and f.beta > 0 else math.nan

            def ci(v, row, n_l=n_l, fr=fr):
                return expanded(v, percentile_interval(fr[row]), n_l) if nb else (math.nan,) * 2

            per_k[k] = {"alpha": f.alpha, "alpha_ci": ci(f.alpha, 0), "beta": f.beta,
                        "beta_ci": ci(f.beta, 1), "alpha_over_beta": zero,
                        "alpha_over_beta_ci": tuple(max(v, 0.0) for v in ci(zero, 2)),
                        "chi2_red": f.chi2_red,
                        "dof": f.dof, "poor": f.poor, "enough": f.enough,
                        "n_points": len(idx), "sigmas": s, "min_seeds": n_l}
        ref = per_k.get(k_ref)
        for k in ks:
            d = per_k[k]
            d["ratio"] = d["alpha"] / ref["alpha"] if ref and ref["alpha"] else math.nan
            if nb and ref:
                rr = ab_reps[k][0] / ab_reps[k_ref][0]
                d["ratio_ci"] = expanded(d["ratio"], percentile_interval(rr),
                                         min(d["min_seeds"], ref["min_seeds"]))
            else:
                d["ratio_ci"] = (math.nan, math.nan)
        res["fits"][name] = per_k
    return res


def moves(points_a: dict, points_b: dict, floor: float) -> dict:
    """Per reading: |value_b / value_a - 1| over the groups both files resolve (same k~, sigma~)."""
    out = {name: [] for name in READINGS}
    for g in sorted(set(points_a) & set(points_b)):
        va, vb = values(points_a[g], floor)[1], values(points_b[g], floor)[1]
        for name in READINGS:
            if math.isfinite(va[name]) and math.isfinite(vb[name]) and va[name] > 0:
                out[name].append((g, vb[name] / va[name] - 1))
    return out


def _load(path):
    from fibril_hpc import load_campaign
    from fibril_hpc.campaign.analysis.report_data import campaign_floor, points_by_group

    c = load_campaign(path, curves=False)
    done = [j for j in c.jobs if j.get("status") == "done"]
    floor, _ = campaign_floor(c.meta, done)
    return points_by_group(done), floor


def _fmt(v, ci=None):
    if not math.isfinite(v):
        return "—"
    s = f"{v:.3g}"
    ci = None if ci is None else tuple(math.inf if x > 1e290 else x for x in ci)
    if ci is not None and all(math.isfinite(x) for x in ci):
        s += f" [{ci[0]:.3g}, {ci[1]:.3g}]"
    elif ci is not None and math.isfinite(ci[0]):
        s += f" [{ci[0]:.3g}, ∞]"
    return s


def report(res: dict, table: list[dict]) -> tuple[list[str], list[dict]]:
    """Lines to print and CSV rows of :func:`analyse`'s result beside the paper."""
    lines, rows = [], []
    ref_paper = paper_row(res["k_ref"], table)
    for name, per_k in res["fits"].items():
        lines.append(f"\n{name}: alpha [seed CI] | ratio alpha/alpha(k~={res['k_ref']:g}) | beta"
                     " | alpha/beta | chi2/dof (dof) || paper alpha | ratio | beta | sigma~_c"
                     " | alpha / paper's")
        for k, d in per_k.items():
            p = paper_row(k, table)
            pa = p["alpha"] if p else math.nan
            pr = pa / ref_paper["alpha"] if p and ref_paper else math.nan
            lines.append(
                f"  k~ {k:g}: {_fmt(d['alpha'], d['alpha_ci'])} | {_fmt(d['ratio'], d['ratio_ci'])}"
                f" | {_fmt(d['beta'], d['beta_ci'])} | {_fmt(d['alpha_over_beta'], d['alpha_over_beta_ci'])}"
                f" | {_fmt(d['chi2_red'])} ({d['dof']}{', poor' if d['poor'] else ''})"
                f" || {_fmt(pa)} | {_fmt(pr)} | {_fmt(p['beta'] if p else math.nan)}"
                f" | {_fmt(p['sigma_c'] if p else math.nan)} | x{_fmt(d['alpha'] / pa if pa else math.nan)}"
                f" (ratio x{_fmt(d['ratio'] / pr if pr else math.nan)})")
            rows.append({"reading": name, "k_tilde": k, **{key: d[key] for key in (
                "alpha", "beta", "alpha_over_beta", "ratio", "chi2_red", "dof", "poor",
                "n_points")},
                "alpha_lo": d["alpha_ci"][0], "alpha_hi": d["alpha_ci"][1],
                "ratio_lo": d["ratio_ci"][0], "ratio_hi": d["ratio_ci"][1],
                "beta_lo": d["beta_ci"][0], "beta_hi": d["beta_ci"][1],
                "paper_alpha": pa, "paper_ratio": pr,
                "paper_beta": p["beta"] if p else math.nan,
                "paper_sigma_c": p["sigma_c"] if p else math.nan})
    if res["plateaus"]:
        lines.append("\nplateau F~_A where the paper quotes one (k~ = 1: ~1 at sigma~ 0.07, almost 0 "
                     "at 2.1; k~ = 0.001: ~2 and 1.5): " + "; ".join(
                         f"k~ {k:g}, sigma~ {s:g}: {v:.3g}" for (k, s), v in sorted(res["plateaus"].items())))
    return lines, rows


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("campaign")
    ap.add_argument("--n-boot", type=int, default=200)
    ap.add_argument("--k-ref", type=float, default=None)
    ap.add_argument("--against", default=None)
    ap.add_argument("--out", default=os.path.join(HERE, "results"))
    a = ap.parse_args(argv)
    t0 = time.time()
    points, floor = _load(a.campaign)
    table = paper_table()
    res = analyse(points, floor, a.n_boot, a.k_ref)
    lines, rows = report(res, table)
    print(f"{a.campaign}: {len(points)} groups, floor {floor:.4g}, {a.n_boot} resamples; "
          f"{time.time() - t0:.1f} s")
    print("\n".join(lines))
    out = {"campaign": os.path.basename(a.campaign), "n_boot": a.n_boot, "k_ref": res["k_ref"],
           "rows": rows, "plateaus": [[k, s, v] for (k, s), v in res["plateaus"].items()]}
    if a.against:
        other, _ = _load(a.against)
        mv = moves(points, other, floor)
        print(f"\n{a.against} against {a.campaign}: value_b / value_a - 1 on the groups both resolve")
        out["against"] = os.path.basename(a.against)
        out["moves"] = {}
        for name, lst in mv.items():
            d = np.abs([v for _, v in lst])
            print(f"  {name}: median |d| {100 * np.median(d):.1f} %, max {100 * d.max():.1f} % "
                  f"(n {d.size}); " + ", ".join(f"({k:g}, {s:g}) {100 * v:+.0f} %"
                                                for (k, s), v in lst) if d.size else f"  {name}: none")
            out["moves"][name] = [[k, s, v] for (k, s), v in lst]
    os.makedirs(a.out, exist_ok=True)
    stamp = time.strftime("%Y-%m-%d-%H%M%S")
    base = os.path.join(a.out, f"paper_table-{stamp}")
    with open(base + ".json", "w") as fh:
        json.dump(out, fh, indent=1, default=float)
    with open(base + ".csv", "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]) if rows else ["reading"])
        w.writeheader()
        w.writerows(rows)
    print(f"\nwrote {base}.json, .csv")
    return 0


if __name__ == "__main__":
    sys.exit(main())
