"""``fibril-campaign report``: readings, fits, figures, tables and two pages showing them all.

The orchestrator: it reads the campaign (:func:`.data.load_campaign`), turns it into numbers
(:func:`.report_data.build`: the plateau, c, c0 per (k~, sigma~), alpha/beta per k~, seed
intervals, the preset's bias, the law comparison, the measured loss; per n_side for a grid
sweeping it), draws the figures (:mod:`.figures`, :mod:`.figures_coeff`, :mod:`.figures_loss`,
:mod:`.figures_size`), writes the tables
(:mod:`.tables`) as CSV, and the pages (:mod:`.page`): ``README.md`` and the self-contained
``report.html``. Any file ``status`` reads, it reads: a campaign with nothing to fit gets a page
that says why.
"""

from __future__ import annotations

import os
import time

from ...io.files import write_text_atomically
from . import (figures, figures_coeff, figures_loss, figures_size, figures_size_loss, page,
               size_loss_page, tables)
from ..laws.study import N_BOOT
from .data import load_campaign
from .report_data import build


def chosen_curve_jobs(jobs, studies, per_k: int = 1) -> list:
    """Jobs whose loading/unloading curves are drawn: per k~, the middle sigma~, the first seed,
    the largest preload."""
    out = []
    for k, st in studies.items():
        sig = [g.sigma_tilde for g in st.groups]
        if not sig:
            continue
        s = sig[len(sig) // 2]
        cand = [j for j in jobs if j.get("status") == "done" and j["k_tilde"] == k
                and j["sigma_tilde"] == s and j.get("loading")]
        if not cand:
            continue
        seed = min(j["seed"] for j in cand)
        cand = sorted((j for j in cand if j["seed"] == seed), key=lambda j: j["preload"])
        out += cand[-per_k:]
    return out


def write_report(path: str, out_dir: str, n_boot: int = N_BOOT,
                 include_unchecked: bool = False, where=None) -> list:
    """Write every figure, table, ``README.md`` and ``report.html`` of the campaign ``path``
    into ``out_dir`` (from the verified records; unchecked ones too with
    ``include_unchecked``); returns the paths written. ``where``: for a grid sweeping lab
    fields, the values to read (``["tip_radius=4"]`` or ``{"tip_radius": 4}``; the fields not
    named read their first listed value); a name or value the grid does not sweep is a
    :class:`~fibril_hpc.errors.ConfigError`, raised before anything is written."""
    t0 = time.perf_counter()
    c = load_campaign(path, curves=True, include_unchecked=include_unchecked)
    d = build(c, path, n_boot=n_boot, where=where)
    os.makedirs(out_dir, exist_ok=True)
    jobs = d.main_jobs(c.jobs)         # the variant read; a grid sweeping n_side: its largest
    kms = tables.machines(jobs)
    figs = [
        ("Pull-off force against preload: linear axes (as the paper) and log axes",
         figures.fa_vs_fp(d, out_dir)),
        ("Adhesion coefficient c against roughness, linear and log–log, with c = max(α/σ̃ − β, 0)",
         figures_coeff.c_vs_sigma(d, out_dir)),
        ("First-contact slope c₀ against roughness", figures_coeff.c0_vs_sigma(d, out_dir)),
        ("Plateau against roughness and against stiffness", figures_coeff.plateau(d, out_dir)),
        ("α and β against stiffness, and the measured σ̃_c with the line's zero α/β beside it",
         figures_coeff.alpha_sigma_c(d, out_dir)),
        ("Where adhesion is lost: c and the plateau against roughness near the loss, the "
         "measured σ̃_c beside α/β's zero", figures_loss.loss(d, out_dir)),
        ("Force and contact area against indentation (loading and unloading)",
         figures.curves(chosen_curve_jobs(jobs, d.studies), out_dir)),
    ]
    if len(kms) > 1:
        figs.append(("Peak tension and final jump-off against the machine stiffness",
                     figures.machine(jobs, out_dir)))
    tabs = [tables.alpha_beta(d), tables.plateau(d), tables.coefficients(d),
            tables.law_comparison(d)]
    if len(kms) > 1:
        tabs.append(tables.machine_table(jobs))
    read = [d.variant.label] if d.variant is not None else []
    if d.n_sides:
        read.append(f"n_side = {d.n_side}")
    if read:                           # each caption names what it reads
        figs = [(f"{title} ({', '.join(read)})", p) for title, p in figs]
    if d.n_sides:                      # finite size first: the question a size sweep asks
        figs.insert(0, ("Finite size: the plateau against the brush size n_side, and its change "
                        "against the largest" + (f" ({d.variant.label})" if d.variant else ""),
                        figures_size.plateau_vs_n_side(d, out_dir)))
        tabs.insert(0, tables.finite_size(d))
    if d.size_loss:                    # where adhesion is lost, per size and per area
        figs.insert(0, ("Where adhesion is lost across brush sizes: the plateau per n_side, "
                        "its N → ∞ extrapolation P∞ and the thresholds",
                        figures_size_loss.loss_across_sizes(d, out_dir)))
        tabs[:0] = [size_loss_page.table(d), size_loss_page.extrapolation_table(d)]
    files = [p for _, p in figs]
    for t in tabs:
        p = os.path.join(out_dir, f"{t.name}.csv")
        write_text_atomically(p, t.csv(), "writing the report")
        files.append(p)
    seconds = time.perf_counter() - t0
    md = os.path.join(out_dir, "README.md")
    write_text_atomically(md, page.markdown(d, tabs, figs, seconds), "writing the report")
    htm = os.path.join(out_dir, "report.html")
    write_text_atomically(htm, page.html_page(d, tabs, figs, seconds), "writing the report")
    return files + [md, htm]
