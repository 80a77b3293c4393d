"""How well one (k~, sigma~) is known from its seeds, and how many seeds would do (``seeds: auto``).

A group's numbers are read as the report reads them (:func:`.reading.read_group`), and their
seed intervals come from a bootstrap over the group's seeds, widened for the number of seeds
(:func:`.intervals.expanded`), as the report's. What must be known depends on the state:

* *rise resolved*: the plateau and c, each within ``width`` (the interval's full width over the
  value: 0.2 is about +-10 %);
* *rise not resolved*: the plateau within ``width`` (c is only a lower bound: more seeds do not
  resolve a rise, smaller preloads do);
* *adhesion lost*: whether it is lost. The plateau's interval must lie below the loss threshold
  (``FEW_PILLARS`` pillars' pull-off): a lost group's plateau is one or two pillars, whose relative
  scatter no number of seeds makes small, and the question it answers is the state;
* a rising group whose plateau interval reaches down to the threshold is not yet told from a lost
  one either: it needs seeds until the interval clears the threshold, besides the widths;
* *undetermined*: nothing to judge (no floor, or too few levels): never more seeds.

:func:`seeds_needed` predicts how many seeds would meet the target from the widths now: an
interval's width falls as f(n)/sqrt(n) with f the small-sample factor
(:func:`.intervals.small_sample_factor`), so the smallest n' with
w (f(n')/f(n)) sqrt(n/n') <= width, at least one more seed, at most ``max``. The answer is a
function of the group's records only (a fixed bootstrap seed), so a resumed campaign makes the
same choices.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .intervals import expanded, percentile_interval, seed_replicates, small_sample_factor
from .reading import FEW_PILLARS, LOST, RESOLVED, UNDETERMINED, UNRESOLVED, read_group

#: bootstrap resamples per group (the planner reads every finished group once per decision)
N_BOOT = 200
NAN2 = (math.nan, math.nan)


@dataclass
class Precision:
    """One group's state, plateau and c with their seed intervals, and what is short."""

    state: str
    n_seeds: int
    plateau: float
    plateau_ci: tuple
    c: float
    c_ci: tuple
    threshold: float                 # the loss threshold (FEW_PILLARS pillars' pull-off)
    short: tuple = ()                # what misses the target: "plateau", "c", "state"
    widths: tuple = ()               # the relative widths that decide (of ``short`` first)

    @property
    def met(self) -> bool:
        """Nothing is short: the seeds are enough."""
        return not self.short


def relative_width(value: float, ci: tuple) -> float:
    """Full width of ``ci`` over ``|value|``; inf where either is undefined or the value is 0."""
    lo, hi = ci
    if not (math.isfinite(value) and math.isfinite(lo) and math.isfinite(hi)) or value == 0:
        return math.inf
    return (hi - lo) / abs(value)


def group_precision(seed, preload, F_P, F_A, floor: float, width: float,
                    n_boot: int = N_BOOT, rng_seed: int = 0) -> Precision:
    """The :class:`Precision` of one group from its done jobs (one entry per job), against the
    relative ``width``; ``floor``: one pillar's pull-off (:func:`.reading.pillar_floor`)."""
    seed = np.asarray(seed)
    pts = (seed, np.asarray(preload, float), np.asarray(F_P, float), np.asarray(F_A, float))
    r = read_group(*pts, floor=floor)
    labels = sorted(set(seed.tolist()))
    n = len(labels)
    thr = FEW_PILLARS * floor if math.isfinite(floor) else math.nan

    def stat(picked):
        idx = [np.flatnonzero(seed == lab) for lab in picked]
        new_seed = np.concatenate([np.full(i.size, j) for j, i in enumerate(idx)])
        sel = np.concatenate(idx)
        rr = read_group(new_seed, pts[1][sel], pts[2][sel], pts[3][sel], floor=floor)
        return [rr.plateau, rr.c]

    reps = seed_replicates(labels, stat, n_boot, rng_seed)
    if reps is None:
        p_ci, c_ci = NAN2, NAN2
    else:
        p_ci = expanded(r.plateau, percentile_interval(reps[0]), n)
        c_ci = expanded(r.c, percentile_interval(reps[1]), n)
    out = Precision(r.state, n, r.plateau, p_ci, r.c, c_ci, thr)
    if r.state == UNDETERMINED:
        return out
    short, widths = [], []
    if r.state == LOST:
        if not (math.isfinite(p_ci[1]) and p_ci[1] <= thr):
            short.append("state")
            widths.append(math.inf)
    else:
        wp = relative_width(r.plateau, p_ci)
        if wp > width:
            short.append("plateau")
            widths.append(wp)
        if r.state == RESOLVED:
            wc = relative_width(r.c, c_ci)
            if wc > width:
                short.append("c")
                widths.append(wc)
        if r.state in (RESOLVED, UNRESOLVED) and math.isfinite(thr) and \
                not (math.isfinite(p_ci[0]) and p_ci[0] > thr):
            short.append("state")
            widths.append(math.inf)
    out.short, out.widths = tuple(short), tuple(widths)
    return out


def seeds_needed(prec: Precision, width: float, max_seeds: int) -> int:
    """How many seeds the group should have (module text): its count when the target is met,
    else the predicted count, at least one more, at most ``max_seeds``."""
    n = prec.n_seeds
    if prec.met or n >= max_seeds:
        return n
    w = max(prec.widths)
    if not math.isfinite(w) or n < 2:
        return min(max(2 * n, n + 1), max_seeds)   # no width to scale: double
    f_n = small_sample_factor(n)
    for m in range(n + 1, max_seeds + 1):
        if w * small_sample_factor(m) / f_n * math.sqrt(n / m) <= width:
            return m
    return max_seeds


__all__ = ["Precision", "group_precision", "seeds_needed", "relative_width", "N_BOOT"]
