"""The words and tables of where adhesion is lost across brush sizes (a grid sweeping
``n_side``): the numbers and states of :mod:`..laws.size_loss`, written for the page.

Two tables: ``size_loss`` (per k~ and n_side, then one row per k~ for the large-brush limit,
n_side = inf) and ``size_extrapolation`` (per k~ and sigma~: the plateau extrapolated in N).
Every column is defined in docs/report.md ("Where adhesion is lost, across sizes").
"""

from __future__ import annotations

import math

from ..laws import size_loss as sl
from ..laws.reading import FEW_PILLARS
from ..laws.size_drift import keeps_falling
from .tables import Table, fmt, num, val_ci


def _end(v) -> str:
    """An interval end: unbounded ends are ``inf`` / ``-inf`` (an empty cell is undefined)."""
    return ("inf" if v > 0 else "-inf") if v is not None and math.isinf(v) else num(v)


def _ci(ci) -> list:
    return [_end(ci[0]), _end(ci[1])]


def _p_text(p: float, ci: tuple) -> str:
    """'= p [lo, hi]' for the page's 'p …'; an end at a bound of the fit
    (:data:`..laws.size_loss.P_BOUNDS`, where :mod:`..laws.size_loss` clips the widened
    interval) written '≤ 0.05' or '≥ 3': the sizes do not bound p there, the fit's range does;
    a p at a bound is no estimate: 'at the fit's bound 0.05 [≤ 0.05, 0.576]'."""
    text = "= " + val_ci(p, ci, ".3g")
    if not (math.isfinite(p) and all(math.isfinite(v) for v in ci)):
        return text
    lo, hi = sl.P_BOUNDS
    ends = [f"≤ {lo:g}" if math.isclose(ci[0], lo) else fmt(ci[0], ".3g"),
            f"≥ {hi:g}" if math.isclose(ci[1], hi) else fmt(ci[1], ".3g")]
    at = lo if math.isclose(p, lo) else hi if math.isclose(p, hi) else None
    value = f"= {fmt(p, '.3g')}" if at is None else f"at the fit's bound {at:g}"
    return f"{value} [{ends[0]}, {ends[1]}]"


def _sigma_cell(kind: str, sigma: float, ci: tuple, bracket: tuple) -> str:
    if kind == sl.BRACKET:
        return val_ci(sigma, ci, ".3g")
    if kind == sl.NO_LOSS:
        return f"> {fmt(bracket[0], '.3g')} (not reached)"
    if kind == sl.ALL_LOST:
        return f"< {fmt(bracket[1], '.3g')} (below every σ̃ run)"
    if kind == sl.NOT_SIZE_FREE:
        return "not read (no N → ∞ limit from these sizes)"
    return "—"


def _not_size_free(s) -> str:
    """Why no N -> inf sigma~ is read for a k~, naming only what blocks it
    (:func:`.laws.size_loss.size_loss`): the lines in N up to the crossing's bracket that read no
    limit (rejected, or below 0), and crossings drifting as a limit that keeps falling; with the
    drift they show."""
    top = s.sigma_inf_bracket[1]
    block = [e for e in s.extrapolations if e.state in sl.NO_LIMIT and e.sigma_tilde <= top]
    bad = ", ".join(f"{e.sigma_tilde:g} (χ²/dof {e.chi2 / e.dof:.3g})"
                    for e in block if e.state == sl.REJECTED)
    neg = ", ".join(f"{e.sigma_tilde:g}" for e in block if e.state == sl.BELOW)
    why = ([f"P∞ + A N^(−3/4) does not fit at σ̃ = {bad}"] if bad else []) + (
        [f"its P∞ lies below 0 at σ̃ = {neg} (a plateau is never negative: it falls faster than "
         "N^(−3/4) there)"] if neg else []) + (
        ["its per-size crossings drift as a limit that keeps falling"]
        if keeps_falling(s.area_drift.state) or not (bad or neg) else [])
    return (f"no N → ∞ σ̃ read ({'; '.join(why)}); the per-size crossing moves as N^q, "
            f"q = {_drift_text(s.area_drift)}")


def _drift_cells(dr) -> list:
    return [num(dr.q), *_ci(dr.q_ci), dr.state]


def _drift_text(dr) -> str:
    if not math.isfinite(dr.q):
        return "—"
    state = dr.state.replace("sigma~", "σ̃").replace("sigma", "σ")
    return f"{val_ci(dr.q, dr.q_ci, '.2g')} ({state})"


