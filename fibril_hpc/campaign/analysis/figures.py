"""The report's figures of forces (matplotlib ``Figure`` objects, no pyplot state): loading
curves, F~_A against F~_P on the paper's linear axes beside the log view, and the machine sweep.
One function per PNG, each returning its path; nothing here computes a reading. A figure with
nothing to draw says why on its face (:func:`say`). The coefficient figures are in
:mod:`.figures_coeff`.
"""

from __future__ import annotations

import math
import os

import numpy as np

from ...io.files import save_figure

FA, FP, SIG, KT = "$\\tilde F_A$", "$\\tilde F_P$", "$\\tilde\\sigma$", "$\\tilde k$"
LEGEND = 8          # legend font size (points)


def subplots(nrows=1, ncols=1, **kw):
    """A new figure and its axes (``matplotlib.figure.Figure``: no pyplot state, so nothing is
    left open when a figure fails, and no backend is chosen for the caller)."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=kw.pop("figsize", None))
    return fig, fig.subplots(nrows, ncols, **kw)


def save(fig, out_dir, name):
    """Write ``fig`` atomically as ``out_dir/name``; returns the path."""
    p = os.path.join(out_dir, name)
    save_figure(fig, p, "writing the report")   # atomic; a full disk is one line
    return p


def legend(ax, **kw):
    """A legend where the axis has labelled artists (none: no legend, no warning)."""
    handles, labels = ax.get_legend_handles_labels()
    if labels:
        ax.legend(fontsize=LEGEND, **kw)


def open_log_range(ax):
    """A log axis whose data span no range (one point, and lines at its value) is widened to a
    factor 2 each way: left as it is, its height is a rounding error and matplotlib divides by
    it (a grid of one preload met this)."""
    for get, put, scale in ((ax.get_xlim, ax.set_xlim, ax.get_xscale),
                            (ax.get_ylim, ax.set_ylim, ax.get_yscale)):
        lo, hi = get()
        if scale() == "log" and lo > 0 and hi > 0 and abs(math.log(hi / lo)) < 1e-9:
            put(min(lo, hi) / 2, max(lo, hi) * 2)


def say(ax, text):
    """Write why an axis is empty on its face (no blank figure)."""
    ax.text(0.5, 0.5, text, transform=ax.transAxes, ha="center", va="center", fontsize=9,
            wrap=True, color="0.25", bbox={"fc": "0.95", "ec": "0.7"})


def colour(i: int, n: int):
    """The i-th of n line colours: matplotlib's ten-colour cycle up to ten, a viridis ramp above
    (the cycle would repeat: two k~ of the paper grid's eleven shared blue)."""
    if n <= 10:
        return f"C{i % 10}"
    from matplotlib import colormaps

    return colormaps["viridis"](0.92 * i / max(n - 1, 1))


def err(val, ci):
    """Asymmetric error bar lengths (0 where the interval is unknown or unbounded)."""
    lo, hi = ci
    return [0.0 if not np.isfinite(lo) else max(val - lo, 0.0),
            0.0 if not np.isfinite(hi) else max(hi - val, 0.0)]


def curves(jobs, out_dir, name="curves.png"):
    """Force and contact area against indentation, loading and unloading, for chosen jobs."""
    fig, (a1, a2) = subplots(1, 2, figsize=(11, 4.4))
    drawn = 0
    for i, j in enumerate(jobs):
        col = colour(i, len(jobs))
        lab = (f"{KT}={j['k_tilde']:g}, {SIG}={j['sigma_tilde']:g}, "
               f"{FP}={j['F_P']:.3g}, seed {j['seed']}")
        for br, ls in (("loading", "-"), ("unloading", "--")):
            cv = j.get(br)
            if not cv or len(cv.get("d_tilde", ())) == 0:
                continue
            drawn += 1
            a1.plot(cv["d_tilde"], cv["F_tilde"], ls, color=col, lw=1,
                    label=lab if br == "loading" else None)
            a2.plot(cv["d_tilde"], cv["contact_fraction"], ls, color=col, lw=1)
    if not drawn:
        for ax in (a1, a2):
            say(ax, "no loading curve stored in the file\n(no done job with curves)")
    a1.axhline(0, color="0.6", lw=0.5)
    a1.set_xlabel("indentation $\\tilde d$")
    a1.set_ylabel("force $\\tilde F$ (compressive > 0)")
    a1.set_title("force; solid: loading, dashed: unloading", fontsize=10)
    a2.set_xlabel("indentation $\\tilde d$")
    a2.set_ylabel("contact area fraction")
    a2.set_title("contact area; solid: loading, dashed: unloading", fontsize=10)
    if drawn:
        legend(a1)
    fig.tight_layout()
    return save(fig, out_dir, name)


def _rise_lines(ax, g, col, linear):
    """The plateau (dashed, over the preloads it was read from) and, on linear axes, the line
    F~_A = c F~_P through the origin and the half point; on log axes the c0 line over the first
    decade."""
    r = g.reading
    if math.isfinite(r.plateau) and math.isfinite(r.plateau_from):
        ax.hlines(r.plateau, r.plateau_from, ax.get_xlim()[1] if linear else r.plateau_from * 8,
                  colors=col, linestyles="--", lw=1)
    if linear and math.isfinite(r.c) and r.c > 0 and math.isfinite(r.F_P_half):
        xs = np.array([0.0, r.plateau / r.c])      # through the origin and the half point
        ax.plot(xs, r.c * xs, ":", color=col, lw=1.2)
    if not linear and math.isfinite(r.c0) and r.c0 > 0 and r.F_P0 > 0:
        xs = np.array([r.F_P0, r.F_P0 * 10])
        ax.plot(xs, r.c0 * xs, ":", color=col, lw=1.2)


def fa_vs_fp(data, out_dir, name="FA_vs_FP.png"):
    """F~_A against F~_P per k~: linear axes (the paper's) and log-log; seed means, bars the
    seed range, dashed the plateau, dotted the line c F~_P (linear) and the c0 line (log)."""
    ks = list(data.studies)
    nrow = max(len(ks), 1)
    fig, axes = subplots(nrow, 2, figsize=(12, 3.9 * nrow), squeeze=False)
    if not ks:
        for ax in axes.flat:
            say(ax, "no done job with finite forces: nothing to draw")
    for row, k in zip(axes, ks):
        groups = data.studies[k].groups
        for linear, ax in zip((True, False), row):
            drawn = False
            for i, g in enumerate(groups):
                lv = data.means.get((k, g.sigma_tilde))
                if lv is None or len(lv) == 0:
                    continue
                x, y = lv.F_P, lv.F_A
                keep = np.ones(x.size, bool) if linear else (x > 0) & (y > 0)
                if not keep.any():
                    continue
                drawn = True
                col = colour(i, len(groups))
                yerr = np.clip(np.vstack([y - lv.lo, lv.hi - y]), 0, None)[:, keep]
                state = g.reading.plateau_state
                ax.errorbar(x[keep], y[keep], yerr=yerr, fmt="o-", ms=3.5, lw=0.8, capsize=2,
                            color=col, mfc=col if state == "reached" else "none",
                            label=f"{SIG}={g.sigma_tilde:g}"
                            + ("" if state == "reached" else f" ({state})"))
            if not drawn:
                say(ax, "no point with F̃_P > 0 and F̃_A > 0 for a log axis" if not linear
                    else "no finite point")
                continue
            if linear:
                ax.set_xlim(left=0)
                ax.set_ylim(bottom=0)
            else:
                ax.set_xscale("log")
                ax.set_yscale("log")
            for i, g in enumerate(groups):
                _rise_lines(ax, g, colour(i, len(groups)), linear)
            open_log_range(ax)
            legend(ax, ncol=1 if len(groups) < 6 else 2)
        row[0].set_title(f"{KT} = {k:g}: linear axes (as the paper); dotted: {FA} = c {FP}",
                         fontsize=10)
        row[1].set_title(f"{KT} = {k:g}: log axes; dotted: first-contact slope c$_0$",
                         fontsize=10)
        for ax in row:
            ax.set_xlabel(f"preload {FP}")
            ax.set_ylabel(f"pull-off force {FA}")
    fig.suptitle("seed means, bars: seed range; dashed: the plateau over the preloads it was "
                 "read from; open markers: plateau not reached / no rise", fontsize=10)
    fig.tight_layout(rect=(0, 0, 1, 1 - 0.35 / (3.9 * nrow)))    # the caption above the panels
    return save(fig, out_dir, name)


def machine(jobs, out_dir, name="machine.png"):
    """F~_A (the peak tension) and F_jump (the final jump-off) against the machine stiffness
    k~_m, seed means per (k~, sigma~, preload), for a grid that sweeps ``k_machine``; a rigid
    machine (no jump) is left out of F_jump."""
    by: dict = {}
    for j in jobs:
        km = float(j.get("k_machine", math.inf))
        if j.get("status") == "done" and math.isfinite(km):
            key = (j["k_tilde"], j["sigma_tilde"], j["preload"])
            by.setdefault(key, {}).setdefault(km, []).append(j)
    fig, ax = subplots(figsize=(6.4, 4.4))
    for i, (key, lev) in enumerate(sorted(by.items())):
        kms = sorted(lev)
        col = f"C{i % 10}"
        fa = [np.mean([j["F_A"] for j in lev[k]]) for k in kms]
        fj = [np.mean([j["F_jump"] for j in lev[k] if j.get("F_jump") is not None] or [math.nan])
              for k in kms]
        lab = f"{KT}={key[0]:g}, {SIG}={key[1]:g}, preload {key[2]:g}"
        ax.plot(kms, fa, "--", color=col, lw=1)
        ax.plot(kms, fj, "o-", color=col, ms=3, lw=1, label=lab)
    if by:
        ax.set_xscale("log")
        legend(ax)
    else:
        say(ax, "no done job with a compliant machine")
    ax.set_xlabel("machine stiffness $\\tilde k_m$")
    ax.set_ylabel("tension / $F_c$")
    ax.set_title(f"solid: final jump-off $F_{{jump}}$; dashed: peak {FA}", fontsize=10)
    fig.tight_layout()
    return save(fig, out_dir, name)
