"""The report's figures of coefficients: c against sigma~ (linear and log-log, with the
alpha/sigma~ - beta lines), c0 against sigma~, the plateau against sigma~ and k~, and alpha,
beta, sigma~_c against k~. Inputs: :class:`.report_data.ReportData`. A panel with nothing to
draw says why; a poor fit is flagged in its legend.
"""

from __future__ import annotations

import math
import textwrap

import numpy as np

from ..laws import loss as _loss
from ..laws.alphabeta import model as ab_model
from ..laws.reading import C0_ON_FLOOR
from .figures import FA, KT, SIG, colour, err, legend, save, say, subplots
from .loss_page import measured_span
from .notation import page_text
from .verdict_text import LAW_REASON_WORDS, law_why
from .zero_cell import law_zero


def _ab_label(k, st) -> str:
    a = st.ab
    if st.status == "undefined":
        why = page_text(LAW_REASON_WORDS.get(st.verdict.law_reason, "")) or "no fit"
        return f"{KT}={k:g}: α, β undefined ({why})"[:72]
    flag = " — POOR FIT" if st.status == "poor fit" else ""
    z = law_zero(st)[0]
    sc = f", zero α/β={z:.3g} (extrapolated)" if math.isfinite(z) else ""
    return f"{KT}={k:g}: α={a.alpha:.3g}, β={a.beta:.3g}{sc}{flag}"


def c_vs_sigma(data, out_dir, name="c_vs_sigma.png"):
    """c against sigma~: left c sigma~ against sigma~ on linear axes, where the law is the
    straight line alpha - beta sigma~ (intercept alpha, slope -beta, zero at alpha/beta); right
    c against sigma~ log-log, its sigma~ axis the groups' (lost ones as arrows). Seed intervals;
    lines: solid fitted within the seed scatter, dotted poor fit, none where alpha and beta are
    undefined. Filled circles: in the fit; open: left out; triangles: a rise not resolved (c is
    at least there); crosses: adhesion lost (c = 0)."""
    fig, (a1, a2) = subplots(1, 2, figsize=(12, 6.0))
    drawn = False
    zeros = []
    bounds = []
    n = len(data.studies)
    for i, (k, st) in enumerate(data.studies.items()):
        col = colour(i, n)
        gs = [g for g in st.groups if g.sigma_tilde > 0]
        res = [g for g in gs if g.reading.state == "rise resolved" and math.isfinite(g.reading.c)]
        label = _ab_label(k, st)
        for ax in (a1, a2):
            scale = (lambda g: g.sigma_tilde) if ax is a1 else (lambda g: 1.0)
            for infit, mfc in ((True, col), (False, "none")):
                sel = [g for g in res if g.in_fit == infit and (ax is a1 or g.reading.c > 0)]
                if not sel:
                    continue
                drawn = True
                ax.errorbar([g.sigma_tilde for g in sel], [g.reading.c * scale(g) for g in sel],
                            yerr=np.array([err(g.reading.c, g.c_ci) for g in sel]).T
                            * np.array([scale(g) for g in sel]), fmt="o", ms=5, capsize=2,
                            color=col, mfc=mfc, label=label if ax is a1 else None)
                label = None
            ub = [g for g in gs if g.reading.state == "rise not resolved"
                  and math.isfinite(g.reading.c_lower) and g.reading.c_lower > 0]
            if ub:
                drawn = True
                ax.plot([g.sigma_tilde for g in ub], [g.reading.c_lower * scale(g) for g in ub],
                        "^", ms=7, color=col, mfc="none", label=label if ax is a1 else None)
                label = None if ax is a1 else label
                bounds += [g.reading.c_lower for g in ub] if ax is a2 else []
        lost = [g for g in gs if g.reading.state == "adhesion lost"]
        if lost:
            drawn = True
            a1.plot([g.sigma_tilde for g in lost], [0.0] * len(lost), "x", ms=7, color=col,
                    label=label)
        zeros += [(g.sigma_tilde, col) for g in lost]
        a = st.ab
        if a.ok and st.status != "undefined":
            lo, hi = min(a.sigmas), max(a.sigmas)
            sg = np.geomspace(lo / 1.3, hi * 1.3, 300)
            fit = ab_model(sg, a.alpha, a.beta)
            ls = ":" if st.status == "poor fit" else "-"
            lin = np.linspace(0, hi * 1.15, 200)
            a1.plot(lin, np.maximum(a.alpha - a.beta * lin, 0.0), ls, color=col, lw=1.2)
            pos = fit > 0
            a2.plot(sg[pos], fit[pos], ls, color=col, lw=1.2)
    if not drawn:
        for ax in (a1, a2):
            say(ax, "no c to draw: no (k̃, σ̃ > 0) whose rise could be read")
    else:
        a1.axhline(0, color="0.6", lw=0.5)
        a1.set_xlim(left=0)
        a2.set_xscale("log")
        a2.set_yscale("log")
        cpos = [g.reading.c for st in data.studies.values() for g in st.groups
                if g.reading.state == "rise resolved" and g.reading.c > 0
                and g.sigma_tilde > 0] + bounds
        if cpos:                    # the cut line dives to 0 at its zero: keep the data in view
            a2.set_ylim(min(cpos) / 5, max(cpos) * 3)
        # sigma~ from the groups drawn, lost ones (their arrows) included, never from the line
        xs = [g.sigma_tilde for st in data.studies.values() for g in st.groups
              if g.sigma_tilde > 0 and (g.reading.state == "adhesion lost"
                                        or math.isfinite(g.reading.c)
                                        or math.isfinite(g.reading.c_lower))]
        if xs:
            a2.set_xlim(min(xs) / 1.3, max(xs) * 1.3)
        for s, col in zeros:
            a2.annotate("", (s, 0), xycoords=("data", "axes fraction"), xytext=(0, 14),
                        textcoords="offset points", arrowprops={"arrowstyle": "->", "color": col})
        handles, labels = a1.get_legend_handles_labels()
        if labels:                  # below both panels: the labels are long, the panels wide
            fig.legend(handles, labels, loc="lower center", fontsize=8,
                       ncol=2 if len(labels) > 3 else 1, frameon=False)
    a1.set_xlabel(f"roughness {SIG}")
    a2.set_xlabel(f"roughness {SIG}")
    a1.set_ylabel(f"c · {SIG} (the law: α − β{SIG}, zero at α/β)")
    a2.set_ylabel("adhesion coefficient c (eq. 15, slope through the origin)")
    a1.set_title("c·σ̃: solid fitted, dotted poor fit; open: not in the fit;\n"
                 "△ rise not resolved (c ≥); × adhesion lost", fontsize=9)
    a2.set_title("c, log–log (arrows: adhesion lost, c = 0)", fontsize=10)
    n_lab = len(a1.get_legend_handles_labels()[1])
    rows = (n_lab + 1) // 2 if n_lab > 3 else n_lab
    fig.tight_layout(rect=(0, min(0.05 + 0.045 * rows, 0.45), 1, 1))
    return save(fig, out_dir, name)


