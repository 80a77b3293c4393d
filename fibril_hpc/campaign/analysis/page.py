"""The report's two pages: ``README.md`` (figures beside it as PNG files) and ``report.html``
(one self-contained file: the same text and tables, every figure embedded as a data URI).

A referee's order: the headline (at most four lines, :func:`.headline.headline`: where the
brush loses adhesion per k~, and what that is of), the figures, the tables, the notes (each said
once, :func:`.headline.notes`), the definitions (those of ``docs/report.md`` in short). One
notation throughout, the symbols (:func:`.notation.page_text`).
"""

from __future__ import annotations

import base64
import html
import os
import re

from ..storage.guard import REPORT_MARK
from .notation import page_text
from .variants import label, show_value

DEFINITIONS = """\
* **Plateau**: the preload-insensitive F̃_A. From the largest preload holding every seed down, a
  preload joins the plateau set while its seed-mean F̃_A is not below the set's mean by more than
  2 standard errors of the difference of the seed means (at least 1 % of the plateau; 3 % with
  one seed). The plateau is the set's mean; with fewer than two preloads in the set it is *not
  reached* (F̃_A still rises at the largest preload: a lower bound). A preload holding fewer
  seeds than the group (seeds per level in bold) is flagged and never sets the plateau alone.
* **State of the rise**, one of three: *adhesion lost* - the plateau is at most 3 pillars'
  pull-off (the floor: one flat pillar's Kendall force φ^¼/N^¾ on this scale, N pillars), c = c₀ = 0,
  a measurement; *rise not resolved* - F̃_A at the smallest preload reached is already half the
  plateau or more: c ≥ F̃_A,0/F̃_P,0 is a lower bound, left out of the α/β fit, and the note says
  which preload would resolve it (or that the first contact overshot every smaller preload);
  *rise resolved* - the seed-mean curve crosses half the plateau above the smallest preload.
* **c** (eq. 15 of He, Li & Popov, F̃_A = c F̃_P on the linear stage): the slope of the line through
  the origin and the point where the seed-mean curve first reaches half the plateau,
  (plateau/2)/F̃_P,½ (F̃_P,½ interpolated in log F̃_P between the two preloads around it: its
  resolution is their spacing, noted where wider than × 2.5); preloads added below the rise do
  not move it. Other readings in `coefficients.csv`: *c_stage*, the least-squares slope through
  the origin over the levels between 3 pillars' pull-off and half the plateau; *c_chord*, the
  chord over the first half of the rise from the smallest preload (the report's c before; it
  moves with the smallest preload).
* **c₀** (the first-contact slope): the geometric mean of F̃_A/F̃_P over the preloads in the first
  quarter of the rise, where a few pillars carry the pull-off. It depends on the smallest preload
  (given beside it).
* **Measured σ̃_c** (model-free, the headline's number): per k̃, the crossing of the seed-mean
  plateau with 3 pillars' pull-off between the last σ̃ holding adhesion and the first lost
  (log–log), its seed interval from the bootstrap over seed labels paired across σ̃. Its **span**
  ("lost in (lo, hi]", the interval to quote): that bracket widened to the next σ̃ on each side
  whose state is certain with its seeds (plateau interval not holding the threshold; where
  seeds: auto ran fewer seeds at one end, the interval of its plateau carried to the other's
  seeds); on a side with no such σ̃, to where another seed set as large would measure σ̃_c (the
  seed interval widened by √2 in log σ̃: an extrapolation past the σ̃ run where it ends there);
  an infinite end stays infinite. The seed interval is the scatter of the line between the two
  bracketing σ̃ and may reach past a σ̃ whose state is certain; the span does not. Over a
  bracket wider than × 4 it is left out (the line's shape, not the seeds, sets the value).
* **α, β** and the **zero of the line**: c = max(α/σ̃ − β, 0) fitted per k̃ to the groups whose
  rise is resolved (scipy.optimize.least_squares, weights 1/sd of c from the seeds, sd widened
  by √(n/(n−1))); groups that lost adhesion are left out of the line; σ̃ = 0, plateaus not reached
  and rises not resolved do not enter. *fitted* needs at least 3 active points and 1 degree of
  freedom, χ² below the 99 % point of a sum of Student t² (each sd from few seeds) and α's
  interval excluding 0; a *poor fit* is shown for orientation only; otherwise *undefined*, with
  the reason. α/β is the line's zero, an extrapolation of c(σ̃), shown only for a fitted law
  whose β interval excludes 0, and described against the measured span: *inside* (the
  intervals overlap, both bounded), *above* (the line still gives c > 0 where adhesion is lost)
  or *below* it (wholly beyond the span), else nothing (e.g. an interval reaching ∞). It is
  never a second σ̃_c.
* **Errors**: [seed CI] is a bootstrap over seeds (seed labels resampled jointly for a k̃: a
  label drawn picks that seed at every σ̃ that has it (paired; `seeds: auto` groups take the
  drawn labels they hold), every reading redone), its 2.5–97.5 % range widened about the value
  by t/z·√(n/(n−1)) for n seeds (over synthetic groups of known truth it then held the true c in
  90 % of draws at 3 seeds and 94–97 % at 5–10). **bias** is the preset's discretisation error
  of F̃_A measured against the converged reference of the default scene (benchmarks/NOTES.md
  §27b), carried to every force-like number as a relative error (σ̃_c, a ratio, is unaffected).
  **larger error** names the one that dominates.
"""


