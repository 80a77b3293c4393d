"""One (k~, sigma~) read from its points, without a law: its state, the plateau, c and c0.

Inputs are the done jobs of one (k~, sigma~): seed, requested preload, F~_P and F~_A per job,
and the *floor*: one pillar's pull-off force on the report's scale (:func:`pillar_floor`).

**Levels.** The jobs are grouped by requested preload; a level is one requested preload, with
the seed mean of F~_P and of F~_A, the seed standard deviation of F~_A and the seeds present.
A level whose every seed gave exactly the F~_P and F~_A of the next level (the first contact
overshoots a small preload: both were reached in the same event) is the same point and is
merged into it. A level holding fewer seeds than the group is flagged (``thin``): its mean is
over other seeds, not comparable with the others', so it is shown but not read (while at least
two full levels remain).

**Plateau** (the preload-insensitive F~_A). From the largest preload down, a level joins the
plateau set while its F~_A is not below the mean of the set by more than the *scatter
tolerance*: ``Z`` (2) standard errors of the difference of two seed means (sd / sqrt(seeds);
a level with one seed takes the group's pooled relative sd), and at least ``NUMERIC_RTOL``
(1 %) of the plateau (the solver's own noise; seeds equal to 1e-14 give zero scatter). With one
seed in the whole group there is no scatter: the tolerance is ``PATH_RTOL`` (3 %), the one
``F_P: auto`` uses on a single path. The plateau is the mean of the set's levels. It is
*reached* when the set holds at least two levels; otherwise F~_A still rises at the largest
preload ("plateau not reached": the value is F~_A there, a lower bound).

**Three states**, decided by the data and the floor, never by one label for two things:

* *adhesion lost*: the plateau is at most ``FEW_PILLARS`` (3) pillars' pull-off
  (``FEW_PILLARS * floor``): F~_A stays at the last few pillars' pull-off at every preload (it may
  creep from one pillar to two or three, but there is no linear stage: F~_A = c F~_P needs many
  pillars in contact). c = c0 = 0 by this threshold; where F~_A creeps, the secant through its
  half point (``c_res``) is how loosely that zero holds (lost groups stay out of the alpha/beta
  line: :mod:`.alphabeta`).
* *rise not resolved*: F~_A at the smallest preload reached is already at half the plateau or
  more (``F~_A,0 >= P/2``: every level in the plateau set is the extreme case) and above the
  few-pillar floor. The linear stage lies below the smallest preload, so c is only bounded:
  ``c >= F~_A,0 / F~_P,0`` (on a concave rise through the origin every secant at a smaller
  preload is steeper). The reading says which preload would resolve it, and whether the first
  contact overshot the smallest preload asked for (then no smaller preload is reachable on this
  scene: the brush saturates at first contact). c is out of the alpha/beta fit.
* *rise resolved*: the seed-mean curve crosses half the plateau above the smallest preload.

**c, eq. 15 of He, Li & Popov** (F~_A = c F~_P on the linear stage, no intercept): the slope
of the line through the origin and the point where the seed-mean curve first reaches half the
plateau, c = (P/2) / F~_P,1/2, with F~_P,1/2 interpolated linearly in F~_A against log F~_P
between the two levels around it (the preloads are spaced in log) (:func:`secant` at ``HALF``).
The rise is concave over decades, so "the linear stage" is a choice of secant; this one is not
the paper's own reading (its alpha is 2.9-3.4 times the paper's Table 1; a secant to 90 % of the
plateau comes near the paper's absolute alpha, which is calibration, not validation). Preloads
added below the rise do not move it (only the two levels around the half point do), and its
resolution is their spacing (``F_P: auto`` brackets the kink to a factor 2; the reading notes a
spacing above ``COARSE_RATIO``); ``c_res``, the difference to the same secant with the crossing
interpolated linearly in F~_P, measures it and enters the alpha/beta fit's errors beside the
seed scatter. Chosen over the alternatives on evidence, not on the paper's numbers
(benchmarks/c_definitions.py, benchmarks/paper_table.py; benchmarks/NOTES.md, "Which c" and
"c against the paper"): it does not move with preloads below the rise, moves least with a
sparser preload list among the readings the law fits, and c = alpha/sigma~ - beta fits it within
the seed scatter for every k~; the secants to 70 and 90 % of the plateau move more with the
preload spacing and the 90 % one fails the law for soft pillars. No reading is robust to loading
batches wider than the brush's length spread (records made before they were bounded): the page
names such groups (:mod:`..analysis.batching`).

Other readings, kept as named columns: ``c_stage``, the least-squares slope through the origin
sum(F~_P F~_A) / sum(F~_P^2) over the levels with F~_A between ``FEW_PILLARS`` pillars' pull-off
and P/2, less the *first-contact floor* (the smallest levels whose F~_A hardly changes to the
next one, within ``FLOOR_RATIO``); real rises are concave over decades, so it leans on the steep
first contacts and moves with the sampling inside the stage. ``c_chord``, the chord over the
first half of the rise from the smallest level, (F~_A,1/2 - F~_A,0) / (F~_P,1/2 - F~_P,0) with
F~_A,1/2 = F~_A,0 + (P - F~_A,0)/2 (log F~_P interpolation; the report's c before: it moves when
preloads are added below the rise); and **c0**, the first-contact slope: the geometric mean of
F~_A / F~_P over the levels in the first quarter of the rise (F~_A <= F~_A,0 + (P - F~_A,0)/4; at
least the smallest level), where a few pillars carry the whole pull-off; on the first-contact
floor it is a ratio that grows as the preload shrinks, and the reading says so.
"""

