"""The report's figures (matplotlib, Agg backend): one function per PNG, each returning its path.

Inputs are the fits of :mod:`fibril_hpc.campaign.laws.fit` and done job records (dicts); nothing here
computes a fit.
"""

from __future__ import annotations

import math
import os

import numpy as np

from ...io.files import save_figure
from ..laws.fit import model

FA, FP, SIG, KT = "$\\tilde F_A$", "$\\tilde F_P$", "$\\tilde\\sigma$", "$\\tilde k$"


def _plt():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _save(fig, out_dir, name):
    plt = _plt()
    p = os.path.join(out_dir, name)
    try:
        save_figure(fig, p, "writing the report")   # atomic; a full disk is one line
    finally:
        plt.close(fig)
    return p


def _spans_decades(v) -> bool:
    v = np.asarray([x for x in v if np.isfinite(x) and x > 0])
    return v.size >= 2 and v.max() / v.min() >= 10.0


def _err(val, ci):
    """Asymmetric error bar lengths (0 where the interval is unknown)."""
    lo, hi = ci
    return [0.0 if not np.isfinite(lo) else max(val - lo, 0.0),
            0.0 if not np.isfinite(hi) else max(hi - val, 0.0)]


def _grid(n):
    ncol = min(3, n)
    return ncol, math.ceil(n / ncol)


def curves(jobs, out_dir, name="curves.png"):
    """Force and contact area against indentation, loading and unloading, for chosen jobs."""
    plt = _plt()
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(11, 4.2))
    for i, j in enumerate(jobs):
        col = f"C{i % 10}"
        lab = (f"{KT}={j['k_tilde']:g}, {SIG}={j['sigma_tilde']:g}, "
               f"{FP}={j['F_P']:.3g}, seed {j['seed']}")
        for br, ls in (("loading", "-"), ("unloading", "--")):
            cv = j.get(br)
            if not cv or len(cv["d_tilde"]) == 0:
                continue
            a1.plot(cv["d_tilde"], cv["F_tilde"], ls, color=col, lw=1,
                    label=lab if br == "loading" else None)
            a2.plot(cv["d_tilde"], cv["contact_fraction"], ls, color=col, lw=1)
    a1.axhline(0, color="0.6", lw=0.5)
    a1.set_xlabel("indentation $\\tilde d$")
    a1.set_ylabel("force $\\tilde F$ (compressive > 0)")
    a1.set_title("force; solid: loading, dashed: unloading")
    a2.set_xlabel("indentation $\\tilde d$")
    a2.set_ylabel("contact area fraction")
    a2.set_title("contact area; solid: loading, dashed: unloading")
    a1.legend(fontsize=6)
    fig.tight_layout()
    return _save(fig, out_dir, name)


def fa_vs_fp(fits, means, out_dir, name="FA_vs_FP.png"):
    """F~_A against F~_P per k~ (seed mean, bars: min-max over seeds) with the fitted law."""
    plt = _plt()
    ks = list(fits)
    ncol, nrow = _grid(len(ks))
    fig, axes = plt.subplots(nrow, ncol, figsize=(4.6 * ncol, 3.8 * nrow), squeeze=False)
    for ax, k in zip(axes.flat, ks):
        xs_all = []
        for i, g in enumerate(fits[k]["groups"]):
            col = f"C{i % 10}"
            m = means[(k, g.sigma_tilde)]
            xs_all += list(m["F_P"])
            yerr = np.vstack([m["F_A"] - m["F_A_min"], m["F_A_max"] - m["F_A"]])
            ax.errorbar(m["F_P"], m["F_A"], yerr=yerr, fmt="o", ms=3, capsize=2, color=col,
                        mfc=col if g.resolved else "none",
                        label=f"{SIG}={g.sigma_tilde:g}" + ("" if g.resolved else " (unresolved)"))
            if np.isfinite(g.c) and np.isfinite(g.plateau):
                xx = np.geomspace(max(min(m["F_P"]), 1e-12) / 1.5, max(m["F_P"]) * 1.5, 200)
                ax.plot(xx, model(g.law, xx, g.c, g.plateau), "-", color=col, lw=1)
                ax.axvline(g.kink, color=col, lw=0.5, ls=":")
        if _spans_decades(xs_all):
            ax.set_xscale("log")
            ax.set_yscale("log")
        ax.set_title(f"{KT} = {k:g}")
        ax.set_xlabel(f"preload {FP}")
        ax.set_ylabel(f"pull-off force {FA}")
        ax.legend(fontsize=6)
    for ax in list(axes.flat)[len(ks):]:
        ax.axis("off")
    law = next(iter(fits.values()))["groups"][0].law if ks else ""
    fig.suptitle(f"fitted law '{law}' (lines; dotted: kink); open markers: unresolved", fontsize=9)
    fig.tight_layout()
    return _save(fig, out_dir, name)