def _on_floor(g) -> bool:
    return any(n.startswith(C0_ON_FLOOR) for n in g.reading.c_notes)


def c0_vs_sigma(data, out_dir, name="c0_vs_sigma.png"):
    """The first-contact slope c0 against sigma~ per k~ (log-log), seed intervals."""
    fig, ax = subplots(figsize=(7.6, 4.6))
    drawn = floor_seen = False
    for i, (k, st) in enumerate(data.studies.items()):
        sel = [g for g in st.groups if math.isfinite(g.reading.c0) and g.reading.c0 > 0
               and g.sigma_tilde > 0]
        if sel:
            drawn = True
            col = colour(i, len(data.studies))
            ax.plot([g.sigma_tilde for g in sel], [g.reading.c0 for g in sel], "-", lw=1,
                    color=col)
            # open: read on the first-contact floor, a ratio F~_A/F~_P and not a slope
            for floor, mfc in ((False, col), (True, "none")):
                part = [g for g in sel if _on_floor(g) == floor]
                if part:
                    ax.errorbar([g.sigma_tilde for g in part], [g.reading.c0 for g in part],
                                yerr=np.array([err(g.reading.c0, g.c0_ci) for g in part]).T,
                                fmt="s", ms=5, capsize=2, color=col, mfc=mfc,
                                label=None if floor else f"{KT}={k:g}")
            floor_seen = floor_seen or any(_on_floor(g) for g in sel)
    if drawn:
        ax.set_xscale("log")
        ax.set_yscale("log")
        legend(ax, loc="upper left", bbox_to_anchor=(1.0, 1.0))
    else:
        say(ax, "no c₀ > 0 to draw (no rise, or no σ̃ > 0)")
    ax.set_xlabel(f"roughness {SIG}")
    ax.set_ylabel(f"first-contact slope c$_0$ ({FA}/" + "$\\tilde F_P$, first quarter of the rise)")
    ax.set_title("first-contact slope c$_0$ (seed intervals" + ("; open: read on the first-contact "
                 "floor, a ratio, not a slope)" if floor_seen else ")"), fontsize=10)
    fig.tight_layout()
    return save(fig, out_dir, name)


