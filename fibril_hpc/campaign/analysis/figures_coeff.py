"""The report's figures of coefficients: c against sigma~ (linear and log-log, with the
alpha/sigma~ - beta lines), c0 against sigma~, the plateau against sigma~ and k~, and alpha,
beta, sigma~_c against k~. Inputs: :class:`.report_data.ReportData`. A panel with nothing to
draw says why; a poor fit is flagged in its legend.
"""

from __future__ import annotations

import math

import numpy as np

from ..laws.alphabeta import model as ab_model
from .figures import FA, KT, SIG, err, legend, save, say, subplots


def _ab_label(k, st) -> str:
    a = st.ab
    if not a.ok:
        return f"{KT}={k:g}: no α/β ({a.notes[0] if a.notes else 'no fit'})"[:70]
    flag = " — POOR FIT" if a.poor else ""
    sc = f", {SIG}$_c$={a.sigma_c:.3g}" if math.isfinite(a.sigma_c) else ", β ≤ 0: no $\\tilde\\sigma_c$"
    return f"{KT}={k:g}: α={a.alpha:.3g}, β={a.beta:.3g}{sc}{flag}"


def c_vs_sigma(data, out_dir, name="c_vs_sigma.png"):
    """c against sigma~, linear and log-log, seed intervals, with the fitted lines."""
    fig, (a1, a2) = subplots(1, 2, figsize=(12, 4.6))
    drawn = False
    zeros = []
    for i, (k, st) in enumerate(data.studies.items()):
        col = f"C{i % 10}"
        gs = [g for g in st.groups if math.isfinite(g.reading.c)]
        for ax in (a1, a2):
            for infit, mfc in ((True, col), (False, "none")):
                sel = [g for g in gs if g.in_fit == infit and g.sigma_tilde > 0
                       and (ax is a1 or g.reading.c > 0)]
                if not sel:
                    continue
                drawn = True
                ax.errorbar([g.sigma_tilde for g in sel], [g.reading.c for g in sel],
                            yerr=np.array([err(g.reading.c, g.c_ci) for g in sel]).T, fmt="o",
                            ms=5, capsize=2, color=col, mfc=mfc,
                            label=None if not infit or ax is a2 else _ab_label(k, st))
        zeros += [(g.sigma_tilde, col) for g in gs if g.reading.c == 0 and g.sigma_tilde > 0]
        a = st.ab
        if a.ok:
            lo, hi = min(a.sigmas), max(a.sigmas)
            sg = np.geomspace(lo / 1.3, hi * 1.3, 300)
            fit = ab_model(sg, a.alpha, a.beta)
            ls = ":" if a.poor else "-"
            a1.plot(sg, fit, ls, color=col, lw=1.2)
            pos = fit > 0
            a2.plot(sg[pos], fit[pos], ls, color=col, lw=1.2)
    if not drawn:
        for ax in (a1, a2):
            say(ax, "no c to draw: no (k̃, σ̃ > 0) whose rise could be read")
    else:
        a1.axhline(0, color="0.6", lw=0.5)
        a2.set_xscale("log")
        a2.set_yscale("log")
        cpos = [g.reading.c for st in data.studies.values() for g in st.groups
                if g.reading.c > 0 and g.sigma_tilde > 0]
        if cpos:                    # the cut line dives to 0 at sigma~_c: keep the data in view
            a2.set_ylim(min(cpos) / 5, max(cpos) * 3)
        for s, col in zeros:
            a2.annotate("c = 0", (s, 0), xycoords=("data", "axes fraction"), xytext=(0, 8),
                        textcoords="offset points", ha="center", fontsize=8, color=col,
                        arrowprops={"arrowstyle": "->", "color": col})
        legend(a1, loc="upper right")
    for ax in (a1, a2):
        ax.set_xlabel(f"roughness {SIG}")
        ax.set_ylabel("adhesion coefficient c (chord over the first half of the rise)")
    a1.set_title(f"c = max(α/{SIG} − β, 0) (lines; dotted: poor fit); open: not in the fit",
                 fontsize=10)
    a2.set_title("log–log (c > 0; arrows: c = 0, adhesion lost)", fontsize=10)
    fig.tight_layout()
    return save(fig, out_dir, name)


