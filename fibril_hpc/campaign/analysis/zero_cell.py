"""alpha/beta's zero on the page: where the fitted line c(sigma~) = alpha/sigma~ - beta reaches
0 is an *extrapolation* of that line, shown beside the measured sigma~_c and described against
its span (inside, above or below), never a second sigma~_c with a verdict.

The one place the page reads the law's zero from a study (:func:`law_zero`, from the states
:mod:`..laws.verdict` decided); the alpha/beta table's zero cell (:func:`zero_cell`, in the
words of :mod:`.verdict_text`).
"""

from __future__ import annotations

import math

from ..laws.verdict import Relation, ZeroReason, ZeroState
from .verdict_text import NO_ZERO_WORDS, RELATION_WORDS, fmt_ci


def law_zero(st) -> tuple:
    """(alpha/beta, its seed interval, relation, why none) of one k~'s study: the value NaN and
    ``why`` a :class:`..laws.verdict.ZeroReason` where the line shows no zero (the law not
    fitted, beta consistent with 0); ``relation`` a key of
    :data:`.verdict_text.RELATION_WORDS` or ""."""
    v = st.verdict
    if v.zero != ZeroState.EXTRAPOLATED or not math.isfinite(st.ab.sigma_c):
        why = v.zero_reason if v.zero_reason in NO_ZERO_WORDS else ZeroReason.NONE
        return math.nan, (math.nan, math.nan), "", why
    rel = v.relation if v.relation in RELATION_WORDS else Relation.NONE
    return st.ab.sigma_c, st.sigma_c_ci, rel, ZeroReason.NONE


def zero_cell(st) -> str:
    """The alpha/beta table's cell: 'A [lo, hi], inside the measured span', or '— (why)'."""
    z, ci, rel, why = law_zero(st)
    if not math.isfinite(z):
        return f"— ({NO_ZERO_WORDS[why]})"
    return fmt_ci(z, ci) + (f", {RELATION_WORDS[rel]}" if rel else "")


__all__ = ["law_zero", "zero_cell", "RELATION_WORDS", "NO_ZERO_WORDS"]