def plateau(data, out_dir, name="plateau.png"):
    """The plateau against sigma~ (per k~) and against k~ (per sigma~), seed intervals; open
    markers: plateau not reached (a lower bound)."""
    fig, (a1, a2) = subplots(1, 2, figsize=(12, 4.6))
    ks = list(data.studies)
    sigmas = sorted({g.sigma_tilde for st in data.studies.values() for g in st.groups})
    allg = [g for st in data.studies.values() for g in st.groups if math.isfinite(g.reading.plateau)]
    if not allg:
        for ax in (a1, a2):
            say(ax, "no plateau to draw: no done job with finite forces")
    for i, k in enumerate(ks):
        gs = [g for g in data.studies[k].groups if math.isfinite(g.reading.plateau)]
        col = colour(i, len(ks))
        if gs:
            a1.plot([g.sigma_tilde for g in gs], [g.reading.plateau for g in gs], "-", color=col,
                    lw=1)
        for reached, mfc in ((True, col), (False, "none")):
            sel = [g for g in gs if (g.reading.plateau_state != "not reached") == reached]
            if sel:
                a1.errorbar([g.sigma_tilde for g in sel], [g.reading.plateau for g in sel],
                            yerr=np.array([err(g.reading.plateau, g.plateau_ci) for g in sel]).T,
                            fmt="o", ms=5, capsize=2, color=col, mfc=mfc,
                            label=f"{KT}={k:g}" + ("" if reached else " (not reached)"))
    for i, s in enumerate(sigmas):
        pts = [(k, g) for k in ks for g in data.studies[k].groups
               if g.sigma_tilde == s and math.isfinite(g.reading.plateau)]
        if pts:
            a2.errorbar([k for k, _ in pts], [g.reading.plateau for _, g in pts],
                        yerr=np.array([err(g.reading.plateau, g.plateau_ci) for _, g in pts]).T,
                        fmt="o-", ms=5, capsize=2, lw=1, color=colour(i, len(sigmas)),
                        label=f"{SIG}={s:g}")
    if allg:
        pos = [g.reading.plateau for g in allg]
        if min(pos) > 0 and max(pos) / min(pos) > 10:
            a1.set_yscale("log")
            a2.set_yscale("log")
        if min(sigmas) > 0 and max(sigmas) / min(sigmas) >= 10:
            a1.set_xscale("log")
        if min(ks) > 0 and max(ks) / min(ks) >= 10:
            a2.set_xscale("log")
        legend(a1)
        legend(a2)
    if allg and len(ks) < 2:
        # one k~ gives no stiffness axis: its points would stand in one column at that k~,
        # the left panel's points again
        a2.clear()
        a2.set_xticks([])
        a2.set_yticks([])
        n = getattr(data, "n_side", None)
        say(a2, f"one {KT} ({ks[0]:g}) among the groups read"
                + (f" (n_side = {n})" if n is not None else "")
                + ": no stiffness axis to draw\n(the left panel has every plateau)")
    a1.set_xlabel(f"roughness {SIG}")
    a2.set_xlabel(f"pillar stiffness {KT}")
    for ax in (a1, a2):
        ax.set_ylabel(f"plateau {FA}")
    a1.set_title("plateau against roughness (seed intervals)", fontsize=10)
    a2.set_title("plateau against stiffness", fontsize=10)
    fig.tight_layout()
    return save(fig, out_dir, name)


