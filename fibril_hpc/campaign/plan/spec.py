"""Campaign grid YAML -> validated :class:`CampaignSpec` -> jobs with stable keys.

A grid YAML is a mapping::

    output: results.h5          # relative to the folder of the YAML file
    scene:                      # fixed scene fields (any Scene field except the swept ones)
      n_side: 18
      solver: {fft_threads: 1, max_wall_s: 3600}
    k_tilde: [1, 0.1, 0.01]     # number or list
    sigma_tilde: [0.1, 0.5]     # number or list; or auto (the loss bracketed, .search)
    F_P: [0.5, 1, 2, 4]         # or d_tilde: [...]; number or list; or auto (see .auto)
    seeds: 10                   # a count (seeds 0..9), a list of seeds, or auto (.search)
    # with scene.physical (SI units, docs/units.md), k: [N/m, ...] and sigma: [m, ...] may
    # stand for k_tilde and sigma_tilde; the jobs are keyed by the normalised values
    group_preloads: true        # jobs sharing (k_tilde, sigma_tilde, seed) share one loading path
    sweep:                      # optional: scene fields swept like the others (lists, .sweep)
      n_side: [6, 12, 18]       # the brush size (a finite-size study)
      k_machine: [.inf, 1, 0.1]
      tip_radius: [1, 4]
      heights: [gaussian, array_a.csv, array_b.npy]   # laws and/or measured files

Every combination (k_tilde, sigma_tilde, preload, seed and the ``sweep`` values) is one job; a
swept field's value is in the job's stored scene (``scene_yaml``). With ``F_P: auto`` only
``n_side`` may be swept: one loading path per (n_side, k_tilde, sigma_tilde, seed). A measured ``heights``
or stiffness (``k_law``) file, in ``scene`` or among the swept values, is read once, relative to
the YAML's folder; the job's scene keeps its values and, in ``heights_source``/``k_source``,
its name and SHA-256.

A job's key is the first 16 hex digits of the SHA-256 of its resolved single-preload scene
(canonical JSON of the fields that differ from their defaults, plus k_tilde, sigma_tilde, seed
and the preload; without the resource and cap options ``solver.fft_threads``,
``solver.max_wall_s``, ``solver.max_events``), so keys do not depend on the order of the lists,
on other jobs, or on scene fields added later. The campaign hash is the SHA-256 of the sorted job
keys: two grids with the same set of jobs have the same hash.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from typing import NamedTuple

import yaml

from ...errors import ConfigError, unknown_key
from ...inputs.config import read_yaml
from ...inputs.heights import is_file as is_height_file
from ...inputs.limits import check_job_count
from ...inputs.physical import grid_values
from ...inputs.scene import SCENE_FIELDS, Scene
from .auto import parse, settings_hash
from .search import check_grid, is_auto, parse_seeds, parse_sigma
from .search import settings_hash as search_hash
from .axes import record_n_side
from .fastjobs import fast_jobs
from .keys import campaign_hash_of, job_key
from .sweep import check_n_side_sweep, parse_sweep, sweep_files
from .values import axis_values, base_scene, seed_values

SWEPT = ("k_tilde", "sigma_tilde", "d_tilde", "F_P", "seed")
TOP_KEYS = ("output", "scene", "k_tilde", "sigma_tilde", "d_tilde", "F_P", "seeds",
            "group_preloads", "description", "sweep", "k", "sigma")


class Job(NamedTuple):
    """One (k_tilde, sigma_tilde, preload, seed) combination (immutable; a named tuple, which
    a grid of 10^6 jobs builds four times faster than a frozen dataclass)."""

    key: str
    index: int
    k_tilde: float
    sigma_tilde: float
    preload_kind: str
    preload: float
    seed: int
    extra: tuple = ()       # ((field, value), ...) of the grid's ``sweep`` (empty without one)

    def inputs(self) -> dict:
        """The job's identity fields, as stored in its record."""
        return {"key": self.key, "k_tilde": self.k_tilde, "sigma_tilde": self.sigma_tilde,
                "preload_kind": self.preload_kind, "preload": self.preload, "seed": self.seed}


@dataclass(frozen=True)
class Task:
    """Jobs run by one ``simulate`` call (one loading path); ``jobs`` in ascending preload."""

    jobs: tuple
    scene: Scene

    @property
    def keys(self):
        """Keys of the task's jobs."""
        return [j.key for j in self.jobs]


