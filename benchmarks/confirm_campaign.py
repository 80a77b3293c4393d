"""A campaign's readings under ``confirm: local`` against the reference ``confirm: global``:
how far each group's plateau and c move, in units of their seed interval (issue 35 asks for
less than a tenth).

    python benchmarks/confirm_campaign.py GLOBAL_REPORT LOCAL_REPORT

Each argument is the folder of ``fibril-campaign report`` of the same grid run twice, once with
``solver: {confirm: global}`` (or no ``confirm``) and once with ``solver: {confirm: local}``
(for the shipped demo: copy campaigns/demo.yaml, add ``confirm: local`` under ``solver`` and a
new ``output``). Reads their ``plateau.csv`` and ``coefficients.csv`` and prints, per
(k~, sigma~), both plateaus and c, the move over the reference's seed interval width, and the
largest of each; writes nothing. Nothing here asserts a time.
"""

from __future__ import annotations

import csv
import math
import os
import sys


def _rows(folder: str, name: str) -> dict:
    with open(os.path.join(folder, name), newline="", encoding="utf-8") as fh:
        return {(float(r["k_tilde"]), float(r["sigma_tilde"])): r for r in csv.DictReader(fh)}


def _num(r, key) -> float:
    try:
        return float(r[key])
    except (KeyError, TypeError, ValueError):
        return math.nan


def moves(ref: dict, new: dict, value: str, lo: str, hi: str) -> dict:
    """{group: (reference, local, |local - reference| / reference interval width)} for the
    groups where both have a finite value and the reference a finite, non-empty interval."""
    out = {}
    for key in sorted(set(ref) & set(new)):
        a, b = _num(ref[key], value), _num(new[key], value)
        w = _num(ref[key], hi) - _num(ref[key], lo)
        if all(math.isfinite(x) for x in (a, b, w)) and w > 0:
            out[key] = (a, b, abs(b - a) / w)
    return out


def main(argv=None) -> int:
    args = sys.argv[1:] if argv is None else argv
    if len(args) != 2:
        print(__doc__.split("\n\n")[1])
        return 2
    g, loc = args
    worst = {}
    for name, value, lo, hi in (("plateau.csv", "plateau", "plateau_lo", "plateau_hi"),
                                ("coefficients.csv", "c", "c_lo", "c_hi")):
        m = moves(_rows(g, name), _rows(loc, name), value, lo, hi)
        print(f"{value}: {'k~':>6s} {'sigma~':>6s} {'reference':>11s} {'local':>11s} "
              f"{'move/CI':>8s}")
        for (k, s), (a, b, r) in m.items():
            print(f"{value}: {k:6g} {s:6g} {a:11.6g} {b:11.6g} {r:8.2e}")
        if m:
            key = max(m, key=lambda q: m[q][2])
            worst[value] = (m[key][2], key, len(m))
    for value, (r, (k, s), n) in worst.items():
        print(f"largest move of {value} over its seed interval: {r:.2e} (k~ {k:g}, sigma~ {s:g}; "
              f"{n} groups compared)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
