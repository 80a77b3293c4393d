"""One (k~, sigma~) read from its points, without a law: the plateau, c0 and c.

Inputs are the done jobs of one (k~, sigma~): seed, requested preload, F~_P and F~_A per job.

**Levels.** The jobs are grouped by requested preload; a level is one requested preload, with
the seed mean of F~_P and of F~_A, the seed standard deviation of F~_A and the seeds present.
A level whose every seed gave exactly the F~_P and F~_A of the next level (the first contact
overshoots a small preload: both were reached in the same event) is the same point and is
merged into it.

**Plateau** (the preload-insensitive F~_A). From the largest preload down, a level joins the
plateau set while its F~_A is not below the mean of the set by more than the *scatter
tolerance*: ``Z`` (2) standard errors of the difference of two seed means (sd / sqrt(seeds);
a level with one seed takes the group's pooled relative sd), and at least ``NUMERIC_RTOL``
(1 %) of the plateau (the solver's own noise; seeds equal to 1e-14 give zero scatter). With one
seed in the whole group there is no scatter: the tolerance is ``PATH_RTOL`` (3 %), the one
``F_P: auto`` uses on a single path. The plateau is the mean of the set's levels. It is
*reached* when the set holds at least two levels; otherwise F~_A still rises at the largest
preload ("plateau not reached": the value is F~_A there, a lower bound).

**No rise.** When every level is in the plateau set, F~_A does not rise with preload over the
preloads run (a rough, stiff brush: the last pillar's pull-off at every preload): both
coefficients are a measured 0 (adhesion lost), not a missing value.

**The rise** runs from F~_A,0 (the smallest level) to the plateau P.

* **c** (the adhesion coefficient of He, Li & Popov, on the plateau's scale): the chord slope
  over the first half of the rise, c = (F~_A,1/2 - F~_A,0) / (F~_P,1/2 - F~_P,0), where
  F~_A,1/2 = F~_A,0 + (P - F~_A,0)/2 and F~_P,1/2 is where the seed-mean curve first reaches it
  (interpolated linearly in F~_A against log F~_P between the two levels around it: the preloads
  are spaced in log). It is the slope a reader sees on the paper's linear axes, and it falls to
  0 with the rise itself.
* **c0** (the first-contact slope): the geometric mean of F~_A / F~_P over the levels in the
  first quarter of the rise (F~_A <= F~_A,0 + (P - F~_A,0)/4; at least the smallest level),
  where a few pillars carry the whole pull-off. It depends on how small the smallest preload is
  (the report gives that preload beside it); where the two smallest preloads give nearly the same
  F~_A (the *first-contact floor*: one pillar's pull-off) it is a ratio, not a slope, and the
  reading says so.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

#: standard errors of a difference of seed means that still count as "not rising"
Z = 2.0
#: the smallest tolerance, relative to the plateau (above the solver's noise, < 0.3 % for fast)
NUMERIC_RTOL = 0.01
#: tolerance with a single seed (no scatter to measure), relative; also ``F_P: auto``'s per path
PATH_RTOL = 0.03
#: fractions of the rise that define c (its first half) and c0 (its first quarter)
HALF, QUARTER = 0.5, 0.25
#: the smallest level's F~_A at least this fraction of the next one's: the first-contact floor
FLOOR_RATIO = 0.95


@dataclass
class Levels:
    """Preload levels of one (k~, sigma~), ascending in F~_P."""

    preload: np.ndarray             # requested preload
    F_P: np.ndarray                 # seed mean of F~_P
    F_A: np.ndarray                 # seed mean of F~_A
    sd: np.ndarray                  # seed sd of F~_A (NaN with one seed)
    n: np.ndarray                   # seeds at the level
    lo: np.ndarray                  # smallest F~_A over seeds
    hi: np.ndarray                  # largest F~_A over seeds

    def __len__(self):
        return int(self.F_P.size)


def levels(seed, preload, F_P, F_A) -> Levels:
    """Group finite points by requested preload (seed statistics), merging repeated points.

    A point repeated with the same (preload, seed, F~_P, F~_A) counts once; two points of one
    (preload, seed) with different numbers are points of different scenes (e.g. two variants
    of a swept field) and raise a ``ValueError`` naming them, never one silently replacing the
    other."""
    seed = np.asarray(seed)
    pre = np.asarray(preload, dtype=float)
    x = np.asarray(F_P, dtype=float)
    y = np.asarray(F_A, dtype=float)
    ok = np.isfinite(pre) & np.isfinite(x) & np.isfinite(y)
    seed, pre, x, y = seed[ok], pre[ok], x[ok], y[ok]
    ps = np.unique(pre)
    per = [_by_seed(p, seed[pre == p], x[pre == p], y[pre == p]) for p in ps]
    keep = []
    for i in range(len(ps)):
        nxt = per[i + 1] if i + 1 < len(ps) else None
        same = nxt is not None and set(per[i]) == set(nxt) and all(
            per[i][s] == nxt[s] for s in per[i])
        if not same:
            keep.append(i)
    rows = []
    for i in keep:
        v = np.array(list(per[i].values()))
        fa = v[:, 1]
        rows.append((ps[i], v[:, 0].mean(), fa.mean(), fa.std(ddof=1) if fa.size > 1 else math.nan,
                     fa.size, fa.min(), fa.max()))
    rows.sort(key=lambda r: (r[1], r[0]))
    cols = list(zip(*rows)) if rows else [()] * 7
    return Levels(*(np.asarray(c, dtype=float) for c in cols[:4]),
                  np.asarray(cols[4], dtype=int), *(np.asarray(c, dtype=float) for c in cols[5:]))


def _by_seed(p, seeds, xs, ys) -> dict:
    """{seed: (F~_P, F~_A)} of the points of one preload ``p``; a seed twice with different
    numbers is a ``ValueError``."""
    out: dict = {}
    for s, xx, yy in zip(seeds, xs, ys):
        pt = (float(xx), float(yy))
        if out.setdefault(s, pt) != pt:
            raise ValueError(f"two points at preload {p:g}, seed {s} with different (F~_P, F~_A):"
                             f" ({out[s][0]:.6g}, {out[s][1]:.6g}) and ({pt[0]:.6g}, "
                             f"{pt[1]:.6g}): points of different scenes in one group")
    return out


@dataclass
class Reading:
    """What one (k~, sigma~) says without a law (see the module text for the definitions)."""

    plateau: float
    plateau_state: str              # "reached", "not reached", "no rise" or "no data"
    plateau_from: float             # smallest F~_P of the plateau set
    n_plateau: int                  # levels in the plateau set
    c: float                        # adhesion coefficient (chord over the first half of the rise)
    c0: float                       # first-contact slope (first quarter of the rise)
    F_P0: float                     # smallest F~_P (where the rise starts)
    F_A0: float
    F_P_half: float                 # where F~_A first reaches half the rise
    c_detect: float                 # smallest c the scatter could tell from 0
    n_levels: int
    n_rise: int                     # levels below the plateau set
    top_lo: float                   # seed range of F~_A at the largest preload
    top_hi: float
    notes: list = field(default_factory=list)          # about the plateau (and the data)
    c_notes: list = field(default_factory=list)        # about c and c0

    @property
    def rises(self) -> bool:
        """F~_A rises with preload (c and c0 are measured, not 0)."""
        return self.plateau_state in ("reached", "not reached")


def _tolerances(lv: Levels, n_seeds: int):
    """Per level: the standard error of its seed mean (pooled relative sd for one seed)."""
    if n_seeds < 2:
        return None
    rel = [s / abs(m) for s, m, k in zip(lv.sd, lv.F_A, lv.n) if k > 1 and m != 0]
    pooled = math.sqrt(float(np.mean(np.square(rel)))) if rel else 0.0
    sd = np.where(lv.n > 1, np.nan_to_num(lv.sd), pooled * np.abs(lv.F_A))
    return sd / np.sqrt(np.maximum(lv.n, 1))


def plateau_set(lv: Levels, n_seeds: int) -> int:
    """Index of the smallest level of the plateau set (the set is that level and all above)."""
    n = len(lv)
    se = _tolerances(lv, n_seeds)
    top = n - 1
    start = top
    for i in range(top - 1, -1, -1):
        members = np.arange(start, n)
        P = float(np.mean(lv.F_A[members]))
        if se is None:
            tol = PATH_RTOL * abs(P)
        else:
            se_set = math.sqrt(float(np.sum(se[members] ** 2))) / members.size
            tol = max(Z * math.hypot(se[i], se_set), NUMERIC_RTOL * abs(P))
        if lv.F_A[i] < P - tol:
            break
        start = i
    return start


def _crossing(lv: Levels, target: float) -> tuple[float, int]:
    """First F~_P where the seed-mean curve reaches ``target`` (log F~_P interpolation)."""
    for i in range(1, len(lv)):
        if lv.F_A[i] >= target:
            y0, y1 = lv.F_A[i - 1], lv.F_A[i]
            x0, x1 = lv.F_P[i - 1], lv.F_P[i]
            t = 0.0 if y1 == y0 else (target - y0) / (y1 - y0)
            if x0 > 0 and x1 > 0:
                return float(math.exp(math.log(x0) + t * math.log(x1 / x0))), i
            return float(x0 + t * (x1 - x0)), i
    return math.nan, len(lv)


def read_group(seed, preload, F_P, F_A, half: float = HALF) -> Reading:
    """The plateau, c and c0 of one (k~, sigma~) from its done jobs (one entry per job); ``half``:
    the fraction of the rise whose chord is c (the report's 1/2; other values for studies)."""
    lv = levels(seed, preload, F_P, F_A)
    n_seeds = int(np.unique(np.asarray(seed)).size)
    nan = math.nan
    if len(lv) == 0:
        return Reading(nan, "no data", nan, 0, nan, nan, nan, nan, nan, nan, 0, 0, nan, nan,
                       ["no finite F~_P, F~_A"])
    notes = []
    s = plateau_set(lv, n_seeds)
    members = np.arange(s, len(lv))
    P = float(np.mean(lv.F_A[members]))
    top_lo, top_hi = float(lv.lo[-1]), float(lv.hi[-1])
    x0, y0 = float(lv.F_P[0]), float(lv.F_A[0])
    if len(lv) == 1:
        why = ["one preload level: no rise or plateau can be read"]
        return Reading(P, "not reached", x0, 1, nan, nan, x0, y0, nan, nan, 1, 0, top_lo,
                       top_hi, why, list(why))
    if s == 0:
        state = "no rise"
        notes.append(f"F~_A does not rise with preload over F~_P = {x0:.3g} .. "
                     f"{lv.F_P[-1]:.3g} (within the seed scatter): c = c0 = 0, adhesion lost")
    elif members.size >= 2:
        state = "reached"
    else:
        state = "not reached"
        notes.append(f"plateau not reached: F~_A still rises from {lv.F_A[-2]:.3g} at "
                     f"F~_P = {lv.F_P[-2]:.3g} to {lv.F_A[-1]:.3g} at {lv.F_P[-1]:.3g}; the "
                     "plateau is a lower bound and c is provisional")
    # the smallest c the scatter can tell from 0: a rise of one tolerance over the preloads run
    rtol = PATH_RTOL if n_seeds < 2 else NUMERIC_RTOL
    spread = float(np.nanmax(lv.hi - lv.lo)) if n_seeds > 1 else 0.0
    span = float(lv.F_P[-1] - x0)
    c_detect = max(spread, rtol * abs(P)) / span if span > 0 else nan
    if state == "no rise":
        return Reading(P, state, float(lv.F_P[0]), int(members.size), 0.0, 0.0, x0, y0, nan,
                       c_detect, len(lv), 0, top_lo, top_hi, notes, list(notes))
    c_notes = [n for n in notes if n.startswith("plateau not reached")]
    y_half = y0 + half * (P - y0)
    xh, _ = _crossing(lv, y_half)
    c = (y_half - y0) / (xh - x0) if math.isfinite(xh) and xh > x0 else nan
    quarter = y0 + QUARTER * (P - y0)
    first = [0]
    while first[-1] + 1 < len(lv) and lv.F_A[first[-1] + 1] <= quarter:
        first.append(first[-1] + 1)
    first = [i for i in first if lv.F_A[i] > 0 and lv.F_P[i] > 0]
    c0 = float(np.exp(np.mean([math.log(lv.F_A[i] / lv.F_P[i]) for i in first]))) if first \
        else nan
    if not math.isfinite(c0):
        c_notes.append("c0 undefined: F~_A or F~_P <= 0 at the smallest preload")
    elif lv.F_A[0] >= FLOOR_RATIO * lv.F_A[1]:
        c_notes.append("c0 read on the first-contact floor (F~_A hardly changes between the two "
                     "smallest preloads): a ratio F~_A/F~_P that grows as the preload shrinks")
    if s < 2:
        c_notes.append(f"the rise is sampled by {s + 1} level(s) below the plateau: c is a chord "
                     "between them, coarse")
    return Reading(P, state, float(lv.F_P[s]), int(members.size), float(c), c0, x0, y0, xh,
                   c_detect, len(lv), int(s), top_lo, top_hi, notes, c_notes)


def path_plateau_reached(F_P, F_A, rtol: float = PATH_RTOL) -> bool:
    """One loading path (one seed): F~_A at its largest preload within ``rtol`` of the level
    below it (or above it): the plateau is reached. Fewer than two points: False."""
    pts = sorted((float(x), float(y)) for x, y in zip(F_P, F_A)
                 if math.isfinite(x) and math.isfinite(y))
    if len(pts) < 2:
        return False
    (_, y1), (_, y2) = pts[-2], pts[-1]
    return y2 <= y1 + rtol * abs(y2)
