"""The page's first lines and its notes, from :class:`.report_data.ReportData`.

**The headline** (:func:`headline`, at most :data:`MAX_LINES` lines) answers one question per
k~: where this brush loses adhesion. One number and one interval per k~ (the measured sigma~_c,
model-free, and its span: the sigma~ run around it widened to the groups beside it whose state
is not certain with their seeds, and on a side with no certain group to where another seed set
of as many seeds would measure it (:attr:`..laws.loss.Loss.another`), the interval alpha/beta's
zero is set against, as the alpha/beta table's first column gives them:
:func:`.loss_page.measured_span`) and what it is of: the
brush (N pillars, phi), the preset and the seeds. Then one line on the law c = alpha/sigma~ -
beta (fitted, poor or undefined per k~; its zero an extrapolation, in the table), and, only
where something must be read before quoting the numbers, one line of cautions.

**The notes** (:func:`notes`): everything else the page says once, below the tables: the states
of the groups, the pillar floor, which error dominates, ``seeds: auto``, the finite-size
summary, the discretisation bias. A note said by a table (a group's shortfall of seeds, a k~
whose beta is consistent with 0) is not repeated here.
"""

from __future__ import annotations

import math

from ..laws import loss as _loss
from ..laws.intervals import dominant
from ..laws.reading import FEW_PILLARS, LOST, UNRESOLVED
from ..laws.size import AT_FLOOR, DIFFERS, WITHIN, reference_sizes
from ..laws.verdict import Relation
from .batching import C_BIAS
from .loss_page import measured_span, open_note, search_max, span_text
from .size_loss_page import headline_line as size_loss_line
from .tables import pct
from .verdict_text import RELATION_WORDS, law_why, why_out
from .zero_cell import law_zero

#: the headline's most lines (issue 34: a page a referee reads in two minutes)
MAX_LINES = 4
#: what a grid needs for alpha and beta (said on the page when a campaign cannot give them)
GRID_ADVICE = ("α and β need, per k̃, at least two σ̃ > 0 whose F̃_A rises with preload to a "
               "plateau the campaign reaches: σ̃ between about 0.07 and 0.9 (on 18 × 18 pillars "
               "F̃_A rises there for k̃ from 1 to 0.001, and stays flat at the last pillar's "
               "pull-off at σ̃ = 2.1 for k̃ = 1) and preloads from the first contacts to the "
               "plateau - `F_P: auto` places them (campaigns/demo.yaml is such a grid)")


def _ks(ks) -> str:
    return ", ".join(f"{k:g}" for k in ks)


def _seeds(d) -> str:
    n = sorted({g.n_seeds for st in d.studies.values() for g in st.groups})
    if not n:
        return "no seeds"
    span = f"{n[0]}" if len(n) == 1 else f"{n[0]}–{n[-1]}"
    return f"{span} seed{'s' if n[-1] > 1 else ''} per (k̃, σ̃)" + (
        " (seeds: auto)" if d.seeds_auto else "")


def of_what(d) -> str:
    """What the measured sigma~_c is of: the brush, the preset, the seeds, what is read."""
    parts = []
    n, phi = d.brush[0], d.brush[1]
    if n is not None:
        parts.append(f"{n * n} pillars ({n} × {n}), φ = {phi:g}")
    parts.append(f"preset {d.preset}" if d.preset else "preset unknown")
    parts.append(_seeds(d))
    if d.n_sides:
        parts.append(f"n_side = {d.n_side} of {', '.join(map(str, d.n_sides))}")
    if d.variant is not None:
        parts.append(d.variant.label)
    return ", ".join(parts)


def _loss_value(k, st, sigma_max) -> str:
    """One k~'s measured sigma~_c as the alpha/beta table's first column gives it."""
    lo, hi = st.loss_bracket
    if st.loss_kind == _loss.BRACKET:
        return (f"k̃ = {k:g}: {st.sigma_loss:.3g}, lost in "
                f"{span_text(measured_span(st))}")
    if st.loss_kind == _loss.NO_LOSS:
        at_max = math.isfinite(sigma_max) and lo >= sigma_max
        return (f"k̃ = {k:g}: > {lo:g} (no loss up to the largest σ̃ run"
                + (", the search's limit" if at_max else "") + f"{open_note(st)})")
    if st.loss_kind == _loss.ALL_LOST:
        return f"k̃ = {k:g}: < {hi:g} (lost at every σ̃ run{open_note(st)})"
    return f"k̃ = {k:g}: not measured"


