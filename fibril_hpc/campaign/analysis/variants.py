"""Which variant of a grid sweeping lab fields the report reads (``--where NAME=VALUE``).

A grid may sweep lab fields of the scene (``sweep: {tip_radius: [0.5, 4]}``): every
combination of the swept values is a job, so the jobs of different variants share
(k~, sigma~, preload, seed) and must never be read as one group. The machine stiffness
``k_machine`` and the brush size ``n_side`` have their own readings (the stiffest machine, the
largest brush: :mod:`.report_data`) and are not variants here. For every other swept field the
report reads **one combination**: the first listed value of each field, in grid order (while
that combination has no done job, the first in grid order that has), or the values named with
``where``; the page says which, and which variants the file holds besides.

A job's variant is read from its key through the file's own grid (rebuilt from
``campaign_yaml``: :func:`..storage.grids.job_sweeps`), else, for a record of no job of that grid
(a file extended from another grid, or a grid that cannot be rebuilt: a measured file no longer
there), from its stored scene (``scene_yaml``): the field's value there (its default when the
scene does not name it; the file's name from ``heights_source``/``k_source`` for a measured
file). A job that is of none of the listed combinations is read in none.
"""

from __future__ import annotations

import dataclasses
import math
import os
from dataclasses import dataclass, field

import yaml

from ...errors import ConfigError
from ...inputs.heights import is_file as is_height_file
from ...inputs.scene import Scene
from ..plan.sweep import FILE_FIELDS
from ..storage.grids import job_sweeps

#: swept fields with their own reading (the stiffest machine, the largest brush): no variants
OWN_READING = ("n_side", "k_machine")
_DEFAULTS = {f.name: f.default for f in dataclasses.fields(Scene)}


@dataclass
class Variant:
    """The combination of swept lab values the report reads, and what it leaves out."""

    values: dict                    # {field: every listed value}, grid order
    chosen: dict                    # {field: the value read}
    keys: frozenset                 # keys of the done jobs of the chosen combination
    others: list = field(default_factory=list)     # [({field: value}, done jobs)] not read
    unknown: int = 0                # done jobs of none of the listed combinations
    by_where: bool = False          # chosen with ``where`` (else: the first listed with done jobs)

    @property
    def label(self) -> str:
        """``tip_radius = 0.5, tip = sphere``: the combination read."""
        return label(self.chosen)


def label(combo: dict) -> str:
    """``NAME = VALUE, ...`` of one combination of swept values."""
    return ", ".join(f"{n} = {show_value(v)}" for n, v in combo.items())


def show_value(v) -> str:
    """One swept value as the page and the messages write it (``null``, ``4``, ``sphere``)."""
    return "null" if v is None else f"{v:g}" if isinstance(v, float) else str(v)


def swept_lab_fields(meta: dict) -> dict:
    """{field: [values]} of the lab fields the file's own grid (``campaign_yaml``) sweeps, other
    than :data:`OWN_READING`, in grid order; {} for a grid without such a sweep."""
    try:
        grid = yaml.safe_load(meta.get("campaign_yaml") or "") or {}
        sweep = grid.get("sweep") or {}
    except (yaml.YAMLError, AttributeError):
        return {}
    if not isinstance(sweep, dict):
        return {}
    return {n: list(v) if isinstance(v, list) else [v] for n, v in sweep.items()
            if n not in OWN_READING}


def _number(v):
    if isinstance(v, bool) or v is None:
        return None
    if isinstance(v, (int, float)):
        return float(v)
    return None


def same_value(a, b) -> bool:
    """Whether two spellings of a swept value are the same value (4 and 4.0; lists and tuples)."""
    x, y = _number(a), _number(b)
    if x is not None and y is not None:
        return x == y or (math.isnan(x) and math.isnan(y))
    if isinstance(a, (list, tuple)) and isinstance(b, (list, tuple)):
        return len(a) == len(b) and all(same_value(p, q) for p, q in zip(a, b))
    return a == b


def _scene_value(name: str, scene: dict, value) -> bool:
    """Whether a stored scene (a mapping) holds the grid's swept ``value`` of field ``name``."""
    if name in FILE_FIELDS and isinstance(value, str) and is_height_file(value):
        src = str(scene.get(FILE_FIELDS[name]) or "").rsplit(" sha256:", 1)[0]
        want = os.path.normpath(value)
        return bool(src) and (src == value or os.path.normpath(src).endswith(os.sep + want)
                              or os.path.normpath(src) == want)
    return same_value(scene.get(name, _DEFAULTS.get(name)), value)


