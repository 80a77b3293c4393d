"""``fibril-campaign report``: fits, figures, tables and one page showing them all.

The orchestrator: it reads the campaign (:func:`.data.load_campaign`), fits the "linear, then
plateau" law per (k~, sigma~) and c(sigma~) = alpha/sigma~ - beta per k~
(:mod:`fibril_hpc.campaign.laws.fit`), draws
the figures (:mod:`.figures`), writes the tables (:mod:`.tables`) and ``README.md``, the page
that shows every figure and table and states the criteria.
"""

from __future__ import annotations

import os

import numpy as np

from ...errors import StoreError
from ...io.files import write_text_atomically
from ..laws import fit as _fit
from . import figures, tables
from .data import load_campaign


def _means(jobs) -> dict:
    """{(k~, sigma~): seed statistics per preload level} of done jobs."""
    by: dict = {}
    for j in jobs:
        if j.get("status") == "done":
            by.setdefault((j["k_tilde"], j["sigma_tilde"]), {}).setdefault(j["preload"], []) \
                .append(j)
    out = {}
    for key, lev in by.items():
        pre = sorted(lev)
        fa = [np.array([j["F_A"] for j in lev[p]]) for p in pre]
        out[key] = {"preload": np.array(pre),
                    "F_P": np.array([np.mean([j["F_P"] for j in lev[p]]) for p in pre]),
                    "F_A": np.array([a.mean() for a in fa]),
                    "F_A_min": np.array([a.min() for a in fa]),
                    "F_A_max": np.array([a.max() for a in fa]),
                    "n": np.array([a.size for a in fa])}
    return out


def chosen_curve_jobs(jobs, fits, per_k: int = 1) -> list:
    """Jobs whose loading/unloading curves are drawn: per k~, the middle sigma~, the first seed,
    the largest preload."""
    out = []
    for k, e in fits.items():
        sig = [g.sigma_tilde for g in e["groups"]]
        s = sig[len(sig) // 2]
        cand = [j for j in jobs if j.get("status") == "done" and j["k_tilde"] == k
                and j["sigma_tilde"] == s and j.get("loading")]
        if not cand:
            continue
        seed = min(j["seed"] for j in cand)
        cand = sorted((j for j in cand if j["seed"] == seed), key=lambda j: j["preload"])
        out += cand[-per_k:]
    return out


def write_report(path: str, out_dir: str, law: str = _fit.DEFAULT_LAW,
                 n_boot: int = _fit.N_BOOT, include_unchecked: bool = False) -> list:
    """Write every figure, table and ``README.md`` of the campaign ``path`` into ``out_dir``
    (from the verified records; unchecked ones too with ``include_unchecked``); returns the
    paths written."""
    c = load_campaign(path, curves=True, include_unchecked=include_unchecked)
    kms = tables.machines(c.jobs)
    # a grid sweeping the machine repeats every (k~, sigma~, preload, seed): the fits take the
    # stiffest machine's jobs (F~_A does not depend on it); the machine table shows them all
    jobs = [j for j in c.jobs if not kms or j.get("k_machine") == kms[0]]
    # the other laws enter only the law comparison (residuals, resolved groups): no bootstrap
    fits_by_law = {lw: _fit.fit_campaign(jobs, law=lw, n_boot=n_boot if lw == law else 0)
                   for lw in (law,) + tuple(x for x in _fit.LAWS if x != law)}
    fits = fits_by_law[law]
    if not fits:
        raise StoreError(f"{path}: no done jobs to report on")
    os.makedirs(out_dir, exist_ok=True)
    means = _means(jobs)
    figs = [
        ("Force and contact area against indentation (loading and unloading)",
         figures.curves(chosen_curve_jobs(jobs, fits), out_dir)),
        ("Pull-off force against preload with the fitted law", figures.fa_vs_fp(fits, means,
                                                                               out_dir)),
        ("Adhesion coefficient c against roughness, with the α/σ̃ − β fits",
         figures.c_vs_sigma(fits, out_dir)),
        ("Plateau against roughness and against stiffness", figures.plateau(fits, out_dir)),
        ("Plateau over (σ̃, k̃)", figures.plateau_map(fits, out_dir)),
        ("α and σ̃_c against k̃", figures.alpha_sigma_c(fits, out_dir)),
    ]
    if len(kms) > 1:
        figs.append(("Peak tension and final jump-off against the machine stiffness",
                     figures.machine(c.jobs, out_dir)))
    texts = {}
    made = [("alpha_beta", tables.alpha_beta_table(fits)), ("fits", tables.groups_table(fits)),
            ("law_comparison", tables.law_comparison(fits_by_law))]
    if len(kms) > 1:
        made.append(("machine", tables.machine_table(c.jobs)))
    for name, (csv, md) in made:
        texts[name] = md
        for ext, t in (("csv", csv), ("md", md)):
            p = os.path.join(out_dir, f"{name}.{ext}")
            write_text_atomically(p, t, "writing the report")
    files = [p for _, p in figs] + [os.path.join(out_dir, f"{n}.{e}") for n in texts
                                    for e in ("csv", "md")]
    page = os.path.join(out_dir, "README.md")
    n_done = sum(1 for j in c.jobs if j.get("status") == "done")
    crit = _fit.__doc__.split("**Law per", 1)[1]
    text = (f"# Report of `{os.path.abspath(path)}`\n\n{len(c.jobs)} job records "
            f"({n_done} done), campaign `{c.meta.get('campaign_hash')}`. Fitted law: "
            f"**{law}**; intervals are 95 % ({n_boot} bootstrap resamples over seeds where there "
            f"are several).\n\n## Criteria\n\n**Law per{crit}\n"
            f"## α, β, σ̃_c per k̃ (`alpha_beta.csv`)\n\n{texts['alpha_beta']}\n"
            f"## The laws compared (`law_comparison.csv`)\n\n{texts['law_comparison']}\n"
            f"## Fit per (k̃, σ̃) (`fits.csv`)\n\n{texts['fits']}\n")
    if "machine" in texts:
        text += (f"## Loading machines (`machine.csv`)\n\nThe grid sweeps the machine stiffness "
                 f"k̃_m ({', '.join(f'{k:g}' for k in kms)}); the fits above use the jobs of "
                 f"k̃_m = {kms[0]:g}. F̃_A is the peak tension, F̃_jump the tension at the "
                 f"jump-off of the final separation (means over seeds).\n\n{texts['machine']}\n")
    text += "## Figures\n\n"
    text += "".join(f"### {title}\n\n![{title}]({os.path.basename(p)})\n\n" for title, p in figs)
    write_text_atomically(page, text, "writing the report")
    files.append(page)
    return files
