"""``fibril-campaign report``: the plots users expect and the alpha, beta, sigma~_c table.

Definitions (also written into the report's ``README.md``):

* **Mean over seeds**: for each (k~, sigma~, preload) the done jobs' F~_P and F~_A are averaged
  over seeds; error bars are the standard deviation over seeds.
* **Linear stage**: the jobs with F~_P <= ``linear_max``. Default ``linear_max``: 1.0 (preloads
  up to the pull-off force of a compact punch, F_P <= F_c). The adhesion coefficient of the
  linear stage is the least-squares slope through the origin, c = sum(F_A F_P) / sum(F_P^2),
  over every done job of that stage (all seeds). Shaded on the F~_A(F~_P) plots.
* **Fit** c = alpha/sigma~ - beta: linear least squares of c against 1/sigma~ over the sigma~ > 0
  whose c > 0 (at least two); sigma~_c = alpha/beta (inf when beta <= 0).
* **Plateau**: F~_A,plateau is the seed-mean F~_A at the largest preload; it is *reached* when
  the seed-mean F~_A changes by less than ``plateau_tol`` (relative, default 5 %) between the two
  largest preloads. Unreached plateaus are drawn with open markers.
"""

from __future__ import annotations

import math
import os

import numpy as np

from ..files import save_figure, write_text_atomically

LINEAR_MAX_DEFAULT = 1.0


def _groups(jobs):
    """{k: {sigma: {preload: [jobs]}}} of done jobs."""
    out: dict = {}
    for j in jobs:
        if j.get("status") != "done":
            continue
        out.setdefault(j["k_tilde"], {}).setdefault(j["sigma_tilde"], {}) \
            .setdefault(j["preload"], []).append(j)
    return out


def analyse(jobs, linear_max=None, plateau_tol=0.05) -> dict:
    """Per k~: curves (mean/std over seeds), c per sigma~, the fit, plateaus."""
    linear_max = LINEAR_MAX_DEFAULT if linear_max is None else linear_max
    res = {}
    for k, by_s in sorted(_groups(jobs).items()):
        entry = {"sigma": [], "c": [], "curves": {}, "plateau": {}, "plateau_reached": {}}
        for s, by_p in sorted(by_s.items()):
            pre = sorted(by_p)
            FP = np.array([np.mean([j["F_P"] for j in by_p[p]]) for p in pre])
            FA = np.array([np.mean([j["F_A"] for j in by_p[p]]) for p in pre])
            FA_sd = np.array([np.std([j["F_A"] for j in by_p[p]]) for p in pre])
            FP_sd = np.array([np.std([j["F_P"] for j in by_p[p]]) for p in pre])
            n = np.array([len(by_p[p]) for p in pre])
            entry["curves"][s] = {"preload": np.array(pre), "F_P": FP, "F_A": FA, "F_A_sd": FA_sd,
                                  "F_P_sd": FP_sd, "n": n}
            lin = [j for p in pre for j in by_p[p] if j["F_P"] <= linear_max]
            if lin:
                x = np.array([j["F_P"] for j in lin])
                y = np.array([j["F_A"] for j in lin])
                c = float(np.sum(x * y) / np.sum(x * x)) if np.sum(x * x) > 0 else math.nan
                entry["sigma"].append(s)
                entry["c"].append(c)
            entry["plateau"][s] = float(FA[-1])
            reached = (len(FA) >= 2 and FA[-1] > 0
                       and abs(FA[-1] - FA[-2]) / abs(FA[-1]) < plateau_tol)
            entry["plateau_reached"][s] = bool(reached)
        sig = np.array(entry["sigma"])
        c = np.array(entry["c"])
        ok = (sig > 0) & (c > 0) & np.isfinite(c)
        alpha = beta = sc = math.nan
        if ok.sum() >= 2:
            A = np.vstack([1.0 / sig[ok], -np.ones(ok.sum())]).T
            (alpha, beta), *_ = np.linalg.lstsq(A, c[ok], rcond=None)
            alpha, beta = float(alpha), float(beta)
            sc = alpha / beta if beta > 0 else math.inf
        entry.update(alpha=alpha, beta=beta, sigma_c=sc, n_fit=int(ok.sum()))
        res[k] = entry
    return {"k": res, "linear_max": linear_max, "plateau_tol": plateau_tol}


def _table(an) -> tuple[str, str]:
    rows = [("k_tilde", "alpha", "beta", "sigma_tilde_c", "n_sigma_in_fit")]
    for k, e in an["k"].items():
        rows.append((repr(k), repr(e["alpha"]), repr(e["beta"]), repr(e["sigma_c"]),
                     str(e["n_fit"])))
    csv = "\n".join(",".join(r) for r in rows) + "\n"
    md = ["| k~ | alpha | beta | sigma~_c | sigma~ values in fit |", "| --- | --- | --- | --- | --- |"]
    for k, e in an["k"].items():
        md.append(f"| {k:g} | {e['alpha']:.4g} | {e['beta']:.4g} | {e['sigma_c']:.4g} | "
                  f"{e['n_fit']} |")
    return csv, "\n".join(md) + "\n"


