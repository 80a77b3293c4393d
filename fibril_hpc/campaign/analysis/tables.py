"""The report's tables from :class:`.report_data.ReportData`: each a :class:`Table` that renders
as CSV (full precision, one column per number), Markdown and HTML.

An undefined value is an empty CSV cell and an em dash on the page; the row's note says why.
Intervals are seed intervals (:mod:`.laws.intervals`); "bias" is the preset's discretisation
bias applied to the value; "dominant" says which of the two is larger.
"""

from __future__ import annotations

import csv
import html
import io
import math
import re
import statistics
from dataclasses import dataclass, field

from ..laws.intervals import dominant
from ..laws.size import DIFFERS, reference_sizes
from .loss_page import measured_cell, measured_span
from .notation import clauses, once, page_text
from .verdict_text import (ab_notes, ci_method, law_why, line_out, loss_note, relation_why,
                           study_notes)
from .zero_cell import zero_cell


@dataclass
class Table:
    """A table: CSV rows (the first is the header) and page rows (header first)."""

    name: str
    title: str
    csv_rows: list = field(default_factory=list)
    page_rows: list = field(default_factory=list)

    def csv(self) -> str:
        """The CSV text."""
        buf = io.StringIO()
        csv.writer(buf, lineterminator="\n").writerows(self.csv_rows)
        return buf.getvalue()

    def markdown(self) -> str:
        """The Markdown table (pipes in cells escaped)."""
        rows = [[page_text(c).replace("|", "\\|").replace("\n", " ") for c in r]
                for r in self.page_rows]
        if not rows:
            return ""
        out = ["| " + " | ".join(rows[0]) + " |", "|" + " --- |" * len(rows[0])]
        out += ["| " + " | ".join(r) + " |" for r in rows[1:]]
        return "\n".join(out) + "\n"

    def html(self) -> str:
        """The HTML table."""
        if not self.page_rows:
            return ""
        def cell(c):                # **x** (a flag on the page) becomes bold
            return re.sub(r"\*\*(.+?)\*\*", r"<strong>\1</strong>", html.escape(page_text(c)))

        head = "".join(f"<th>{cell(c)}</th>" for c in self.page_rows[0])
        body = "".join("<tr>" + "".join(f"<td>{cell(c)}</td>" for c in r) + "</tr>"
                       for r in self.page_rows[1:])
        return f"<table><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>"


def num(v) -> str:
    """A CSV number: full precision, empty when undefined."""
    return repr(float(v)) if v is not None and math.isfinite(v) else ""


def num_inf(v) -> str:
    """A CSV interval end: :func:`num`, and ``inf`` for an unbounded one."""
    return "inf" if v == math.inf else num(v)


def fmt(v, f=".4g") -> str:
    """A page number: an em dash when undefined, ∞ for infinity."""
    if v is None or (isinstance(v, float) and math.isnan(v)):
        return "—"
    if math.isinf(v):
        return "∞" if v > 0 else "−∞"
    return format(v, f)


def val_ci(v, ci, f=".4g") -> str:
    """'value [lo, hi]'; an undefined value is one em dash; no interval: the value alone."""
    if v is None or not math.isfinite(v):
        return "—"
    if all(isinstance(x, float) and math.isnan(x) for x in ci):
        return fmt(v, f)
    return f"{fmt(v, f)} [{fmt(ci[0], '.3g')}, {fmt(ci[1], '.3g')}]"


def bias_cell(v, bias) -> str:
    """The bias of ``v`` (relative bias x value), or an em dash when unknown."""
    if not (math.isfinite(bias) and v is not None and math.isfinite(v)):
        return "—"
    if v == 0:
        return "0"
    return f"{fmt(bias * v, '+.2g')} ({100 * bias:+.1f} %)"


def _ci_csv(ci) -> list:
    return [num(ci[0]), num(ci[1])]


def _ab_note(st) -> str:
    """The alpha/beta row's note, each clause once: why the law is not fitted, what the loss
    adds to the measured cell (an uncertain state, adhesion found again), the fit's notes.
    The zero's relation to the loss is its own cell (:func:`.zero_cell.zero_cell`)."""
    extra = clauses(loss_note(st))[1:]
    return once([law_why(st)] + extra + ab_notes(st.ab) + study_notes(st))


