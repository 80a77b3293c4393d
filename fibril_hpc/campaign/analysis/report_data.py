"""The report's numbers: a campaign's done jobs turned into the per-k~ studies of
:mod:`.laws.study`, the law comparison of :mod:`.fit`, the preset's bias, the brush read, and
the page's headline and notes (:mod:`.headline`).

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
from ..laws.intervals import preset_bias
from ..laws.reading import FEW_PILLARS, levels, pillar_floor
from ..laws.size import size_rows
from ..laws.size_loss import adopt_measured, size_losses
from ..laws.study import N_BOOT, study
from .batching import coarse_groups
from .headline import headline, notes
from .seed_limits import seed_limits, seeds_auto
from .variants import Variant, select

#: a law whose rms residual of log F~_A exceeds this many seed standard deviations is "poor"
POOR_FACTOR = 2.0
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
    #: (n_side, phi, tip) of the brush read (:func:`campaign_brush`)
    brush: tuple = (None, math.nan, "")
    #: the scene's ``solver.far_field`` (:func:`campaign_far_field`; "multipole": events uncertified)
    far_field: str = "exact"
    #: every other line the page says once, below the tables (:func:`.headline.notes`)
    notes: list = field(default_factory=list)
    #: a grid sweeping n_side over two sizes or more: where adhesion is lost, per size and in
    #: the large-brush limit ({k~: :class:`.laws.size_loss.SizeLoss`})
    size_loss: dict = field(default_factory=dict)
    #: the (k~, sigma~) loaded in batches wider than today's bound (:mod:`.batching`): their
    #: rise, and c, are biased
    coarse: list = field(default_factory=list)
    #: a grid sweeping n_side: the k~ with no done job at :attr:`n_side` ({k~: its largest
    #: n_side}), which every per-(k~, sigma~) reading leaves out
    elsewhere: dict = field(default_factory=dict)

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


def campaign_far_field(meta, jobs) -> str:
    """The campaign scene's ``solver.far_field`` (:func:`_scene_maps`), "exact" where none
    sets it."""
    for d in _scene_maps(meta, jobs):
        solver = d.get("solver")
        if isinstance(solver, dict) and "far_field" in solver:
            return str(solver["far_field"])
    return "exact"


def campaign_brush(meta, jobs, n_side=None) -> tuple:
    """(n_side, phi, tip) of the campaign's brush (:func:`_scene_maps`): ``n_side`` the one read
    when given, else the scene's; the scene defaults where a field is not stored; (None, NaN,
    "") when no scene tells."""
    from ...inputs.scene import Scene

    dflt = Scene()
    for d in _scene_maps(meta, jobs):
        try:
            n = int(n_side if n_side is not None else d.get("n_side", dflt.n_side))
            phi = float(d.get("phi", dflt.phi))
        except (TypeError, ValueError):
            continue
        if n >= 1 and 0 < phi < 1:
            return n, phi, str(d.get("tip", "flat"))
    return None, math.nan, ""


def campaign_floor(meta, jobs, n_side=None) -> tuple[float, str]:
    """(one pillar's pull-off, how it was computed) from the campaign's brush
    (:func:`campaign_brush`); NaN (and why) when no scene tells, or when the pillars are not
    flat punches (the floor is Kendall's flat punch)."""
    n, phi, tip = campaign_brush(meta, jobs, n_side)
    if n is None:
        return math.nan, "no scene to tell the pillar floor"
    if tip != "flat":
        return math.nan, "no pillar floor: the tips are not flat punches"
    f = pillar_floor(n, phi)
    return f, (f"one flat pillar's Kendall pull-off phi^(1/4) / N^(3/4) = {f:.3g} for "
               f"N = {n * n} pillars at phi {phi:g}; adhesion lost: a plateau of at most "
               f"{FEW_PILLARS:g} x that ({FEW_PILLARS * f:.3g})")


def campaign_phi(meta, jobs) -> float:
    """The nominal filling ratio phi of the campaign's scene (:func:`_scene_maps`; the default
    scene's when none gives it), NaN when it is not a number in (0, 1)."""
    from ...inputs.scene import Scene

    for d in _scene_maps(meta, jobs):
        try:
            phi = float(d.get("phi", Scene().phi))
        except (TypeError, ValueError):
            continue
        return phi if 0 < phi < 1 else math.nan
    return math.nan


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
    n_sides, n_read, rows, sloss = [], None, [], {}
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
        phi = campaign_phi(c.meta, done)
        # its thresholds are flat pillars' pull-off: no floor (tips not flat), no section
        if len(by_n) >= 2 and math.isfinite(phi) and math.isfinite(floor):
            sloss = size_losses(by_n, phi, n_boot=n_boot)
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
    d.brush = campaign_brush(c.meta, done, n_read)
    d.far_field = campaign_far_field(c.meta, done)
    d.size_loss = sloss
    for k, s in sloss.items():                     # the read size: the measured sigma~_c
        if k in studies:
            adopt_measured(s, n_read, studies[k].loss)
    if n_sides:
        for n, pts in sorted(by_n.items()):
            d.elsewhere.update({k: n for k, _ in pts if k not in studies})
    d.coarse = [g for g in coarse_groups(d.main_jobs(jobs)) if g in points]
    d.headline, d.notes = headline(d), notes(d)
    return d
