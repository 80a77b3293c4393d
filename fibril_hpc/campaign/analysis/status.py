"""What a campaign file holds and what is left to do: :func:`file_status` and :func:`plan`.

Both read the file the way every reader does (journal first, never blocking the writer), so they
are safe while a campaign runs.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field

import yaml

from ...errors import StoreError
from ..plan import search
from ..plan.auto import path_todo, results_by_path
from ..plan.axes import record_n_side
from ..plan.estimate import fft_pair_seconds, later_rounds_seconds, task_seconds
from ..plan.spec import spec_from_dict
from ..storage.store import read_records
from .data import load_campaign

STATES = ("done", "failed", "pending")
#: a record without a checksum: shown apart (nothing vouches for it; resume does not rerun it)
UNCHECKED = "unchecked"


@dataclass
class FileStatus:
    """Job counts of a campaign file, in total and by k~ (see :func:`file_status`)."""

    meta: dict
    totals: dict
    by_k_tilde: dict
    in_journal: int
    done_wall_s: list = field(default_factory=list)
    failed: list = field(default_factory=list)
    #: keys of corrupt records (counted as pending: resume recomputes them)
    corrupt: list = field(default_factory=list)
    #: keys of records without a checksum (counted apart, in ``totals["unchecked"]``)
    unchecked: list = field(default_factory=list)
    #: members of /jobs that are not this file's own records (name -> why): never counted
    foreign: dict = field(default_factory=dict)
    #: for a grid sweeping n_side: the counts by (n_side, k~) (empty otherwise)
    by_n_side: dict = field(default_factory=dict)


def _grid_jobs(meta: dict, path: str, records=()) -> dict | None:
    """{key: Job} of the grid stored in the file, or None (a merged file may hold several).

    With ``F_P: auto`` the grid's jobs so far: the current round of every unfinished path,
    replayed from ``records`` (later rounds are not known yet)."""
    try:
        resolved = yaml.safe_load(meta.get("campaign_yaml", ""))
        resolved["output"] = os.path.abspath(path)
        spec = spec_from_dict(resolved)
    except Exception:  # noqa: BLE001 - no single grid: count the records only
        return None
    if spec.search:
        return {j.key: j for path, pre in search.frontier(spec, records)
                for j in spec.auto_task(path, pre).jobs}
    if spec.auto is None:
        return {j.key: j for j in spec.jobs}

    done, failed = results_by_path(records, spec.paths(), spec.record_path)
    out = {}
    for p in spec.paths():
        todo, _ = path_todo(spec.auto, done[p], False, failed[p])
        if todo:
            out.update({j.key: j for j in spec.auto_task(p, todo).jobs})
    return out


def file_status(path: str) -> FileStatus:
    """Done, failed and pending jobs of the file at ``path`` (pending: in its grid, no record)."""
    c = load_campaign(path, curves=False, include_unchecked=True)
    grid = _grid_jobs(c.meta, path, c.jobs) or {}
    recs = {j["key"]: j for j in c.jobs}
    by_k: dict = {}
    by_n: dict = {}
    swept = c.n_side_swept
    for k in set(recs) | set(grid):
        r = recs.get(k)
        kt = r["k_tilde"] if r else grid[k].k_tilde
        st = UNCHECKED if k in c.unchecked else r["status"] if r else "pending"
        d = by_k.setdefault(kt, dict.fromkeys(STATES + (UNCHECKED,), 0))
        d[st if st in d else "failed"] += 1
        if swept:
            n = r.get("n_side") if r else dict(grid[k].extra).get("n_side")
            d = by_n.setdefault((n, kt), dict.fromkeys(STATES + (UNCHECKED,), 0))
            d[st if st in d else "failed"] += 1
    totals = {s: sum(d[s] for d in by_k.values()) for s in STATES + (UNCHECKED,)}
    vouched = [r for r in c.jobs if r["key"] not in c.unchecked]
    walls = [r["wall_s"] / max(1, r.get("group_size", 1)) for r in vouched
             if r["status"] == "done"]
    return FileStatus(meta=c.meta, totals=totals, by_k_tilde=dict(sorted(by_k.items())),
                      in_journal=c.pending_in_journal, done_wall_s=walls,
                      corrupt=sorted(c.corrupt), unchecked=sorted(c.unchecked),
                      foreign=dict(c.foreign),
                      failed=[r for r in vouched if r["status"] == "failed"],
                      by_n_side=dict(sorted(by_n.items(), key=lambda kv: (kv[0][0] is None,
                                                                           kv[0][0] or 0,
                                                                           kv[0][1]))))


@dataclass
class Plan:
    """What ``fibril-campaign run`` would do now (see :func:`plan`)."""

    done: int
    failed: int
    to_run: set
    #: simulate calls (loading paths) the run would make, and how many of them per brush size
    n_tasks: int
    sizes: dict
    fft_pair_s: float
    fft_size: int
    #: elements in one pillar's footprint (an area count)
    elements_per_pillar: int
    estimate_s: float
    how: str
    #: ``F_P: auto``: the modelled cost of the later rounds of the loading paths priced by the
    #: model (0.0 for a fixed grid, and for paths priced by finished jobs)
    later_s: float = 0.0

    @property
    def elements_per_diameter(self) -> float:
        """Elements per pillar diameter, the presets' measure of resolution: the diameter of the
        discretised footprint's equal-area circle over the element side (as ``fibril-run``)."""
        return 2.0 * math.sqrt(self.elements_per_pillar / math.pi)