def c_vs_sigma(fits, out_dir, name="c_vs_sigma.png"):
    """c against sigma~, linear and log-log, with the alpha/sigma~ - beta fits."""
    plt = _plt()
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(11, 4.2))
    for i, (k, e) in enumerate(fits.items()):
        col = f"C{i % 10}"
        gs = [g for g in e["groups"] if np.isfinite(g.c)]
        ab = e["ab"]
        for ax in (a1, a2):
            for res, mfc in ((True, col), (False, "none")):
                sel = [g for g in gs if g.resolved == res and (ax is a1 or g.sigma_tilde > 0)]
                if not sel:
                    continue
                yerr = np.array([_err(g.c, g.c_ci) for g in sel]).T
                ax.errorbar([g.sigma_tilde for g in sel], [g.c for g in sel], yerr=yerr, fmt="o",
                            ms=4, capsize=2, color=col, mfc=mfc,
                            label=(f"{KT}={k:g}" if res else f"{KT}={k:g} unresolved"))
            if np.isfinite(ab.alpha):
                sg = np.geomspace(max(min(ab.sigmas), 1e-3) / 1.3, max(ab.sigmas) * 1.3, 200)
                fit = ab.alpha / sg - ab.beta
                keep = fit > 0 if ax is a2 else np.ones_like(fit, bool)
                ax.plot(sg[keep], fit[keep], "-", color=col, lw=1)
    a1.axhline(0, color="0.6", lw=0.5)
    for ax in (a1, a2):
        ax.set_xlabel(f"roughness {SIG}")
        ax.set_ylabel(f"adhesion coefficient c ({FA} = c {FP})")
    a1.set_title(f"c = α/{SIG} − β (lines), 95 % intervals")
    a2.set_xscale("log")
    a2.set_yscale("log")
    a2.set_title("log–log (c > 0)")
    a1.legend(fontsize=6)
    fig.tight_layout()
    return _save(fig, out_dir, name)


def plateau(fits, out_dir, name="plateau.png"):
    """Plateau F~_A against sigma~ (per k~) and against k~ (per sigma~)."""
    plt = _plt()
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(11, 4.2))
    ks = list(fits)
    sigmas = sorted({g.sigma_tilde for e in fits.values() for g in e["groups"]})
    for i, k in enumerate(ks):
        gs = [g for g in fits[k]["groups"] if np.isfinite(g.plateau)]
        col = f"C{i % 10}"
        a1.plot([g.sigma_tilde for g in gs], [g.plateau for g in gs], "-", color=col, lw=1)
        for conf, mfc in ((True, col), (False, "none")):
            sel = [g for g in gs if g.plateau_confirmed == conf]
            if sel:
                a1.errorbar([g.sigma_tilde for g in sel], [g.plateau for g in sel],
                            yerr=np.array([_err(g.plateau, g.plateau_ci) for g in sel]).T,
                            fmt="o", ms=4, capsize=2, color=col, mfc=mfc,
                            label=f"{KT}={k:g}" + ("" if conf else " (not confirmed)"))
    for i, s in enumerate(sigmas):
        pts = [(k, g) for k in ks for g in fits[k]["groups"]
               if g.sigma_tilde == s and np.isfinite(g.plateau)]
        if not pts:
            continue
        col = f"C{i % 10}"
        a2.errorbar([k for k, _ in pts], [g.plateau for _, g in pts],
                    yerr=np.array([_err(g.plateau, g.plateau_ci) for _, g in pts]).T,
                    fmt="o-", ms=4, capsize=2, lw=1, color=col, label=f"{SIG}={s:g}")
    a1.set_xlabel(f"roughness {SIG}")
    a1.set_ylabel(f"plateau {FA}")
    a1.set_title("plateau of the fitted law, 95 % intervals")
    if _spans_decades(sigmas):
        a1.set_xscale("log")
    if _spans_decades(ks):
        a2.set_xscale("log")
    if _spans_decades([g.plateau for e in fits.values() for g in e["groups"]]):
        a1.set_yscale("log")
        a2.set_yscale("log")
    a2.set_xlabel(f"pillar stiffness {KT}")
    a2.set_ylabel(f"plateau {FA}")
    a1.legend(fontsize=6)
    a2.legend(fontsize=6)
    fig.tight_layout()
    return _save(fig, out_dir, name)