def alpha_sigma_c(data, out_dir, name="alpha_sigma_c.png"):
    """alpha, beta and sigma~_c against k~, seed intervals, on linear axes wherever an interval
    reaches 0 or below (a log axis would hide it). Only k~ whose law is not undefined; open
    markers: poor fit. sigma~_c: the measured one with its interval in its bracket,
    the line's zero beside it as an extrapolation (:func:`_sigma_c_panel`); missing
    values say why."""
    fig, axes = subplots(1, 3, figsize=(14, 4.4))
    ks = [k for k, st in data.studies.items() if st.ab.ok and st.status != "undefined"]
    why = "; ".join(f"{KT}={k:g}: {page_text(law_why(st))}" for k, st in data.studies.items()
                    if st.status == "undefined" and law_why(st))
    for ax, (name_, attr, ci) in zip(axes, (("α", "alpha", "alpha_ci"), ("β", "beta", "beta_ci"),
                                             (f"{SIG}$_c$", "sigma_c", "sigma_c_ci"))):
        if attr == "sigma_c":
            drawn = _sigma_c_panel(ax, data)
        else:
            pts = [(k, getattr(data.studies[k].ab, attr), getattr(data.studies[k], ci),
                    data.studies[k].status == "poor fit") for k in ks]
            pts = [p for p in pts if math.isfinite(p[1])]
            drawn = bool(pts)
            for poor in (False, True):
                sel = [p for p in pts if p[3] == poor]
                if sel:
                    ax.errorbar([p[0] for p in sel], [p[1] for p in sel],
                                yerr=np.array([err(v, c) for _, v, c, _ in sel]).T, fmt="o",
                                capsize=3, color="C0", mfc="none" if poor else "C0",
                                label="poor fit (orientation only)" if poor else "fitted")
            if pts:
                lows = [c[0] if math.isfinite(c[0]) else v for _, v, c, _ in pts]
                v = [p[1] for p in pts]
                if attr != "beta" and min(lows) > 0 and max(v) / min(v) >= 10:
                    ax.set_yscale("log")
                legend(ax)
        xs = [k for k in data.studies if k > 0]
        if drawn and len(xs) > 1 and max(xs) / min(xs) >= 10:
            ax.set_xscale("log")
        if not drawn:
            text = f"no {name_} to draw:\n" + (why or "no k̃ has α and β")
            say(ax, note_lines(text))
        if attr == "beta" or (attr == "alpha" and ax.get_yscale() == "linear"):
            ax.axhline(0, color="0.6", lw=0.5)
        ax.set_xlabel(f"pillar stiffness {KT}")
        ax.set_ylabel(name_)
        if attr != "sigma_c":
            ax.set_title(f"{name_} (seed intervals)", fontsize=10)
    fig.tight_layout()
    return save(fig, out_dir, name)


def note_lines(text: str, width: int = 60, most: int = 6) -> str:
    """``text`` wrapped at word boundaries into at most ``most`` lines of ``width`` characters
    (its own line breaks kept), an ellipsis closing a cut."""
    lines = [ln for part in text.split("\n") for ln in (textwrap.wrap(part, width) or [""])]
    return "\n".join(lines[:most] + (["…"] if len(lines) > most else []))


def _sigma_c_panel(ax, data) -> bool:
    """Per k~ the measured sigma~_c with its seed interval (red), its bracket (grey bar; a
    triangle at the largest sigma~ run where none lost adhesion), and the line's zero alpha/beta
    as an open diamond, an extrapolation beside them. The axis is the measurements': a zero
    beyond it is drawn at the edge as a triangle."""
    drawn, above, wide, zeros = False, False, False, []
    for k, st in data.studies.items():
        lo, hi = st.loss_bracket
        if st.loss_kind == _loss.BRACKET:
            ax.plot([k, k], [lo, hi], "-", color="0.6", lw=6, alpha=0.6,
                    label="bracket (lo, hi]" if not drawn else None)
            s_lo, s_hi = measured_span(st)
            if (s_lo, s_hi) != (lo, hi) and math.isfinite(s_hi) and s_lo > 0:
                ax.plot([k, k], [s_lo, s_hi], "-", color="0.2", lw=1,
                        label=None if wide else "span: lost in (lo, hi]")
                wide = True
            s, ci = st.sigma_loss, st.sigma_loss_ci
            if math.isfinite(s):
                ax.errorbar([k], [s], yerr=np.array([err(s, ci)]).T, fmt="o", capsize=3,
                            color="C3", label=None if drawn else f"{SIG}$_c$ measured [seed CI]")
            drawn = True
        elif st.loss_kind == _loss.NO_LOSS and math.isfinite(lo):
            ax.plot([k], [lo], "^", color="0.5", ms=7, mfc="none",
                    label=None if above else f"{SIG}$_c$ > the largest {SIG} run")
            above = True
            drawn = True
        z = law_zero(st)[0]
        if math.isfinite(z):
            zeros.append((k, z))
    if drawn:
        ax.set_yscale("log")
        y0, y1 = ax.get_ylim()
        for i, (k, z) in enumerate(zeros):
            ax.plot([k], [min(max(z, y0), y1)], "D" if y0 <= z <= y1 else
                    ("^" if z > y1 else "v"), color="C1", mfc="none", ms=7,
                    label=None if i else "zero of the line α/β (extrapolation; "
                    "▲▼ beyond the axis)")
        ax.set_ylim(y0, y1)
        legend(ax, loc="upper center", bbox_to_anchor=(0.5, -0.16), ncol=2)
    ax.set_title(f"{SIG}$_c$ measured (red) in its bracket (grey);\n"
                 "◇ the line's zero α/β, an extrapolation", fontsize=9)
    return drawn
