"""A grid's axis values and its base scene, validated against the ranges of
:class:`~fibril_hpc.inputs.scene.Scene` (one line naming the field on a bad value)."""

from __future__ import annotations

from ...errors import ConfigError
from ...inputs.ranges import as_float, range_of
from ...inputs.scene import Scene, scene_from_dict


def axis_values(name, v):
    """A number or a list of numbers in the range of Scene field ``name`` (order kept)."""
    rng = range_of(Scene, name)
    allowed = rng.allowed(plural=True)
    items = list(v) if isinstance(v, (list, tuple)) else [v]
    if not items:
        raise ConfigError(name, v, allowed)
    out = []
    for item in items:
        if isinstance(item, bool) or not isinstance(item, (int, float, str)):
            raise ConfigError(name, item, allowed)
        x = as_float(name, item, allowed)       # "inf", never a number in quotes
        if not rng.contains(x):
            raise ConfigError(name, item, allowed)
        out.append(x)
    if len(set(out)) != len(out):
        raise ConfigError(name, v, allowed + " (no duplicates)")
    return tuple(out)


SEEDS_ALLOWED = ("a count in [1, 100000], a list of distinct integers >= 0, auto or "
                 "{auto: {start, max, width, first}}")


def seed_values(v) -> tuple:
    """The seeds of a grid: a count n (seeds 0 .. n-1) or a list of distinct integers >= 0."""
    if isinstance(v, int) and not isinstance(v, bool) and 1 <= v <= 100000:
        return tuple(range(v))
    if isinstance(v, list) and v and all(
            isinstance(s, int) and not isinstance(s, bool) and 0 <= s < 2**63 for s in v):
        if len(set(v)) != len(v):
            raise ConfigError("seeds", v, "a list of distinct integers >= 0")
        return tuple(v)
    raise ConfigError("seeds", v, SEEDS_ALLOWED)


def base_scene(scene_map: dict, sweep: dict):
    """The grid's base scene. A lab field that the scene leaves out and the grid sweeps, whose
    absence alone makes the scene invalid (``tip: sphere`` with ``tip_radius`` only swept), takes
    its first swept value there: every job sets its own value, so no key changes, and a grid
    that was valid before is built exactly as before."""
    try:
        return scene_from_dict(scene_map, where="scene.")
    except ConfigError as exc:
        field = exc.field
        name = field.removeprefix("scene.")
        if name == "n_side" or name in scene_map or not sweep.get(name):
            raise
    try:
        return base_scene({**scene_map, name: sweep[name][0]}, sweep)
    except ConfigError as again:
        if again.field != field:
            raise
        raise ConfigError(f"sweep.{name}", again.value, again.allowed) from None
