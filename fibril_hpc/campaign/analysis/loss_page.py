"""The page's words on the measured loss of adhesion (:mod:`..laws.loss`): per k~ where adhesion
is lost along sigma~ (model-free), and where alpha/beta's extrapolated sigma~_c disagrees with
it, in plain words. Inputs: the per-k~ studies (:class:`..laws.study.KStudy`)."""

from __future__ import annotations

import math

from ..laws import loss as _loss
from ..laws.verdict import Relation
from ..laws.reading import FEW_PILLARS
from .verdict_text import RELATION_WORDS, fmt_ci, relation_why


def measured_cell(st) -> str:
    """The measured sigma~_c of one k~ for a table cell: 'value [CI] in (lo, hi]', or the bound."""
    lo, hi = st.loss.span if st.loss.uncertain else st.loss_bracket
    if st.loss_kind == _loss.BRACKET:
        return f"{fmt_ci(st.sigma_loss, st.sigma_loss_ci)} in ({lo:.4g}, {hi:.4g}]"
    if st.loss_kind == _loss.NO_LOSS:
        return f"> {lo:g} (no loss up to the largest σ̃ run)"
    if st.loss_kind == _loss.ALL_LOST:
        return f"< {hi:g} (lost at every σ̃ run)"
    return "—"


def verdict_cell(st) -> str:
    """alpha/beta against the measured loss for a table cell: a disagreement in bold."""
    words = RELATION_WORDS.get(st.loss_vs_law)
    if not words:
        return "—"
    return words if st.loss_vs_law == Relation.WITHIN else f"**{words}**"


def _in(span) -> str:
    return f"({span[0]:.3g}, {'∞' if span[1] == math.inf else f'{span[1]:.3g}'}]"


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


def headline_lines(studies: dict, sigma_max: float = math.nan) -> list:
    """The headline's lines: where adhesion is lost per k~, then every k~ whose alpha/beta
    sigma~_c disagrees with it (one line each), then those that agree. ``sigma_max``: a search
    grid's upper limit of sigma~ (:func:`search_max`): a k~ without a loss up to it is said to
    have reached the search's limit."""
    if not studies:
        return []
    by: dict = {}
    for k, st in studies.items():
        by.setdefault(st.loss_kind, []).append((k, st))
    parts = []
    if by.get(_loss.BRACKET):
        parts.append("; ".join(f"k~ = {k:g} at {fmt_ci(st.sigma_loss, st.sigma_loss_ci)} "
                               + (f"(bracket {st.loss_bracket[0]:g}-{st.loss_bracket[1]:g})"
                                  if not st.loss.uncertain else
                                  f"(a state not certain with its seeds: in {_in(st.loss.span)})")
                               for k, st in by[_loss.BRACKET]))
    if by.get(_loss.NO_LOSS):
        parts.append("no loss up to the largest sigma~ run for k~ = " + ", ".join(
            f"{k:g} (sigma~_c > {st.loss_bracket[0]:g}"
            + (", the search's limit sigma_tilde.auto.max: raise it to look further"
               if st.loss_bracket[0] >= sigma_max else "") + ")"
            for k, st in by[_loss.NO_LOSS]))
    if by.get(_loss.ALL_LOST):
        parts.append("lost at every sigma~ run for k~ = " + ", ".join(
            f"{k:g} (sigma~_c < {st.loss_bracket[1]:g})" for k, st in by[_loss.ALL_LOST]))
    if by.get(_loss.NOT_READ):
        parts.append("not measured for k~ = " + ", ".join(f"{k:g}" for k, _ in by[_loss.NOT_READ]))
    lines = ["Measured sigma~_c (model-free: where the seed-mean plateau falls to "
             f"{FEW_PILLARS:g} pillars' pull-off, interpolated between the last sigma~ holding "
             "adhesion and the first lost): " + "; ".join(parts) + "."]
    bad = [(k, st) for k, st in studies.items()
           if st.loss_vs_law in (Relation.ABOVE, Relation.BELOW)]
    for k, st in bad:
        lines.append(f"**k~ = {k:g}: {relation_why(st)}.**")
    good = [k for k, st in studies.items() if st.loss_vs_law == Relation.WITHIN]
    if good:
        lines.append("alpha/beta's zero (an extrapolation) lies within the measured loss for k~ = "
                     + ", ".join(f"{k:g}" for k in good) + ".")
    return lines


__all__ = ["measured_cell", "verdict_cell", "headline_lines"]
