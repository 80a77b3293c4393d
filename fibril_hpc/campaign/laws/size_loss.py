"""Where adhesion is lost, read across brush sizes: the few-pillar crossing of each size and an
intensive (size-independent) estimate, for one k~ of a grid that sweeps ``n_side``.

Inputs: per n_side, the done points of each sigma~ ({n_side: {sigma~: (seed, preload, F~_P,
F~_A)}}), the nominal filling ratio phi. Every plateau is the report's reading
(:func:`.reading.read_group`, with the size's own pillar floor). Returns numbers and states; the
page writes the words (:mod:`..analysis.size_loss_page`).

**Seeds.** Within one size a seed is the same height pattern at every sigma~, so a bootstrap
replicate resamples that size's seed labels once and reads every sigma~ of the size on the same
labels (paired). Different sizes are different brushes: each size is resampled on its own
(independent draws). A group that lacks a picked label takes the picked labels it holds.
Intervals are percentile intervals of the replicates widened about the value for the smallest
seed count involved (:func:`.intervals.expanded`).

**Few-pillar crossing** (per size): the sigma~ where the seed-mean plateau first falls to
``FEW_PILLARS`` pillars' pull-off, FEW_PILLARS phi^(1/4) N^(-3/4) (N = n_side^2 pillars), after a
sigma~ above it, interpolated log-log between the two sigma~ around it (:func:`.loss.first_fall`);
its replicates are read the same way over every sigma~ (0 or inf where one does not cross inside
the sigma~ run). This is the report's measured sigma~_c of that size; at the size the report's
other tables read, the page gives that measurement itself (:func:`adopt_measured`: the same
number, the interval of its bracket's replicates). Its threshold is a pillar *count*, so it
moves with N.

**Per-area crossing** (per size): the same crossing of a fixed threshold ``area_threshold`` in
F~ units (the plateau is F_A / F_c with F_c the Kendall force of a punch of the whole brush's
area: at the paper's fixed brush side L it is a pull-off *stress*, so a fixed F~ is a fixed
stress). ``below_floor`` marks a size whose few-pillar threshold is at or above it (the
crossing there is a pillar count, not a stress). :attr:`SizeLoss.area_trend` compares the two
largest sizes: STEADY when their intervals overlap, DRIFTS when they do not.

**Drift of a crossing with N** (:class:`Drift`, per threshold): q = d ln sigma~ / d ln N, the
least-squares slope of ln sigma~ against ln N over the sizes where that crossing is bracketed
(at least two; for the per-area threshold, not ``below_floor``); its interval from the same
replicates (each size's own, so a replicate's slope pairs independent draws; a replicate that
does not cross at one size gives an infinite slope of the sign that size's weight has). Three
limits are told apart (:data:`LIMITS`): a loss at a fixed sigma~ of the paper's variables has
q = 0; one at a fixed pillar-scale roughness sigma / d_c1 = sigma~ (phi N)^(1/4) has
q = -1/4; one at a fixed spring force at the roughness against one pillar's pull-off,
k sigma / F_c1 = (k / (E* D)) (sigma / d_c1) (E* D d_c1 = F_c1 for a flat punch), which grows
as k~ sigma~ N^(3/4), has q = -3/4. The state names every limit whose q lies in the interval
(joined by " or "), NEITHER when none does, NOT_MEASURED with fewer than two bracketed sizes
or no interval. Over close sizes a crossing that converges from above to a fixed sigma~ still
has q < 0: the state reads the sizes run, not the limit.

**Extrapolation in N** (per sigma~ run at every size of at least ``MIN_SIZES``): the weighted
least-squares line P(N) = P_inf + A N^(-p) with p = 3/4 (a fixed number of pillars' pull-off
scales as N^(-3/4)), weights 1 / (seed sd of the plateau)^2 at each size (floored at
``SD_FLOOR`` of the plateau). P_inf's interval: the replicates refitted with the same weights.
State HOLDS when its interval lies above 0, GONE when it reaches 0, BELOW when it lies wholly
below 0 (a plateau is never negative: the line overshoots, the plateau falls faster than
N^(-3/4) there, and like REJECTED it reads no limit), UNKNOWN without an interval, REJECTED when
the line, weighted by seed variances (not one seed or no resamples), does not fit: chi^2 / dof
above ``POOR_CHI2`` (four seeds: a residual over its sd is a t of 3 dof, t^2 = 30 leaves ~1 %;
synthetic losses at a fixed sigma~ stay below 21, at a fixed sigma / d_c1 give 60-2 400 over
16-64).
**p measured**: one fit of every sigma~ whose groups hold adhesion at every size
(rise resolved or not resolved; a lost group's plateau is a few pillars, N^(-3/4) by
construction) with its own P_inf and A and one shared p (``scipy.optimize.least_squares``),
replicates refitted; its state is CONSISTENT when 3/4 lies in p's interval, DIFFERS when not,
NOT_DETERMINED when the interval spans more than a factor ``P_SPAN`` (sizes too close together
to tell p from P_inf) or when p or an end of its interval lies at a bound of the fit
(``P_BOUNDS``; an end widened past one is clipped to it), NOT_FITTED with fewer than two sigma~ or
fewer than three sizes.

**sigma~_inf**, where adhesion per area is lost: the first sigma~ (ascending) where P_inf falls
to ``area_threshold`` (the per-area threshold of the crossings above: the limit those crossings
approach as N grows, where they converge), P_inf interpolated linearly in sigma~ from the sigma~
below it; per replicate the same (+inf when a replicate's P_inf never falls to it, 0 when it is
already at or below it at the smallest sigma~). Kind BRACKET, NO_LOSS or ALL_LOST.
**sigma~_0**: the same for P_inf = 0 (its upper end is often unbounded: near its zero P_inf
scatters about 0, and a replicate that stays above 0 never crosses). Either is NOT_SIZE_FREE,
with no number, when a sigma~ up to its bracket's top is REJECTED or BELOW (a first crossing rests on
all of them) or the per-area drift names only limits that keep falling (``keeps_falling``).

**Pillar variables** (docs/finite-size.md): with N pillars of diameter D on the side L,
sigma / d_c1 = sigma~ (phi N)^(1/4) and k / (E* D) = k~ sqrt(pi N / (4 phi)); from them
k sigma / F_c1 (:func:`pillar_spring`) and sigma over one pillar's reach (:func:`pillar_reach`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .intervals import expanded, percentile_interval, replicate_sd
from .loss import first_fall
from .reading import FEW_PILLARS, RESOLVED, UNRESOLVED, pillar_floor, read_group
from .size_drift import (BRACKET, FIXED_PILLAR, FIXED_SIGMA, FIXED_SPRING, LIMITS, NEITHER, NOT_MEASURED,
                         Q_PILLAR, Q_SPRING, Drift, crossing_drift, drift_state, keeps_falling,
                         pillar_k, pillar_reach, pillar_sigma, pillar_spring)

NAN2 = (math.nan, math.nan)
#: the finite-size exponent of a fixed number of pillars' pull-off, in N = n_side^2
P_FEW = 0.75
#: the default per-area threshold, in F~ units (a tenth of a rigid punch's pull-off stress)
AREA_THRESHOLD = 0.1
#: the smallest number of sizes an extrapolation in N uses
MIN_SIZES = 3
#: the smallest seed sd of a plateau in the weights, relative to the plateau
SD_FLOOR = 0.01
#: the default number of bootstrap replicates
N_BOOT = 400
#: crossing kinds
NO_LOSS, ALL_LOST, NOT_READ = "no loss", "lost at every sigma~", "not read"   # and BRACKET
#: P_inf states
HOLDS, GONE, UNKNOWN, REJECTED = "holds", "gone", "unknown", "model rejected"
BELOW = "below 0"
#: states of the line in N that read no limit
NO_LIMIT = (REJECTED, BELOW)
#: chi^2 / dof of P(N) = P_inf + A N^(-3/4) above which that line is rejected (module text)
POOR_CHI2 = 30.0
#: the kind of sigma~_inf and sigma~_0 when none is read (a rejected line, a falling drift)
NOT_SIZE_FREE = "no size-free sigma~"
#: p states
CONSISTENT, DIFFERS, NOT_DETERMINED, NOT_FITTED = ("consistent with 3/4", "differs from 3/4",
                                                   "not determined", "not fitted")
#: a p interval wider than this factor (hi / lo) does not determine p
P_SPAN = 4.0
#: the range p is fitted in; a p or an interval end at a bound is not determined
P_BOUNDS = (0.05, 3.0)
#: per-area crossing trend over the two largest sizes
STEADY, DRIFTS = "steady", "drifts"


@dataclass
class Crossing:
    """Where one size's plateau falls to a threshold along sigma~."""

    n_side: int
    threshold: float
    kind: str = NOT_READ
    sigma: float = math.nan
    ci: tuple = NAN2
    bracket: tuple = NAN2
    n_seeds: int = 0
    below_floor: bool = False        # the few-pillar threshold reaches this one
    replicates: tuple = ()           # the bootstrap replicates' crossings (0 / inf: none inside)


