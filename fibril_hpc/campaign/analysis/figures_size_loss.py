"""The report's figure of where adhesion is lost across brush sizes (a grid sweeping
``n_side``): per k~, the plateau against sigma~ at every size with its seed interval, the
extrapolation P_inf of P(N) = P_inf + A N^(-3/4) with its interval, the per-area threshold and
each size's few-pillar threshold. Inputs: :attr:`.report_data.ReportData.size_loss`. The axes
are set by the measured plateaus, never by the extrapolation.
"""

from __future__ import annotations

import math

import numpy as np

from ..laws import size_loss as sl
from ..laws.reading import FEW_PILLARS
from .figures import FA, KT, SIG, err, legend, save, say, subplots


def loss_across_sizes(data, out_dir, name="loss_across_sizes.png"):
    """One panel per k~: plateau against sigma~ per n_side (seed intervals), P_inf (black,
    interval band; a sigma~ whose line is rejected a red cross, one whose P_inf lies below 0 an
    open magenta triangle; where no limit is read, points
    with intervals and no line), the per-area threshold (grey) and the few-pillar thresholds
    (dotted, the size's colour); crossings marked with their intervals on the threshold lines."""
    ks = list(data.size_loss)
    fig, axes = subplots(1, max(1, len(ks)), figsize=(5.2 * max(1, len(ks)), 4.4), squeeze=False)
    if not ks:
        say(axes[0][0], "no grid sweeping n_side over two sizes")
    for ax, k in zip(axes[0], ks):
        s = data.size_loss[k]
        sig = np.array(s.sigmas, float)
        top = 0.0
        for i, n in enumerate(s.n_sides):
            col = f"C{i % 10}"
            p = np.asarray(s.plateau[n], float)
            ok = np.isfinite(p)
            if not ok.any():
                continue
            top = max(top, float(np.nanmax(p[ok])))
            e = np.array([err(v, ci) for v, ci in zip(p[ok], np.asarray(s.plateau_ci[n])[ok])]).T
            ax.errorbar(sig[ok], p[ok], yerr=e, fmt="o-", ms=4, lw=1, capsize=2, color=col,
                        label=f"n_side = {n}")
            few = next(c for c in s.few if c.n_side == n)
            ax.axhline(few.threshold, color=col, ls=":", lw=0.9)
            if math.isfinite(few.sigma):
                ax.plot([few.sigma], [few.threshold], "v", color=col, ms=7)
        ex = [e for e in s.extrapolations if math.isfinite(e.p_inf)]
        if ex:
            xs = np.array([e.sigma_tilde for e in ex])
            ys = np.array([e.p_inf for e in ex])
            lo = np.array([e.p_inf_ci[0] for e in ex])
            hi = np.array([e.p_inf_ci[1] for e in ex])
            bad = np.array([e.state in sl.NO_LIMIT for e in ex])
            if s.sigma_inf_kind == sl.NOT_SIZE_FREE:
                # no limit is read: P_inf as points only, no line that would cross a threshold
                ok = ~bad & np.isfinite(lo) & np.isfinite(hi)
                ax.errorbar(xs[ok], ys[ok], yerr=[ys[ok] - lo[ok], hi[ok] - ys[ok]], fmt="ks",
                            ms=4, capsize=2, label="P∞ (N^(−3/4) line), no limit read")
            else:
                ax.plot(xs, ys, "ks-", ms=4, lw=1.3, label="P∞ (N → ∞, N^(−3/4))")
                if np.all(np.isfinite(lo)) and np.all(np.isfinite(hi)):
                    ax.fill_between(xs, lo, hi, color="0.6", alpha=0.35, lw=0)
            rej = np.array([e.state == sl.REJECTED for e in ex])
            if rej.any():
                ax.plot(xs[rej], ys[rej], "rx", ms=8, mew=1.5,
                        label=f"P∞ rejected (χ²/dof > {sl.POOR_CHI2:g})")
            if (bad & ~rej).any():
                ax.plot(xs[bad & ~rej], ys[bad & ~rej], "v", color="m", ms=7, mfc="none",
                        mew=1.5, label="P∞ below 0: the line overshoots")
        ax.axhline(s.area_threshold, color="0.4", lw=1, ls="--",
                   label=f"per-area threshold {s.area_threshold:g}")
        ax.axhline(0.0, color="0.7", lw=0.6)
        if math.isfinite(s.sigma_inf):
            ax.errorbar([s.sigma_inf], [s.area_threshold],
                        xerr=np.array([err(s.sigma_inf, s.sigma_inf_ci)]).T, fmt="k*", ms=11,
                        capsize=3, label="σ̃ where P∞ falls to it")
        if top > 0:                      # set by the measured plateaus only
            ax.set_ylim(-0.08 * top, 1.1 * top)
        ax.set_xscale("log")
        ax.set_xlabel(f"{SIG} (log axis)")
        ax.set_ylabel(f"plateau {FA}")
        ax.set_title(f"{KT} = {k:g}: dotted, {FEW_PILLARS:g} pillars of each size (▼ crossing)",
                     fontsize=9)
        legend(ax)
    fig.tight_layout()
    return save(fig, out_dir, name)


__all__ = ["loss_across_sizes"]
