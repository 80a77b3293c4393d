"""Where adhesion is lost along sigma~ for one k~, measured without a law: the one critical
roughness the report gives per brush.

**The measured sigma~_c.** A group is *lost* when its plateau is at most ``FEW_PILLARS`` pillars'
pull-off (:mod:`.reading`; c = 0 by definition from there on). Going up in sigma~, the first
lost group that has a non-lost group (rise resolved or rise not resolved) below it sets the
*loss bracket* (lo, hi]: hi that lost sigma~, lo the largest non-lost sigma~ below it. The
measured sigma~_c is the sigma~ where the seed-mean plateau crosses the threshold
``FEW_PILLARS * floor``, interpolated linearly in log(plateau) against log(sigma~) between the
two groups (exact when the plateau falls as a power of sigma~ there), inside [lo, hi]; with
lo = 0 (the smooth limit) linearly in sigma~. Its seed interval comes from the bootstrap
replicates of the two plateaus (the study's resampling of seed labels, paired across the two
groups: a seed is the same brush in both): the crossing of every replicate, unclipped (a
replicate whose two plateaus lie on one side of the threshold crosses outside [lo, hi], on the
log-log line extended, or beyond hi where the plateau does not fall), its percentile interval
widened for the fewer seeds of the two groups (:func:`.intervals.expanded`).

**Another seed set.** The seed interval says where the population's crossing lies; another
set of as many seeds measures its own crossing, scattered about the population's as much as
this one: the difference of two such estimates is sqrt(2) times as wide. The interval another
seed set of this size would measure in (:attr:`Loss.another`, 95 %) is the seed interval widened
about the estimate by ``ANOTHER`` = sqrt(2) on each side, in log sigma~ (the crossing scatters
in proportion: its two sides keep their skew). A narrow seed interval that another seed set's
estimate falls outside is the failure this guards against (``benchmarks/pillar_reproduce.py``
measures both rates on brushes of whole pillars through the real search).

**States that are not certain.** A group's state is *not certain* with its seeds when its
plateau's seed interval holds the threshold. The *span* of the measurement is the bracket
widened down to the largest sigma~ below it whose group holds adhesion for certain and up to the
smallest sigma~ from hi on that is lost for certain: a group certain of its state bounds where
the loss can be. On a side with no certain group the span reaches the interval another seed set
would measure in (and 0 or inf where that has no end): the least certain case, never the
bracket. :mod:`.verdict` compares alpha/beta's zero with the span.

**Each seed's own crossing** (:attr:`Loss.per_seed`, set by the study): for every seed in both
bracketing groups, the crossing of its own two plateaus (unclipped): how far one brush's loss
lies from another's, beside the interval of the seed mean.

Without a bracket: no group lost (:data:`NO_LOSS`, sigma~_c above the largest run), or the
smallest sigma~ run already lost (:data:`ALL_LOST`: below it). The module returns numbers and
states (:class:`Loss`); the words are the page's (``analysis/verdict_text.py``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .intervals import expanded, percentile_interval
from .reading import LOST, RESOLVED, UNRESOLVED

NAN2 = (math.nan, math.nan)
#: how much wider (in log sigma~, each side) another seed set's estimate scatters about this one
#: than the population's crossing does: the sd of a difference of two independent estimates
ANOTHER = math.sqrt(2.0)
#: :attr:`Loss.kind` values: a bracket, no group lost, every group lost, nothing read
BRACKET, NO_LOSS, ALL_LOST, NOT_READ = "bracket", "no loss", "lost at every sigma~", "not read"


@dataclass
class Loss:
    """The measured loss of one k~ (module text): numbers and states, no words."""

    kind: str = NOT_READ
    bracket: tuple = NAN2           # (lo, hi]: the point states' bracket, or the one-sided bound
    span: tuple = NAN2              # the bracket widened by states not certain (module text)
    sigma: float = math.nan         # where the seed-mean plateau crosses the threshold
    ci: tuple = NAN2                # its seed interval (widened for few seeds)
    another: tuple = NAN2           # where another seed set of this size would measure it
    threshold: float = math.nan     # FEW_PILLARS pillars' pull-off
    n_seeds: int = 0                # the fewer seeds of the two bracketing groups
    uncertain: tuple = ()           # sigma~ whose state is not certain with its seeds
    again: tuple = ()               # sigma~ above the loss holding adhesion again (not monotone)
    per_seed: tuple = ()            # ((seed, its own crossing), ...) for seeds in both groups
    matched: tuple = ()             # (seeds of the larger group, of the other) where the
    #                                 other's plateau was carried to the larger's seeds (study)


def bracket_indices(sigmas, states):
    """(i_lo, i_hi) of the loss bracket in ascending ``sigmas`` (module text), or None."""
    for j, st in enumerate(states):
        if st != LOST:
            continue
        below = [i for i in range(j) if states[i] in (RESOLVED, UNRESOLVED)]
        if below:
            return below[-1], j
    return None


def crossing(s_lo: float, s_hi: float, p_lo: float, p_hi: float, thr: float,
             clip: bool = True) -> float:
    """The sigma~ where the plateau, interpolated between (s_lo, p_lo) and (s_hi, p_hi), crosses
    ``thr``: log-log (linear in sigma~ when s_lo = 0), clipped to [s_lo, s_hi]; NaN where a
    plateau is not a positive number. Unclipped (a bootstrap replicate in which both groups lie
    on one side of the threshold), the line is extended beyond the bracket; a replicate whose
    plateau does not fall from lo to hi crosses beyond hi (inf) when both are above, at 0 when
    both are below."""
    if not (math.isfinite(p_lo) and math.isfinite(p_hi)) or p_lo <= 0 or p_hi <= 0 or thr <= 0:
        return math.nan
    above_lo, above_hi = p_lo > thr, p_hi > thr
    if above_lo == above_hi and (clip or p_hi >= p_lo):
        if clip:
            return s_hi if above_lo else s_lo
        return math.inf if above_lo else 0.0
    t = (math.log(p_lo) - math.log(thr)) / (math.log(p_lo) - math.log(p_hi))
    if s_lo > 0:
        s = math.exp(math.log(s_lo) + t * math.log(s_hi / s_lo))
    else:
        s = max(s_lo + t * (s_hi - s_lo), 0.0)
    return min(max(s, s_lo), s_hi) if clip else s


def first_fall(sigmas, plateaus, thr: float, clip: bool = True) -> tuple:
    """(sigma~, (lo, hi) bracket) where the plateau over ascending ``sigmas`` first falls to
    ``thr`` after a sigma~ above it (the bracket rule of :func:`bracket_indices` read on the
    numbers), by :func:`crossing` between the two sigma~ around it. Points that are no positive
    number are skipped. Without such a fall: lost at the smallest sigma~ (bracket (0, first);
    sigma~ 0 unclipped) or adhesion held from there on (bracket (last, inf); inf unclipped);
    clipped, those give NaN. Nothing to read: NaN and no bracket. Each brush size's crossing
    of :mod:`.size_loss` is read so."""
    s = np.asarray(sigmas, dtype=float)
    p = np.asarray(plateaus, dtype=float)
    ok = np.isfinite(p) & (p > 0)
    s, p = s[ok], p[ok]
    if s.size == 0 or not thr > 0:
        return math.nan, NAN2
    above = p > thr
    for j in range(1, s.size):
        if not above[j] and above[:j].any():
            lo, hi = float(s[j - 1]), float(s[j])
            return crossing(lo, hi, float(p[j - 1]), float(p[j]), thr), (lo, hi)
    if not above[0]:
        return (math.nan if clip else 0.0), (0.0, float(s[0]))
    return (math.nan if clip else math.inf), (float(s[-1]), math.inf)


def another_set(s: float, ci: tuple, factor: float = ANOTHER) -> tuple:
    """The interval another seed set of as many seeds would measure the crossing in: ``ci``
    widened about ``s`` by ``factor`` on each side in log sigma~ (an end at 0 or inf stays; no
    interval or no estimate: no interval)."""
    lo, hi = ci
    if not (math.isfinite(s) and s > 0) or math.isnan(lo) or math.isnan(hi):
        return NAN2
    lo2 = s * (lo / s) ** factor if 0 < lo < s else min(lo, s)
    hi2 = s * (hi / s) ** factor if s < hi < math.inf else max(hi, s)
    return lo2, hi2


def _uncertain(plateau_cis, thr: float, i: int) -> bool:
    """Group ``i``'s plateau interval holds the threshold (no interval: taken as certain)."""
    if plateau_cis is None or i >= len(plateau_cis):
        return False
    lo, hi = plateau_cis[i]
    return math.isfinite(lo) and math.isfinite(hi) and lo <= thr < hi