@dataclass
class Extrapolation:
    """One sigma~ extrapolated in N: P(N) = P_inf + A N^(-p), p = 3/4."""

    sigma_tilde: float
    n_sides: tuple
    p_inf: float = math.nan
    p_inf_ci: tuple = NAN2
    amplitude: float = math.nan
    chi2: float = math.nan
    dof: int = 0
    state: str = UNKNOWN


@dataclass
class SizeLoss:
    """One k~ read across sizes (module text)."""

    k_tilde: float
    phi: float
    n_sides: tuple
    sigmas: tuple                    # every sigma~ run, ascending
    plateau: dict                    # {n_side: array over sigmas (NaN where not run)}
    plateau_ci: dict                 # {n_side: [(lo, hi)] over sigmas}
    states: dict                     # {n_side: [reading state] over sigmas}
    n_seeds: dict                    # {n_side: seeds}
    area_threshold: float = AREA_THRESHOLD
    few: list = field(default_factory=list)          # Crossing per size, FEW_PILLARS threshold
    area: list = field(default_factory=list)         # Crossing per size, area_threshold
    area_trend: str = UNKNOWN
    few_drift: Drift = field(default_factory=Drift)
    area_drift: Drift = field(default_factory=Drift)
    extrapolations: list = field(default_factory=list)
    p: float = math.nan
    p_ci: tuple = NAN2
    p_state: str = NOT_FITTED
    p_sigmas: tuple = ()             # the sigma~ the shared-p fit used
    sigma_inf_kind: str = NOT_READ
    sigma_inf: float = math.nan
    sigma_inf_ci: tuple = NAN2
    sigma_inf_bracket: tuple = NAN2
    sigma_zero_kind: str = NOT_READ
    sigma_zero: float = math.nan
    sigma_zero_ci: tuple = NAN2
    sigma_zero_bracket: tuple = NAN2