def table(d) -> Table:
    """Per k~ and n_side: the few-pillar crossing (the report's measured sigma~_c of that size)
    and the per-area crossing, each in sigma~ and in the pillar's own sigma / d_c1; then per
    k~ the large-brush row (n_side = inf): sigma~_inf, sigma~_0 and the measured exponent p."""
    thr = next(iter(d.size_loss.values())).area_threshold if d.size_loss else sl.AREA_THRESHOLD
    t = Table("size_loss", "Where adhesion is lost, per brush size and for a large brush "
              f"(per-area threshold F̃_A = {thr:g})")
    t.csv_rows.append([
        "k_tilde", "n_side", "n_pillars", "n_seeds", "k_pillar", "few_threshold", "sigma_few",
        "sigma_few_lo", "sigma_few_hi", "few_kind", "pillar_sigma_few", "area_threshold",
        "sigma_area", "sigma_area_lo", "sigma_area_hi", "area_kind", "area_below_floor",
        "pillar_sigma_area", "area_trend", "sigma_zero", "sigma_zero_lo", "sigma_zero_hi",
        "zero_kind", "p", "p_lo", "p_hi", "p_state", "few_drift", "few_drift_lo",
        "few_drift_hi", "few_drift_state", "area_drift", "area_drift_lo", "area_drift_hi",
        "area_drift_state", "spring_few", "spring_area", "reach_few", "reach_area"])
    t.page_rows.append(["k̃", "n_side", "k/(E* D)", f"σ̃ at {FEW_PILLARS:g} pillars [CI]",
                        "σ/d_c1 there", f"σ̃ at F̃_A = {thr:g} [CI]", "σ/d_c1 there",
                        "k σ/F_c1 there", "σ/(d_c1 + F_c1/k) there", "note"])
    for k, s in d.size_loss.items():
        for few, area in zip(s.few, s.area):
            n = few.n_side
            ps_few = sl.pillar_sigma(few.sigma, n, s.phi)
            ps_area = sl.pillar_sigma(area.sigma, n, s.phi)
            kp = sl.pillar_k(k, n, s.phi)
            t.csv_rows.append([
                repr(k), str(n), str(n * n), str(s.n_seeds.get(n, 0)), num(kp),
                num(few.threshold), num(few.sigma), *_ci(few.ci), few.kind, num(ps_few),
                num(area.threshold), num(area.sigma), *_ci(area.ci), area.kind,
                str(area.below_floor).lower(), num(ps_area), *[""] * 17,
                num(sl.pillar_spring(few.sigma, k, n, s.phi)),
                num(sl.pillar_spring(area.sigma, k, n, s.phi)),
                num(sl.pillar_reach(few.sigma, k, n, s.phi)),
                num(sl.pillar_reach(area.sigma, k, n, s.phi))])
            note = (f"the per-area threshold is within {FEW_PILLARS:g} pillars' pull-off here"
                    if area.below_floor else "")
            t.page_rows.append([f"{k:g}", str(n), fmt(kp, ".3g"),
                                _sigma_cell(few.kind, few.sigma, few.ci, few.bracket),
                                fmt(ps_few, ".3g"),
                                _sigma_cell(area.kind, area.sigma, area.ci, area.bracket),
                                fmt(ps_area, ".3g"),
                                fmt(sl.pillar_spring(area.sigma, k, n, s.phi), ".3g"),
                                fmt(sl.pillar_reach(area.sigma, k, n, s.phi), ".3g"), note])
        t.csv_rows.append([
            repr(k), "inf", "inf", str(min(s.n_seeds.values(), default=0)), "inf", "", "", "",
            "", "", "", num(s.area_threshold), num(s.sigma_inf), *_ci(s.sigma_inf_ci),
            s.sigma_inf_kind, "", "inf", s.area_trend, num(s.sigma_zero), *_ci(s.sigma_zero_ci),
            s.sigma_zero_kind, num(s.p), *_ci(s.p_ci), s.p_state,
            *_drift_cells(s.few_drift), *_drift_cells(s.area_drift), "inf", "inf", "", ""])
        zero = _sigma_cell(s.sigma_zero_kind, s.sigma_zero, s.sigma_zero_ci,
                           s.sigma_zero_bracket)
        t.page_rows.append([
            f"{k:g}", "∞ (P∞)", "∞", "—", "∞",
            _sigma_cell(s.sigma_inf_kind, s.sigma_inf, s.sigma_inf_ci, s.sigma_inf_bracket), "∞",
            "∞", "—",
            f"σ̃ where P∞ = 0: {zero}; per-area crossing over the two largest sizes: "
            f"{s.area_trend}; p {_p_text(s.p, s.p_ci)} ({s.p_state}); "
            f"d ln σ̃ / d ln N at {FEW_PILLARS:g} pillars {_drift_text(s.few_drift)}, "
            f"at F̃_A = {thr:g} {_drift_text(s.area_drift)}"])
    return t