def _summary(d) -> str:
    s = (f"{d.n_jobs} job records: {d.n_done} done, {d.n_failed} failed"
         + (f", {d.n_nonfinite} done with non-finite forces (left out)" if d.n_nonfinite else "")
         + f"; campaign `{d.meta.get('campaign_hash', '?')}`; "
         + f"{d.n_boot} bootstrap resamples over seeds.")
    if len(d.machines) > 1:
        s += (f" The grid sweeps the machine stiffness k̃_m ({', '.join(f'{k:g}' for k in d.machines)}); "
              f"the readings use k̃_m = {d.machines[0]:g}.")
    if d.n_sides:
        n = "—" if d.n_side is None else str(d.n_side)
        s += (f" The grid sweeps the brush size n_side ({', '.join(map(str, d.n_sides))}): the "
              f"finite-size table and figure compare every n_side; every other table, fit and "
              f"figure reads n_side = {n} only, the largest with done jobs (the closest to an "
              "infinite brush), so no group mixes brush sizes.")
    if d.variant is not None:
        s += " " + variant_sentence(d.variant)
    return s


def variant_sentence(v) -> str:
    """What a grid sweeping lab fields is read at, and what the file holds besides."""
    swept = "; ".join(f"{n} ({', '.join(show_value(x) for x in xs)})" for n, xs in v.values.items())
    how = ("chosen with `--where`" if v.by_where else
           "the first listed combination with done jobs; another with `--where NAME=VALUE`")
    s = (f"The grid sweeps {swept}: every table, fit and figure reads **{v.label}** only "
         f"({how}; {len(v.keys)} done jobs), so no group mixes variants.")
    if v.others:
        s += " Not read: " + "; ".join(f"{label(c)} ({n} done jobs)" for c, n in v.others) + "."
    else:
        s += " No other variant has done jobs in the file."
    if v.unknown:
        s += (f" {v.unknown} done job(s) of none of the listed combinations (another grid's "
              "scene) are not read either.")
    return s


SIZE_DEFINITION = """\
* **Finite size**: the plateau of each (k̃, σ̃) read as above at every n_side on its own (each
  n_side's seeds are other brushes: a bootstrap per n_side). *Change* = plateau(n_side) /
  plateau(largest n_side) − 1, in brackets the range the two seed intervals allow
  ([lo/hi′ − 1, hi/lo′ − 1]); *within the seed scatter* when that range holds 0, *not
  resolved* instead where the largest brush's plateau interval reaches 3 pillars' pull-off (a
  ratio to a plateau that may be that floor). The preset's bias is the same at every n_side and
  cancels from the ratio to first order.
"""


def _definitions(d) -> str:
    return DEFINITIONS + (SIZE_DEFINITION if d.n_sides else "")


TABLES_NOTE = ("Every table is also a CSV file beside this page (full precision, one column per "
               "number; every column defined in docs/report.md); `report.html` is this page "
               "with the figures embedded.")