# ------------------------------------------------------------------------------ crossings
def _crossing(n, sigmas, plat, reps, thr, n_seeds) -> Crossing:
    c = Crossing(int(n), float(thr), n_seeds=int(n_seeds))
    s, br = first_fall(sigmas, plat, thr)
    c.bracket = br
    if not math.isfinite(br[0]):
        return c
    c.kind = BRACKET if math.isfinite(s) else (ALL_LOST if br[0] == 0.0 else NO_LOSS)
    c.sigma = s
    if math.isfinite(s) and reps is not None:
        r = [first_fall(sigmas, row, thr, clip=False)[0] for row in reps]
        c.replicates = tuple(r)
        c.ci = tuple(max(v, 0.0) for v in expanded(s, percentile_interval(r), n_seeds))
    return c


# ------------------------------------------------------------------------------ fits in N
def fit_line(x, y, w) -> tuple:
    """Weighted least squares y = a + b x: (a, b, chi^2); NaN with fewer than two points."""
    x, y, w = (np.asarray(v, float) for v in (x, y, w))
    ok = np.isfinite(x) & np.isfinite(y) & np.isfinite(w) & (w > 0)
    if ok.sum() < 2:
        return math.nan, math.nan, math.nan
    x, y, w = x[ok], y[ok], w[ok]
    A = np.stack([np.ones_like(x), x], axis=1) * np.sqrt(w)[:, None]
    (a, b), *_ = np.linalg.lstsq(A, y * np.sqrt(w), rcond=None)
    return float(a), float(b), float(np.sum(w * (y - a - b * x) ** 2))