def _span(sigmas, states, plateau_cis, thr, i_lo, i_hi) -> tuple:
    """(the largest sigma~ at or below index ``i_lo`` holding adhesion for certain, else 0;
    the smallest sigma~ from index ``i_hi`` on lost for certain, else inf)."""
    held = [float(sigmas[k]) for k in range(i_lo + 1) if states[k] in (RESOLVED, UNRESOLVED)
            and not _uncertain(plateau_cis, thr, k)]
    gone = [float(sigmas[k]) for k in range(max(i_hi, 0), len(sigmas)) if states[k] == LOST
            and not _uncertain(plateau_cis, thr, k)]
    return (max(held) if held else 0.0), (min(gone) if gone else math.inf)


def measure(sigmas, states, plateaus, thr: float, reps=None, n_seeds=(),
            plateau_cis=None) -> Loss:
    """The measured loss of one k~ from its groups in ascending ``sigmas`` (their ``states``,
    seed-mean ``plateaus``, numbers of seeds ``n_seeds`` and plateau seed intervals
    ``plateau_cis``), the loss threshold ``thr`` and the bootstrap replicates of the plateaus
    (``reps``: one row per group, or None) (module text)."""
    out = Loss(threshold=thr)
    idx = [k for k, st in enumerate(states) if st in (RESOLVED, UNRESOLVED, LOST)]
    if not idx:
        return out
    out.uncertain = tuple(float(sigmas[k]) for k in idx if _uncertain(plateau_cis, thr, k))
    pair = bracket_indices(sigmas, states)
    if pair is None:
        lost = [k for k in idx if states[k] == LOST]
        if not lost:
            top = max(float(sigmas[k]) for k in idx)
            out.kind, out.bracket = NO_LOSS, (top, math.inf)
            out.span = (_span(sigmas, states, plateau_cis, thr, len(sigmas) - 1, len(sigmas))[0],
                        math.inf)
        else:
            first = min(float(sigmas[k]) for k in idx)
            out.kind, out.bracket = ALL_LOST, (0.0, first)
            out.span = (0.0, _span(sigmas, states, plateau_cis, thr, -1, 0)[1])
            out.again = tuple(float(sigmas[k]) for k in idx if states[k] != LOST)
        return out
    i, j = pair
    lo, hi = float(sigmas[i]), float(sigmas[j])
    out.kind, out.bracket = BRACKET, (lo, hi)
    s = crossing(lo, hi, plateaus[i], plateaus[j], thr)
    out.sigma = s
    out.n_seeds = min(n_seeds[i], n_seeds[j]) if len(n_seeds) > j else 0
    if reps is not None and math.isfinite(s):
        rs = np.array([crossing(lo, hi, a, b, thr, clip=False)
                       for a, b in zip(reps[i], reps[j])])
        out.ci = tuple(max(v, 0.0) for v in expanded(s, percentile_interval(rs), out.n_seeds))
    out.another = another_set(s, out.ci)
    s_lo, s_hi = _span(sigmas, states, plateau_cis, thr, i, j)
    c_lo, c_hi = out.another
    # a sigma~ whose state is certain bounds the span; where no group is certain on a side
    # (0 or inf there), the interval another seed set would measure in does
    out.span = (min(lo, c_lo) if s_lo <= 0 and not math.isnan(c_lo) else s_lo,
                max(hi, c_hi) if s_hi == math.inf and not math.isnan(c_hi) else s_hi)
    out.again = tuple(float(x) for x, st in zip(sigmas[j + 1:], states[j + 1:])
                      if st in (RESOLVED, UNRESOLVED))
    return out


__all__ = ["Loss", "measure", "crossing", "first_fall", "another_set", "ANOTHER", "bracket_indices",
           "BRACKET", "NO_LOSS", "ALL_LOST", "NOT_READ"]