def _notes(d, seconds) -> list:
    """The notes section: :attr:`.report_data.ReportData.notes`, then the file's summary."""
    return list(d.notes) + [_summary(d) + (f" Report written in {seconds:.1f} s."
                                           if seconds else "")]


def markdown(d, tables, figures, seconds=None) -> str:
    """The Markdown page: headline, figures (relative links), tables, notes, definitions; in
    one notation (:func:`.notation.page_text`)."""
    out = [f"# Report of `{os.path.abspath(d.path)}`", ""]
    for i, line in enumerate(d.headline):
        out += [f"**{line}**" if i == 0 else line, ""]
    out += ["## Figures", ""]
    for title, p in figures:
        out += [f"### {title}", "", f"![{title}]({os.path.basename(p)})", ""]
    out += ["## Tables", "", TABLES_NOTE, ""]
    for t in tables:
        out += [f"### {t.title} (`{t.name}.csv`)", "", t.markdown()]
    out += ["## Notes", ""] + [f"* {n}" for n in _notes(d, seconds)]
    out += ["", "## Definitions", "", _definitions(d)]
    return "\n".join(page_text(line) for line in out)


_CSS = """body{font-family:sans-serif;max-width:1300px;margin:1em auto;padding:0 1em;color:#222}
table{border-collapse:collapse;margin:.5em 0 1.5em;font-size:13px}
td,th{border:1px solid #bbb;padding:3px 6px;vertical-align:top;text-align:left}
th{background:#eee}img{max-width:100%;border:1px solid #ddd}.head{background:#fff6d6;
padding:.6em 1em;border-left:4px solid #d8a300}code{background:#f2f2f2}"""


def _inline(text: str) -> str:
    """Markdown emphasis and code of one line -> HTML (after escaping)."""
    t = html.escape(text)
    t = re.sub(r"\*\*(.+?)\*\*", r"<strong>\1</strong>", t)
    t = re.sub(r"(?<![\w*])\*(?!\s)(.+?)(?<!\s)\*(?![\w*])", r"<em>\1</em>", t)
    return re.sub(r"`(.+?)`", r"<code>\1</code>", t)


def _definitions_html(text: str) -> str:
    items, cur = [], []
    for line in text.splitlines():
        if line.startswith("* ") and cur:
            items.append(" ".join(cur))
            cur = []
        cur.append(line[2:].strip())
    if cur:
        items.append(" ".join(cur))
    return "<ul>" + "".join(f"<li>{_inline(i)}</li>" for i in items) + "</ul>"


def html_page(d, tables, figures, seconds=None) -> str:
    """The self-contained HTML page, in the order and notation of :func:`markdown`: every
    figure embedded as a base64 PNG data URI."""
    title = html.escape(os.path.abspath(d.path))
    parts = ["<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'>" + REPORT_MARK,
             f"<title>Report of {title}</title><style>{_CSS}</style></head><body>",
             f"<h1>Report of <code>{title}</code></h1><div class='head'>"]
    parts += [f"<p>{_inline(page_text(line))}</p>" for line in d.headline]
    parts += ["</div>", "<h2>Figures</h2>"]
    for ftitle, p in figures:
        with open(p, "rb") as fh:
            b64 = base64.b64encode(fh.read()).decode("ascii")
        alt = html.escape(page_text(ftitle), quote=True)
        parts += [f"<h3>{html.escape(page_text(ftitle))}</h3>",
                  f"<figure><img class='figure' alt='{alt}' src='data:image/png;base64,{b64}'>"
                  "</figure>"]
    parts += ["<h2>Tables</h2>", f"<p>{_inline(TABLES_NOTE)}</p>"]
    for t in tables:
        parts += [f"<h3>{html.escape(page_text(t.title))} (<code>{t.name}.csv</code>)</h3>",
                  t.html()]
    parts += ["<h2>Notes</h2><ul>"] + [f"<li>{_inline(page_text(n))}</li>"
                                       for n in _notes(d, seconds)] + ["</ul>"]
    parts += ["<h2>Definitions</h2>", _definitions_html(page_text(_definitions(d)))]
    parts.append("</body></html>")
    return "\n".join(parts)