def fit_shared_p(N, Y, W, p0: float = P_FEW) -> float:
    """One p for several sigma~: Y[i, n] = P_inf[i] + A[i] N[n]^(-p), weights W; NaN where
    the fit fails. ``N``: sizes (pillars), ``Y``, ``W``: arrays (sigma~, size)."""
    from scipy.optimize import least_squares

    N, Y, W = (np.asarray(v, float) for v in (N, Y, W))
    if not (np.all(np.isfinite(Y)) and np.all(np.isfinite(W))):
        return math.nan
    sw = np.sqrt(W)

    def resid(q):
        p = q[0]
        x = N ** (-p)
        # P_inf and A per sigma~ by linear least squares at this p (variable projection)
        out = []
        for y, s in zip(Y, sw):
            A = np.stack([np.ones_like(x), x], axis=1) * s[:, None]
            coef, *_ = np.linalg.lstsq(A, y * s, rcond=None)
            out.append(y * s - A @ coef)
        return np.concatenate(out)

    res = least_squares(resid, [p0], bounds=([P_BOUNDS[0]], [P_BOUNDS[1]]))
    return float(res.x[0]) if res.success else math.nan


def _weights(plat, sd):
    sd = np.where(np.isfinite(sd), sd, 0.0)
    return 1.0 / np.maximum(sd, SD_FLOOR * np.abs(plat)) ** 2


def level_crossing(sigmas, p_inf, level: float = 0.0, clip: bool = True) -> tuple:
    """(sigma~, bracket) where P_inf over ascending ``sigmas`` first falls to ``level``, linear
    in sigma~ (module text); unclipped, 0 or inf where it does not cross inside."""
    s = np.asarray(sigmas, float)
    p = np.asarray(p_inf, float)
    ok = np.isfinite(p)
    s, p = s[ok], p[ok]
    if s.size == 0:
        return math.nan, NAN2
    p = p - level
    if p[0] <= 0:
        return (math.nan if clip else 0.0), (0.0, float(s[0]))
    below = np.flatnonzero(p <= 0)
    if below.size == 0:
        return (math.nan if clip else math.inf), (float(s[-1]), math.inf)
    j = int(below[0])
    lo, hi = float(s[j - 1]), float(s[j])
    return lo + (hi - lo) * p[j - 1] / (p[j - 1] - p[j]), (lo, hi)


# ------------------------------------------------------------------------------ the study
def _replicates(pts_by_sigma: dict, sigmas, floor, n_boot, rng) -> np.ndarray | None:
    """(n_boot, len(sigmas)) plateaus of one size, seed labels resampled once per replicate
    for every sigma~ (paired); None with fewer than two seeds."""
    labels = sorted(set().union(*(set(np.asarray(p[0]).tolist())
                                  for p in pts_by_sigma.values())))
    if len(labels) < 2 or n_boot < 1:
        return None
    out = np.full((n_boot, len(sigmas)), np.nan)
    for b in range(n_boot):
        pick = [labels[i] for i in rng.integers(0, len(labels), len(labels))]
        for i, s in enumerate(sigmas):
            if s not in pts_by_sigma:
                continue
            seed, pre, x, y = pts_by_sigma[s]
            idx = [np.flatnonzero(seed == lab) for lab in pick]
            idx = [ix for ix in idx if ix.size]
            if not idx:
                continue
            new = np.concatenate([np.full(ix.size, m) for m, ix in enumerate(idx)])
            sel = np.concatenate(idx)
            out[b, i] = read_group(new, pre[sel], x[sel], y[sel], floor=floor).plateau
    return out


def size_loss(k_tilde: float, by_n: dict, phi: float, n_boot: int = N_BOOT, rng_seed: int = 0,
              area_threshold: float = AREA_THRESHOLD) -> SizeLoss:
    """One k~ across sizes (module text). ``by_n``: {n_side: {sigma~: (seed, preload, F~_P,
    F~_A) arrays}}; ``phi``: the nominal filling ratio."""
    by_n = {int(n): {float(s): tuple(np.asarray(a) for a in p) for s, p in g.items()}
            for n, g in by_n.items() if g}
    sizes = tuple(sorted(by_n))
    sigmas = tuple(sorted(set().union(*(set(g) for g in by_n.values())))) if by_n else ()
    out = SizeLoss(float(k_tilde), float(phi), sizes, sigmas, {}, {}, {}, {},
                   area_threshold=float(area_threshold))
    reps = {}
    for n in sizes:
        floor = pillar_floor(n, phi)
        rd = {s: read_group(*by_n[n][s], floor=floor) for s in by_n[n]}
        out.plateau[n] = np.array([rd[s].plateau if s in rd else math.nan for s in sigmas])
        out.states[n] = [rd[s].state if s in rd else "" for s in sigmas]
        out.n_seeds[n] = len(set().union(*(set(p[0].tolist()) for p in by_n[n].values())))
        rng = np.random.default_rng(rng_seed + 7919 * n)     # sizes drawn independently
        reps[n] = _replicates(by_n[n], sigmas, floor, n_boot, rng)
        out.plateau_ci[n] = [
            expanded(v, percentile_interval(reps[n][:, i]), out.n_seeds[n])
            if reps[n] is not None and math.isfinite(v) else NAN2
            for i, v in enumerate(out.plateau[n])]
        few_thr = FEW_PILLARS * floor
        out.few.append(_crossing(n, sigmas, out.plateau[n], reps[n], few_thr, out.n_seeds[n]))
        area = _crossing(n, sigmas, out.plateau[n], reps[n], area_threshold, out.n_seeds[n])
        area.below_floor = few_thr >= area_threshold
        out.area.append(area)
    _trend(out)
    _extrapolate(out, reps, n_boot)
    return out


