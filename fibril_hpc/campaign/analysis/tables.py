"""The report's tables, as (CSV text, Markdown text) pairs, from the fits of
:mod:`fibril_hpc.campaign.laws.fit`.

An undefined value is an empty CSV cell and an em dash in Markdown; the row's ``note`` says why.
"""

from __future__ import annotations

import csv
import io
import math


def _num(v) -> str:
    return repr(float(v)) if v is not None and math.isfinite(v) else ""


def _md(v, fmt=".4g") -> str:
    return format(v, fmt) if v is not None and math.isfinite(v) else "—"


def _ci_md(ci, fmt=".3g") -> str:
    lo, hi = ci
    if not (math.isfinite(lo) or math.isfinite(hi)):
        return "—"
    return f"[{_md(lo, fmt)}, {_md(hi, fmt) if math.isfinite(hi) else '∞'}]"


def _val_ci(v, ci, fmt=".4g") -> str:
    """'value [lo, hi]'; an undefined value is one em dash."""
    if v is None or not math.isfinite(v):
        return "—"
    return f"{_md(v, fmt)} {_ci_md(ci)}"


def _csv(rows) -> str:
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerows(rows)
    return buf.getvalue()


def alpha_beta_table(fits) -> tuple[str, str]:
    """Table 1: alpha, beta, sigma~_c with 95 % intervals per k~."""
    head = ["k_tilde", "alpha", "alpha_lo", "alpha_hi", "beta", "beta_lo", "beta_hi",
            "sigma_tilde_c", "sigma_tilde_c_lo", "sigma_tilde_c_hi", "n_sigma_in_fit",
            "sigmas_in_fit", "rms_residual_c", "chi2_reduced", "note"]
    rows = [head]
    md = ["| k̃ | α [95 % CI] | β [95 % CI] | σ̃_c = α/β [95 % CI] | σ̃ in fit | rms residual of c "
          "| note |", "| --- | --- | --- | --- | --- | --- | --- |"]
    for k, e in fits.items():
        a = e["ab"]
        rows.append([repr(float(k)), _num(a.alpha), _num(a.alpha_ci[0]), _num(a.alpha_ci[1]),
                     _num(a.beta), _num(a.beta_ci[0]), _num(a.beta_ci[1]), _num(a.sigma_c),
                     _num(a.sigma_c_ci[0]), _num(a.sigma_c_ci[1]), str(a.n_sigma),
                     " ".join(f"{s:g}" for s in a.sigmas), _num(a.rms_residual),
                     _num(a.chi2_red), a.note])
        md.append(f"| {k:g} | {_val_ci(a.alpha, a.alpha_ci)} | {_val_ci(a.beta, a.beta_ci)} | "
                  f"{_val_ci(a.sigma_c, a.sigma_c_ci)} | {a.n_sigma} "
                  f"| {_md(a.rms_residual, '.3g')} | {a.note} |")
    return _csv(rows), "\n".join(md) + "\n"