def alpha_beta(d) -> Table:
    """Per k~: the measured sigma~_c first; then alpha, beta with seed intervals (a poor fit
    for orientation, an undefined law with its reason) and the line's zero alpha/beta, an
    extrapolation described against the measured span, never a second sigma~_c; the bias,
    quality, notes."""
    t = Table("alpha_beta", "σ̃_c measured, and c = max(α/σ̃ − β, 0) per k̃")
    t.csv_rows.append(["k_tilde", "status", "alpha", "alpha_lo", "alpha_hi", "beta", "beta_lo",
                       "beta_hi", "sigma_tilde_c", "sigma_tilde_c_lo", "sigma_tilde_c_hi",
                       "sigma_tilde_c_status", "bracket_c_positive_up_to", "bracket_c_zero_from",
                       "n_sigma_in_fit", "n_c_zero", "chi2_per_dof", "poor_fit", "bias_rel",
                       "dominant_alpha", "ci_method", "sigma_tilde_c_measured",
                       "sigma_tilde_c_measured_lo", "sigma_tilde_c_measured_hi", "loss_kind",
                       "loss_bracket_lo", "loss_bracket_hi", "sigma_tilde_c_another_lo",
                       "sigma_tilde_c_another_hi", "loss_span_lo", "loss_span_hi",
                       "loss_vs_law", "loss_vs_law_why", "note"])
    t.page_rows.append(["k̃", "σ̃_c measured: adhesion lost [seed CI] in its span "
                        "(model-free)", "law", "α [seed CI]", "β [seed CI]",
                        "zero of the line, α/β: an extrapolation [seed CI]",
                        "σ̃ active in fit (lost, left out)", "χ²/dof", "bias of α",
                        "larger error", "note"])
    for k, st in d.studies.items():
        a = st.ab
        note = _ab_note(st)
        dom = dominant(a.alpha, st.alpha_ci, d.bias)
        t.csv_rows.append([repr(k), str(st.status), num(a.alpha), *_ci_csv(st.alpha_ci),
                           num(a.beta),
                           *_ci_csv(st.beta_ci), num(a.sigma_c), *_ci_csv(st.sigma_c_ci),
                           str(st.verdict.zero), num(a.bracket[0]), num(a.bracket[1]),
                           str(a.n_active), str(a.n_zero), num(a.chi2_red), str(a.poor).lower(),
                           num(d.bias), dom, ci_method(st), num(st.sigma_loss),
                           *_ci_csv(st.sigma_loss_ci), st.loss_kind, num(st.loss_bracket[0]),
                           num(st.loss_bracket[1]), *map(num_inf, st.loss.another),
                           *map(num_inf, measured_span(st)), str(st.loss_vs_law), relation_why(st),
                           note])
        shown = st.status != "undefined"
        law = st.status if st.status == "fitted" else f"**{st.status}**"
        t.page_rows.append([f"{k:g}", measured_cell(st), law,
                            val_ci(a.alpha, st.alpha_ci) if shown else "—",
                            val_ci(a.beta, st.beta_ci) if shown else "—", zero_cell(st),
                            f"{a.n_active} ({a.n_zero})", fmt(a.chi2_red, ".3g")
                            + (" **poor fit**" if a.poor else ""),
                            bias_cell(a.alpha, d.bias) if shown else "—", dom, note])
    return t


def _seed_counts(r) -> str:
    """Seeds per level, ascending preload: '3' when every level has the same, else the list."""
    if not r.seeds:
        return "—"
    if len(set(r.seeds)) == 1:
        return str(r.seeds[0])
    return "**" + " ".join(str(n) for n in r.seeds) + "**"