def _trend(out: SizeLoss) -> None:
    out.few_drift = crossing_drift(out.few)
    out.area_drift = crossing_drift([c for c in out.area if not c.below_floor])
    use = [c for c in out.area if c.kind == BRACKET and not c.below_floor
           and all(math.isfinite(v) for v in c.ci)]
    if len(use) >= 2:
        a, b = use[-2].ci, use[-1].ci
        out.area_trend = STEADY if a[0] <= b[1] and b[0] <= a[1] else DRIFTS


def _extrapolate(out: SizeLoss, reps: dict, n_boot: int) -> None:
    sizes = out.n_sides
    if len(sizes) < MIN_SIZES:
        return
    N = np.array([n * n for n in sizes], float)
    x = N ** (-P_FEW)
    n_min = min(out.n_seeds[n] for n in sizes)
    have_reps = all(reps[n] is not None for n in sizes)
    sd = {n: np.array([replicate_sd(reps[n][:, i]) if reps[n] is not None else math.nan
                       for i in range(len(out.sigmas))]) for n in sizes}
    rows = []                 # (i, weights) of the sigma~ run at every size
    for i, s in enumerate(out.sigmas):
        y = np.array([out.plateau[n][i] for n in sizes])
        if not np.all(np.isfinite(y)):
            continue
        w = _weights(y, np.array([sd[n][i] for n in sizes]))
        a, b, chi2 = fit_line(x, y, w)
        e = Extrapolation(s, sizes, a, NAN2, b, chi2, len(sizes) - 2)
        if have_reps:
            r = [fit_line(x, [reps[n][j, i] for n in sizes], w)[0] for j in range(n_boot)]
            e.p_inf_ci = expanded(a, percentile_interval(r), n_min)
        e.state = extrapolation_state(e.p_inf_ci[0], chi2 if have_reps else math.nan, e.dof,
                                      e.p_inf_ci[1])
        out.extrapolations.append(e)
        rows.append((i, w))
    ss = [e.sigma_tilde for e in out.extrapolations]
    rep_pinf = ([[fit_line(x, [reps[n][j, i] for n in sizes], w)[0] for i, w in rows]
                 for j in range(n_boot)] if have_reps else [])
    for name, level in (("sigma_inf", out.area_threshold), ("sigma_zero", 0.0)):
        _loss_at(out, name, level, ss, [e.p_inf for e in out.extrapolations], rep_pinf, n_min)
    # p measured on the sigma~ that hold adhesion at every size
    keep = [(i, w) for i, w in rows
            if all(out.states[n][i] in (RESOLVED, UNRESOLVED) for n in sizes)]
    out.p_sigmas = tuple(out.sigmas[i] for i, _ in keep)
    if len(keep) < 2:
        return
    Y = np.array([[out.plateau[n][i] for n in sizes] for i, _ in keep])
    W = np.array([w for _, w in keep])
    out.p = fit_shared_p(N, Y, W)
    if have_reps and math.isfinite(out.p):
        r = [fit_shared_p(N, np.array([[reps[n][j, i] for n in sizes] for i, _ in keep]), W)
             for j in range(n_boot)]
        out.p_ci = tuple(np.clip(expanded(out.p, percentile_interval(r), n_min), *P_BOUNDS).tolist())
        out.p_state = exponent_state(out.p, out.p_ci)