def write_report(path: str, out_dir: str, linear_max=None, plateau_tol=0.05) -> list:
    """Write the plots and the alpha, beta, sigma_c table of a campaign file into ``out_dir``.

    Returns the paths written.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from .data import load_campaign

    c = load_campaign(path, curves=False)
    an = analyse(c.jobs, linear_max, plateau_tol)
    ks = list(an["k"])
    files = []
    lm = an["linear_max"]
    if not ks:
        raise_empty(path)
    # 1. F_A versus F_P per k, one curve per sigma
    ncol = min(4, len(ks))
    nrow = math.ceil(len(ks) / ncol)
    fig, axes = plt.subplots(nrow, ncol, figsize=(4 * ncol, 3.4 * nrow), squeeze=False)
    for ax, k in zip(axes.flat, ks):
        e = an["k"][k]
        for s, cv in e["curves"].items():
            ax.errorbar(cv["F_P"], cv["F_A"], yerr=cv["F_A_sd"], xerr=cv["F_P_sd"], marker="o",
                        ms=3, capsize=2, label=f"σ~={s:g}")
        ax.axvspan(0, lm, color="0.9", zorder=0, label=f"linear stage F~_P ≤ {lm:g}")
        ax.set_title(f"k~ = {k:g}")
        ax.set_xlabel("F~_P")
        ax.set_ylabel("F~_A (mean ± sd over seeds)")
    for ax in list(axes.flat)[len(ks):]:
        ax.axis("off")
    axes.flat[0].legend(fontsize=6)
    fig.tight_layout()
    files.append(_save(fig, out_dir, "FA_vs_FP.png"))
    # 2. c versus sigma, linear and log-log, with the fit
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(10, 4))
    for i, k in enumerate(ks):
        e = an["k"][k]
        if not e["sigma"]:
            continue
        col = f"C{i % 10}"
        sig, cc = np.array(e["sigma"]), np.array(e["c"])
        for ax in (a1, a2):
            pos = cc > 0 if ax is a2 else np.ones_like(cc, bool)
            ax.plot(sig[pos], cc[pos], "o", color=col, label=f"k~={k:g}")
            if math.isfinite(e["alpha"]):
                sg = np.linspace(max(sig[sig > 0].min() if (sig > 0).any() else 0.01, 1e-3),
                                 sig.max(), 200)
                fit = e["alpha"] / sg - e["beta"]
                keep = fit > 0 if ax is a2 else np.ones_like(fit, bool)
                ax.plot(sg[keep], fit[keep], "-", color=col, lw=1)
    a1.set_xlabel("σ~")
    a1.set_ylabel(f"c = F~_A/F~_P (linear stage, F~_P ≤ {lm:g})")
    a1.set_title("c = α/σ~ − β fits")
    a2.set_xscale("log")
    a2.set_yscale("log")
    a2.set_xlabel("σ~")
    a2.set_title("log–log")
    a1.legend(fontsize=6)
    fig.tight_layout()
    files.append(_save(fig, out_dir, "c_vs_sigma.png"))
    # 3. plateau versus sigma (per k) and versus k (per sigma)
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(10, 4))
    sigmas = sorted({s for e in an["k"].values() for s in e["plateau"]})
    for i, k in enumerate(ks):
        e = an["k"][k]
        ss = sorted(e["plateau"])
        y = [e["plateau"][s] for s in ss]
        a1.plot(ss, y, "-", color=f"C{i % 10}", label=f"k~={k:g}")
        for s, v in zip(ss, y):
            a1.plot([s], [v], "o", color=f"C{i % 10}",
                    mfc=f"C{i % 10}" if e["plateau_reached"][s] else "none")
    for i, s in enumerate(sigmas):
        kk = [k for k in ks if s in an["k"][k]["plateau"]]
        y = [an["k"][k]["plateau"][s] for k in kk]
        a2.plot(kk, y, "-", color=f"C{i % 10}", label=f"σ~={s:g}")
        for k, v in zip(kk, y):
            a2.plot([k], [v], "o", color=f"C{i % 10}",
                    mfc=f"C{i % 10}" if an["k"][k]["plateau_reached"][s] else "none")
    a1.set_xlabel("σ~")
    a1.set_ylabel("plateau F~_A (largest preload)")
    a1.set_title(f"filled: plateau reached (ΔF~_A < {plateau_tol:.0%})")
    a2.set_xscale("log")
    a2.set_xlabel("k~")
    a2.set_ylabel("plateau F~_A")
    a1.legend(fontsize=6)
    a2.legend(fontsize=6)
    fig.tight_layout()
    files.append(_save(fig, out_dir, "plateau.png"))
    csv, md = _table(an)
    for name, text in (("fit_table.csv", csv), ("fit_table.md", md)):
        p = os.path.join(out_dir, name)
        write_text_atomically(p, text, "writing the report")
        files.append(p)
    p = os.path.join(out_dir, "README.md")
    write_text_atomically(
        p, f"# Report of {os.path.abspath(path)}\n\n{len(c.jobs)} job records, campaign "
        f"{c.meta.get('campaign_hash')}.\n\n## Criteria\n{__doc__.split('Definitions')[1]}"
        f"\nUsed here: linear_max = {lm:g}, plateau_tol = {plateau_tol:g}.\n\n"
        f"## alpha, beta, sigma~_c\n\n{md}", "writing the report")
    files.append(p)
    return files


def raise_empty(path):
    """Raise the one-line :class:`StoreError` of a file with no done jobs."""
    from ..errors import StoreError

    raise StoreError(f"{path}: no done jobs to report on")


def _save(fig, out_dir, name):
    import matplotlib.pyplot as plt

    p = os.path.join(out_dir, name)
    try:
        save_figure(fig, p, "writing the report")
    finally:
        plt.close(fig)
    return p
