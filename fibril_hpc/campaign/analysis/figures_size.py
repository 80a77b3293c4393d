"""The report's finite-size figure (a grid sweeping ``n_side``): the plateau of every (k~, sigma~)
against the brush size, and its ratio to the largest n_side's (log axis). Inputs: the rows of
:func:`fibril_hpc.campaign.laws.size.size_rows` held by :class:`.report_data.ReportData`.
"""

from __future__ import annotations

import math

import numpy as np

from ..laws.size import reference_sizes
from .figures import FA, KT, SIG, err, legend, save, say, subplots

#: relative offset in n_side between the lines, so that their error bars stay apart
OFFSET = 0.012
#: lowest end of a ratio's bar on the log axis, as a fraction of the ratio itself
FLOOR = 0.1


def _size_axis(ax, sizes):
    ax.set_xscale("log")
    ax.set_xticks(sizes)
    ax.set_xticklabels([str(n) for n in sizes])
    ax.minorticks_off()
    ax.set_xlim(min(sizes) / 1.25, max(sizes) * 1.25)
    ax.set_xlabel("brush size n_side (pillars per side, log axis)")


def plateau_vs_n_side(data, out_dir, name="plateau_vs_n_side.png"):
    """The plateau against n_side (log axis), one line per (k~, sigma~), seed intervals as error
    bars (open markers: plateau not reached, a lower bound), beside its ratio to the largest
    n_side's on a log axis (error bars: the range the two seed intervals allow)."""
    fig, (a1, a2) = subplots(1, 2, figsize=(13, 4.9))
    groups: dict = {}
    for r in data.size:
        if math.isfinite(r.plateau):
            groups.setdefault((r.k_tilde, r.sigma_tilde), []).append(r)
    sizes = sorted({r.n_side for rs in groups.values() for r in rs} | set(data.n_sides))
    # each k~ against its own largest size (a merged file whose k~ ran other sizes)
    refs = reference_sizes(data.size, data.n_sides)
    ref = (f"n_side = {refs[0]}" if len(refs) == 1 else
           "each k̃'s largest n_side (" + ", ".join(map(str, refs)) + ")")
    if not groups:
        for ax in (a1, a2):
            say(ax, "no plateau to draw: no done job with finite forces")
    ks = sorted({k for k, _ in groups}, reverse=True)
    markers = "osD^vP*X"
    m = len(groups)
    for i, ((k, s), rows) in enumerate(groups.items()):
        rows = sorted(rows, key=lambda r: r.n_side)
        col = f"C{i % 10}"
        mk = markers[ks.index(k) % len(markers)]
        shift = 1.0 + OFFSET * (i - (m - 1) / 2)
        label = f"{KT}={k:g}, {SIG}={s:g}"
        x = np.array([r.n_side for r in rows], dtype=float) * shift
        a1.plot(x, [r.plateau for r in rows], "-", color=col, lw=1)
        for reached, mfc in ((True, col), (False, "none")):
            sel = [j for j, r in enumerate(rows) if (r.state != "not reached") == reached]
            if sel:
                a1.errorbar(x[sel], [rows[j].plateau for j in sel],
                            yerr=np.array([err(rows[j].plateau, rows[j].plateau_ci)
                                           for j in sel]).T,
                            fmt=mk, ms=5, capsize=2, color=col, mfc=mfc,
                            label=label if reached or len(sel) == len(rows) else None)
        rel = [j for j, r in enumerate(rows) if math.isfinite(r.rel) and r.rel > -1.0]
        if rel:
            # the ratio to the largest brush on a log axis: a rough brush's x 30 and a smooth
            # one's 5 % are both read off it (bars clipped where a range reaches ratio 0)
            y = [1.0 + rows[j].rel for j in rel]
            lo = [max(1.0 + rows[j].rel_ci[0], FLOOR * y[i]) for i, j in enumerate(rel)]
            hi = [1.0 + rows[j].rel_ci[1] for j in rel]
            yerr = np.array([[v - a for v, a in zip(y, lo)], [b - v for v, b in zip(y, hi)]])
            a2.errorbar(x[rel], y, yerr=np.maximum(yerr, 0.0), fmt=mk + "-", ms=5, lw=1,
                        capsize=2, color=col)
    if groups:
        for ax in (a1, a2):
            _size_axis(ax, sizes)
        legend(a1, ncol=1 if m <= 8 else 2)
        a2.set_yscale("log")
        a2.axhline(1.0, color="0.5", lw=0.8)
    a1.set_ylabel(f"plateau {FA}")
    a1.set_title(f"plateau {FA} against the brush size (seed intervals; open: not reached)",
                 fontsize=10)
    a2.set_ylabel(f"plateau / plateau at {ref if len(refs) == 1 else 'the largest'} (log axis)")
    a2.set_title(f"ratio to {ref} (bars: the range the two seed intervals allow)", fontsize=10)
    fig.suptitle("one line per (k̃, σ̃); markers offset slightly in n_side so that the bars stay "
                 "apart", fontsize=9)
    fig.tight_layout()
    return save(fig, out_dir, name)


__all__ = ["plateau_vs_n_side"]