def plateau_map(fits, out_dir, name="plateau_map.png"):
    """The plateau over (sigma~, k~): one cell per grid point (hatched: not confirmed)."""
    plt = _plt()
    ks = sorted(fits)
    sigmas = sorted({g.sigma_tilde for e in fits.values() for g in e["groups"]})
    z = np.full((len(ks), len(sigmas)), np.nan)
    conf = np.zeros_like(z, dtype=bool)
    for a, k in enumerate(ks):
        for g in fits[k]["groups"]:
            b = sigmas.index(g.sigma_tilde)
            z[a, b] = g.plateau
            conf[a, b] = g.plateau_confirmed
    fig, ax = plt.subplots(figsize=(1.2 * len(sigmas) + 3, 0.8 * len(ks) + 2))
    im = ax.imshow(np.ma.masked_invalid(z), origin="lower", aspect="auto", cmap="viridis")
    for a in range(len(ks)):
        for b in range(len(sigmas)):
            if np.isfinite(z[a, b]):
                ax.text(b, a, f"{z[a, b]:.3g}" + ("" if conf[a, b] else "*"), ha="center",
                        va="center", fontsize=7, color="w")
    ax.set_xticks(range(len(sigmas)), [f"{s:g}" for s in sigmas])
    ax.set_yticks(range(len(ks)), [f"{k:g}" for k in ks])
    ax.set_xlabel(f"roughness {SIG}")
    ax.set_ylabel(f"pillar stiffness {KT}")
    ax.set_title(f"plateau {FA} (*: not confirmed by two preloads above the kink)", fontsize=9)
    fig.colorbar(im, ax=ax, label=f"plateau {FA}")
    fig.tight_layout()
    return _save(fig, out_dir, name)


def alpha_sigma_c(fits, out_dir, name="alpha_sigma_c.png"):
    """alpha and sigma~_c against k~, 95 % intervals."""
    plt = _plt()
    ks = [k for k in fits if np.isfinite(fits[k]["ab"].alpha)]
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(11, 4.2))
    if ks:
        abs_ = [fits[k]["ab"] for k in ks]
        a1.errorbar(ks, [a.alpha for a in abs_],
                    yerr=np.array([_err(a.alpha, a.alpha_ci) for a in abs_]).T,
                    fmt="o-", capsize=3, lw=1)
        sc = [(k, a) for k, a in zip(ks, abs_) if np.isfinite(a.sigma_c)]
        if sc:
            a2.errorbar([k for k, _ in sc], [a.sigma_c for _, a in sc],
                        yerr=np.array([_err(a.sigma_c, a.sigma_c_ci) for _, a in sc]).T,
                        fmt="s-", capsize=3, lw=1, color="C1")
            for k, a in sc:
                if not np.isfinite(a.sigma_c_ci[1]):
                    a2.annotate("↑ unbounded", (k, a.sigma_c), fontsize=7,
                                textcoords="offset points", xytext=(4, 6))
    for ax in (a1, a2):
        if _spans_decades(ks):
            ax.set_xscale("log")
        ax.set_xlabel(f"pillar stiffness {KT}")
    if ks and _spans_decades([fits[k]["ab"].alpha for k in ks]):
        a1.set_yscale("log")
    a1.set_ylabel("α (c = α/$\\tilde\\sigma$ − β)")
    a1.set_title("α, 95 % intervals")
    a2.set_ylabel(f"critical roughness {SIG}$_c$ = α/β")
    a2.set_title(f"{SIG}$_c$, 95 % intervals (β > 0 only)")
    fig.tight_layout()
    return _save(fig, out_dir, name)


def machine(jobs, out_dir, name="machine.png"):
    """F~_A (the peak tension) and F_jump (the final jump-off) against the machine stiffness
    k~_m, seed means per (k~, sigma~, preload), for a grid that sweeps ``k_machine``; a rigid
    machine (no jump) is left out of F_jump."""
    plt = _plt()
    by: dict = {}
    for j in jobs:
        km = float(j.get("k_machine", math.inf))
        if j.get("status") == "done" and math.isfinite(km):
            key = (j["k_tilde"], j["sigma_tilde"], j["preload"])
            by.setdefault(key, {}).setdefault(km, []).append(j)
    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    for i, (key, lev) in enumerate(sorted(by.items())):
        kms = sorted(lev)
        col = f"C{i % 10}"
        fa = [np.mean([j["F_A"] for j in lev[k]]) for k in kms]
        fj = [np.mean([j["F_jump"] for j in lev[k] if j.get("F_jump") is not None] or [math.nan])
              for k in kms]
        lab = f"{KT}={key[0]:g}, {SIG}={key[1]:g}, preload {key[2]:g}"
        ax.plot(kms, fa, "--", color=col, lw=1)
        ax.plot(kms, fj, "o-", color=col, ms=3, lw=1, label=lab)
    ax.set_xscale("log")
    ax.set_xlabel("machine stiffness $\\tilde k_m$")
    ax.set_ylabel("tension / $F_c$")
    ax.set_title(f"solid: final jump-off $F_{{jump}}$; dashed: peak {FA}")
    ax.legend(fontsize=6)
    fig.tight_layout()
    return _save(fig, out_dir, name)
