"""The page's words on the measured loss of adhesion (:mod:`..laws.loss`): per k~ where adhesion
is lost along sigma~ (model-free), for a table cell, and the search grid's sigma~ limit. Inputs:
the per-k~ studies (:class:`..laws.study.KStudy`). The headline says it per k~
(:mod:`.headline`); alpha/beta's zero beside it is :mod:`.zero_cell`'s."""

from __future__ import annotations

import math

from ..laws import loss as _loss
from .verdict_text import fmt_ci


def measured_span(st) -> tuple:
    """The honest interval of one k~'s measured sigma~_c, the one :mod:`..laws.verdict` sets
    alpha/beta's zero against (:attr:`..laws.loss.Loss.span`): its bracket (lo, hi], widened to
    the groups beside the loss whose state is not certain with their seeds, and on a side with
    no certain group to where another seed set of as many seeds would measure it (an infinite
    end stays infinite); the bracket where no span was made."""
    span = tuple(st.loss.span)
    return tuple(st.loss_bracket) if any(math.isnan(x) for x in span) else span


def span_text(span) -> str:
    """'(lo, hi]' of :func:`measured_span` (∞ for an open end)."""
    return f"({span[0]:.4g}, {'∞' if span[1] == math.inf else f'{span[1]:.4g}'}]"


def open_note(st) -> str:
    """Where no pair of groups brackets the loss (adhesion held at every sigma~ run, or lost at
    every one) but the end groups' seeds leave their state uncertain, the span that gives:
    '; with its seeds σ̃ = 0.6 is not certain: lost in (0.5, ∞]'; else ''. The bound alone
    ('> 0.6') would claim more than those seeds show."""
    lo, hi = st.loss_bracket
    span = tuple(st.loss.span)
    if not ((st.loss_kind == _loss.NO_LOSS and span[0] < lo)
            or (st.loss_kind == _loss.ALL_LOST and span[1] > hi)):
        return ""
    unc = [s for s in st.loss.uncertain if span[0] < s < span[1]]
    which = (f"σ̃ = {', '.join(f'{s:g}' for s in unc)} {'is' if len(unc) == 1 else 'are'} "
             "not certain" if unc else "the end groups are not certain")
    return f"; with its seeds {which}: lost in {span_text(span)}"


#: a bracket wider than this factor (two of the search's steps) is too coarse for its crossing's
#: seed interval: that is the scatter of the log-log line between its ends, not of the loss
WIDE_BRACKET = 4.0


def measured_cell(st) -> str:
    """The measured sigma~_c of one k~ for a table cell: 'value [CI] in (lo, hi]' (the span of
    :func:`measured_span`), or the bound. Over a bracket wider than :data:`WIDE_BRACKET` the
    seed interval is left out and the cell says why (a corner grid of sigma~ 0.01 and 2.1 read
    '0.574 [0.57, 0.579]')."""
    lo, hi = st.loss_bracket
    if st.loss_kind == _loss.BRACKET and lo > 0 and hi / lo > WIDE_BRACKET:
        return (f"{st.sigma_loss:.4g} in {span_text(measured_span(st))} (the bracket is "
                f"× {hi / lo:.3g} wide: the value is the log–log line's between its ends and "
                "has no seed interval worth quoting; σ̃ inside it would measure the loss)")
    if st.loss_kind == _loss.BRACKET:
        return f"{fmt_ci(st.sigma_loss, st.sigma_loss_ci)} in {span_text(measured_span(st))}"
    if st.loss_kind == _loss.NO_LOSS:
        return f"> {lo:g} (no loss up to the largest σ̃ run{open_note(st)})"
    if st.loss_kind == _loss.ALL_LOST:
        return f"< {hi:g} (lost at every σ̃ run{open_note(st)})"
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


__all__ = ["WIDE_BRACKET", "measured_cell", "measured_span", "span_text", "search_max"]