def plan(spec, retry_failed: bool = False) -> Plan:
    """The jobs of ``spec`` still to run in its output file, and their estimated cost.

    The estimate is, per brush size, the measured mean per job of the finished jobs of that
    size when there are any (a grid that sweeps ``n_side`` mixes brushes whose jobs differ in
    cost by 100x and more), else the cost model of :mod:`fibril_hpc.campaign.plan.estimate`,
    scaled by the measured/model ratio at the largest size that has finished jobs.

    Lean on a large grid: the tasks are counted and priced without building them (their scenes),
    and the model is evaluated once per distinct (brush size, preloads), which is all a task's
    modelled cost depends on (:func:`~fibril_hpc.campaign.plan.estimate.task_pairs`).
    """
    recs = {}
    if os.path.exists(spec.output):
        try:
            _, recs, _ = read_records(spec.output, curves=False)
        except StoreError:
            recs = {}
    # a search grid: the rounds the file's records lead to now
    front = search.frontier(spec, recs.values(), retry_failed) if spec.search else None
    if front is not None:
        jobs = [j for path, pre in front for j in spec.auto_task(path, pre).jobs]
    else:
        jobs = spec.jobs if spec.auto is None else [    # F_P: auto: its round 0 only
            j for p in spec.paths() for j in spec.auto_task(p, spec.auto.start).jobs]
    todo = {j.key for j in jobs}
    done = failed = 0
    walls = {}                  # n_side -> per-job wall seconds of the finished jobs
    if recs:
        # a search grid's records are all its own (its frontier holds none of them)
        mine = (search.results(spec, recs.values()) if front is not None else None)
        for k, r in recs.items():
            if mine is not None:
                done += r.get("status") == "done" and _holds(mine[0], spec, r)
                failed += r.get("status") == "failed" and _holds(mine[1], spec, r)
            if r.get("status") == "done":
                done += k in todo
                walls.setdefault(record_n_side(r), []).append(
                    float(r.get("wall_s", 0.0)) / max(1, int(r.get("group_size", 1))))
                todo.discard(k)
            elif r.get("status") == "failed":
                failed += k in todo
                if not retry_failed:
                    todo.discard(k)
    timed = {n: fft_pair_seconds(spec.base if n == spec.base.n_side else
                                 spec.base.replace(n_side=n)) for n in spec.n_sides}
    if len(spec.n_sides) == 1 and None in walls:    # records naming no size: the grid's own
        walls.setdefault(spec.n_sides[0], []).extend(walls.pop(None))
    model = _Model(spec, timed)
    sizes: dict = {}            # n_side -> tasks to run
    measured: dict = {}         # n_side -> jobs to run priced by that size's finished jobs
    modelled: dict = {}         # model key -> tasks of the sizes that have no finished job
    for js, scene in _task_jobs(spec, todo, front):
        n = _n_side(spec, js)
        sizes[n] = sizes.get(n, 0) + 1
        if walls.get(n):
            measured[n] = measured.get(n, 0) + len(js)
        else:
            key = model.key(js, n, scene)
            modelled[key] = modelled.get(key, 0) + 1
    est = sum(sum(walls[n]) / len(walls[n]) * jobs for n, jobs in measured.items())
    scale, ref = _calibration(spec, walls, model, front) if modelled else (1.0, None)
    est += scale * sum(model.seconds(key) * count for key, count in modelled.items())
    later = 0.0 if spec.auto is None else scale * sum(model.later(key) * count
                                                      for key, count in modelled.items())
    n_tasks = sum(sizes.values())
    pair_s, m, epp = timed[max(timed)]           # the largest brush's (the base scene's)
    how = _how(sum(len(w) for w in walls.values()), {key[0] for key in modelled},
               len(spec.n_sides) > 1, scale, ref)
    return Plan(done=done, failed=failed, to_run=todo, n_tasks=n_tasks, sizes=sizes,
                fft_pair_s=pair_s, fft_size=m, elements_per_pillar=epp, estimate_s=est, how=how,
                later_s=later)