def extrapolation_table(d) -> Table:
    """Per k~ and sigma~ run at every size: P_inf, A of P(N) = P_inf + A N^(-3/4), chi^2 and
    the state of P_inf."""
    t = Table("size_extrapolation", "The plateau extrapolated in the number of pillars N: "
              "P(N) = P∞ + A N^(−3/4)")
    t.csv_rows.append(["k_tilde", "sigma_tilde", "n_sides", "P_inf", "P_inf_lo", "P_inf_hi",
                       "A", "chi2", "dof", "state"])
    t.page_rows.append(["k̃", "σ̃", "sizes", "P∞ [CI]", "A", "χ² (dof)", "P∞"])
    for k, s in d.size_loss.items():
        for e in s.extrapolations:
            t.csv_rows.append([repr(k), repr(e.sigma_tilde), " ".join(map(str, e.n_sides)),
                               num(e.p_inf), *_ci(e.p_inf_ci), num(e.amplitude), num(e.chi2),
                               str(e.dof), e.state])
            t.page_rows.append([f"{k:g}", f"{e.sigma_tilde:g}", ", ".join(map(str, e.n_sides)),
                                val_ci(e.p_inf, e.p_inf_ci, ".3g"), fmt(e.amplitude, ".3g"),
                                f"{fmt(e.chi2, '.2g')} ({e.dof})",
                                _state_cell(e.state)])
    return t


def _state_cell(state: str) -> str:
    if state == sl.BELOW:
        return "**below 0**: the line overshoots (a plateau is never negative)"
    return f"**{state}**" if state in (sl.GONE, sl.REJECTED) else state


def headline_line(size_loss: dict) -> str:
    """One line: per k~, where adhesion per area is lost (sigma~_inf) beside the few-pillar
    crossing of each size."""
    sizes = {s.n_sides for s in size_loss.values()}
    own = len(sizes) > 1                 # k~ read over different sizes: each says its own
    parts = []
    for k, s in size_loss.items():
        few = ", ".join(f"{c.n_side}: {_sigma_cell(c.kind, c.sigma, c.ci, c.bracket)}"
                        for c in s.few)
        inf = _sigma_cell(s.sigma_inf_kind, s.sigma_inf, s.sigma_inf_ci, s.sigma_inf_bracket)
        of = f" (sizes {', '.join(map(str, s.n_sides))})" if own else ""
        area = (f"per area (F̃_A = {s.area_threshold:g}) {_not_size_free(s)}"
                if s.sigma_inf_kind == sl.NOT_SIZE_FREE else
                f"per area (F̃_A = {s.area_threshold:g} in the N → ∞ extrapolation) σ̃ = {inf}")
        if s.sigma_inf_kind == sl.BRACKET and s.area_drift.state != sl.NOT_MEASURED \
                and sl.FIXED_SIGMA not in s.area_drift.state:
            # an extrapolated limit from sizes whose crossings have not settled: say so
            area += f" (the sizes' crossings still move: q = {_drift_text(s.area_drift)})"
        if s.sigma_inf_kind == sl.BRACKET and s.p_state != sl.CONSISTENT:
            # the limit rests on the exponent 3/4; say where the sizes do not back it
            area += (" (N^(−3/4) assumed: " + (
                f"these sizes measure p {_p_text(s.p, s.p_ci)}" if s.p_state == sl.DIFFERS
                else "these sizes do not determine the exponent") + ")")
        parts.append(f"k̃ = {k:g}{of}: {area}; at {FEW_PILLARS:g} pillars, by n_side, {few}")
    head = ("Loss across sizes: " if own else "Loss across sizes (sizes " + ", ".join(
        str(n) for n in next(iter(sizes))) + "): ")
    return head + "; ".join(parts) + "."


__all__ = ["table", "extrapolation_table", "headline_line"]
