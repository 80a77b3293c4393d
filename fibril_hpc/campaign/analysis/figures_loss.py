"""The report's figure of the loss of adhesion along sigma~ (:mod:`..laws.loss`): per k~ whose
sigma~ run brackets a loss, c against sigma~ on linear axes around it (above) and the plateau
against sigma~ with the loss threshold (below), so a reader sees whether adhesion is lost
sharply or fades to the few-pillar floor, and where the alpha/beta line puts its zero against
the measured sigma~_c. Inputs: :class:`.report_data.ReportData`.
"""

from __future__ import annotations

import math

import numpy as np

from ..laws import loss as _loss
from ..laws.alphabeta import model as ab_model
from ..laws.reading import FEW_PILLARS, LOST, RESOLVED, UNRESOLVED
from .figures import FA, KT, SIG, err, save, say, subplots
from .loss_page import measured_span, span_text
from .notation import page_text
from .verdict_text import NO_ZERO_WORDS, RELATION_WORDS, fmt_ci
from .zero_cell import law_zero

#: panels per row of the grid (one k~ per column: c above, the plateau below)
COLUMNS = 4
#: the sigma~ window around the bracket (lo / LEFT to hi * RIGHT); all sigma~ if it holds fewer
#: than MIN_POINTS groups
LEFT, RIGHT, MIN_POINTS = 3.0, 1.5, 4
BRACKET_C, LOSS_C, LAW_C, LOST_C = "0.55", "C3", "C0", "k"
#: characters of a panel title's line that fit its width (longer ones are broken)
TITLE_LINE = 52


def _window(st):
    lo, hi = st.loss_bracket
    gs = [g for g in st.groups if g.sigma_tilde > 0]
    near = [g for g in gs if lo / LEFT <= g.sigma_tilde <= hi * RIGHT]
    return near if len(near) >= MIN_POINTS else gs


def _c_panel(ax, st, gs):
    """c with its seed interval, rises not resolved as lower bounds, lost groups at c = 0, the
    alpha/beta line with its zero (and its interval), the bracket and the measured sigma~_c."""
    res = [g for g in gs if g.reading.state == RESOLVED and math.isfinite(g.reading.c)]
    for infit, mfc, lab in ((True, LAW_C, "c [seed CI], in the α/β fit"),
                            (False, "none", "c, not in the fit")):
        sel = [g for g in res if g.in_fit == infit]
        if sel:
            ax.errorbar([g.sigma_tilde for g in sel], [g.reading.c for g in sel],
                        yerr=np.array([err(g.reading.c, g.c_ci) for g in sel]).T, fmt="o",
                        ms=5, capsize=2, color=LAW_C, mfc=mfc, label=lab)
    ub = [g for g in gs if g.reading.state == UNRESOLVED and math.isfinite(g.reading.c_lower)]
    if ub:
        ax.plot([g.sigma_tilde for g in ub], [g.reading.c_lower for g in ub], "^", ms=7,
                color=LAW_C, mfc="none", label="rise not resolved (c ≥)")
    lost = [g for g in gs if g.reading.state == LOST]
    if lost:
        ax.plot([g.sigma_tilde for g in lost], [0.0] * len(lost), "X", ms=8, color=LOST_C,
                label="adhesion lost (c = 0)", zorder=7)
    x0, x1 = ax.get_xlim()
    # the axes are the data's: c with its intervals (the law's line and zero never set them)
    tops = [max(g.reading.c, g.c_ci[1] if math.isfinite(g.c_ci[1]) else g.reading.c)
            for g in res] + [g.reading.c_lower for g in ub]
    top = max([t for t in tops if math.isfinite(t)] or [1.0])
    ax.set_ylim(-0.06 * top, 1.12 * top)
    a = st.ab
    if a.ok and st.status != "undefined":          # an undefined law draws no line (as c_vs_sigma)
        ls = "-" if st.status == "fitted" else ":"
        lo_x = min(g.sigma_tilde for g in gs)     # the line over the sigma~ run only
        xs = np.linspace(lo_x, x1, 300)
        ax.plot(xs, ab_model(xs, a.alpha, a.beta), ls, color="C1", lw=1.3,
                label=f"α/{SIG} − β" + ("" if st.status == "fitted" else f" ({st.status})"))
    z, ci, _, _ = law_zero(st)
    if math.isfinite(z) and x0 <= z <= x1:
        xerr = np.array([[e] for e in err(z, ci)]) if math.isfinite(ci[0]) else None
        ax.errorbar([z], [0.0], xerr=xerr, fmt="D", ms=7, color="C1", mfc="w", capsize=3,
                    label="zero of the line, α/β (extrapolation)", zorder=6)
    elif math.isfinite(z):                      # beyond the data: named at the edge
        ax.annotate(f"α/β = {z:.3g} →" if z > x1 else f"← α/β = {z:.3g}",
                    xy=(0.98 if z > x1 else 0.02, 0.04), xycoords="axes fraction",
                    ha="right" if z > x1 else "left", fontsize=8, color="C1")
    ax.set_xlim(x0, x1)
    ax.axhline(0, color="0.6", lw=0.5)