def plateau(d) -> Table:
    """Per (k~, sigma~): the plateau, its state, where it was read, the top preload's range."""
    t = Table("plateau", "Plateau per (k̃, σ̃): the preload-insensitive F̃_A")
    t.csv_rows.append(["k_tilde", "sigma_tilde", "plateau", "plateau_lo", "plateau_hi",
                       "state", "read_from_F_P", "n_levels_in_plateau", "F_P_largest",
                       "F_A_largest_seed_min", "F_A_largest_seed_max", "n_seeds",
                       "seeds_per_level", "group_state", "bias_rel", "dominant", "note"])
    t.page_rows.append(["k̃", "σ̃", "plateau [seed CI]", "plateau", "state of the rise",
                        "read from F̃_P ≥", "F̃_A at the largest full level (seed range)",
                        "seeds (per level if they differ)", "bias", "larger error", "note"])
    at_max = {(x.k_tilde, x.sigma_tilde): x.what() for x in d.seed_limits}
    for k, st in d.studies.items():
        for g in st.groups:
            r = g.reading
            lv = d.means.get((k, g.sigma_tilde))
            full = [] if lv is None else [i for i in range(len(lv)) if not lv.thin[i]]
            top = float(lv.F_P[full[-1]]) if full else math.nan
            dom = dominant(r.plateau, g.plateau_ci, d.bias)
            lim = at_max.get((k, g.sigma_tilde))
            note = once(r.notes + ([lim] if lim else []))
            t.csv_rows.append([repr(k), repr(g.sigma_tilde), num(r.plateau),
                               *_ci_csv(g.plateau_ci), r.plateau_state, num(r.plateau_from),
                               str(r.n_plateau), num(top), num(r.top_lo), num(r.top_hi),
                               str(g.n_seeds), " ".join(map(str, r.seeds)), r.state,
                               num(d.bias), dom, note])
            state = r.plateau_state if r.plateau_state == "reached" else f"**{r.plateau_state}**"
            t.page_rows.append([f"{k:g}", f"{g.sigma_tilde:g}", val_ci(r.plateau, g.plateau_ci),
                                state, _state_cell(r), fmt(r.plateau_from, ".3g"),
                                f"{fmt(r.top_lo)} … {fmt(r.top_hi)} at {fmt(top, '.3g')}",
                                _seed_counts(r), bias_cell(r.plateau, d.bias), dom,
                                once(r.notes + ([f"**{lim}**"] if lim else []))])
    return t


def _state_cell(r) -> str:
    return r.state if r.state == "rise resolved" else f"**{r.state}**"


def _c_cell(r, ci) -> str:
    """c on the page: the value [CI] when the rise is resolved, '≥ bound' when not, 0 when lost."""
    if r.state == "rise not resolved":
        return f"≥ {fmt(r.c_lower, '.3g')}"
    return val_ci(r.c, ci)


def coefficients(d) -> Table:
    """Per (k~, sigma~): the state, c (eq. 15 of the paper: slope through the origin over the
    secant through the origin to half the plateau), its other readings (c_stage, c_chord), c0
    (first contact)."""
    t = Table("coefficients", "Adhesion coefficient c and first-contact slope c₀ per (k̃, σ̃)")
    t.csv_rows.append(["k_tilde", "sigma_tilde", "state", "c", "c_lo", "c_hi", "c_resolution",
                       "c_lower_bound",
                       "c_stage", "c_chord", "n_stage_levels", "F_P_half_plateau",
                       "resolve_with_F_P_below", "c0", "c0_lo", "c0_hi", "F_P_smallest",
                       "F_A_smallest", "c_detectable", "in_alpha_beta_fit", "c_minus_law",
                       "bias_rel", "dominant_c", "why_out", "note"])
    t.page_rows.append(["k̃", "σ̃", "state", "c [seed CI]", "F̃_P at half plateau",
                        "c₀ [seed CI]", "smallest F̃_P", "in α/β fit: c − law", "bias of c",
                        "larger error", "note"])
    for k, st in d.studies.items():
        res = dict(zip(st.ab.sigmas, st.ab.residuals))
        for g in st.groups:
            r = g.reading
            out = line_out(g, st.ab)
            rr = res.get(g.sigma_tilde, math.nan) if not out else math.nan
            dom = dominant(r.c, g.c_ci, d.bias)
            note = once(r.c_notes)
            t.csv_rows.append([repr(k), repr(g.sigma_tilde), r.state, num(r.c), *_ci_csv(g.c_ci),
                               num(r.c_res), num(r.c_lower), num(r.c_stage), num(r.c_chord), str(r.n_stage),
                               num(r.F_P_half), num(r.resolve_below), num(r.c0),
                               *_ci_csv(g.c0_ci), num(r.F_P0), num(r.F_A0), num(r.c_detect),
                               str(not out).lower(), num(rr), num(d.bias), dom, out, note])
            fitcell = (f"no: {out}" if out else
                       f"yes: {fmt(rr, '+.3g')}" if st.ab.ok and st.status != "undefined" else
                       "yes (law undefined)" if st.ab.ok else "yes (no fit)")
            t.page_rows.append([f"{k:g}", f"{g.sigma_tilde:g}", _state_cell(r), _c_cell(r, g.c_ci),
                                fmt(r.F_P_half, ".3g"), val_ci(r.c0, g.c0_ci), fmt(r.F_P0, ".3g"),
                                fitcell, bias_cell(r.c, d.bias), dom, _c_page_note(r)])
    return t


