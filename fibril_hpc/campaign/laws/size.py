"""Finite size: the plateau of every (k~, sigma~) against the brush size n_side.

Inputs are the per-k~ studies (:func:`.study.study`) of each brush size, read exactly as the
report reads one campaign: the plateau of a (k~, sigma~) and its seed interval (a bootstrap over
that brush size's seeds). Seeds of different brush sizes are different brushes, so each n_side
has its own bootstrap.

**Relative change** against the reference, the largest n_side of the grid:
rel = P(n) / P(n_ref) - 1. Its interval is the range the two seed intervals allow,
[lo(n) / hi(n_ref) - 1, hi(n) / lo(n_ref) - 1] (independent seeds: no joint resampling is
possible); undefined when either interval is unknown (one seed), unbounded above when the
reference interval reaches 0. The preset's discretisation bias is the same at every n_side
and cancels from the ratio to first order, so only the seed scatter enters. *Verdict*:
"within the seed scatter" when the interval holds 0, "differs" when it does not; a plateau
not reached is a lower bound, and the note says so. *Not resolved* instead of "within the
seed scatter" when the reference plateau's seed interval reaches the loss threshold
(``FEW_PILLARS`` pillars' pull-off of the reference brush, :mod:`.loss`): a ratio to a
plateau that may be the floor of a brush that lost adhesion spans decades (+438 % [-22,
+45 666] % on a 64 x 64 reference of 0.007 [0.0001, 0.015]), which is no agreement. An
interval that excludes 0 still "differs" (the smaller brush holds more than the reference
can).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from .reading import FEW_PILLARS

NAN2 = (math.nan, math.nan)
WITHIN, DIFFERS, REFERENCE, UNKNOWN = ("within the seed scatter", "differs", "reference",
                                       "no seed interval")
AT_FLOOR = "not resolved"


@dataclass
class SizeRow:
    """One (k~, sigma~) at one n_side: its plateau and its change against the reference."""

    k_tilde: float
    sigma_tilde: float
    n_side: int
    plateau: float
    plateau_ci: tuple
    state: str                      # the reading's plateau state ("reached", ...)
    n_seeds: int
    ref_n_side: int
    rel: float = math.nan           # P(n) / P(ref) - 1
    rel_ci: tuple = NAN2
    verdict: str = UNKNOWN
    notes: list = field(default_factory=list)


def _ratio_interval(ci, ref_ci) -> tuple:
    lo, hi = ci
    rlo, rhi = ref_ci
    if not all(math.isfinite(v) for v in (lo, hi, rlo, rhi)) or rhi <= 0:
        return NAN2
    # a reference interval reaching 0 leaves the ratio unbounded above, not unknown: its lower
    # end still says whether the smaller brush holds more than the reference can
    return lo / rhi - 1.0, (hi / rlo - 1.0 if rlo > 0 else math.inf)


def _threshold(st) -> float:
    """The reference brush's loss threshold (:attr:`.loss.Loss.threshold`); NaN if unknown."""
    thr = getattr(getattr(st, "loss", None), "threshold", math.nan)
    return float(thr) if thr is not None else math.nan


def size_rows(by_n: dict, ref_n_side: int | None = None) -> list:
    """``by_n``: {n_side: {k~: KStudy}} -> one :class:`SizeRow` per (k~, sigma~, n_side), k~
    descending, sigma~ and n_side ascending. ``ref_n_side``: the reference brush size (default,
    and for a k~ that did not run it: the largest size of that k~); a group without a plateau
    there has no relative change."""
    if not by_n:
        return []
    sizes_of: dict = {}
    for n, studies in by_n.items():
        for k in studies:
            sizes_of.setdefault(float(k), set()).add(int(n))
    groups: dict = {}
    for n, studies in by_n.items():
        for k, st in studies.items():
            for g in st.groups:
                groups.setdefault((float(k), float(g.sigma_tilde)), {})[int(n)] = g
    rows = []
    for (k, s) in sorted(groups, key=lambda ks: (-ks[0], ks[1])):
        per = groups[(k, s)]
        # a k~ that did not run the reference size (a merged file) is read against its own
        # largest size, not reported as having no plateau there
        ref = ref_n_side if ref_n_side in sizes_of[k] else max(sizes_of[k])
        g_ref = per.get(ref)
        for n in sorted(per):
            g = per[n]
            r = g.reading
            row = SizeRow(k, s, n, r.plateau, g.plateau_ci, r.plateau_state, g.n_seeds, ref)
            if r.plateau_state == "not reached":
                row.notes.append(f"plateau not reached at n_side = {n}: a lower bound")
            if n == ref:
                row.rel, row.rel_ci, row.verdict = 0.0, (0.0, 0.0), REFERENCE
                rows.append(row)
                continue
            pr = g_ref.reading.plateau if g_ref is not None else math.nan
            if not (math.isfinite(pr) and pr != 0 and math.isfinite(r.plateau)):
                row.notes.append(f"no plateau at the reference n_side = {ref}")
                rows.append(row)
                continue
            row.rel = r.plateau / pr - 1.0
            if g_ref.reading.plateau_state == "not reached":
                row.notes.append(f"plateau not reached at the reference n_side = {ref}")
            row.rel_ci = _ratio_interval(g.plateau_ci, g_ref.plateau_ci)
            if math.isfinite(row.rel_ci[0]):
                row.verdict = WITHIN if row.rel_ci[0] <= 0.0 <= row.rel_ci[1] else DIFFERS
            thr = _threshold(next((st for kk, st in by_n[ref].items() if float(kk) == k), None))
            if row.verdict == WITHIN and g_ref.plateau_ci[0] <= thr:
                row.verdict = AT_FLOOR
                row.notes.append(f"the n_side = {ref} plateau's seed interval reaches "
                                 f"{FEW_PILLARS:g} pillars' pull-off ({thr:.3g}): the change is not "
                                 "resolved against a plateau that may be that floor")
            rows.append(row)
    return rows


def reference_sizes(rows, n_sides) -> list:
    """The sorted reference sizes of ``rows`` (each k~'s largest n_side; a row without one takes
    the largest of ``n_sides``), or ``[largest]`` without rows ([None] without sizes)."""
    top = max(n_sides) if n_sides else None
    return sorted({getattr(r, "ref_n_side", None) or top for r in rows}) or [top]


__all__ = ["SizeRow", "size_rows", "reference_sizes", "WITHIN", "DIFFERS", "REFERENCE", "UNKNOWN",
           "AT_FLOOR"]