def _plateau_panel(ax, st, gs, floor):
    """The plateau with its seed interval (lost groups marked), the loss threshold and the
    one-pillar floor, on a log axis."""
    ok = [g for g in gs if math.isfinite(g.reading.plateau) and g.reading.plateau > 0]
    for lost, fmt_, col, lab in ((False, "o", LAW_C, "plateau [seed CI]"),
                                 (True, "X", LOST_C, "plateau of a lost group")):
        sel = [g for g in ok if (g.reading.state == LOST) == lost]
        if sel:
            ax.errorbar([g.sigma_tilde for g in sel], [g.reading.plateau for g in sel],
                        yerr=np.array([err(g.reading.plateau, g.plateau_ci) for g in sel]).T,
                        fmt=fmt_, ms=6, capsize=2, color=col, label=lab)
    if ok:
        ax.plot([g.sigma_tilde for g in ok], [g.reading.plateau for g in ok], "-", color="0.7",
                lw=0.8, zorder=0)
    if math.isfinite(floor):
        ax.axhline(FEW_PILLARS * floor, color=LOSS_C, ls="--", lw=1,
                   label=f"loss threshold: {FEW_PILLARS:g} pillars' pull-off")
        ax.axhline(floor, color="0.5", ls=":", lw=1, label="one pillar's pull-off")
    ax.set_yscale("log")


def _marks(ax, st):
    """The bracket (grey band), the span where it is wider (grey dashed ends: the interval the
    headline gives, :func:`.loss_page.measured_span`) and the measured sigma~_c with its interval
    (red line, band)."""
    lo, hi = st.loss_bracket
    ax.axvspan(lo, hi, color=BRACKET_C, alpha=0.15, lw=0, label="bracket (lo, hi]")
    ends = [x for x, b in zip(measured_span(st), (lo, hi)) if x != b and math.isfinite(x)]
    for i, x in enumerate(ends):
        ax.axvline(x, color="0.45", ls="--", lw=1,
                   label=None if i else "span: lost in (lo, hi] (states not certain, seed CI)")
    if math.isfinite(st.sigma_loss):
        a, b = st.sigma_loss_ci
        if math.isfinite(a) and math.isfinite(b) and b > a:
            ax.axvspan(a, b, color=LOSS_C, alpha=0.25, lw=0)
        ax.axvline(st.sigma_loss, color=LOSS_C, lw=1.5, label=f"{SIG}$_c$ measured [seed CI]")


def _title(k, st) -> str:
    if st.loss_kind == _loss.BRACKET and math.isfinite(st.sigma_loss):
        # one number and one interval, the headline's: the span the zero is set against
        head = (f"{KT} = {k:g}: {SIG}$_c$ = {st.sigma_loss:.3g} in "
                f"{span_text(measured_span(st))} (measured)")
    else:
        head = f"{KT} = {k:g}: {SIG}$_c$ = {fmt_ci(st.sigma_loss, st.sigma_loss_ci)} (measured)"
    z, _, rel, why = law_zero(st)
    if not math.isfinite(z):
        tail = f"line's zero: none ({page_text(NO_ZERO_WORDS[why])})"
    else:
        where = RELATION_WORDS[rel].split(" (")[0] if rel else ""
        tail = f"line's zero α/β = {z:.3g}" + (f", {where}" if where else "")
    if len(tail) > TITLE_LINE:              # wider than a panel: its reason on a line of its own
        tail = tail.replace(" (", "\n(", 1) if " (" in tail else tail.replace(", ", ",\n", 1)
    return head + "\n" + tail


