"""What ``fibril-campaign --dry-run`` prices against what the grid then costs (issue 36, item 8).

    python benchmarks/price_check.py [--cases NAME,...] [--quick]

Small grids from 8 x 8 to 36 x 36 (fixed preloads, ``F_P: auto``, a ``seeds: auto`` /
``sigma_tilde: auto`` search) are priced as ``--dry-run`` prices them (round 0, then with the
expected later ``F_P: auto`` rounds; a search: the whole-search range), then run serially in
this process, the CPU time of the whole run measured (``time.process_time``: the simulate
calls, the journal and the checkpoints). Prints measured / priced with the machine-independent
counts (loading paths, simulate calls, jobs, FFT pairs) and writes
``benchmarks/results/price_check-*``. The whole set costs about 5 CPU minutes; "README grid"
is README's campaign example; the "... confirm local" grids are twins of two others with
``solver: {confirm: local}``.
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time

import yaml

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

from benchmarks.common import write_results  # noqa: E402

OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "results")
R1 = {"fft_threads": 1}
CASES = {
    "8x8 fast F_P auto": dict(scene={"n_side": 8, "preset": "fast", "solver": R1},
                              k_tilde=[1, 0.01], sigma_tilde=[0.1, 1], F_P="auto", seeds=2),
    "README grid": dict(scene={"n_side": 8, "preset": "fast", "solver": R1},
                        k_tilde=[1, 0.01], sigma_tilde=[0.1, 0.3, 1, 3], F_P="auto", seeds=3),
    "8x8 default F_P list": dict(scene={"n_side": 8, "preset": "default", "solver": R1},
                                 k_tilde=[1, 0.01], sigma_tilde=[0.1, 1], F_P=[0.1, 1, 4],
                                 seeds=2),
    "12x12 fast F_P auto": dict(scene={"n_side": 12, "preset": "fast", "solver": R1},
                                k_tilde=[0.01], sigma_tilde=[0.3, 1], F_P="auto", seeds=2),
    "18x18 fast F_P auto": dict(scene={"n_side": 18, "preset": "fast", "solver": R1},
                                k_tilde=[0.01], sigma_tilde=[0.5], F_P="auto", seeds=2),
    "8x8 fast search seeds auto": dict(
        scene={"n_side": 8, "preset": "fast", "solver": R1}, k_tilde=[0.01],
        sigma_tilde={"auto": {"start": [0.1, 0.4, 1.6, 6.4], "bracket": 1.5, "spacing": 2,
                              "rounds": 6}},
        F_P="auto", seeds={"auto": {"start": 2, "max": 4, "width": 0.3}}),
    "36x36 fast one job": dict(scene={"n_side": 36, "preset": "fast", "solver": R1},
                               k_tilde=[0.01], sigma_tilde=[0.5], F_P=[4], seeds=1),
}
#: twins of two grids above with the opt-in ``solver.confirm: local`` (priced by
#: ``estimate.CONFIRM_LOCAL_PAIRS``; left out of the OVERHEAD / PAIR_FIXED_S fit)
LOCAL = {**R1, "confirm": "local"}
for _name in ("8x8 default F_P list", "12x12 fast F_P auto"):
    CASES[_name + " confirm local"] = {**CASES[_name],
                                       "scene": {**CASES[_name]["scene"], "solver": LOCAL}}


def price(spec, terms: bool = False) -> dict:
    """What --dry-run says: round 0, with the later F_P auto rounds, and a search's range; with
    ``terms``, also the price's two parts apart (``fft_term_s``: OVERHEAD 1 and no fixed term;
    ``pair_term``: the modelled FFT pairs, the fixed term's factor), which --fit fits."""
    from fibril_hpc.campaign.analysis.status import plan
    from fibril_hpc.campaign.plan import estimate, search

    out = {}
    if terms:
        keep = estimate.OVERHEAD, estimate.PAIR_FIXED_S
        try:
            for name, ov, fixed in (("fft_term_s", 1.0, 0.0), ("pair_term", 0.0, 1.0)):
                estimate.OVERHEAD = dict.fromkeys(keep[0], ov)
                estimate.PAIR_FIXED_S = fixed
                out[name] = price(spec)["priced_s"]
        finally:
            estimate.OVERHEAD, estimate.PAIR_FIXED_S = keep
    pl = plan(spec)
    out.update(priced_round0_s=pl.estimate_s, priced_s=pl.estimate_s + pl.later_s,
               priced_hi_s=pl.estimate_s + pl.later_s)
    if spec.search and pl.n_tasks:
        per_path = (pl.estimate_s + pl.later_s) / pl.n_tasks
        a, sa = spec.sigma_auto, spec.seeds_auto
        n_s = search.expected_sigmas(a) if a is not None else len(spec.sigma_tilde)
        lo, hi = (sa.start, sa.max) if sa is not None else (len(spec.seeds),) * 2
        paths = len(spec.lines()) * n_s
        out["priced_s"], out["priced_hi_s"] = per_path * paths * lo, per_path * paths * hi
    return out