from __future__ import annotations

import dataclasses
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
#: the start of the note that c0 was read on the first-contact floor (a ratio, not a slope)
C0_ON_FLOOR = "c0 read on the first-contact floor"
#: the smallest level's F~_A at least this fraction of the next one's: the first-contact floor
FLOOR_RATIO = 0.95
#: a plateau of at most this many pillars' pull-off that does not rise: adhesion lost
FEW_PILLARS = 3.0
#: the states of a reading (:attr:`Reading.state`)
RESOLVED, UNRESOLVED, LOST, UNDETERMINED = ("rise resolved", "rise not resolved",
                                            "adhesion lost", "undetermined")
STATES = (RESOLVED, UNRESOLVED, LOST, UNDETERMINED)
#: a smallest reached F~_P above this multiple of the smallest requested preload: overshot
OVERSHOOT = 1.5
#: levels around the half point further apart than this: c is coarse (F_P: auto brackets 2)
COARSE_RATIO = 2.5


def pillar_floor(n_side: int, phi: float) -> float:
    """One flat pillar's pull-off on the report's scale: Kendall's force of a punch of radius
    a = a0 sqrt(phi) / n_side over F_c = sqrt(8 pi phi E* dgamma a0^3), that is
    phi^(1/4) / n_side^(3/2) (0.00828 for 18 x 18 pillars at phi = 0.16)."""
    return float(phi) ** 0.25 / float(n_side) ** 1.5


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

    def subset(self, keep) -> Levels:
        """The levels where ``keep`` is true (same order)."""
        keep = np.asarray(keep, dtype=bool)
        return Levels(*(getattr(self, f.name)[keep] for f in dataclasses.fields(self)))

    @property
    def thin(self) -> np.ndarray:
        """Levels holding fewer seeds than the most any level holds (mixed seed sets)."""
        return self.n < (self.n.max() if self.n.size else 0)


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


def read_levels(lv: Levels) -> Levels:
    """The levels a reading reads: ``lv`` without its thin levels, while at least two full
    levels remain (else all of them)."""
    return lv.subset(~lv.thin) if lv.thin.any() and int((~lv.thin).sum()) >= 2 else lv