def _law_line(d) -> str:
    by = {s: [k for k, st in d.studies.items() if st.status == s]
          for s in ("fitted", "poor fit", "undefined")}
    n = len(d.studies)
    parts = []
    if by["fitted"]:
        parts.append(f"fitted within the seed scatter for k̃ = {_ks(by['fitted'])}")
    if by["poor fit"]:
        parts.append("a **poor fit** (for orientation only) for k̃ = " + ", ".join(
            f"{k:g} (χ²/dof {d.studies[k].ab.chi2_red:.3g})" for k in by["poor fit"]))
    if by["undefined"]:
        parts.append(f"undefined for k̃ = {_ks(by['undefined'])}")
    rel = {}
    for k, st in d.studies.items():             # law_zero: st.verdict's relation, if a zero
        r = law_zero(st)[2]
        if r in (Relation.ABOVE, Relation.BELOW):
            rel.setdefault(r, []).append(k)
    where = "; ".join(f"{RELATION_WORDS[r].split(' (')[0]} for k̃ = {_ks(ks)}"
                      for r, ks in rel.items())
    if not any(math.isfinite(law_zero(st)[0]) for st in d.studies.values()):
        # no line shows a zero (none fitted, or beta consistent with 0): none to speak of
        return f"c = α/σ̃ − β ({n} k̃): " + "; ".join(parts) + "." + (
            " No line shows a zero (the α/β table says why)."
            if by["fitted"] or by["poor fit"] else "")
    return (f"c = α/σ̃ − β ({n} k̃): " + "; ".join(parts) + ". Its zero α/β is an "
            "extrapolation of that line, given beside the measurement in the α/β table"
            + (f" ({where})" if where else "") + ".")


def _cautions(d) -> list:
    out = []
    bad = d.n_failed + d.n_nonfinite
    if bad:
        out.append(f"{bad} of {d.n_jobs} jobs failed or gave non-finite forces (left out)")
    if getattr(d, "far_field", "exact") == "multipole":
        out.append("its jobs were solved with solver.far_field: multipole, whose contact "
                   "events are not certified, so F̃_A is not (each relaxed state's force is, "
                   "within confirm_tol of the exact state on its set; on the 18 × 18 and "
                   "36 × 36 corner scenes at F̃_P = 4, F̃_A within 9e-5 relative at preset "
                   "default, up to 1.6 % at fast; on paper.yaml's smooth corners at small "
                   "preloads up to 0.23 % at default and 0.71 % at fast; docs/model.md §6): "
                   "no interval here includes that")
    unsure = [k for k, st in d.studies.items() if st.loss_kind == _loss.BRACKET
              and st.loss.uncertain]
    if unsure:
        out.append(f"for k̃ = {_ks(unsure)} a group beside the loss is not certainly lost or "
                   "holding with its seeds (its interval is widened to hold it)")
    away = d.elsewhere
    if away:
        ks = sorted(away, reverse=True)
        out.append(f"k̃ = {_ks(ks)} ran no job at n_side = {d.n_side} (largest: "
                   + ", ".join(f"{away[k]}" for k in ks) + "): the σ̃_c line, the "
                   "per-(k̃, σ̃) tables and the figures leave them out; the across-sizes tables "
                   "read them at their sizes")
    if d.seed_limits:
        out.append(f"{len(d.seed_limits)} (k̃, σ̃) stopped at the maximum of seeds: auto short "
                   "of its precision target (plateau table)")
    undefined = [k for k, st in d.studies.items() if st.status == "undefined"]
    if undefined and not any(d.studies[k].ab.ok for k in undefined):
        out.append("α and β need a wider grid (notes)")
    return out