def measure(name: str, grid: dict, folder: str) -> dict:
    from fibril_hpc.campaign.analysis.data import load_campaign
    from fibril_hpc.campaign.plan.spec import load_spec
    from fibril_hpc.campaign.run.runner import run_serial

    path = os.path.join(folder, name.replace(" ", "_").replace(",", "") + ".yaml")
    with open(path, "w") as fh:
        yaml.safe_dump({"output": os.path.basename(path)[:-5] + ".h5", "group_preloads": True,
                        **grid}, fh)
    spec = load_spec(path)
    row = {"case": name, "preset": grid["scene"]["preset"],
           "confirm": grid["scene"]["solver"].get("confirm", "global"), **price(spec, terms=True)}
    t0 = time.process_time()
    code = run_serial(spec, progress=False)
    row["measured_s"] = time.process_time() - t0
    c = load_campaign(spec.output, curves=False)
    df = c.to_dataframe()
    axes = ["k_tilde", "sigma_tilde", "seed"]
    tasks = df.groupby(axes + ["wall_s", "fft_pairs"]).size()
    row.update(status=code, paths=int(df.groupby(axes).ngroups), tasks=len(tasks),
               jobs=len(df), fft_pairs=int(tasks.index.get_level_values("fft_pairs").to_numpy().sum()))
    row["measured/priced"] = row["measured_s"] / row["priced_s"]
    row["measured/priced_hi"] = row["measured_s"] / row["priced_hi_s"]
    return row


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--cases", default=",".join(CASES), help="comma-separated subset of: "
                   + "; ".join(CASES))
    args = p.parse_args(argv)
    names = [c.strip() for c in args.cases.split(",") if c.strip()]
    for n in names:
        if n not in CASES:
            print(f"price_check: unknown case {n!r}", file=sys.stderr)
            return 2
    from fibril_hpc import Scene, simulate

    simulate(Scene(n_side=2, preset="fast", F_P=[1], k_tilde=0.01, sigma_tilde=0.5))  # warm-up
    rows = []
    with tempfile.TemporaryDirectory() as folder:
        for n in names:
            rows.append(measure(n, CASES[n], folder))
            r = rows[-1]
            print(f"{r['case']:30s} paths {r['paths']:3d} tasks {r['tasks']:3d} jobs {r['jobs']:4d} "
                  f"pairs {r['fft_pairs']:7d}  priced {r['priced_round0_s']:7.1f} (round 0) "
                  f"{r['priced_s']:7.1f}" + (f"-{r['priced_hi_s']:.1f}" if r['priced_hi_s'] !=
                                             r['priced_s'] else "")
                  + f" s  measured {r['measured_s']:7.1f} CPU s  ratio "
                  f"{r['measured/priced']:.2f}", flush=True)
    print("\n| grid | paths | simulate calls | jobs | FFT pairs | priced CPU s (round 0) | "
          "priced CPU s | measured CPU s | measured / priced |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    for r in rows:
        pr = (f"{r['priced_s']:.1f}" if r["priced_hi_s"] == r["priced_s"] else
              f"{r['priced_s']:.1f}–{r['priced_hi_s']:.1f}")
        ratio = (f"{r['measured/priced']:.2f}" if r["priced_hi_s"] == r["priced_s"] else
                 f"{r['measured/priced_hi']:.2f}–{r['measured/priced']:.2f}")
        print(f"| {r['case']} | {r['paths']} | {r['tasks']} | {r['jobs']} | {r['fft_pairs']} | "
              f"{r['priced_round0_s']:.1f} | {pr} | {r['measured_s']:.1f} | {ratio} |")
    fit = _fit(rows)
    print("\nleast squares of measured CPU s = OVERHEAD[preset] x FFT term + PAIR_FIXED_S x "
          "pairs (searches at their low end): " + ", ".join(f"{k} {v:.4g}" for k, v in fit.items()))
    write_results(OUT, "price_check", rows, {"meta": {"cases": names}, "fit": fit})
    return 0


def _fit(rows) -> dict:
    """OVERHEAD per preset and PAIR_FIXED_S that fit the measured costs (relative errors), on the
    reference path's grids (``confirm: global``) alone."""
    import numpy as np

    rows = [r for r in rows if r.get("confirm", "global") == "global"]

    presets = sorted({r["preset"] for r in rows})
    a = np.array([[r["fft_term_s"] * (r["preset"] == p) for p in presets] + [r["pair_term"]]
                  for r in rows]) / np.array([[r["measured_s"]] for r in rows])
    coef, *_ = np.linalg.lstsq(a, np.ones(len(rows)), rcond=None)
    return {**{f"OVERHEAD[{p}]": float(c) for p, c in zip(presets, coef)},
            "PAIR_FIXED_S": float(coef[-1])}


if __name__ == "__main__":
    sys.exit(main())