def secant(lv: Levels, plateau: float, fraction: float = HALF) -> float:
    """The slope of the line through the origin and the point where the seed-mean curve first
    reaches ``fraction`` of ``plateau`` above the smallest level (F~_P interpolated linearly in
    F~_A against log F~_P): c at ``fraction`` = HALF, other fractions for studies
    (benchmarks/paper_table.py). NaN where the smallest level is already there or the curve
    never gets there."""
    y = fraction * plateau
    if not len(lv) or lv.F_A[0] >= y:
        return math.nan
    x, _ = _crossing(lv, y, log=True)
    return y / x if math.isfinite(x) and x > 0 else math.nan


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
    c: float                        # eq. 15: secant through the origin to half the plateau
    c0: float                       # first-contact slope (first quarter of the rise)
    F_P0: float                     # smallest F~_P (where the rise starts)
    F_A0: float
    F_P_half: float                 # where F~_A first reaches half the plateau
    c_detect: float                 # smallest c the scatter could tell from 0
    n_levels: int
    n_rise: int                     # levels below the plateau set
    top_lo: float                   # seed range of F~_A at the largest full level
    top_hi: float
    notes: list = field(default_factory=list)          # about the plateau (and the data)
    c_notes: list = field(default_factory=list)        # about c and c0
    state: str = UNDETERMINED       # one of STATES
    c_lower: float = math.nan       # rise not resolved: c >= c_lower
    c_stage: float = math.nan       # least-squares slope through the origin over the stage
    c_res: float = math.nan         # c's interpolation resolution (log against linear in F~_P)
    c_chord: float = math.nan       # chord over the first half of the rise from the smallest level
    n_stage: int = 0                # levels on the linear stage (besides the half point)
    floor: float = math.nan         # one pillar's pull-off (the scale of "adhesion lost")
    resolve_below: float = math.nan  # rise not resolved: preloads needed at or below this
    seeds: tuple = ()               # seeds per level, ascending F~_P
    n_seeds: int = 0                # seeds in the group

    @property
    def rises(self) -> bool:
        """F~_A rises with preload and c is measured (the rise is resolved)."""
        return self.state == RESOLVED


def _tolerances(lv: Levels, n_seeds: int):
    """Per level: the standard error of its seed mean (pooled relative sd for one seed)."""
    if n_seeds < 2:
        return None
    rel = [s / abs(m) for s, m, k in zip(lv.sd, lv.F_A, lv.n) if k > 1 and m != 0]
    pooled = math.sqrt(float(np.mean(np.square(rel)))) if rel else 0.0
    sd = np.where(lv.n > 1, np.nan_to_num(lv.sd), pooled * np.abs(lv.F_A))
    return sd / np.sqrt(np.maximum(lv.n, 1))


def plateau_set(lv: Levels, n_seeds: int) -> int:
    """Index of the smallest level of the plateau set (the set is that level and all above).

    The set starts at the largest level holding the group's full seed set (a thin level above
    it, one seed's extra preload, joins only if it is not below the set)."""
    n = len(lv)
    se = _tolerances(lv, n_seeds)
    full = np.flatnonzero(~lv.thin)
    top = int(full[-1]) if full.size else n - 1
    start = top
    for i in range(top - 1, -1, -1):
        members = np.arange(start, top + 1)
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


def _crossing(lv: Levels, target: float, log: bool = True) -> tuple[float, int]:
    """First F~_P where the seed-mean curve reaches ``target`` above the smallest level, and the
    level at or above it; interpolated linearly in F~_A against log F~_P (``log``) or against
    F~_P (the linear stage: exact on a straight line); NaN if it never does."""
    for i in range(1, len(lv)):
        if lv.F_A[i] >= target:
            y0, y1 = lv.F_A[i - 1], lv.F_A[i]
            x0, x1 = lv.F_P[i - 1], lv.F_P[i]
            t = 0.0 if y1 == y0 else (target - y0) / (y1 - y0)
            if log and x0 > 0 and x1 > 0:
                return float(math.exp(math.log(x0) + t * math.log(x1 / x0))), i
            return float(x0 + t * (x1 - x0)), i
    return math.nan, len(lv)


def _floor_levels(lv: Levels, s: int) -> int:
    """How many of the smallest levels lie on the first-contact floor (F~_A hardly changes to
    the next level) below the plateau set's index ``s``."""
    i = 0
    while i + 1 < s and lv.F_A[i] >= FLOOR_RATIO * lv.F_A[i + 1]:
        i += 1
    return i


def _c0(lv: Levels, P: float) -> float:
    y0 = lv.F_A[0]
    quarter = y0 + QUARTER * (P - y0)
    first = [0]
    while first[-1] + 1 < len(lv) and lv.F_A[first[-1] + 1] <= quarter:
        first.append(first[-1] + 1)
    first = [i for i in first if lv.F_A[i] > 0 and lv.F_P[i] > 0]
    return float(np.exp(np.mean([math.log(lv.F_A[i] / lv.F_P[i]) for i in first]))) if first \
        else math.nan


