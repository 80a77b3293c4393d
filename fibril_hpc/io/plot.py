"""Figures of one simulation (matplotlib, Agg backend; imported only when a plot is asked for)."""

from __future__ import annotations

import numpy as np

from .files import save_figure
from .results import SimulationResult


def plot_result(result: SimulationResult, path: str, exclusive: str | None = None) -> None:
    """F~ vs d~ (loading and unloading), contact fraction vs d~, and contact maps at the
    largest preload and at pull-off; written as PNG to ``path`` (a new file, checked
    atomically, with ``exclusive``: see :func:`fibril_hpc.io.files.write_bytes_atomically`)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig = plt.figure(figsize=(12, 8), constrained_layout=True)
    gs = fig.add_gridspec(2, 3)
    ax_f = fig.add_subplot(gs[0, :2])
    ax_a = fig.add_subplot(gs[1, :2], sharex=ax_f)
    ax_m1 = fig.add_subplot(gs[0, 2])
    ax_m2 = fig.add_subplot(gs[1, 2])
    colours = plt.cm.viridis(np.linspace(0.1, 0.85, max(len(result.results), 1)))
    for r, c in zip(result.results, colours):
        if r.loading is None:
            continue
        label = f"{r.preload_kind} = {r.preload:g}: F~_P = {r.F_P:.3g}, F~_A = {r.F_A:.3g}"
        ax_f.plot(r.loading.d_tilde, r.loading.F_tilde, color=c, lw=1.2, label=label)
        ax_a.plot(r.loading.d_tilde, r.loading.contact_fraction, color=c, lw=1.2)
        if r.unloading is not None:
            ax_f.plot(r.unloading.d_tilde, r.unloading.F_tilde, color=c, lw=1.2, ls="--")
            ax_a.plot(r.unloading.d_tilde, r.unloading.contact_fraction, color=c, lw=1.2, ls="--")
            if np.isfinite(r.d_tilde_at_F_A):
                ax_f.plot([r.d_tilde_at_F_A], [-r.F_A], "v", color=c)
    ax_f.axhline(0.0, color="0.6", lw=0.6)
    ax_f.set_ylabel("F~ = F / F_c")
    ax_f.set_title(f"{result.scene.n_side}x{result.scene.n_side} pillars, k~ = "
                   f"{result.scene.k_tilde:g}, sigma~ = {result.scene.sigma_tilde:g}, "
                   f"seed {result.scene.seed} (solid: loading, dashed: unloading)")
    ax_f.legend(fontsize=8)
    ax_a.set_xlabel("d~ = d / d_c")
    ax_a.set_ylabel("contact fraction of pillar area")
    main = result.main
    for ax, state, title in ((ax_m1, main and main.at_preload, "contact at preload"),
                             (ax_m2, main and main.at_pulloff, "contact at pull-off (min F)")):
        ax.set_xticks([])
        ax.set_yticks([])
        if state is None:
            ax.set_title(title + ": n/a")
            continue
        pm = np.where(state.contact_map > 0, state.pressure_map, np.nan)
        lim = np.nanmax(np.abs(pm)) if np.isfinite(pm).any() else 1.0
        im = ax.imshow(pm, origin="lower", cmap="RdBu_r", vmin=-lim, vmax=lim,
                       interpolation="nearest")
        ax.set_title(f"{title}, d~ = {state.d_tilde:.3g}")
        fig.colorbar(im, ax=ax, shrink=0.8, label="p A0 / F_c (attached)")

    try:
        save_figure(fig, path, "writing the plot", exclusive)
    finally:
        plt.close(fig)