def c0_vs_sigma(data, out_dir, name="c0_vs_sigma.png"):
    """The first-contact slope c0 against sigma~ per k~ (log-log), seed intervals."""
    fig, ax = subplots(figsize=(6.6, 4.6))
    drawn = False
    for i, (k, st) in enumerate(data.studies.items()):
        sel = [g for g in st.groups if math.isfinite(g.reading.c0) and g.reading.c0 > 0
               and g.sigma_tilde > 0]
        if sel:
            drawn = True
            ax.errorbar([g.sigma_tilde for g in sel], [g.reading.c0 for g in sel],
                        yerr=np.array([err(g.reading.c0, g.c0_ci) for g in sel]).T, fmt="s-",
                        ms=5, lw=1, capsize=2, color=f"C{i % 10}", label=f"{KT}={k:g}")
    if drawn:
        ax.set_xscale("log")
        ax.set_yscale("log")
        legend(ax)
    else:
        say(ax, "no c₀ > 0 to draw (no rise, or no σ̃ > 0)")
    ax.set_xlabel(f"roughness {SIG}")
    ax.set_ylabel(f"first-contact slope c$_0$ ({FA}/" + "$\\tilde F_P$, first quarter of the rise)")
    ax.set_title("first-contact slope c$_0$ (seed intervals)", fontsize=10)
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
        col = f"C{i % 10}"
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
                        fmt="o-", ms=5, capsize=2, lw=1, color=f"C{i % 10}", label=f"{SIG}={s:g}")
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
    a1.set_xlabel(f"roughness {SIG}")
    a2.set_xlabel(f"pillar stiffness {KT}")
    for ax in (a1, a2):
        ax.set_ylabel(f"plateau {FA}")
    a1.set_title("plateau against roughness (seed intervals)", fontsize=10)
    a2.set_title("plateau against stiffness", fontsize=10)
    fig.tight_layout()
    return save(fig, out_dir, name)


def alpha_sigma_c(data, out_dir, name="alpha_sigma_c.png"):
    """alpha, beta and sigma~_c against k~, seed intervals; missing values say why."""
    fig, axes = subplots(1, 3, figsize=(14, 4.4))
    ks = [k for k, st in data.studies.items() if st.ab.ok]
    why = "; ".join(f"{KT}={k:g}: {st.ab.notes[0]}" for k, st in data.studies.items()
                    if not st.ab.ok and st.ab.notes)
    for ax, (name_, attr, ci) in zip(axes, (("α", "alpha", "alpha_ci"), ("β", "beta", "beta_ci"),
                                             (f"{SIG}$_c$ = α/β", "sigma_c", "sigma_c_ci"))):
        pts = [(k, getattr(data.studies[k].ab, attr), getattr(data.studies[k], ci)) for k in ks]
        pts = [p for p in pts if math.isfinite(p[1])]
        if pts:
            ax.errorbar([p[0] for p in pts], [p[1] for p in pts],
                        yerr=np.array([err(v, c) for _, v, c in pts]).T, fmt="o-", capsize=3,
                        lw=1)
            for k, v, c in pts:
                if math.isinf(c[1]):
                    ax.annotate("↑ unbounded", (k, v), fontsize=8, textcoords="offset points",
                                xytext=(4, 6))
            if len(pts) > 1 and min(p[0] for p in pts) > 0 and \
                    max(p[0] for p in pts) / min(p[0] for p in pts) >= 10:
                ax.set_xscale("log")
            v = [p[1] for p in pts]
            if attr != "beta" and min(v) > 0 and max(v) / min(v) >= 10:
                ax.set_yscale("log")
        else:
            text = (f"no {name_} to draw:\n" + (why or "no k̃ has α and β")
                    if not ks else f"no {name_}: β ≤ 0 for every k̃\n(the lines never reach c = 0)")
            say(ax, "\n".join(text[i:i + 60] for i in range(0, min(len(text), 360), 60)))
        if attr == "beta":
            ax.axhline(0, color="0.6", lw=0.5)
        ax.set_xlabel(f"pillar stiffness {KT}")
        ax.set_ylabel(name_)
        ax.set_title(f"{name_} (seed intervals)", fontsize=10)
    fig.tight_layout()
    return save(fig, out_dir, name)