@dataclass
class CampaignSpec:
    """A validated campaign grid: the base scene, the swept values, the output and the jobs."""

    base: Scene
    k_tilde: tuple
    sigma_tilde: tuple
    preload_kind: str
    preloads: tuple
    seeds: tuple
    group_preloads: bool
    output: str
    source: str = ""
    description: str = ""
    jobs: list = field(default_factory=list)
    #: ``F_P: auto`` settings (:class:`.auto.AutoPreloads`), None for a fixed preload list
    auto: object = None
    sweep: dict = field(default_factory=dict)      # field -> tuple of values (``sweep:``)
    #: a shard's (:mod:`.shard`): the hash of the whole grid, and the loading paths it keeps
    grid_hash: str = ""
    only_paths: frozenset | None = None
    #: ``sigma_tilde: auto`` and ``seeds: auto`` settings (:mod:`.search`), None for lists
    sigma_auto: object = None
    seeds_auto: object = None
    #: a search grid's shard: the lines (k~[, n_side]) it keeps
    only_lines: frozenset | None = None

    # ------------------------------------------------------------------ identity
    def resolved(self) -> dict:
        """The resolved campaign as a plain mapping (what the HDF5 file stores as YAML)."""
        scene = self.base.to_dict()
        for k in SWEPT + (("n_side",) if "n_side" in self.sweep else ()):
            scene.pop(k, None)
        pre = list(self.preloads) if self.auto is None else {"auto": self.auto.to_dict()}
        sig = (list(self.sigma_tilde) if self.sigma_auto is None
               else {"auto": self.sigma_auto.to_dict()})
        seeds = list(self.seeds) if self.seeds_auto is None else {"auto": self.seeds_auto.to_dict()}
        out = {"description": self.description, "scene": scene,
               "k_tilde": list(self.k_tilde), "sigma_tilde": sig,
               self.preload_kind: pre, "seeds": seeds,
               "group_preloads": self.group_preloads}
        if self.sweep:
            out["sweep"] = {k: list(v) for k, v in self.sweep.items()}
        return out

    def resolved_yaml(self) -> str:
        """The resolved campaign as YAML (stored in the file as ``campaign_yaml``)."""
        return yaml.safe_dump(self.resolved(), sort_keys=False)

    @property
    def campaign_hash(self) -> str:
        """SHA-256 of the sorted job keys; with ``F_P: auto`` (jobs chosen while it runs) of the
        sorted path keys ``auto:<settings hash>:<key of the path's scene at F_P = 1>``; for a
        search grid of the sorted line keys ``search:<settings hash>:<line key>``."""
        if self.grid_hash:
            return self.grid_hash
        if self.search:
            r = self.resolved()
            h = search_hash(r["sigma_tilde"], r["seeds"], r[self.preload_kind])
            return campaign_hash_of(f"search:{h}:{self.line_key(ln)}" for ln in self.lines(True))
        if self.auto is None:
            return campaign_hash_of(j.key for j in self.jobs)

        h = settings_hash(self.auto)
        return campaign_hash_of(f"auto:{h}:{self.path_key(p)}" for p in self.paths())

    # ------------------------------------------------------------------ search grids
    @property
    def search(self) -> bool:
        """``sigma_tilde: auto`` or ``seeds: auto``: lines searched round by round (:mod:`.search`)."""
        return self.sigma_auto is not None or self.seeds_auto is not None

    @property
    def adaptive(self) -> bool:
        """The jobs are chosen while the campaign runs (``F_P: auto`` or a search grid)."""
        return self.auto is not None or self.search

    def lines(self, whole: bool = False) -> list:
        """The lines (k_tilde,) of a search grid, (k_tilde, n_side) when it sweeps ``n_side``
        (a shard's own, unless ``whole``)."""
        sizes = [(n,) for n in self.sweep["n_side"]] if "n_side" in self.sweep else [()]
        return [(k,) + n for n in sizes for k in self.k_tilde
                if whole or self.only_lines is None or (k,) + n in self.only_lines]

    def line_key(self, line) -> str:
        """Key of the line's scene at sigma~ = 1, seed 0 and preload 1 (its identity)."""
        return job_key(self.base.replace(k_tilde=line[0], sigma_tilde=1.0, seed=0,
                                         **{self.preload_kind: (1.0,)},
                                         **dict(self._path_extra((0, 0, 0) + tuple(line[1:])))))

    def holds_path(self, path) -> bool:
        """Whether a loading path (k~, sigma~, seed[, n_side]) may be one of this grid's."""
        k, s, seed = path[:3]
        if len(path) != 3 + ("n_side" in self.sweep) or k not in self.k_tilde or \
                (len(path) > 3 and path[3] not in self.n_sides):
            return False
        a, sa = self.sigma_auto, self.seeds_auto
        s_ok = (a.min <= s <= a.max) if a is not None else s in self.sigma_tilde
        seed_ok = (sa.first <= seed < sa.first + sa.max) if sa is not None else seed in self.seeds
        if not (s_ok and seed_ok):
            return False
        if self.only_lines is not None and (k,) + tuple(path[3:]) not in self.only_lines:
            return False
        return self.search or self.only_paths is None or tuple(path) in self.only_paths

    # ------------------------------------------------------------------ F_P: auto
    @property
    def n_sides(self) -> tuple:
        """The brush sizes of the grid: the swept ``n_side`` values, else the scene's one."""
        return tuple(self.sweep.get("n_side", (self.base.n_side,)))

    def paths(self, whole: bool = False) -> list:
        """The loading paths (k_tilde, sigma_tilde, seed), in grid order (a shard's own, unless
        ``whole``); (k_tilde, sigma_tilde, seed, n_side) when the grid sweeps ``n_side``."""
        sizes = [(n,) for n in self.sweep["n_side"]] if "n_side" in self.sweep else [()]
        return [(k, s, seed) + n for n in sizes for k in self.k_tilde for s in self.sigma_tilde
                for seed in self.seeds
                if whole or self.only_paths is None or (k, s, seed) + n in self.only_paths]

    @staticmethod
    def _path_extra(path) -> tuple:
        """The ``sweep`` entries of a path: ``(("n_side", n),)`` or ``()``."""
        return (("n_side", path[3]),) if len(path) > 3 else ()

    def path_of_job(self, job) -> tuple:
        """The loading path a job of an ``F_P: auto`` grid belongs to."""
        n = dict(job.extra).get("n_side")
        return (job.k_tilde, job.sigma_tilde, job.seed) + ((n,) if "n_side" in self.sweep else ())

    def record_path(self, rec: dict) -> tuple:
        """The loading path of a stored record (its brush size read from its stored scene when
        the grid sweeps ``n_side``: :func:`.axes.record_n_side`)."""
        path = (float(rec["k_tilde"]), float(rec["sigma_tilde"]), int(rec["seed"]))
        return path + ((record_n_side(rec),) if "n_side" in self.sweep else ())

    def path_key(self, path) -> str:
        """Key of the path's scene at F_P = 1 (its identity in an auto grid's campaign hash)."""
        k, s, seed = path[:3]
        return job_key(self.base.replace(k_tilde=k, sigma_tilde=s, seed=seed, F_P=(1.0,),
                                         **dict(self._path_extra(path))))

    def auto_task(self, path, preloads) -> Task:
        """One round of an ``F_P: auto`` path, or the jobs a search grid runs on one path: a
        task with one ordinary job per preload."""
        k, s, seed = path[:3]
        extra = self._path_extra(path)
        kind = self.preload_kind
        base_index = 0 if self.search else self.paths(whole=True).index(tuple(path)) * 1000
        jobs = []
        for i, p in enumerate(sorted(preloads)):
            job = Job("", base_index + i, k, s, kind, p, seed, extra)
            jobs.append(Job(job_key(self.job_scene(job)), job.index, k, s, kind, p, seed, extra))
        scene = self.base.replace(k_tilde=k, sigma_tilde=s, seed=seed,
                                  **{kind: tuple(j.preload for j in jobs)}, **dict(extra))
        return Task(tuple(jobs), scene)

    # ------------------------------------------------------------------ jobs
    def job_scene(self, job: Job) -> Scene:
        """The single-preload scene of one job (what its key is computed from)."""
        return self.base.replace(k_tilde=job.k_tilde, sigma_tilde=job.sigma_tilde, seed=job.seed,
                                 **{self.preload_kind: (job.preload,)}, **dict(job.extra))

    def tasks(self, keys=None) -> list:
        """Tasks for the jobs whose key is in ``keys`` (all when None), in grid order, grouped
        by (k_tilde, sigma_tilde, seed) when ``group_preloads``."""
        return [Task(js, self.task_scene(js)) for js in self.task_jobs(keys)]

    def task_jobs(self, keys=None):
        """The jobs of each task of :meth:`tasks` (tuples in ascending preload, in grid order),
        one at a time and without building their scenes: what a plan counts and prices."""
        want = None if keys is None else (keys if isinstance(keys, (set, frozenset, dict))
                                          else set(keys))
        jobs = (j for j in self.jobs if want is None or j.key in want)
        if not self.group_preloads:              # one job per task: no grouping to do
            for j in jobs:
                yield (j,)
            return
        groups: dict = {}
        for j in jobs:
            groups.setdefault((j.k_tilde, j.sigma_tilde, j.seed, j.extra), []).append(j)
        for js in groups.values():
            yield tuple(sorted(js, key=lambda j: j.preload))

    def path_preloads(self) -> int:
        """The most preloads one task (one loading path, one ``simulate`` call) of this grid
        holds: what a rank keeps a snapshot of each of (``F_P: auto``: round 0's; the later
        rounds run fewer per path)."""
        if not self.group_preloads:
            return 1
        return max(1, len(self.auto.start if self.auto is not None else self.preloads))

    def n_tasks(self) -> int:
        """How many tasks (loading paths) the whole grid has, counted without building them."""
        if not self.group_preloads:
            return len(self.jobs)
        return len({(j.k_tilde, j.sigma_tilde, j.seed, j.extra) for j in self.jobs})

    def task_scene(self, js) -> Scene:
        """The scene of the task running the jobs ``js`` (of one loading path, in ascending
        preload)."""
        axes = {"k_tilde": js[0].k_tilde, "sigma_tilde": js[0].sigma_tilde,
                "seed": js[0].seed, self.preload_kind: tuple(j.preload for j in js)}
        # every job's scene was validated when the grid was read; a path's scene differs
        # from them only in holding several of the validated preloads
        return (self.base.replace(**axes, **dict(js[0].extra)) if js[0].extra
                else self.base.with_checked_axes(**axes))