def headline(d) -> list:
    """The page's first lines (at most :data:`MAX_LINES`): where the brush loses adhesion per
    k~, what that is of, the law's line, and the cautions to read before quoting them."""
    if not d.studies:
        return [f"No done job with finite forces ({d.n_jobs} job records, {d.n_failed} failed): "
                "nothing to read. " + GRID_ADVICE + "."]
    smax = search_max(d.meta)
    lines = [f"Where this brush loses adhesion, σ̃_c per k̃ (model-free: the σ̃ where the "
             f"seed-mean plateau falls to {FEW_PILLARS:g} pillars' pull-off; lost in: the σ̃ "
             f"run around it, widened to any σ̃ beside it whose state its seeds leave uncertain, "
             f"and where none is certain to where another seed set as large would measure it), "
             f"of {of_what(d)}:",
             "; ".join(_loss_value(k, st, smax) for k, st in d.studies.items()) + ".",
             _law_line(d)]
    if getattr(d, "size_loss", None):
        # a grid sweeping n_side: the large-brush (per-area) loss beside each size's crossing
        lines.insert(2, size_loss_line(d.size_loss))
    cautions = _cautions(d)
    if cautions:
        lines.append("Before quoting: " + "; ".join(cautions) + ".")
    if len(lines) > MAX_LINES:
        lines[MAX_LINES - 1:] = [" ".join(lines[MAX_LINES - 1:])]
    return lines


def notes(d) -> list:
    """Every other line the page says about the campaign, each once (below the tables)."""
    if not d.studies:
        return []
    out = []
    states: dict = {}
    for st in d.studies.values():
        for g in st.groups:
            states[g.reading.state] = states.get(g.reading.state, 0) + 1
    out.append(f"States of the {sum(states.values())} (k̃, σ̃): "
               + ", ".join(f"{v} {s}" for s, v in sorted(states.items()))
               + (f" (pillar floor: {d.floor_note})" if d.floor_note else "") + ".")
    if d.coarse:
        out.append(f"{len(d.coarse)} (k̃, σ̃) were loaded in batches wider than a tenth of the "
                   "brush's length spread (records finished before loading batches were bounded "
                   "by it, or `load_merge_spread` set above 0.1): "
                   + ", ".join(f"({k:g}, {s:g})" for k, s in d.coarse)
                   + ". Their plateau stands, their rise does not: many pillars touch at once, "
                   f"F̃_A rises early and c comes out too high (by up to {C_BIAS:.0%} on "
                   "the same seeds; no reading of c undoes it). Rerun them into a fresh output.")
    if states.get(UNRESOLVED):
        out.append(f"{states[UNRESOLVED]} (k̃, σ̃) have a rise not resolved: F̃_A is already "
                   "near the plateau at the smallest preload reached, c is only a lower bound "
                   "and stays out of the fit (the coefficients table says which preload would "
                   "resolve it).")
    if states.get(LOST):
        out.append(f"{states[LOST]} (k̃, σ̃) have lost adhesion (a plateau within "
                   f"{FEW_PILLARS:g} pillars' pull-off): c = 0 by that threshold, left out of "
                   "the α/β line, whose zero is set beside the measured loss.")
    undefined = [k for k, st in d.studies.items() if st.status == "undefined"]
    if undefined:
        left: dict = {}
        for k in undefined:
            for g in d.studies[k].groups:
                if g.out:
                    left.setdefault(why_out(g).split(":")[0], []).append(
                        f"({k:g}, {g.sigma_tilde:g})")
        why = "; ".join(f"{w}: {', '.join(v)}" for w, v in left.items())
        out.append("α and β undefined: " + "; ".join(
            f"k̃ = {k:g}: {law_why(d.studies[k])}" for k in undefined)
            + (f". Left out of the fit: {why}" if why else "") + "."
            # the grid advice where too few sigma~ could be fitted, not where the law was
            # fitted and failed (alpha consistent with 0 on many rising groups)
            + ("" if all(d.studies[k].ab.ok for k in undefined) else " " + GRID_ADVICE + "."))
    dom: dict = {}
    for st in d.studies.values():
        for g in st.groups:
            for name, v, ci in (("plateau", g.reading.plateau, g.plateau_ci),
                                ("c", g.reading.c, g.c_ci)):
                dom.setdefault(name, []).append(dominant(v, ci, d.bias))
    if any(x != "unknown" for v in dom.values() for x in v):
        out.append("Larger error: " + "; ".join(
            f"{name}: the seeds in {v.count('seeds')}, the discretisation in "
            f"{v.count('discretisation')} of {len(v)} (k̃, σ̃)" for name, v in dom.items()) + ".")
    if d.seeds_auto:
        out.append(seeds_line(d.seeds_auto, d.seed_limits))
    if d.n_sides:
        out.append(size_line(d))
    if math.isfinite(d.bias):
        out.append(f"Discretisation bias: {d.bias_note} ({100 * d.bias:+.1f} % on every "
                   "force-like number; measured on one scene, carried over as an assumption).")
    else:
        out.append(f"Discretisation bias: {d.bias_note}.")
    return out