def job_variant(job: dict, values: dict, by_key: dict | None) -> tuple | None:
    """The index into each field's listed values of a job (a tuple in grid order), or None when
    the job is of none of the listed combinations."""
    combo = (by_key or {}).get(job.get("key"))
    if combo is not None:
        try:
            return tuple(next(i for i, v in enumerate(values[n]) if same_value(v, combo[n])
                              and repr(v) == repr(combo[n])) for n in values)
        except (StopIteration, KeyError):
            return None
    try:
        scene = yaml.safe_load(job.get("scene_yaml") or "")
    except yaml.YAMLError:
        return None
    if not isinstance(scene, dict):
        return None
    out = []
    for n, vs in values.items():
        i = next((i for i, v in enumerate(vs) if _scene_value(n, scene, v)), None)
        if i is None:
            return None
        out.append(i)
    return tuple(out)


def parse_where(where, values: dict, option: str = "where") -> dict:
    """{field: index of the value read} from ``where`` (``NAME=VALUE`` strings, or a mapping
    NAME -> value); every other swept field reads its first listed value. A name the grid does
    not sweep (or sweeps with a reading of its own), a value not listed, or a name given twice
    is a :class:`ConfigError` naming ``option`` and what is allowed."""
    if isinstance(where, dict):
        items = [(str(n), v, f"{n}={v}") for n, v in where.items()]
    else:
        items = []
        for text in where or ():
            name, eq, raw = str(text).partition("=")
            if not eq or not name.strip():
                raise ConfigError(option, text, _allowed(values))
            items.append((name.strip(), raw.strip(), text))
    chosen = {}
    for name, raw, text in items:
        if name not in values:
            why = (" (it has its own reading: the stiffest machine, the largest n_side)"
                   if name in OWN_READING else "")
            raise ConfigError(option, text, _allowed(values) + why)
        if name in chosen:
            raise ConfigError(option, text, f"each NAME once: {_values(name, values[name])}")
        i = _match(raw, values[name])
        if i is None:
            raise ConfigError(option, text, _values(name, values[name]))
        chosen[name] = i
    return chosen


def _match(raw, listed) -> int | None:
    parsed = raw
    if isinstance(raw, str):
        try:
            parsed = yaml.safe_load(raw) if raw else raw
        except yaml.YAMLError:
            parsed = raw
    for i, v in enumerate(listed):
        if same_value(parsed, v) or same_value(raw, v) or (isinstance(raw, str)
                                                           and raw == show_value(v)):
            return i
    return None


def _values(name, vs) -> str:
    return "one of " + ", ".join(f"{name}={show_value(v)}" for v in vs)


def _allowed(values: dict) -> str:
    if not values:
        return ("nothing: the file's grid sweeps no lab field (n_side and k_machine have their "
                "own reading)")
    return "NAME=VALUE, " + "; ".join(_values(n, vs) for n, vs in values.items())


def select(meta: dict, done: list, where=None, option: str = "where") -> Variant | None:
    """The variant the report reads from the done jobs ``done`` of a file with root attributes
    ``meta``; None when its grid sweeps no lab field (beyond :data:`OWN_READING`: then ``where``
    must be empty)."""
    values = swept_lab_fields(meta)
    picks = parse_where(where, values, option)
    if not values:
        return None
    idx = tuple(picks.get(n, 0) for n in values)
    by_key = job_sweeps(meta.get("campaign_yaml"))
    counts: dict = {}
    unknown = 0
    variant_of = {}
    for j in done:
        v = job_variant(j, values, by_key)
        if v is None:
            unknown += 1
            continue
        counts[v] = counts.get(v, 0) + 1
        variant_of[j.get("key")] = v
    if not picks and idx not in counts and counts:
        idx = min(counts)       # the first listed one has no done job yet: the first that has
    keys = {k for k, v in variant_of.items() if v == idx}
    others = [({n: values[n][i] for n, i in zip(values, v)}, c)
              for v, c in sorted(counts.items()) if v != idx]
    return Variant(values, {n: values[n][i] for n, i in zip(values, idx)}, frozenset(keys),
                   others, unknown, by_where=bool(picks))


__all__ = ["Variant", "OWN_READING", "label", "show_value", "swept_lab_fields", "same_value", "job_variant",
           "parse_where", "select"]