def _holds(by_path: dict, spec, rec) -> bool:
    """Whether a record's path is among a search grid's records by path (:func:`.search.results`)."""
    try:
        return spec.record_path(rec) in by_path
    except (KeyError, TypeError, ValueError):
        return False


def _task_jobs(spec, keys=None, front=None):
    """(jobs, scene or None) of each task of ``spec`` with a job in ``keys`` (all when None):
    a fixed grid's without building their scenes, an ``F_P: auto`` grid's round 0, a search
    grid's ``front`` (:func:`~fibril_hpc.campaign.plan.search.frontier`)."""
    if front is not None:
        for path, pre in front:
            t = spec.auto_task(path, pre)
            if keys is None or any(j.key in keys for j in t.jobs):
                yield t.jobs, t.scene
        return
    if spec.auto is None:
        for js in spec.task_jobs(keys):
            yield js, None
        return
    for p in spec.paths():
        t = spec.auto_task(p, spec.auto.start)
        if keys is None:
            yield t.jobs, t.scene
        elif any(j.key in keys for j in t.jobs):
            t = spec.auto_task(p, [j.preload for j in t.jobs if j.key in keys])
            yield t.jobs, t.scene


def _n_side(spec, js) -> int:
    extra = js[0].extra
    return dict(extra).get("n_side", spec.base.n_side) if extra else spec.base.n_side


class _Model:
    """The modelled CPU seconds of a task, evaluated once per (brush size, preloads): what
    :func:`~fibril_hpc.campaign.plan.estimate.task_seconds` reads of a task's scene besides the
    base scene's preset."""

    def __init__(self, spec, timed: dict):
        self.spec, self.timed = spec, timed
        self.scenes: dict = {}
        self.cache: dict = {}

    def key(self, js, n: int, scene=None) -> tuple:
        """The model's key of the task running ``js`` (its scene kept for :meth:`seconds`)."""
        key = (n, (js[0].preload,) if len(js) == 1 else tuple(j.preload for j in js))
        if key not in self.scenes:
            self.scenes[key] = scene if scene is not None else self.spec.task_scene(js)
        return key

    def seconds(self, key) -> float:
        """Modelled CPU seconds of one task of ``key``."""
        if key not in self.cache:
            pair_s, _, epp = self.timed[key[0]]
            self.cache[key] = task_seconds(self.scenes[key], pair_s, epp)
        return self.cache[key]

    def later(self, key) -> float:
        """Modelled CPU seconds of the later ``F_P: auto`` rounds of the path of a task of
        ``key`` (priced as its round 0 is)."""
        pair_s, _, epp = self.timed[key[0]]
        return later_rounds_seconds(self.scenes[key], pair_s, epp)