def read_group(seed, preload, F_P, F_A, half: float = HALF, floor: float = math.nan) -> Reading:
    """The state, plateau, c and c0 of one (k~, sigma~) from its done jobs (one entry per job).

    ``floor``: one pillar's pull-off on the report's scale (:func:`pillar_floor`); without it
    (NaN) a group that does not rise cannot be told lost from unresolved and is *undetermined*.
    ``half``: the fraction of the rise of the chord ``c_chord`` (other values for studies)."""
    lv = levels(seed, preload, F_P, F_A)
    n_seeds = int(np.unique(np.asarray(seed)).size)
    nan = math.nan
    if len(lv) == 0:
        return Reading(nan, "no data", nan, 0, nan, nan, nan, nan, nan, nan, 0, 0, nan, nan,
                       ["no finite F~_P, F~_A"], floor=floor, n_seeds=n_seeds)
    notes: list = []
    c_notes: list = []
    seeds = tuple(int(v) for v in lv.n)
    thin = [i for i in range(len(lv)) if lv.thin[i]]
    if thin:
        notes.append(f"{len(thin)} level(s) with fewer seeds than the group's {int(lv.n.max())} "
                     "(F~_P = " + ", ".join(f"{lv.F_P[i]:.3g}: {lv.n[i]}" for i in thin)
                     + "): shown, not read (a seed mean over other seeds is not comparable)")
    lv = read_levels(lv)
    s = plateau_set(lv, n_seeds)
    full = np.flatnonzero(~lv.thin)
    top = int(full[-1]) if full.size else len(lv) - 1
    members = np.arange(s, top + 1)
    P = float(np.mean(lv.F_A[members]))
    top_lo, top_hi = float(lv.lo[top]), float(lv.hi[top])
    x0, y0 = float(lv.F_P[0]), float(lv.F_A[0])
    base = dict(floor=floor, seeds=seeds, n_seeds=n_seeds)
    if len(lv) == 1:
        why = ["one preload level: no rise or plateau can be read"]
        return Reading(P, "not reached", x0, 1, nan, nan, x0, y0, nan, nan, 1, 0, top_lo,
                       top_hi, why, list(why), **base)
    if s == 0:
        plateau_state = "no rise"
        notes.append(f"F~_A does not rise with preload over F~_P = {x0:.3g} .. "
                     f"{lv.F_P[top]:.3g} (within the seed scatter)")
    elif members.size >= 2:
        plateau_state = "reached"
    else:
        plateau_state = "not reached"
        notes.append(f"plateau not reached: F~_A still rises from {lv.F_A[top - 1]:.3g} at "
                     f"F~_P = {lv.F_P[top - 1]:.3g} to {lv.F_A[top]:.3g} at {lv.F_P[top]:.3g}; "
                     "the plateau is a lower bound and c is provisional")
        c_notes.append(notes[-1])
    # the smallest c the scatter can tell from 0: a rise of one tolerance over the preloads run
    rtol = PATH_RTOL if n_seeds < 2 else NUMERIC_RTOL
    spread = float(np.nanmax(lv.hi - lv.lo)) if n_seeds > 1 else 0.0
    span = float(lv.F_P[-1] - x0)
    c_detect = max(spread, rtol * abs(P)) / span if span > 0 else nan
    few = FEW_PILLARS * floor
    asked = np.asarray(preload, dtype=float)
    asked = float(np.min(asked[np.isfinite(asked)])) if np.isfinite(asked).any() else nan
    overshot = asked > 0 and x0 > OVERSHOOT * asked         # merged levels keep the larger
    if math.isfinite(floor) and P <= few:
        # c = 0 by the threshold; the secant the few pillars draw is how uncertain that zero is
        xw, _ = _crossing(lv, 0.5 * P) if y0 < 0.5 * P else (x0, 0)
        c_would = 0.5 * P / xw if math.isfinite(xw) and xw > 0 else nan
        notes.append(f"adhesion lost: plateau F~_A = {P:.3g}, within {FEW_PILLARS:g} pillars' "
                     f"pull-off ({few:.3g}; one pillar: {floor:.3g})"
                     + (f"; it creeps from {y0:.3g} (a secant of {c_would:.3g} through its half "
                        "point: how loosely its c = 0 holds)" if y0 < 0.5 * P else ""))
        return Reading(P, plateau_state, x0, int(members.size), 0.0, 0.0, x0, y0, nan, c_detect,
                       len(lv), 0, top_lo, top_hi, notes, list(notes), state=LOST, c_stage=0.0,
                       c_chord=0.0, c_res=c_would if y0 < 0.5 * P else nan, **base)
    y_half = 0.5 * P
    if y0 >= y_half or s == 0:
        c_lower = y0 / x0 if x0 > 0 else nan
        if s == 0 and not math.isfinite(floor):
            state = UNDETERMINED
            c_notes.append("F~_A does not rise and no pillar floor was given: adhesion lost "
                           "and a rise below the smallest preload cannot be told apart")
        else:
            state = UNRESOLVED
            where = (f"the first contact overshot the smallest preload asked for "
                     f"({asked:.3g}) to F~_P = {x0:.3g}: the brush saturates "
                     "at first contact, no smaller preload is reachable on this scene"
                     if overshot else
                     f"preloads at or below {0.1 * x0:.3g} (a tenth of the smallest reached) "
                     "would resolve it")
            c_notes.append(f"rise not resolved: F~_A = {y0:.3g} at the smallest preload "
                           f"F~_P = {x0:.3g} is already {y0 / P:.0%} of the plateau {P:.3g}; "
                           f"c >= {c_lower:.3g} (a lower bound, out of the fit); {where}")
        c0 = _c0(lv, P)
        return Reading(P, plateau_state, float(lv.F_P[s]), int(members.size), nan, c0, x0, y0,
                       nan, c_detect, len(lv), int(s), top_lo, top_hi, notes, c_notes,
                       state=state, c_lower=c_lower,
                       resolve_below=nan if overshot else 0.1 * x0, **base)
    # the rise is resolved: the seed-mean curve crosses P/2 above the smallest level
    xh, ih = _crossing(lv, y_half, log=True)
    nf = _floor_levels(lv, s)
    few_ = few if math.isfinite(few) else 0.0
    stage = [i for i in range(nf, ih)
             if few_ < lv.F_A[i] <= y_half and lv.F_P[i] > 0]
    c = secant(lv, P, HALF)
    # the half point's resolution: the crossing interpolated linearly in F~_P instead of log
    xl, _ = _crossing(lv, y_half, log=False)
    c_res = abs(c - y_half / xl) if math.isfinite(c) and math.isfinite(xl) and xl > 0 else nan
    if stage:
        xs, ys = lv.F_P[stage], lv.F_A[stage]
        c_stage = float(np.sum(xs * ys) / np.sum(xs * xs))
    else:
        c_stage = nan
    yc = y0 + half * (P - y0)
    xc, _ = _crossing(lv, yc)
    c_chord = (yc - y0) / (xc - x0) if math.isfinite(xc) and xc > x0 else nan
    c0 = _c0(lv, P)
    if not math.isfinite(c0):
        c_notes.append("c0 undefined: F~_A or F~_P <= 0 at the smallest preload")
    elif lv.F_A[0] >= FLOOR_RATIO * lv.F_A[1]:
        c_notes.append(C0_ON_FLOOR + " (F~_A hardly changes between the two smallest "
                       "preloads): a ratio F~_A/F~_P that grows as the preload shrinks")
    lo_x, hi_x = float(lv.F_P[max(ih - 1, 0)]), float(lv.F_P[min(ih, len(lv) - 1)])
    if lo_x > 0 and hi_x / lo_x > COARSE_RATIO:
        c_notes.append(f"the half point lies between preloads {lo_x:.3g} and {hi_x:.3g} "
                       f"(x {hi_x / lo_x:.2g} apart): c is resolved to that factor at worst; "
                       "preloads between them would refine it")
    return Reading(P, plateau_state, float(lv.F_P[s]), int(members.size), c, c0, x0, y0, xh,
                   c_detect, len(lv), int(s), top_lo, top_hi, notes, c_notes, state=RESOLVED,
                   c_stage=c_stage, c_chord=float(c_chord), n_stage=len(stage), c_res=c_res,
                   **base)


def path_plateau_reached(F_P, F_A, rtol: float = PATH_RTOL) -> bool:
    """One loading path (one seed): F~_A at its largest preload within ``rtol`` of the level
    below it (or above it): the plateau is reached. Fewer than two points: False."""
    pts = sorted((float(x), float(y)) for x, y in zip(F_P, F_A)
                 if math.isfinite(x) and math.isfinite(y))
    if len(pts) < 2:
        return False
    (_, y1), (_, y2) = pts[-2], pts[-1]
    return y2 <= y1 + rtol * abs(y2)
