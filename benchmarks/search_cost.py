"""What a search grid (``sigma_tilde: auto``, ``seeds: auto``) cost, against a fixed grid of equal
accuracy.

    python benchmarks/search_cost.py campaigns/critical_roughness.h5 [more files]

For every line (k~, n_side) of a finished search campaign it prints what the search ran (the
sigma~, loading paths, jobs, FFT pairs and CPU seconds of its records: a record's wall time and
FFT pairs are its simulate call's, shared by the ``group_size`` jobs of that call) and the loss
bracket it reached, then prices the fixed grid that would guarantee the same answer without
knowing where the loss is: sigma~ log-spaced at the the setting ``bracket`` (what the search
guarantees) over the range the search
explored (from its smallest sigma~ to its largest), every group with the largest seed count the
search gave any group of the line (a fixed grid has one seed count), each loading path costed as
the search's mean path at the nearest sigma~ it ran (in log sigma~). Machine-independent counts
(paths, FFT pairs) are given beside the CPU seconds. Writes ``benchmarks/results/search_cost-*``.
"""

from __future__ import annotations

import argparse
import math
import os
import sys
from collections import defaultdict

import yaml

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

from benchmarks.common import write_results  # noqa: E402
from fibril_hpc.campaign.analysis.data import load_campaign  # noqa: E402
from fibril_hpc.campaign.plan import search  # noqa: E402
from fibril_hpc.campaign.plan.spec import spec_from_dict  # noqa: E402

OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "results")


def line_rows(path: str) -> list:
    """One row per line of the search campaign at ``path``."""
    c = load_campaign(path, curves=False)
    data = yaml.safe_load(c.meta["campaign_yaml"])
    spec = spec_from_dict(dict(data, output=os.path.abspath(path)))
    if not spec.search:
        raise SystemExit(f"{path}: not a search grid (sigma_tilde: auto or seeds: auto)")
    done, failed = search.results(spec, c.jobs)
    per_path: dict = defaultdict(lambda: [0.0, 0.0, 0])     # path -> [cpu s, fft pairs, jobs]
    for j in c.jobs:
        p = spec.record_path(j)
        g = max(1, int(j.get("group_size", 1)))
        per_path[p][0] += float(j.get("wall_s", 0.0)) / g
        per_path[p][1] += float(j.get("fft_pairs", 0)) / g
        per_path[p][2] += 1
    rows = []
    for line in spec.lines():
        ln = search.replay_line(spec, line, done, failed)
        states = {s: g.state for s, g in ln.groups.items()}
        lo, hi = search.loss_bracket(states)
        mine = {p: v for p, v in per_path.items() if (p[0],) + tuple(p[3:]) == tuple(line)}
        by_sigma: dict = defaultdict(list)
        for p, v in mine.items():
            by_sigma[p[1]].append(v)
        sig = sorted(by_sigma)
        cpu = sum(v[0] for v in mine.values())
        pairs = sum(v[1] for v in mine.values())
        max_seeds = max(len(g.seeds) for g in ln.groups.values())
        ratio = spec.sigma_auto.bracket if spec.sigma_auto is not None else 1.1
        n_fixed = math.ceil(math.log(sig[-1] / sig[0]) / math.log(ratio)) + 1
        fixed = [sig[0] * ratio**i for i in range(n_fixed)]

        def mean(s, i, sig=sig, by_sigma=by_sigma):       # the nearest sigma~ run's mean path
            vs = by_sigma[min(sig, key=lambda x: abs(math.log(x / s)))]
            return sum(v[i] for v in vs) / len(vs)

        f_cpu = sum(mean(s, 0) for s in fixed) * max_seeds
        f_pairs = sum(mean(s, 1) for s in fixed) * max_seeds
        rows.append({
            "file": os.path.basename(path), "k_tilde": line[0],
            "n_side": line[1] if len(line) > 1 else spec.base.n_side,
            "sigma_run": len(sig), "rounds": ln.rounds + 1,
            "bracket_lo": lo, "bracket_hi": hi,
            "bracket_ratio": hi / lo if math.isfinite(lo) and math.isfinite(hi) else math.nan,
            "seeds_min": min(len(g.seeds) for g in ln.groups.values()), "seeds_max": max_seeds,
            "at_max": sum(1 for g in ln.groups.values() if spec.seeds_auto is not None
                          and len(g.seeds) >= spec.seeds_auto.max and g.precision is not None
                          and not g.precision.met),
            "paths": len(mine), "jobs": sum(v[2] for v in mine.values()),
            "fft_pairs": round(pairs), "cpu_s": round(cpu, 1),
            "fixed_sigma": n_fixed, "fixed_paths": n_fixed * max_seeds,
            "fixed_fft_pairs": round(f_pairs), "fixed_cpu_s": round(f_cpu, 1),
            "fixed_over_search_cpu": round(f_cpu / cpu, 2) if cpu else math.nan,
        })
    return rows


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("files", nargs="+")
    args = ap.parse_args(argv)
    rows = [r for f in args.files for r in line_rows(f)]
    cols = ("k_tilde", "n_side", "sigma_run", "rounds", "bracket_lo", "bracket_hi", "seeds_min",
            "seeds_max", "at_max", "paths", "fft_pairs", "cpu_s", "fixed_sigma", "fixed_paths",
            "fixed_fft_pairs", "fixed_cpu_s", "fixed_over_search_cpu")
    print(" | ".join(cols))
    for r in rows:
        print(" | ".join(f"{r[c]:.4g}" if isinstance(r[c], float) else str(r[c]) for c in cols))
    tot = {k: sum(r[k] for r in rows) for k in ("paths", "cpu_s", "fixed_paths", "fixed_cpu_s",
                                                "fft_pairs", "fixed_fft_pairs")}
    print(f"all lines: search {tot['paths']} paths, {tot['fft_pairs']} FFT pairs, "
          f"{tot['cpu_s']:.0f} CPU s; fixed grid of equal accuracy {tot['fixed_paths']} paths, "
          f"{tot['fixed_fft_pairs']} FFT pairs, {tot['fixed_cpu_s']:.0f} CPU s "
          f"({tot['fixed_cpu_s'] / max(tot['cpu_s'], 1e-9):.2g}x)")
    write_results(OUT, "search_cost", rows, {"meta": {"files": args.files}, "totals": tot})
    return 0


if __name__ == "__main__":
    sys.exit(main())
