"""Where adhesion is lost along sigma~ for one k~, measured without a law, and whether the
alpha/beta extrapolation agrees with it.

**The measured sigma~_c.** A group is *lost* when its plateau is at most ``FEW_PILLARS`` pillars'
pull-off (:mod:`.reading`; c = 0 by definition from there on). Going up in sigma~, the first
lost group that has a non-lost group (rise resolved or rise not resolved) below it sets the
*loss bracket* (lo, hi]: hi that lost sigma~, lo the largest non-lost sigma~ below it. The
measured sigma~_c is the sigma~ where the seed-mean plateau crosses the threshold
``FEW_PILLARS * floor``, interpolated linearly in log(plateau) against log(sigma~) between the
two groups (exact when the plateau falls as a power of sigma~ there), inside [lo, hi]; with
lo = 0 (the smooth limit) linearly in sigma~. Its seed interval comes from the bootstrap
replicates of the two plateaus (the study's resampling of seeds, lo and hi fixed): the crossing
of every replicate, its percentile interval widened for the number of seeds
(:func:`.intervals.expanded`). A replicate whose two plateaus lie on one side of the threshold
crosses outside [lo, hi] (the log-log line extended; beyond hi where the plateau does not fall):
the state of a bracketing group is then not certain with its seeds, the interval reaches beyond
the bracket and the note says so; the comparison with alpha/beta takes the wider span.

Without a bracket: no group lost ("no loss up to sigma~ = the largest run"), or the smallest
sigma~ run already lost ("lost at every sigma~ run": sigma~_c below it).

**Against alpha/beta** (:func:`compare`). The measurement is the whole bracket (lo, hi] (the
bracket is what the data say without a shape of the plateau), widened to the interpolation's
interval where that reaches beyond it; without a bracket the one-sided bound. alpha/beta's
sigma~_c, with its seed interval (the value alone when it has none), *agrees* when the two
overlap; the law is *above* (it overshoots: c of the law is still > 0 where adhesion is already
lost) when its interval lies wholly above hi, *below* when wholly below lo. A law whose value
sits on the bracket's c = 0 point within the allowance ``TOL`` that :func:`.study.judge` gives a
*pinned* sigma~_c (lo <= alpha/beta <= TOL hi) agrees (a pinned law is never called above); an
interval reaching infinity that does not lie wholly above the bracket says nothing (beta
consistent with 0: ""). Where alpha/beta gives no finite sigma~_c there is nothing to compare
("").
"""

from __future__ import annotations

import math

import numpy as np

from .intervals import expanded, percentile_interval
from .reading import LOST, RESOLVED, UNRESOLVED

NAN2 = (math.nan, math.nan)
#: :attr:`KStudy.loss_vs_law` values
AGREE, ABOVE, BELOW = "agree", "law above the measured loss", "law below the measured loss"
#: how far beyond the bracket alpha/beta's zero still counts as at its end (the same allowance
#: :func:`.study.judge` gives a sigma~_c *pinned* to the c = 0 point: the cut line's zero may sit
#: a little past a c = 0 point at no cost to the fit)
TOL = 1.05
#: :attr:`KStudy.loss_kind` values: a bracket, no group lost, every group lost, nothing read
BRACKET, NO_LOSS, ALL_LOST, NOT_READ = "bracket", "no loss", "lost at every sigma~", "not read"


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