def groups_table(fits) -> tuple[str, str]:
    """Per (k~, sigma~): c, plateau, kink with intervals, the counts and flags."""
    head = ["k_tilde", "sigma_tilde", "law", "c", "c_lo", "c_hi", "plateau", "plateau_lo",
            "plateau_hi", "kink_F_P", "kink_lo", "kink_hi", "n_seeds", "n_preloads",
            "n_below_kink", "n_above_kink", "resolved", "plateau_confirmed", "rms_log",
            "rms_log_other_laws", "c_residual_of_alpha_beta_fit", "ci_method", "note"]
    rows = [head]
    md = ["| k̃ | σ̃ | c [95 % CI] | plateau F̃_A [95 % CI] | kink F̃_P [95 % CI] | below / above "
          "kink | resolved | rms log F̃_A (other law) | c − (α/σ̃ − β) | note |",
          "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
    for k, e in fits.items():
        ab = e["ab"]
        resid = dict(zip(ab.sigmas, ab.residuals))
        for g in e["groups"]:
            r = resid.get(float(g.sigma_tilde), math.nan)
            other = " ".join(f"{lw}={v:.4g}" for lw, v in g.rms_log_other.items())
            rows.append([repr(float(k)), repr(float(g.sigma_tilde)), g.law, _num(g.c),
                         _num(g.c_ci[0]), _num(g.c_ci[1]), _num(g.plateau),
                         _num(g.plateau_ci[0]), _num(g.plateau_ci[1]), _num(g.kink),
                         _num(g.kink_ci[0]), _num(g.kink_ci[1]), str(g.n_seeds),
                         str(g.n_levels), str(g.n_below), str(g.n_above), str(g.resolved).lower(),
                         str(g.plateau_confirmed).lower(), _num(g.rms_log), other, _num(r),
                         g.ci_method, g.note])
            md.append(f"| {k:g} | {g.sigma_tilde:g} | {_val_ci(g.c, g.c_ci)} | "
                      f"{_val_ci(g.plateau, g.plateau_ci)} | {_val_ci(g.kink, g.kink_ci, '.3g')} "
                      f"| {g.n_below} / {g.n_above} | "
                      f"{'yes' if g.resolved else '**unresolved**'} | {_md(g.rms_log, '.3g')} "
                      f"({other}) | {_md(r, '.3g')} | {g.note} |")
    return _csv(rows), "\n".join(md) + "\n"


def law_comparison(fits_by_law) -> tuple[str, str]:
    """rms residual of log F~_A of each law over all (k~, sigma~), and how often each fits best."""
    laws = list(fits_by_law)
    rows = [["law", "rms_log_all", "groups_best", "groups", "resolved_groups"]]
    md = ["| law | rms residual of log F̃_A (all groups) | groups where it fits best | resolved "
          "groups |", "| --- | --- | --- | --- |"]
    per = {}
    for lw in laws:
        per[lw] = [(g.rms_log, g.resolved)
                   for e in fits_by_law[lw].values() for g in e["groups"]]
    n = len(per[laws[0]]) if laws else 0
    for lw in laws:
        r = [x for x, _ in per[lw] if math.isfinite(x)]
        rms = math.sqrt(sum(x * x for x in r) / len(r)) if r else math.nan
        best = sum(1 for i in range(n)
                   if all(per[lw][i][0] <= per[o][i][0] for o in laws if o != lw))
        res = sum(1 for _, ok in per[lw] if ok)
        rows.append([lw, _num(rms), str(best), str(n), str(res)])
        md.append(f"| {lw} | {_md(rms, '.4g')} | {best} of {n} | {res} |")
    return _csv(rows), "\n".join(md) + "\n"


def machines(jobs) -> list:
    """The distinct machine stiffnesses k~_m of the done jobs, stiffest (``inf``) first."""
    return sorted({float(j.get("k_machine", math.inf)) for j in jobs
                   if j.get("status") == "done"}, reverse=True)


def machine_table(jobs) -> tuple[str, str]:
    """Per (k~, sigma~, preload, k~_m): seed means of F~_P, F~_A (the peak tension) and F~_jump
    (the tension at the jump-off of the final separation) and the plate's jumps (README,
    'Compliant loading')."""
    by: dict = {}
    for j in jobs:
        if j.get("status") == "done":
            key = (j["k_tilde"], j["sigma_tilde"], j["preload"], float(j.get("k_machine",
                                                                               math.inf)))
            by.setdefault(key, []).append(j)
    head = ["k_tilde", "sigma_tilde", "preload", "k_machine", "n_seeds", "F_P", "F_A", "F_jump",
            "jumps", "note"]
    rows = [head]
    md = ["| k̃ | σ̃ | preload | k̃_m | seeds | F̃_P | F̃_A (peak) | F̃_jump (final jump-off) "
          "| jumps | note |", "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"]

    def mean(js, name):
        v = [float(j[name]) for j in js if j.get(name) is not None]
        return sum(v) / len(v) if v else math.nan

    for (k, s, p, km), js in sorted(by.items(), key=lambda kv: (kv[0][:3], -kv[0][3])):
        rigid = math.isinf(km)
        note = "rigid machine: the plate does not jump" if rigid else ""
        fp, fa, fj, nj = (mean(js, n) for n in ("F_P", "F_A", "F_jump", "jumps"))
        rows.append([repr(float(k)), repr(float(s)), repr(float(p)), repr(km), str(len(js)),
                     _num(fp), _num(fa), _num(fj), "" if rigid else _num(nj), note])
        md.append(f"| {k:g} | {s:g} | {p:g} | {km:g} | {len(js)} | {_md(fp)} | {_md(fa)} | "
                  f"{_md(fj)} | {'—' if rigid else _md(nj, '.3g')} | {note} |")
    return _csv(rows), "\n".join(md) + "\n"