def extrapolation_state(lo: float, chi2: float, dof: int, hi: float = math.nan) -> str:
    """The state of P_inf with interval (``lo``, ``hi``) (NaN: no interval) from a line of
    ``chi2`` on ``dof`` degrees of freedom (module text)."""
    if dof > 0 and chi2 / dof > POOR_CHI2:
        return REJECTED
    return HOLDS if lo > 0 else BELOW if hi < 0 else GONE if lo <= 0 else UNKNOWN


def exponent_state(p: float, ci: tuple) -> str:
    """The state of a measured exponent ``p`` with interval ``ci`` (module text)."""
    lo, hi = ci
    if not (math.isfinite(p) and math.isfinite(lo) and math.isfinite(hi)):
        return NOT_FITTED
    at_bound = any(v <= P_BOUNDS[0] * 1.01 or v >= P_BOUNDS[1] * 0.99 for v in (p, lo, hi))
    if at_bound or not lo > 0 or hi / lo > P_SPAN:
        return NOT_DETERMINED
    return CONSISTENT if lo <= P_FEW <= hi else DIFFERS


def _loss_at(out: SizeLoss, name: str, level: float, ss, p_inf, rep_pinf, n_min) -> None:
    """Set ``name`` (sigma_inf or sigma_zero), its kind, bracket and interval: where P_inf
    falls to ``level``."""
    s0, br = level_crossing(ss, p_inf, level)
    setattr(out, name + "_bracket", br)
    if not math.isfinite(br[0]):
        return
    if keeps_falling(out.area_drift.state) or any(    # a first crossing: every P_inf below
            e.state in NO_LIMIT and e.sigma_tilde <= br[1] for e in out.extrapolations):
        setattr(out, name + "_kind", NOT_SIZE_FREE)
        return
    setattr(out, name + "_kind", BRACKET if math.isfinite(s0) else
            ALL_LOST if br[0] == 0.0 else NO_LOSS)
    setattr(out, name, s0)
    if math.isfinite(s0) and rep_pinf:
        r = [level_crossing(ss, pj, level, clip=False)[0] for pj in rep_pinf]
        setattr(out, name + "_ci", tuple(max(float(v), 0.0) for v in
                                         expanded(s0, percentile_interval(r), n_min)))


def size_losses(by_n_k: dict, phi: float, n_boot: int = N_BOOT, rng_seed: int = 0,
                area_threshold: float = AREA_THRESHOLD) -> dict:
    """{k~: :class:`SizeLoss`} from {n_side: {(k~, sigma~): points}} (the report's groups per
    size; k~ descending)."""
    ks = sorted({k for g in by_n_k.values() for k, _ in g}, reverse=True)
    return {k: size_loss(k, {n: {s: p for (kk, s), p in g.items() if kk == k}
                             for n, g in by_n_k.items()}, phi, n_boot, rng_seed, area_threshold)
            for k in ks}


def adopt_measured(s: SizeLoss, n_side: int, measured) -> None:
    """Give ``s``'s few-pillar crossing at ``n_side`` the measured sigma~_c of that size
    (:class:`.loss.Loss`, a bracket of the same threshold): one number, one interval per page."""
    for c in s.few:
        if (c.n_side == n_side and measured.kind == BRACKET
                and math.isclose(c.threshold, measured.threshold, rel_tol=1e-9)):
            c.kind, c.sigma, c.ci, c.bracket = BRACKET, measured.sigma, measured.ci, measured.bracket


__all__ = ["SizeLoss", "Crossing", "Extrapolation", "Drift", "crossing_drift", "drift_state",
           "Q_PILLAR", "Q_SPRING", "LIMITS", "FIXED_SIGMA", "FIXED_PILLAR", "FIXED_SPRING",
           "NEITHER", "NOT_MEASURED", "pillar_spring", "pillar_reach", "size_loss", "size_losses",
           "adopt_measured",
           "level_crossing", "fit_line", "fit_shared_p", "exponent_state",
           "extrapolation_state", "pillar_sigma", "pillar_k", "P_FEW", "AREA_THRESHOLD",
           "BRACKET", "NO_LOSS", "ALL_LOST", "NOT_READ", "HOLDS", "GONE", "UNKNOWN", "REJECTED",
           "BELOW", "NO_LIMIT",
           "POOR_CHI2", "NOT_SIZE_FREE", "CONSISTENT", "DIFFERS", "NOT_DETERMINED", "NOT_FITTED",
           "STEADY", "DRIFTS"]
