"""alpha/beta's zero on the page: where the fitted line c(sigma~) = alpha/sigma~ - beta reaches
0 is an *extrapolation* of that line, shown beside the measured sigma~_c and described against
it (inside, above or below the measured span), never a second sigma~_c with a verdict.

The one place the page reads the law's zero from a study (:func:`law_zero`); the words of the
alpha/beta table's zero cell (:func:`zero_cell`).
"""

from __future__ import annotations

import math

from ..laws.study import beta_is_zero
from ..laws.loss import fmt_ci

#: where the zero lies against the measured loss, in the page's words
RELATION_WORDS = {
    "within": "inside the measured span",
    "above": "above the measured span (the line still gives c > 0 where adhesion is lost)",
    "below": "below the measured span (the line reaches 0 where the brush still holds)",
}
#: why the page shows no zero
NO_ZERO = {"not fitted": "law not fitted", "beta zero": "β consistent with 0: the line "
           "does not reach 0", "no zero": "the line does not reach 0"}
#: the comparison's values as laws.loss / laws.verdict spell them -> RELATION_WORDS' keys
_RELATION = {"agree": "within", "within": "within", "law above the measured loss": "above",
             "above": "above", "law below the measured loss": "below", "below": "below"}


def _value(x) -> str:
    return str(getattr(x, "value", x) or "")


def law_zero(st) -> tuple:
    """(alpha/beta, its seed interval, relation, why none) of one k~'s study: the value NaN and
    ``why`` one of :data:`NO_ZERO`'s keys where the page shows no zero (the law not fitted, beta
    consistent with 0, no finite zero); ``relation`` a key of :data:`RELATION_WORDS` or ""."""
    a = st.ab
    nan2 = (math.nan, math.nan)
    verdict = getattr(st, "verdict", None)
    if verdict is not None:                        # laws.verdict: the states decided there
        if _value(verdict.zero) != "extrapolated":
            why = {"BETA_ZERO": "beta zero"}.get(getattr(verdict.zero_reason, "name", ""),
                                                 "not fitted" if st.status != "fitted"
                                                 else "no zero")
            return math.nan, nan2, "", why
        return a.sigma_c, st.sigma_c_ci, _RELATION.get(_value(verdict.relation), ""), ""
    if st.status != "fitted":
        return math.nan, nan2, "", "not fitted"
    if beta_is_zero(st):
        return math.nan, nan2, "", "beta zero"
    if not math.isfinite(a.sigma_c):
        return math.nan, nan2, "", "no zero"
    return a.sigma_c, st.sigma_c_ci, _RELATION.get(_value(st.loss_vs_law), ""), ""


def zero_cell(st) -> str:
    """The alpha/beta table's cell: 'A [lo, hi], inside the measured span', or '— (why)'."""
    z, ci, rel, why = law_zero(st)
    if not math.isfinite(z):
        return f"— ({NO_ZERO[why]})"
    text = fmt_ci(z, ci)
    return text + (f", {RELATION_WORDS[rel]}" if rel else "")


__all__ = ["law_zero", "zero_cell", "RELATION_WORDS", "NO_ZERO"]
