"""The report's numbers: a campaign's done jobs turned into the per-k~ studies of
:mod:`.laws.study`, the law comparison of :mod:`.fit`, the preset's bias and the page's
headline (what the campaign gives, and why not where it gives nothing).

Reads any campaign :func:`.data.load_campaign` reads: failed and non-finite jobs are counted
and left out, a machine sweep is reported at its stiffest machine, a campaign still being
written is read as far as it got. A grid sweeping the brush size n_side is read at its largest
n_side with done jobs (the closest to an infinite brush: every per-(k~, sigma~) table, fit and
figure), and every n_side is read the same way for the finite-size section
(:mod:`.laws.size`); brush sizes are never mixed in one group. A grid sweeping other lab fields
(tip, heights, ...) is read at one combination of their values (:mod:`.variants`: the first
listed, or the one named with ``where``); variants are never mixed in one group either.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ...errors import ConfigError
from ..laws import fit as _fit
from ..laws.intervals import dominant, preset_bias
from ..laws.reading import FEW_PILLARS, LOST, UNRESOLVED, levels, pillar_floor
from ..laws.size import DIFFERS, WITHIN, size_rows
from ..laws.study import N_BOOT, beta_is_zero, study
from .loss_page import headline_lines as loss_lines
from .loss_page import search_max
from .seed_limits import headline_line as seeds_line
from .seed_limits import seed_limits, seeds_auto
from .variants import Variant, select
from .verdict_text import law_why, why_out

#: a law whose rms residual of log F~_A exceeds this many seed standard deviations is "poor"
POOR_FACTOR = 2.0
#: what a grid needs for alpha and beta (said on the page when a campaign cannot give them)
GRID_ADVICE = ("alpha and beta need, per k~, at least two sigma~ > 0 whose F~_A rises with "
               "preload to a plateau the campaign reaches: sigma~ between about 0.07 and 0.9 "
               "(on 18 x 18 pillars F~_A rises there for k~ from 1 to 0.001, and stays flat at "
               "the last pillar's pull-off at sigma~ = 2.1 for k~ = 1) and preloads from the "
               "first contacts to the plateau - `F_P: auto` places them (campaigns/demo.yaml "
               "is such a grid)")


@dataclass
class LawRow:
    """One law fitted to one (k~, sigma~): its fit, residual against the seed scatter."""

    fit: _fit.LawFit
    seed_log_sd: float              # pooled seed sd of log F~_A over the levels
    poor: bool
    plateau_vs_read: float          # law plateau / read plateau - 1


@dataclass
class ReportData:
    """Everything the tables, figures and page show."""

    path: str
    meta: dict
    n_jobs: int
    n_done: int
    n_failed: int
    n_nonfinite: int
    machines: list
    preset: str
    bias: float
    bias_note: str
    studies: dict                   # {k~: KStudy}
    laws: dict                      # {(k~, sigma~): {law: LawRow}}
    means: dict                     # {(k~, sigma~): Levels}
    headline: list = field(default_factory=list)
    n_boot: int = N_BOOT
    #: a grid sweeping n_side: its brush sizes (grid and done jobs), [] otherwise
    n_sides: list = field(default_factory=list)
    #: the brush size every per-(k~, sigma~) reading uses (the largest with done jobs)
    n_side: int | None = None
    #: the finite-size rows (:class:`.laws.size.SizeRow`), per (k~, sigma~, n_side)
    size: list = field(default_factory=list)
    #: a grid sweeping lab fields (other than k_machine, n_side): the combination read, or None
    variant: Variant | None = None
    #: one pillar's pull-off on the report's scale (:func:`.laws.reading.pillar_floor`), and how
    floor: float = math.nan
    floor_note: str = ""
    #: ``seeds: auto`` of the grid ({start, max, width}) or None, and the groups that hit its
    #: maximum short of the target (:mod:`.seed_limits`)
    seeds_auto: dict | None = None
    seed_limits: list = field(default_factory=list)

    def main_jobs(self, jobs) -> list:
        """The jobs the per-(k~, sigma~) readings use: those of :attr:`variant` and
        :attr:`n_side` (all jobs when the grid sweeps neither)."""
        if self.variant is not None:
            jobs = [j for j in jobs if j.get("key") in self.variant.keys]
        return list(jobs) if self.n_side is None else [j for j in jobs
                                                       if j.get("n_side") == self.n_side]


def _finite(j) -> bool:
    return all(isinstance(j.get(n), (int, float)) and math.isfinite(j[n])
               for n in ("F_P", "F_A", "preload", "k_tilde", "sigma_tilde"))


def points_by_group(jobs) -> dict:
    """{(k~, sigma~): (seed, preload, F_P, F_A) arrays} of the done jobs with finite numbers.

    Two jobs of one (k~, sigma~, preload, seed) with different numbers are jobs of different
    scenes (a swept field, another grid's scene) that no reading may mix: a
    :class:`~fibril_hpc.errors.ConfigError` naming both keys (one line and exit status 2 on the
    command line; the callers read one scene per group)."""
    rows: dict = {}
    seen: dict = {}
    for j in jobs:
        if j.get("status") == "done" and _finite(j):
            k, s, seed, pre = (float(j["k_tilde"]), float(j["sigma_tilde"]),
                               int(j.get("seed", 0)), float(j["preload"]))
            pt = (float(j["F_P"]), float(j["F_A"]))
            other = seen.setdefault((k, s, pre, seed), (pt, j.get("key")))
            if other[0] != pt:           # a user's file, not a bug: one line, exit 2
                raise ConfigError("report", f"jobs {other[1]} and {j.get('key')} (k~ = {k:g}, "
                                  f"sigma~ = {s:g}, preload {pre:g}, seed {seed}) with different "
                                  "F~_A", "one scene per grid point: a file whose grid points "
                                  "hold jobs of different scenes (extended with another grid) "
                                  "cannot be read as one campaign")
            rows.setdefault((k, s), []).append((seed, pre) + pt)
    return {k: tuple(np.asarray(c) for c in zip(*v)) for k, v in sorted(rows.items())}


def _scene_maps(meta, jobs):
    """The campaign's scene mappings, first what tells most: the resolved grid's ``scene`` in
    the file's ``campaign_yaml``, then the stored scene of its first done job (texts that are
    missing, not YAML or not mappings are skipped)."""
    import yaml

    texts = [meta.get("campaign_yaml")] + [j.get("scene_yaml") for j in jobs
                                            if j.get("status") == "done"][:1]
    for text in texts:
        if not text:
            continue
        try:
            d = yaml.safe_load(text) or {}
        except yaml.YAMLError:
            continue
        d = d.get("scene", d) if isinstance(d, dict) else {}
        if isinstance(d, dict):
            yield d


def campaign_preset(meta, jobs) -> tuple[str, float | None]:
    """(preset name, elements per diameter) of the campaign's scene (:func:`_scene_maps`);
    ("", None) if none tells."""
    for d in _scene_maps(meta, jobs):
        if "preset" in d or "elements_per_diameter" in d:
            epd = d.get("elements_per_diameter")
            try:
                epd = float(epd) if epd is not None else None
            except (TypeError, ValueError):
                epd = None
            return str(d.get("preset", "default")), epd
    return "", None


def campaign_floor(meta, jobs, n_side=None) -> tuple[float, str]:
    """(one pillar's pull-off, how it was computed) from the campaign's scene
    (:func:`_scene_maps`): ``n_side`` (the one read, else the scene's) and ``phi``; NaN (and
    why) when no scene tells, or when the pillars are not flat punches (the floor is Kendall's
    flat punch)."""
    from ...inputs.scene import Scene

    dflt = Scene()
    for d in _scene_maps(meta, jobs):
        try:
            n = int(n_side if n_side is not None else d.get("n_side", dflt.n_side))
            phi = float(d.get("phi", dflt.phi))
        except (TypeError, ValueError):
            continue
        if str(d.get("tip", "flat")) != "flat":
            return math.nan, "no pillar floor: the tips are not flat punches"
        if n < 1 or not 0 < phi < 1:
            continue
        f = pillar_floor(n, phi)
        return f, (f"one flat pillar's Kendall pull-off phi^(1/4) / N^(3/4) = {f:.3g} for "
                   f"N = {n * n} pillars at phi {phi:g}; adhesion lost: a plateau of at most "
                   f"{FEW_PILLARS:g} x that ({FEW_PILLARS * f:.3g})")
    return math.nan, "no scene to tell the pillar floor"


def grid_n_sides(meta) -> list:
    """The ``sweep.n_side`` values of the file's own grid (``campaign_yaml``), or []."""
    import yaml

    try:
        grid = yaml.safe_load(meta.get("campaign_yaml") or "") or {}
        values = (grid.get("sweep") or {}).get("n_side") or []
        return sorted(int(n) for n in values)
    except (yaml.YAMLError, AttributeError, TypeError, ValueError):
        return []


def _seed_log_sd(pts) -> float:
    seed, pre, x, y = pts
    sds = []
    for p in np.unique(pre):
        v = y[(pre == p) & (y > 0)]
        if v.size > 1:
            sds.append(np.var(np.log(v), ddof=1))
    return math.sqrt(float(np.mean(sds))) if sds else math.nan


def law_rows(points: dict, studies: dict) -> dict:
    """Every law of :data:`.fit.LAWS` fitted to every (k~, sigma~), against the reading."""
    out = {}
    for (k, s), pts in points.items():
        sd = _seed_log_sd(pts)
        read = next((g.reading.plateau for g in studies[k].groups if g.sigma_tilde == s),
                    math.nan)
        row = {}
        for law in _fit.LAWS:
            f = _fit.fit_law(pts[2], pts[3], law)
            poor = bool(math.isfinite(sd) and math.isfinite(f.rms_log)
                        and f.rms_log > POOR_FACTOR * max(sd, 1e-3))
            rel = f.plateau / read - 1 if read and math.isfinite(read) else math.nan
            row[law] = LawRow(f, sd, poor, rel)
        out[(k, s)] = row
    return out


def headline(d: ReportData) -> list:
    """The page's first lines: what the campaign gives, what it does not and why (a poor fit is
    never "fitted"; an undefined alpha, beta or sigma~_c says why), the states of the groups."""
    lines = []
    if not d.studies:
        lines.append(f"No done job with finite forces ({d.n_jobs} job records, {d.n_failed} "
                     "failed): nothing to read. " + GRID_ADVICE + ".")
        return lines
    by = {s: [k for k, st in d.studies.items() if st.status == s]
          for s in ("fitted", "poor fit", "undefined")}
    ks = ", ".join
    if by["fitted"]:
        lines.append("alpha and beta fitted within the seed scatter for k~ = "
                     + ks(f"{k:g}" for k in by["fitted"]) + f" (of {len(d.studies)} k~).")
    else:
        lines.append(f"alpha and beta fitted within the seed scatter for none of the "
                     f"{len(d.studies)} k~.")
    flat = [k for k in by["fitted"] if beta_is_zero(d.studies[k])]
    if flat:
        lines.append("beta is consistent with 0 for k~ = " + ks(f"{k:g}" for k in flat)
                     + ": only alpha is determined there (c falls as alpha/sigma~), and no "
                     "sigma~_c.")
    if by["poor fit"]:
        lines.append("POOR FIT (c = alpha/sigma~ - beta does not describe c within the seed "
                     "scatter; alpha and beta shown for orientation only) for k~ = "
                     + ks(f"{k:g} (chi^2/dof {d.studies[k].ab.chi2_red:.3g})"
                          for k in by["poor fit"]) + ".")
    if by["undefined"]:
        out: dict = {}
        for k in by["undefined"]:
            for g in d.studies[k].groups:
                if g.out:
                    out.setdefault(why_out(g).split(":")[0], []).append(
                        f"({k:g}, {g.sigma_tilde:g})")
        why = "; ".join(f"{w}: {', '.join(v)}" for w, v in out.items())
        lines.append("alpha and beta undefined for k~ = " + ks(f"{k:g}" for k in by["undefined"])
                     + ": " + "; ".join(f"k~ = {k:g}: {law_why(d.studies[k])}"
                                        for k in by["undefined"])
                     + (f". Left out of the fit: {why}" if why else "") + "."
                     # the grid advice where too few sigma~ could be fitted, not where the law
                     # was fitted and failed (alpha consistent with 0 on many rising groups)
                     + ("" if all(d.studies[k].ab.ok for k in by["undefined"])
                        else " " + GRID_ADVICE + "."))
    lines += loss_lines(d.studies, search_max(d.meta))
    states: dict = {}
    for st in d.studies.values():
        for g in st.groups:
            states[g.reading.state] = states.get(g.reading.state, 0) + 1
    n_groups = sum(states.values())
    lines.append("States of the " + str(n_groups) + " (k~, sigma~): "
                 + ", ".join(f"{v} {s}" for s, v in sorted(states.items()))
                 + (f" (pillar floor: {d.floor_note})" if d.floor_note else "") + ".")
    if states.get(UNRESOLVED):
        lines.append(f"{states[UNRESOLVED]} (k~, sigma~) have a rise not resolved: F~_A is "
                     "already near the plateau at the smallest preload reached, c is only a "
                     "lower bound and stays out of the fit (the coefficients table says which "
                     "preload would resolve it).")
    if states.get(LOST):
        lines.append(f"{states[LOST]} (k~, sigma~) have lost adhesion (a plateau within "
                     f"{FEW_PILLARS:g} pillars' pull-off: c = 0 by that threshold, left out of "
                     "the alpha/beta line, whose zero is set beside the measured loss).")
    dom: dict = {}
    for st in d.studies.values():
        for g in st.groups:
            for name, v, ci in (("plateau", g.reading.plateau, g.plateau_ci),
                                ("c", g.reading.c, g.c_ci)):
                dom.setdefault(name, []).append(dominant(v, ci, d.bias))
    if any(x != "unknown" for v in dom.values() for x in v):
        lines.append("Larger error: " + "; ".join(
            f"{name}: the seeds in {v.count('seeds')}, the discretisation in "
            f"{v.count('discretisation')} of {len(v)} (k~, sigma~)" for name, v in dom.items())
            + ".")
    if d.seeds_auto:
        lines.append(seeds_line(d.seeds_auto, d.seed_limits))
    if d.n_sides:
        lines.append(size_headline(d))
    if math.isfinite(d.bias):
        lines.append(f"Discretisation bias: {d.bias_note} ({100 * d.bias:+.1f} % on every "
                     "force-like number; measured on one scene, carried over as an assumption).")
    else:
        lines.append(f"Discretisation bias: {d.bias_note}.")
    return lines


def size_headline(d: ReportData) -> str:
    """The finite-size line of the headline: per smaller n_side, the range of the plateau's
    relative change against the largest n_side, and in how many (k~, sigma~) it is within the
    seed scatter."""
    ref = max(d.n_sides)
    text = (f"Finite size: n_side = {', '.join(map(str, d.n_sides))}; the other tables and "
            f"figures read n_side = {d.n_side if d.n_side is not None else '—'}"
            + (" (the largest with done jobs)" if d.n_side not in (None, ref) else "")
            + f". Plateau against n_side = {ref}: ")
    parts = []
    for n in d.n_sides:
        rows = [r for r in d.size if r.n_side == n and n != ref]
        rel = sorted(100 * r.rel for r in rows if math.isfinite(r.rel))
        if n == ref or not rows:
            continue
        if not rel:
            parts.append(f"n_side = {n}: no relative change (no plateau at {ref})")
            continue
        within = sum(r.verdict == WITHIN for r in rows)
        known = sum(r.verdict in (WITHIN, DIFFERS) for r in rows)
        parts.append(f"n_side = {n}: {rel[0]:+.1f} … {rel[-1]:+.1f} %"
                     + (f" (within the seed scatter in {within} of {known} (k~, sigma~))"
                        if known else ""))
    return text + ("; ".join(parts) if parts else "no smaller n_side with a plateau yet") + "."


def build(c, path: str, n_boot: int = N_BOOT, where=None) -> ReportData:
    """The report's numbers from a loaded campaign (:class:`.data.CampaignData`); ``where``:
    the values of the swept lab fields to read (:func:`.variants.select`: ``NAME=VALUE``
    strings or a mapping; default the first listed value of each)."""
    done = [j for j in c.jobs if j.get("status") == "done"]
    variant = select(c.meta, done, where)
    read = done if variant is None else [j for j in done if j.get("key") in variant.keys]
    kms = sorted({float(j.get("k_machine", math.inf)) for j in read}, reverse=True)
    # a grid sweeping the machine repeats every (k~, sigma~, preload, seed): the readings take
    # the stiffest machine's jobs (F~_A does not depend on it); the machine table shows them all
    jobs = [j for j in read if not kms or float(j.get("k_machine", math.inf)) == kms[0]]
    n_sides, n_read, rows = [], None, []
    floor, floor_note = campaign_floor(c.meta, done)
    if c.n_side_swept:
        # every brush size read as one campaign; the per-(k~, sigma~) readings at the largest
        by_n = {n: points_by_group([j for j in jobs if j.get("n_side") == n])
                for n in sorted({j["n_side"] for j in jobs if j.get("n_side") is not None})}
        by_n = {n: p for n, p in by_n.items() if p}
        n_sides = sorted(set(by_n) | set(grid_n_sides(c.meta)))
        size_studies = {n: study(p, n_boot=n_boot, floor=campaign_floor(c.meta, done, n)[0])
                        for n, p in by_n.items()}
        if by_n:
            n_read = max(by_n)
            rows = size_rows(size_studies, max(n_sides))
        points = by_n.get(n_read, {})
        studies = size_studies.get(n_read, {})
        if n_read is not None:
            floor, floor_note = campaign_floor(c.meta, done, n_read)
    else:
        points = points_by_group(jobs)
        studies = study(points, n_boot=n_boot, floor=floor)
    preset, epd = campaign_preset(c.meta, done)
    bias, note = preset_bias(preset, epd) if preset else (math.nan, "no scene to tell the preset")
    d = ReportData(path, dict(c.meta), len(c.jobs), len(done),
                   sum(1 for j in c.jobs if j.get("status") != "done"),
                   sum(1 for j in done if not _finite(j)), kms, preset, bias, note, studies,
                   law_rows(points, studies), {k: levels(*p) for k, p in points.items()},
                   n_boot=n_boot, n_sides=n_sides, n_side=n_read, size=rows, variant=variant,
                   floor=floor, floor_note=floor_note, seeds_auto=seeds_auto(c.meta))
    d.seed_limits = seed_limits(points, floor, d.seeds_auto)
    d.headline = headline(d)
    return d