def spec_from_dict(data, *, source: str = "", base_dir: str = ".") -> CampaignSpec:
    """Validate a grid mapping; every problem is a one-line :class:`ConfigError`."""
    if not isinstance(data, dict):
        raise ConfigError("campaign", data, "a mapping with output, scene, k_tilde, sigma_tilde, "
                          "d_tilde or F_P, seeds")
    unknown = sorted(set(map(str, data)) - set(TOP_KEYS))
    if unknown:
        if unknown[0] in SCENE_FIELDS and unknown[0] not in SWEPT:
            raise ConfigError(unknown[0], data.get(unknown[0]), "a key of the grid; "
                              f"{unknown[0]} is a scene field: write it under scene:")
        raise unknown_key(unknown[0], data.get(unknown[0]), TOP_KEYS)
    out = data.get("output")
    if not isinstance(out, str) or not out.strip() or not out.endswith((".h5", ".hdf5")):
        raise ConfigError("output", out, "a file name ending in .h5 (relative to the YAML's folder)")
    output = os.path.normpath(os.path.join(base_dir, os.path.expanduser(out)))
    scene_map = data.get("scene") or {}
    if not isinstance(scene_map, dict):
        raise ConfigError("scene", scene_map, "a mapping of fixed scene fields")
    for k in scene_map:
        if k in SWEPT:
            allowed = "set at the top level" + (" as seeds" if k == "seed" else f" as {k}")
            raise ConfigError(f"scene.{k}", scene_map[k], allowed + " (it is swept)")
    scene_map = dict(scene_map)
    sweep = parse_sweep(data.get("sweep"))
    check_n_side_sweep(scene_map, sweep, data)
    for key in ("heights", "k_law"):          # measured files: relative to the YAML's folder
        if is_height_file(scene_map.get(key)):
            scene_map[key] = os.path.join(base_dir, os.path.expanduser(scene_map[key]))
    if "n_side" in sweep:                     # the base scene: the largest brush (limits, memory)
        scene_map["n_side"] = max(sweep["n_side"])
    try:
        base = base_scene(scene_map, sweep)
    except ConfigError as exc:
        if "n_side" not in sweep or exc.field != "scene.n_side":
            raise
        raise ConfigError("sweep.n_side", exc.value, exc.allowed) from None
    data = {**{k: v for k, v in data.items() if k not in ("k", "sigma")},   # SI lists, converted
            **grid_values(data, scene_map.get("physical"), base)}
    for name in ("k_tilde", "sigma_tilde"):
        if name not in data:
            raise ConfigError(name, None, "a number or a list of numbers (required)")
    ks = axis_values("k_tilde", data["k_tilde"])
    sigma_auto = parse_sigma(data["sigma_tilde"]) if is_auto(data["sigma_tilde"]) else None
    try:
        ss = () if sigma_auto else axis_values("sigma_tilde", data["sigma_tilde"])
    except ConfigError as exc:
        raise ConfigError(exc.field, exc.value, exc.allowed + "; or auto, or {auto: {settings}} "
                          "(docs/campaigns.md, 'sigma_tilde: auto')") from None
    if ("d_tilde" in data) == ("F_P" in data):
        raise ConfigError("F_P", data.get("F_P"), "give either F_P or d_tilde (one of them)")
    kind = "F_P" if "F_P" in data else "d_tilde"
    auto = None
    if kind == "F_P" and (data["F_P"] == "auto" or isinstance(data["F_P"], dict)):
        auto = parse(data["F_P"])
        pre = ()
    else:
        try:
            pre = axis_values(kind, data[kind])
        except ConfigError as exc:
            if kind != "F_P":
                raise
            raise ConfigError(exc.field, exc.value, exc.allowed + "; or auto, or "
                              "{auto: {settings}} (docs/campaigns.md, 'F_P: auto')") from None
    seeds_v = data.get("seeds", 1)
    seeds_auto = parse_seeds(seeds_v)
    seeds = (tuple(seeds_auto.seeds(seeds_auto.max)) if seeds_auto is not None
             else seed_values(seeds_v))
    group = data.get("group_preloads", True)
    if not isinstance(group, bool):
        raise ConfigError("group_preloads", group, "true or false")
    desc = data.get("description", "") or ""
    if not isinstance(desc, str):
        raise ConfigError("description", desc, "a text")
    spec = CampaignSpec(base=base, k_tilde=ks, sigma_tilde=ss, preload_kind=kind, preloads=pre,
                        seeds=seeds, group_preloads=group, output=output, source=source,
                        description=desc, auto=auto, sweep=sweep, sigma_auto=sigma_auto,
                        seeds_auto=seeds_auto)
    counts = {"k_tilde": len(ks),
              "sigma_tilde": len(sigma_auto.start) if sigma_auto else len(ss)}
    if auto is None:
        counts[kind] = len(pre)
    counts["seeds"] = len(seeds)
    counts.update({f"sweep.{name}": len(values) for name, values in sweep.items()})
    check_job_count(counts)                  # before enumerating any job or path
    if spec.search:
        return check_grid(spec, sweep, group)
    if auto is not None:
        if not group:
            raise ConfigError("group_preloads", group, "true with F_P: auto (a round is one "
                              "loading path)")
        lab = [name for name in sweep if name != "n_side"]
        if lab:
            raise ConfigError(f"sweep.{lab[0]}", list(sweep[lab[0]]), "no lab-field sweep with F_P: "
                              "auto (n_side is the one field it sweeps): give the preloads as a "
                              "list, or run one grid per value")
        for path in spec.paths():            # validates every path's scene now
            spec.auto_task(path, auto.start[:1])
        return spec
    if not sweep:
        jobs = fast_jobs(spec, Job, ks, ss, seeds, pre, kind)
        if jobs is not None:
            spec.jobs = jobs
            return spec
    files = sweep_files(sweep, base, base_dir)
    extras = [()]
    for name, values in sweep.items():
        extras = [e + (files.get((name, v), ((name, v),)) if isinstance(v, str) else ((name, v),))
                  for e in extras for v in values]
    jobs = []
    for extra in extras:
        for k in ks:
            for s in ss:
                for seed in seeds:
                    for p in pre:
                        job = Job("", len(jobs), k, s, kind, p, seed, extra)
                        # validates the combination exactly as the solver will see it
                        try:
                            scene = spec.job_scene(job)
                        except ConfigError as exc:
                            where = "sweep." if exc.field in sweep else ""
                            raise ConfigError(where + exc.field, exc.value, exc.allowed) from None
                        jobs.append(Job(job_key(scene), len(jobs), k, s, kind, p, seed, extra))
    spec.jobs = jobs
    return spec


def load_spec(path: str, output: str | None = None) -> CampaignSpec:
    """Read a grid YAML; ``output`` (a path relative to the working directory) overrides the
    file's ``output`` (which is relative to the YAML's folder)."""
    data = read_yaml(path, field="grid")
    if data is None:                   # an empty file (or only comments): say so, not "got None"
        raise ConfigError("grid", path, "a YAML mapping with output, scene, k_tilde, sigma_tilde, "
                          "F_P or d_tilde, seeds (this file is empty; `fibril-campaign example "
                          "demo` prints one to start from)")
    if isinstance(data, dict) and output is not None:
        data = dict(data)
        data["output"] = os.path.abspath(output)
    base_dir = os.path.dirname(os.path.abspath(path))
    return spec_from_dict(data, source=os.path.abspath(path), base_dir=base_dir)
