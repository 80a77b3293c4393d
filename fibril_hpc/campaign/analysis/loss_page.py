"""The page's words on the measured loss of adhesion (:mod:`..laws.loss`): per k~ where adhesion
is lost along sigma~ (model-free), for a table cell, and the search grid's sigma~ limit. Inputs:
the per-k~ studies (:class:`..laws.study.KStudy`). The headline says it per k~
(:mod:`.headline`); alpha/beta's zero beside it is :mod:`.zero_cell`'s."""

from __future__ import annotations

import math

from ..laws import loss as _loss
from ..laws.loss import fmt_ci


def measured_span(st) -> tuple:
    """The honest interval of one k~'s measured sigma~_c: its bracket (lo, hi], widened where a
    state beside the loss is not certain with its seeds (``laws.loss.Loss.span``; without it,
    to the crossing's seed interval where that reaches beyond the bracket)."""
    loss = getattr(st, "loss", None)
    if loss is not None and hasattr(loss, "span"):
        return tuple(loss.span) if loss.uncertain else tuple(st.loss_bracket)
    (lo, hi), (a, b) = st.loss_bracket, st.sigma_loss_ci
    return (min(lo, a) if math.isfinite(a) else lo, max(hi, b) if math.isfinite(b) else hi)


def span_text(span) -> str:
    """'(lo, hi]' of :func:`measured_span` (∞ for an open end)."""
    return f"({span[0]:.4g}, {'∞' if span[1] == math.inf else f'{span[1]:.4g}'}]"


def measured_cell(st) -> str:
    """The measured sigma~_c of one k~ for a table cell: 'value [CI] in (lo, hi]' (the span of
    :func:`measured_span`), or the bound."""
    lo, hi = st.loss_bracket
    if st.loss_kind == _loss.BRACKET:
        return f"{fmt_ci(st.sigma_loss, st.sigma_loss_ci)} in {span_text(measured_span(st))}"
    if st.loss_kind == _loss.NO_LOSS:
        return f"> {lo:g} (no loss up to the largest σ̃ run)"
    if st.loss_kind == _loss.ALL_LOST:
        return f"< {hi:g} (lost at every σ̃ run)"
    return "—"


def search_max(meta) -> float:
    """The grid's ``sigma_tilde: auto`` upper limit (``max``), read by the planner's own parser;
    NaN for a fixed sigma~ list or a grid text that is missing or not valid."""
    import yaml

    from ...errors import ConfigError
    from ..plan.search import is_auto, parse_sigma

    try:
        grid = yaml.safe_load((meta or {}).get("campaign_yaml") or "") or {}
        value = grid.get("sigma_tilde") if isinstance(grid, dict) else None
        return parse_sigma(value).max if is_auto(value) else math.nan
    except (yaml.YAMLError, ConfigError):
        return math.nan


__all__ = ["measured_cell", "measured_span", "span_text", "search_max"]