def measure(sigmas, states, plateaus, thr: float, reps=None, n_seeds=()) -> dict:
    """The measured loss of one k~ from its groups in ascending ``sigmas`` (their ``states``,
    seed-mean ``plateaus`` and numbers of seeds ``n_seeds``), the loss threshold ``thr`` and the
    bootstrap replicates of the plateaus (``reps``: one row per group, or None); the interval is
    widened for the fewer seeds of the two bracketing groups. Returns a dict with ``bracket``,
    ``sigma``, ``ci``, ``kind`` (:data:`BRACKET`, :data:`NO_LOSS`, :data:`ALL_LOST` or
    :data:`NOT_READ`) and ``note`` (the sentence the page shows)."""
    out = {"bracket": NAN2, "sigma": math.nan, "ci": NAN2, "kind": NOT_READ, "note": ""}
    run = [(s, st) for s, st in zip(sigmas, states) if st in (RESOLVED, UNRESOLVED, LOST)]
    if not run:
        out["note"] = "no sigma~ whose state could be read: the loss is not measured"
        return out
    pair = bracket_indices(sigmas, states)
    if pair is None:
        lost = [s for s, st in run if st == LOST]
        if not lost:
            top = max(s for s, _ in run)
            out["bracket"], out["kind"] = (top, math.inf), NO_LOSS
            out["note"] = f"no loss up to sigma~ = {top:g} (the largest run): sigma~_c > {top:g}"
        else:
            first = min(s for s, _ in run)
            out["bracket"], out["kind"] = (0.0, first), ALL_LOST
            out["note"] = (f"lost at every sigma~ run (< {first:g}): adhesion is already lost at"
                           f" the smallest sigma~, sigma~_c < {first:.3g}")
            found = [s for s, st in run if st != LOST]
            if found:
                out["note"] += ("; adhesion is found again at sigma~ = "
                                + ", ".join(f"{x:g}" for x in found) + " (not monotone in sigma~)")
        return out
    i, j = pair
    lo, hi = float(sigmas[i]), float(sigmas[j])
    out["bracket"], out["kind"] = (lo, hi), BRACKET
    s = crossing(lo, hi, plateaus[i], plateaus[j], thr)
    out["sigma"] = s
    if reps is not None and math.isfinite(s):
        rs = np.array([crossing(lo, hi, a, b, thr, clip=False)
                       for a, b in zip(reps[i], reps[j])])
        n = min(n_seeds[i], n_seeds[j]) if len(n_seeds) > j else 0
        out["ci"] = tuple(max(v, 0.0) for v in expanded(s, percentile_interval(rs), n))
    again = [float(x) for x, st in zip(sigmas[j + 1:], states[j + 1:])
             if st in (RESOLVED, UNRESOLVED)]
    out["note"] = (f"adhesion lost at sigma~ = {fmt_ci(s, out['ci'])} (the plateau crosses the "
                   f"loss threshold {thr:.3g}; bracket {lo:.3g}-{hi:.3g})")
    c_lo, c_hi = out["ci"]
    if c_hi > hi or c_lo < lo:
        out["note"] += ("; the interval reaches beyond the bracket: with their seeds, the state of "
                        + " and ".join(x for x, far in (("the last group holding adhesion", c_lo < lo),
                                                      ("the first lost group", c_hi > hi)) if far)
                        + " is not certain")
    if again:
        out["note"] += ("; adhesion is found again above it at sigma~ = "
                        + ", ".join(f"{x:g}" for x in again) + " (not monotone in sigma~)")
    return out


def fmt_ci(v: float, ci: tuple) -> str:
    """'v [lo, hi]' in three digits (the value alone without an interval)."""
    if not math.isfinite(v):
        return "—"
    if not all(math.isfinite(x) for x in ci):
        return f"{v:.3g}" + (f" [{ci[0]:.3g}, ∞]" if math.isfinite(ci[0]) else "")
    return f"{v:.3g} [{ci[0]:.3g}, {ci[1]:.3g}]"


def compare(kind: str, bracket: tuple, sigma_loss: float, loss_ci: tuple, sigma_c: float,
            sigma_c_ci: tuple) -> tuple[str, str]:
    """(verdict, one-line reason) of alpha/beta's sigma~_c against the measured loss of
    :func:`measure` (its ``kind``, ``bracket``, ``sigma`` and ``ci``; module text); ("", why)
    where there is nothing to compare."""
    lo, hi = b_lo, b_hi = bracket
    if kind == BRACKET and all(math.isfinite(v) for v in loss_ci):   # an uncertain end state
        lo, hi = min(lo, loss_ci[0]), max(hi, loss_ci[1])
    if kind == NOT_READ:
        return "", "the loss is not measured"
    if not math.isfinite(sigma_c):
        return "", "alpha/beta gives no finite sigma~_c to compare with the measured loss"
    a, b = sigma_c_ci
    if math.isnan(a) or math.isnan(b):
        a = b = sigma_c
    law = f"alpha/beta extrapolates sigma~_c = {fmt_ci(sigma_c, sigma_c_ci)}"
    if kind == BRACKET:
        meas = (f"adhesion is lost at {fmt_ci(sigma_loss, loss_ci)} (bracket {b_lo:.3g}-{b_hi:.3g})"
                if math.isfinite(sigma_loss) else f"adhesion is lost in ({b_lo:.3g}, {b_hi:.3g}]")
    elif kind == NO_LOSS:
        meas = f"adhesion is not lost up to sigma~ = {lo:g} (sigma~_c > {lo:g})"
    else:
        meas = f"adhesion is lost at every sigma~ run (sigma~_c < {hi:g})"
    if a > hi and not lo <= sigma_c <= hi * TOL:
        return ABOVE, f"{law}, but {meas}: the law overshoots the measured loss"
    if math.isinf(b):
        return "", (f"{law}: its interval is unbounded above (beta consistent with 0), so it "
                    f"cannot be told from the measured loss ({meas})")
    if b < lo:
        return BELOW, f"{law}, but {meas}: the law undershoots the measured loss"
    return AGREE, f"{law}; {meas}: they agree"


__all__ = ["measure", "compare", "crossing", "bracket_indices", "fmt_ci", "AGREE", "ABOVE",
           "BELOW", "BRACKET", "NO_LOSS", "ALL_LOST", "NOT_READ"]