#: the reading's long notes that recur on many rows, in the page's short form (the definitions
#: say the rest once): the half point's spacing, c0 on the first-contact floor
_SHORT = (
    (re.compile(r"the half point lies between preloads (\S+) and (\S+) \(x (\S+) apart\): c is "
                r"resolved to that factor at worst; preloads between them would refine it"),
     r"c resolved to × \3 (half point between preloads \1 and \2)"),
    (re.compile(r"c0 read on the first-contact floor \(F~_A hardly changes between the two "
                r"smallest preloads\): a ratio F~_A/F~_P that grows as the preload shrinks"),
     "c0 on the first-contact floor: a ratio, not a slope"),
)


def _c_page_note(r) -> str:
    """The coefficients row's note on the page: what the plateau table's row does not already
    say, recurring notes in their short form."""
    said = {" ".join(x.split()) for x in r.notes}
    text = "; ".join(x for x in r.c_notes if " ".join(x.split()) not in said)
    for pat, rep in _SHORT:
        text = pat.sub(rep, text)
    return once([text])


def law_comparison(d) -> Table:
    """Every law against the seed scatter and against the plateau read without a law."""
    t = Table("law_comparison", "The laws compared (fitted in log F̃_A to every point)")
    t.csv_rows.append(["law", "k_tilde", "sigma_tilde", "c_initial", "plateau", "kink",
                       "rms_log", "seed_log_sd", "poor", "plateau_over_read_minus_1"])
    t.page_rows.append(["law", "rms residual of log F̃_A (all groups)", "groups where it fits "
                        "best", "groups with residuals > 2 seed sd (poor)",
                        "its plateau against the read one (median, range)"])
    laws = list(next(iter(d.laws.values()))) if d.laws else []
    for law in laws:
        rows = [(key, v[law]) for key, v in d.laws.items()]
        for (k, s), lr in rows:
            f = lr.fit
            t.csv_rows.append([law, repr(k), repr(s), num(f.c), num(f.plateau), num(f.kink),
                               num(f.rms_log), num(lr.seed_log_sd), str(lr.poor).lower(),
                               num(lr.plateau_vs_read)])
        r = [lr.fit.rms_log for _, lr in rows if math.isfinite(lr.fit.rms_log)]
        rms = math.sqrt(sum(x * x for x in r) / len(r)) if r else math.nan
        best = sum(1 for key, v in d.laws.items()
                   if math.isfinite(v[law].fit.rms_log)
                   and all(v[law].fit.rms_log <= o.fit.rms_log for o in v.values()
                           if math.isfinite(o.fit.rms_log)))
        rel = sorted(lr.plateau_vs_read for _, lr in rows if math.isfinite(lr.plateau_vs_read))
        relc = (f"{100 * statistics.median(rel):+.1f} % ({100 * rel[0]:+.0f} … {100 * rel[-1]:+.0f} %)"
                if rel else "—")
        t.page_rows.append([law, fmt(rms, ".3g"), f"{best} of {len(rows)}",
                            str(sum(lr.poor for _, lr in rows)), relc])
    return t


def pct(v: float) -> str:
    """A relative change in percent to three significant figures, at most two decimals:
    '+0.35', '+12.3', '+168', '+1419' (the page gave '+1418.69' on an interval spanning a
    factor 250)."""
    x = 100 * v
    if x == 0 or not math.isfinite(x):
        return f"{x:+.2f}"
    return f"{x:+.{min(2, max(0, 2 - math.floor(math.log10(abs(x)))))}f}"