def seeds_line(auto: dict | None, limits: list) -> str:
    """The notes' line on ``seeds: auto`` ("" without it): the rule, and which (k~, sigma~)
    stopped at its maximum (what is short is said once, in the plateau table)."""
    if not auto:
        return ""
    head = (f"seeds: auto (from {auto['start']}, at most {auto['max']} per (k̃, σ̃), target: "
            f"intervals {100 * auto['width']:.0f} % wide)")
    if not limits:
        return head + ": no (k̃, σ̃) stopped at the maximum short of the target."
    return (head + f": {len(limits)} (k̃, σ̃) stopped at the maximum short of the target, their "
            "intervals as narrow as the campaign could make them, not as asked ("
            + "; ".join(f"k̃ = {x.k_tilde:g}, σ̃ = {x.sigma_tilde:g}" for x in limits)
            + "; the plateau table says what is short).")


def size_line(d) -> str:
    """The finite-size note: per smaller n_side, the range of the plateau's relative change
    against the largest n_side (of each k~, in a merged file whose k~ ran other sizes), and in
    how many (k~, sigma~) it is within the seed scatter."""
    top = max(d.n_sides)

    def ref_of(r) -> int:
        return getattr(r, "ref_n_side", None) or top

    refs = reference_sizes(d.size, d.n_sides)
    ref = refs[0] if len(refs) == 1 else None
    text = (f"Finite size: n_side = {', '.join(map(str, d.n_sides))}; the other tables and "
            f"figures read n_side = {d.n_side if d.n_side is not None else '—'}"
            + (" (the largest with done jobs)" if d.n_side not in (None, top) else "")
            + (f". Plateau against n_side = {ref}: " if ref else
               f". Plateau against each k̃'s largest n_side ({', '.join(map(str, refs))}): "))
    parts = []
    for n in d.n_sides:
        rows = [r for r in d.size if r.n_side == n and n != ref_of(r)]
        rel = sorted(r.rel for r in rows if math.isfinite(r.rel))
        if not rows:
            continue
        if not rel:
            parts.append(f"n_side = {n}: no relative change (no plateau at "
                         f"{ref if ref else 'the reference'})")
            continue
        within = sum(r.verdict == WITHIN for r in rows)
        known = sum(r.verdict in (WITHIN, DIFFERS) for r in rows)
        floor = sum(r.verdict == AT_FLOOR for r in rows)
        said = ([f"within the seed scatter in {within} of {known} (k̃, σ̃)"] if known else []) + (
            [f"not resolved in {floor}: the {f'n_side = {ref}' if ref else 'reference'} plateau "
             f"may be the {FEW_PILLARS:g}-pillar floor"]
            if floor else [])
        parts.append(f"n_side = {n}: {pct(rel[0])} … {pct(rel[-1])} %"
                     + (f" ({'; '.join(said)})" if said else ""))
    unread = (len(d.n_sides) >= 2 and not d.size_loss and not math.isfinite(d.floor)
              and d.floor_note)
    return text + ("; ".join(parts) if parts else "no smaller n_side with a plateau yet") + "." + (
        f" Where adhesion is lost across sizes is not read ({d.floor_note}: its thresholds are "
        "flat pillars' pull-off)." if unread else "")


__all__ = ["headline", "notes", "of_what", "seeds_line", "size_line", "MAX_LINES",
           "GRID_ADVICE"]
