"""Which job keys belong to a campaign file: :class:`GridIndex` (no h5py, no MPI).

A record is counted or published only when its key is a job of a grid the file was written
for: the grid of ``campaign_yaml``, the earlier grids of ``extended_from`` and, in a merged file,
the grids of ``merged_from``. Every grid is rebuilt from its stored YAML (the same validation as
``fibril-campaign run``). With ``F_P: auto`` a key belongs when its (k~, sigma~, seed, and
n_side where the grid sweeps it) is a path of the grid and the key is that path's job at the
record's preload. A grid that cannot be rebuilt (e.g. a measured height file that is no longer
there) falls back to the record itself: its key must be the key of its own stored scene
(``scene_yaml``). Anything else is *foreign*.
"""

from __future__ import annotations

import functools
import itertools
import json
import logging

import yaml

from ...inputs.scene import scene_from_dict
from ..plan.keys import job_key
from ..plan.spec import spec_from_dict
from .record import layout_problem

log = logging.getLogger(__name__)


@functools.lru_cache(maxsize=8)
def _rebuilt(campaign_yaml: str):
    """The spec of one stored grid (the same validation as ``fibril-campaign run``); None when
    this version cannot rebuild it. Cached: the same file is read by several commands."""
    try:
        data = yaml.safe_load(campaign_yaml)
        if not isinstance(data, dict):
            return None
        return spec_from_dict(dict(data, output="grid-index.h5"))
    except Exception:  # noqa: BLE001 - not a grid this version can rebuild
        return None


@functools.lru_cache(maxsize=8)
def _grid(campaign_yaml: str):
    """(frozenset of job keys, auto spec or None, {key: n_side} of a fixed grid sweeping
    n_side) of one stored grid; None when it cannot be rebuilt."""
    spec = _rebuilt(campaign_yaml)
    if spec is None:
        return None
    if spec.adaptive:
        return frozenset(), spec, {}
    sizes = {j.key: dict(j.extra)["n_side"] for j in spec.jobs} if "n_side" in spec.sweep else {}
    return frozenset(j.key for j in spec.jobs), None, sizes