def finite_size(d) -> Table:
    """Per (k~, sigma~, n_side): the plateau with its seed interval, and its relative change
    against the largest n_side of the grid (:mod:`.laws.size`)."""
    refs = reference_sizes(d.size, d.n_sides)
    ref = (f"n_side = {refs[0]}" if len(refs) == 1
           else f"the largest n_side of each k̃ ({', '.join(map(str, refs))})")
    t = Table("finite_size", f"Finite size: the plateau against the brush size n_side "
              f"(relative to {ref})")
    t.csv_rows.append(["k_tilde", "sigma_tilde", "n_side", "plateau", "plateau_lo", "plateau_hi",
                       "state", "n_seeds", "reference_n_side", "rel_change", "rel_change_lo",
                       "rel_change_hi", "verdict", "note"])
    t.page_rows.append(["k̃", "σ̃", "n_side", "plateau [seed CI]", "state", "seeds",
                        f"change against {ref} [range of the seed CIs]", "verdict",
                        "note"])
    for r in d.size:
        note = "; ".join(r.notes)
        t.csv_rows.append([repr(r.k_tilde), repr(r.sigma_tilde), str(r.n_side), num(r.plateau),
                           *_ci_csv(r.plateau_ci), r.state, str(r.n_seeds), str(r.ref_n_side),
                           num(r.rel), *_ci_csv(r.rel_ci), r.verdict, note])
        if r.n_side == r.ref_n_side:
            change = "reference"
        elif not math.isfinite(r.rel):
            change = "—"
        else:
            ci = r.rel_ci
            change = f"{pct(r.rel)} %" + (
                f" [{pct(ci[0])}, {pct(ci[1])}] %" if math.isfinite(ci[0]) else "")
        state = r.state if r.state == "reached" else f"**{r.state}**"
        verdict = f"**{r.verdict}**" if r.verdict == DIFFERS else r.verdict
        t.page_rows.append([f"{r.k_tilde:g}", f"{r.sigma_tilde:g}", str(r.n_side),
                            val_ci(r.plateau, r.plateau_ci), state, str(r.n_seeds), change,
                            verdict, note])
    return t


def machines(jobs) -> list:
    """The distinct machine stiffnesses k~_m of the done jobs, stiffest (``inf``) first."""
    return sorted({float(j.get("k_machine", math.inf)) for j in jobs
                   if j.get("status") == "done"}, reverse=True)


def machine_table(jobs) -> Table:
    """Per (k~, sigma~, preload, k~_m): seed means of F~_P, F~_A (the peak tension) and F~_jump
    (the tension at the jump-off of the final separation) and the plate's jumps."""
    by: dict = {}
    for j in jobs:
        if j.get("status") == "done":
            key = (j["k_tilde"], j["sigma_tilde"], j["preload"],
                   float(j.get("k_machine", math.inf)))
            by.setdefault(key, []).append(j)
    t = Table("machine", "Loading machines")
    t.csv_rows.append(["k_tilde", "sigma_tilde", "preload", "k_machine", "n_seeds", "F_P", "F_A",
                       "F_jump", "jumps", "note"])
    t.page_rows.append(["k̃", "σ̃", "preload", "k̃_m", "seeds", "F̃_P", "F̃_A (peak)",
                        "F̃_jump (final jump-off)", "jumps", "note"])

    def mean(js, name):
        v = [float(j[name]) for j in js if j.get(name) is not None]
        return sum(v) / len(v) if v else math.nan

    for (k, s, p, km), js in sorted(by.items(), key=lambda kv: (kv[0][:3], -kv[0][3])):
        rigid = math.isinf(km)
        note = "rigid machine: the plate does not jump" if rigid else ""
        fp, fa, fj, nj = (mean(js, n) for n in ("F_P", "F_A", "F_jump", "jumps"))
        t.csv_rows.append([repr(float(k)), repr(float(s)), repr(float(p)), repr(km),
                           str(len(js)), num(fp), num(fa), num(fj), "" if rigid else num(nj),
                           note])
        t.page_rows.append([f"{k:g}", f"{s:g}", f"{p:g}", f"{km:g}", str(len(js)), fmt(fp),
                            fmt(fa), fmt(fj), "—" if rigid else fmt(nj, ".3g"), note])
    return t
