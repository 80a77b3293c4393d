"""The tables of docs/validation.md from a report folder (``fibril-campaign report ... --out``).

    python benchmarks/validation_tables.py REPORT_DIR

Prints, as Markdown: the state of every (k~, sigma~) as a matrix (R rise resolved, U rise not
resolved, L adhesion lost, with c or its bound), and the alpha/beta table (status, data bracket,
alpha, beta, sigma~_c and what the page may claim of it), from the report's CSV files.
"""

from __future__ import annotations

import csv
import math
import os
import sys

ABBR = {"rise resolved": "R", "rise not resolved": "U", "adhesion lost": "L", "undetermined": "?"}


def _rows(folder, name):
    with open(os.path.join(folder, name), newline="") as fh:
        return list(csv.DictReader(fh))


def _g(v, f=".3g"):
    try:
        x = float(v)
    except (TypeError, ValueError):
        return "—"
    return format(x, f) if math.isfinite(x) else ("∞" if x > 0 else "—")


def states(folder) -> str:
    rows = _rows(folder, "coefficients.csv")
    ks = sorted({float(r["k_tilde"]) for r in rows}, reverse=True)
    ss = sorted({float(r["sigma_tilde"]) for r in rows})
    cell = {}
    for r in rows:
        st = ABBR.get(r["state"], r["state"])
        if st == "R":
            v = _g(r["c"])
        elif st == "U":
            v = "≥ " + _g(r["c_lower_bound"])
        else:
            v = "0" if st == "L" else "—"
        cell[(float(r["k_tilde"]), float(r["sigma_tilde"]))] = f"{st} {v}"
    out = ["| k̃ \\ σ̃ | " + " | ".join(f"{s:g}" for s in ss) + " |",
           "|" + " --- |" * (len(ss) + 1)]
    for k in ks:
        out.append(f"| {k:g} | " + " | ".join(cell.get((k, s), "") for s in ss) + " |")
    return "\n".join(out)


def alpha_beta(folder) -> str:
    out = ["| k̃ | law | χ²/dof | data bracket of σ̃_c | α [seed CI] | β [seed CI] | α/β (extrapolated zero) |",
           "| --- | --- | --- | --- | --- | --- | --- |"]
    for r in _rows(folder, "alpha_beta.csv"):
        br = f"({_g(r['bracket_c_positive_up_to'], 'g')}, {_g(r['bracket_c_zero_from'], 'g')}]"
        ab = r["status"] != "undefined"
        a = f"{_g(r['alpha'])} [{_g(r['alpha_lo'])}, {_g(r['alpha_hi'])}]" if ab else "undefined"
        b = f"{_g(r['beta'])} [{_g(r['beta_lo'])}, {_g(r['beta_hi'])}]" if ab else "undefined"
        sc = (f"{_g(r['sigma_tilde_c'])} [{_g(r['sigma_tilde_c_lo'])}, "
              f"{_g(r['sigma_tilde_c_hi'])}]" if r["sigma_tilde_c_status"] == "extrapolated"
              else "none")
        out.append(f"| {float(r['k_tilde']):g} | {r['status']} | {_g(r['chi2_per_dof'])} | {br} | "
                   f"{a} | {b} | {sc} |")
    return "\n".join(out)


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if len(argv) != 1 or not os.path.isdir(argv[0]):
        print("usage: python benchmarks/validation_tables.py REPORT_DIR", file=sys.stderr)
        return 2
    print(states(argv[0]))
    print()
    print(alpha_beta(argv[0]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