def job_sweeps(campaign_yaml) -> dict | None:
    """{job key: {field: value}} of a stored fixed-preload grid with a ``sweep:``: each job's
    swept values as the grid spells them (a file's name, not its values), read from the order in
    which the grid enumerates its jobs (every combination of the swept values, the first field
    outermost, holds the same number of consecutive jobs). {} for a grid without a sweep or with
    ``F_P: auto``; None when the grid cannot be rebuilt."""
    spec = _rebuilt(campaign_yaml) if isinstance(campaign_yaml, str) and campaign_yaml else None
    if spec is None:
        return None
    if not spec.sweep or spec.adaptive:
        return {}
    names = list(spec.sweep)
    combos = list(itertools.product(*(spec.sweep[n] for n in names)))
    per, rest = divmod(len(spec.jobs), len(combos))
    if not per or rest:
        return None
    return {j.key: dict(zip(names, combos[j.index // per])) for j in spec.jobs}


def rebuild_problem(campaign_yaml: str) -> str:
    """Why a stored grid does not rebuild ("" when it does): the YAML does not parse, is not a
    mapping, or is not a grid this version accepts (the validation's one line)."""
    if _rebuilt(campaign_yaml) is not None:
        return ""
    try:
        data = yaml.safe_load(campaign_yaml)
    except yaml.YAMLError as exc:
        return f"it does not parse as YAML ({str(exc).splitlines()[0][:100]})"
    if not isinstance(data, dict):
        return "it is not a mapping of grid fields"
    try:
        spec_from_dict(dict(data, output="grid-index.h5"))
    except Exception as exc:  # noqa: BLE001 - the one line of the validation
        return str(exc).splitlines()[0][:200] if str(exc) else type(exc).__name__
    return ""


def rebuilt_hash(campaign_yaml) -> str | None:
    """The campaign hash of a stored grid rebuilt (None when it does not rebuild)."""
    spec = _rebuilt(campaign_yaml) if isinstance(campaign_yaml, str) and campaign_yaml else None
    return None if spec is None else spec.campaign_hash


def grid_matches(root: dict) -> bool:
    """Whether a file's root is whole: its ``campaign_yaml`` rebuilds to a grid whose campaign
    hash is the root's ``campaign_hash`` (a flipped byte in either breaks it)."""
    y = root.get("campaign_yaml")
    spec = _rebuilt(y) if isinstance(y, str) and y else None
    return spec is not None and spec.campaign_hash == root.get("campaign_hash")


def stored_grids(root: dict) -> list:
    """The YAML texts of every grid named by a file's root attributes."""
    out = [root.get("campaign_yaml")]
    for attr in ("extended_from", "merged_from"):
        try:
            items = json.loads(root.get(attr) or "[]")
        except (ValueError, TypeError):
            continue
        if isinstance(items, list):
            out += [i.get("campaign_yaml") for i in items if isinstance(i, dict)]
    return [y for y in out if isinstance(y, str) and y]


class GridIndex:
    """Whether a record's key belongs to one of the grids of a file (see the module doc)."""

    def __init__(self, yamls=(), specs=()):
        self.keys: set = set()
        self.auto: list = []
        self.unknown = 0                 # grids that could not be rebuilt
        self.sizes: dict = {}            # key -> n_side, of fixed grids sweeping n_side
        self._seen: dict = {}
        self._paths: dict = {}           # id(auto spec) -> the set of its loading paths
        for y in yamls:
            g = _grid(y)
            if g is None:
                self.unknown += 1
                continue
            self.keys |= g[0]
            self.sizes.update(g[2])
            if g[1] is not None:
                self.auto.append(g[1])
        for spec in specs:
            self.add_spec(spec)

    @classmethod
    def of_root(cls, root: dict, trusted: bool = True) -> GridIndex:
        """The index of a file with root attributes ``root``. A root without a grid (lost, and
        salvaged without it), or one not ``trusted`` (damaged: ``salvage``), names no grid that
        can be rebuilt: its records belong when their key is the key of their own stored scene,
        as for a grid this version cannot rebuild."""
        idx = cls(stored_grids(root) if trusted else ())
        if not trusted or not isinstance(root.get("campaign_yaml"), str) \
                or not root.get("campaign_yaml"):
            idx.unknown += 1
        return idx

    def add_spec(self, spec) -> None:
        """Add the grid of a campaign spec (the writer's own)."""
        if not spec.adaptive:
            self.keys |= {j.key for j in spec.jobs}
            if "n_side" in spec.sweep:
                self.sizes.update({j.key: dict(j.extra)["n_side"] for j in spec.jobs})
        else:
            self.auto.append(spec)
        self._seen.clear()

    @property
    def empty(self) -> bool:
        """Whether no grid is known at all (then nothing belongs)."""
        return not (self.keys or self.auto or self.unknown)

    def belongs(self, rec: dict) -> bool:
        """Whether the record ``rec`` has the layout of a job record and is a job of one of
        the grids."""
        key = rec.get("key")
        if not isinstance(key, str) or layout_problem(rec):
            return False
        if key in self.keys:
            return True
        got = self._seen.get((key, rec.get("record_id")))
        if got is None:
            got = self._auto_job(rec) or (self.unknown > 0 and _own_key(rec))
            self._seen[(key, rec.get("record_id"))] = got
        return got

    def n_side_of(self, rec: dict) -> int | None:
        """The brush size of a record of a grid sweeping n_side, found from its key (for a
        record without a stored scene to read it from); None when no such grid holds it."""
        n = self.sizes.get(rec.get("key"))
        if n is None and rec.get("preload_kind") in ("F_P", "d_tilde"):
            n = next((m for spec in self.auto
                      for m in _auto_sizes(spec, self._path_set(spec), rec)), None)
        return n

    def _path_set(self, spec):
        """The loading paths of an auto grid of this index, as a set made once (a file of many
        records asks for every record); a search grid's open set (:meth:`holds_path`)."""
        got = self._paths.get(id(spec))
        if got is None:
            got = self._paths[id(spec)] = (_Open(spec) if spec.search
                                           else frozenset(spec.paths()))
        return got

    def _auto_job(self, rec: dict) -> bool:
        if not self.auto:
            return False
        for spec in self.auto:
            if rec.get("preload_kind") != spec.preload_kind:
                continue
            try:
                path = spec.record_path(rec)
            except (KeyError, TypeError, ValueError):
                continue
            paths = self._path_set(spec)
            if path[3:] == (None,):      # a swept n_side that the record does not name
                if any(True for _ in _auto_sizes(spec, paths, rec)):
                    return True
                continue
            if path in paths and _auto_key(spec, path, rec) == rec["key"]:
                return True
        return False


class _Open:
    """The paths of a search grid, which are chosen while it runs: ``in`` asks the grid."""

    def __init__(self, spec):
        self.spec = spec

    def __contains__(self, path) -> bool:
        return self.spec.holds_path(path)


def _auto_key(spec, path, rec) -> str | None:
    """The key of the job of an auto grid's ``path`` at the record's preload (None: none)."""
    if spec.auto is None and rec.get("preload") not in spec.preloads:
        return None
    try:
        return spec.auto_task(path, [rec.get("preload")]).jobs[0].key
    except Exception:  # noqa: BLE001 - a preload the grid cannot hold
        return None


def _auto_sizes(spec, paths, rec):
    """The n_side values of an auto grid sweeping n_side (its loading ``paths``, a set) whose job
    at the record's (k~, sigma~, seed, preload) has the record's key (at most one: the keys
    differ by n_side)."""
    if "n_side" not in spec.sweep:
        return
    try:
        k, s, seed = float(rec["k_tilde"]), float(rec["sigma_tilde"]), int(rec["seed"])
    except (KeyError, TypeError, ValueError):
        return
    for n in spec.n_sides:
        path = (k, s, seed, n)
        if path in paths and _auto_key(spec, path, rec) == rec.get("key"):
            yield n


def _own_key(rec: dict) -> bool:
    """Whether a record's key is the key of its own stored scene."""
    try:
        return job_key(scene_from_dict(yaml.safe_load(rec.get("scene_yaml") or ""))) == rec["key"]
    except Exception:  # noqa: BLE001 - a scene this version cannot read
        return False


__all__ = ["GridIndex", "stored_grids", "job_sweeps", "grid_matches", "rebuild_problem",
           "rebuilt_hash"]