def _calibration(spec, walls: dict, model: _Model, front=None) -> tuple:
    """(measured / modelled cost per job, n_side) at the largest brush size of a grid sweeping
    n_side that has finished jobs, to scale the model of its sizes that have none; (1.0, None)
    without one. The model's own growth with the brush is kept, its level taken from the file."""
    measured = [n for n in spec.n_sides if walls.get(n)]
    if len(spec.n_sides) < 2 or not measured:
        return 1.0, None
    ref = max(measured)
    total = jobs = 0
    for js, scene in _task_jobs(spec, None, front):
        if _n_side(spec, js) == ref:
            total += model.seconds(model.key(js, ref, scene))
            jobs += len(js)
    if total <= 0.0 or not jobs:
        return 1.0, None
    return sum(walls[ref]) / len(walls[ref]) / (total / jobs), ref


def _how(n_walls: int, modelled: set, swept: bool, scale: float = 1.0, ref=None) -> str:
    """How :func:`plan`'s estimate was made, for the dry-run line."""
    if not n_walls:
        return "model"
    how = f"measured mean{' per brush size' if swept else ''} of {n_walls} finished jobs"
    if modelled:
        how += f"; model for n_side {', '.join(str(n) for n in sorted(modelled))}"
        if ref is not None:
            how += f", scaled by the measured/model ratio at n_side {ref} ({scale:.2g})"
    return how


def search_plan_line(spec) -> str:
    """What a search grid is, for ``--dry-run``: its lines and its settings."""
    a, sa = spec.sigma_auto, spec.seeds_auto
    sizes = f" x {len(spec.n_sides)} n_side" if len(spec.n_sides) > 1 else ""
    sig = (f"sigma~ auto from {', '.join(f'{x:g}' for x in a.start)} (in [{a.min:g}, {a.max:g}]; "
           f"adhesion loss bracketed to {a.bracket:g}x, fit gaps closed to {a.spacing:g}x, at "
           f"most {a.rounds} rounds)" if a is not None
           else f"sigma~ {', '.join(f'{x:g}' for x in spec.sigma_tilde)}")
    seeds = (f"seeds auto {sa.start} to {sa.max} per group (until plateau and c are known "
             f"within {sa.width:g} of their value; seeds {sa.first} .. {sa.first + sa.max - 1})"
             if sa is not None
             else f"{len(spec.seeds)} seeds")
    pre = ("F_P auto" if spec.auto is not None
           else f"{spec.preload_kind} {', '.join(f'{x:g}' for x in spec.preloads)}")
    return (f"campaign {spec.campaign_hash[:12]}: search grid, {len(spec.lines())} lines "
            f"({len(spec.k_tilde)} k_tilde{sizes}); {sig}; {seeds}; {pre}. The counts and cost "
            "below are the round the file's records lead to now")


def search_cost_line(spec, per_path_s: float) -> str:
    """The whole search's likely cost, for ``--dry-run``: a line's typical sigma~ count
    (:func:`~fibril_hpc.campaign.plan.search.expected_sigmas`) x its seeds, priced per loading
    path as the round to run now (``per_path_s``: with F_P auto's expected later rounds)."""
    a, sa = spec.sigma_auto, spec.seeds_auto
    n_s = search.expected_sigmas(a) if a is not None else len(spec.sigma_tilde)
    lo, hi = (sa.start, sa.max) if sa is not None else (len(spec.seeds),) * 2
    paths = len(spec.lines()) * n_s
    cost = [per_path_s * paths * n / 3600 for n in (lo, hi)]
    seeds = f"{lo} to {hi} seeds" if lo != hi else f"{lo} seeds"
    return (f"the whole search, if the loss lies inside the start range: about {n_s} sigma~ per "
            f"line x {seeds} = {paths * lo}" + (f" to {paths * hi}" if hi != lo else "")
            + f" loading paths, {cost[0]:.3g}" + (f" to {cost[1]:.3g}" if hi != lo else "")
            + " core-hours (at this round's cost per path, F_P auto's later rounds included when "
            "the grid has them; a loss outside the start range adds more)")


__all__ = ["file_status", "FileStatus", "plan", "Plan", "search_plan_line", "search_cost_line"]