def _not_drawn(data) -> str:
    """The k~ without a bracket, grouped by why (a second line of the title, or "")."""
    by: dict = {}
    for k, st in data.studies.items():
        if st.loss_kind == _loss.NO_LOSS:
            by.setdefault(f"no loss up to {SIG} = {st.loss_bracket[0]:g}", []).append(k)
        elif st.loss_kind == _loss.ALL_LOST:
            by.setdefault(f"lost at every {SIG} (< {st.loss_bracket[1]:g})", []).append(k)
        elif st.loss_kind == _loss.NOT_READ:
            by.setdefault("no state read", []).append(k)
    if not by:
        return ""
    return "\nnot drawn: " + "; ".join(f"{why} for {KT} = " + ", ".join(f"{k:g}" for k in ks)
                                       for why, ks in by.items())


def loss(data, out_dir, name="sigma_c_loss.png"):
    """Per k~ with a loss bracket: c against sigma~ near the loss (linear axes) above, the
    plateau against sigma~ with the threshold below; a k~ without a bracket is named in the
    figure's title (no loss up to the largest sigma~, or lost at every sigma~)."""
    ks = [k for k, st in data.studies.items() if st.loss_kind == _loss.BRACKET]
    n = max(len(ks), 1)
    ncol = min(COLUMNS, n)
    nrow = -(-n // ncol)
    fig, axes = subplots(2 * nrow, ncol, figsize=(max(4.3 * ncol, 9.5), 6.2 * nrow + 1.0), squeeze=False,
                         gridspec_kw={"height_ratios": [3, 2] * nrow})
    fig.set_layout_engine("constrained")
    if not ks:
        say(axes[0, 0], "no k̃ whose σ̃ run brackets a loss of adhesion\n(no lost group with a "
            "group holding adhesion below it)")
        axes[1, 0].set_visible(False)
    handles: dict = {}
    for i, k in enumerate(ks):
        st = data.studies[k]
        top, bot = axes[2 * (i // ncol), i % ncol], axes[2 * (i // ncol) + 1, i % ncol]
        gs = _window(st)
        xs = [g.sigma_tilde for g in gs]
        # the data's range (never the law's zero), widened to the span's ends where a group
        # run lies there; an end beyond every sigma~ run is named at the edge instead
        run = [g.sigma_tilde for g in st.groups]
        ends = [e for e in measured_span(st) if math.isfinite(e)]
        inside = [e for e in ends if min(run) <= e <= max(run)]
        x0_, x1 = min(xs + inside), max(xs + inside) * 1.08
        gs = [g for g in st.groups if g.sigma_tilde > 0 and x0_ <= g.sigma_tilde <= x1 / 1.08]
        for ax in (top, bot):
            ax.set_xlim(x0_ - 0.08 * (x1 - x0_), x1)
            _marks(ax, st)
        for e in ends:
            if e > x1:
                top.annotate(f"span to {e:.4g} →", xy=(0.98, 0.96), xycoords="axes fraction",
                             ha="right", va="top", fontsize=8, color="0.35")
        _c_panel(top, st, gs)
        _plateau_panel(bot, st, gs, data.floor)
        top.set_title(_title(k, st), fontsize=9)
        top.set_ylabel("adhesion coefficient c")
        bot.set_ylabel(f"plateau {FA}")
        bot.set_xlabel(f"roughness {SIG}")
        for ax in (top, bot):
            for h, lab in zip(*ax.get_legend_handles_labels()):
                handles.setdefault(lab, h)      # a poor fit's dotted line keeps its own entry
    for j in range(len(ks), nrow * ncol):
        axes[2 * (j // ncol), j % ncol].set_visible(False)
        axes[2 * (j // ncol) + 1, j % ncol].set_visible(False)
    fig.suptitle("Where adhesion is lost: c (above) and the plateau (below) against "
                 f"{SIG}; grey the bracket, red the measured {SIG}$_c$" + _not_drawn(data),
                 fontsize=10)
    if handles:
        # as many legend columns as the panels' width holds (two panels: three)
        fig.legend(list(handles.values()), list(handles), loc="outside lower center",
                   ncol=min(5 if ncol >= 3 else 3, len(handles)), fontsize=8)
    return save(fig, out_dir, name)
