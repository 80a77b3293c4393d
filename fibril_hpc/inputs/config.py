"""YAML -> validated :class:`~fibril_hpc.inputs.scene.Scene`; built-in scenes.

A scene file is a mapping of scene fields (see :class:`~fibril_hpc.inputs.scene.Scene`) with an optional
``solver:`` mapping. Unknown keys are rejected; nothing in the working directory changes numerics
implicitly.
"""

from __future__ import annotations

import math
import os
import re

import yaml

from ..errors import ConfigError
from .heights import is_file as is_height_file
from .scene import Scene, scene_from_dict

#: Built-in scenes for ``fibril-run --builtin NAME``.
BUILTIN_SCENES = {
    "default": {},
    "quick": {"n_side": 6, "k_tilde": 0.01, "sigma_tilde": 0.5, "F_P": [1.0, 2.0],
              "elements_per_diameter": 6},
    "single-pillar": {"n_side": 1, "k_tilde": math.inf, "sigma_tilde": 0.0, "d_tilde": 1.0,
                      "elements_per_diameter": 16},
}


class _Loader(yaml.SafeLoader):
    """PyYAML's safe loader, strict where a user would be surprised: a key given twice is an
    error, and ``1e6`` is a number (YAML 1.2) rather than the text YAML 1.1 makes of it."""

    def construct_mapping(self, node, deep=False):
        """A mapping, refusing a key that appears twice."""
        seen = set()
        for key_node, _ in node.value:
            key = self.construct_object(key_node, deep=deep)
            if key in seen:
                raise _Duplicate(key, key_node.start_mark.line + 1)
            seen.add(key)
        return super().construct_mapping(node, deep=deep)


class _Duplicate(yaml.YAMLError):
    def __init__(self, key, line):
        super().__init__(key, line)
        self.key, self.line = key, line


_Loader.add_implicit_resolver(
    "tag:yaml.org,2002:float",
    re.compile(r"^[-+]?(?:[0-9][0-9_]*)(?:\.[0-9_]*)?[eE][-+]?[0-9]+$"), list("-+0123456789"))


#: most values a YAML document may expand to (aliases counted as often as they are used): a
#: scene or grid holds a few thousand at most, an alias bomb billions
MAX_YAML_VALUES = 1_000_000


def expanded_size(obj, limit: int = MAX_YAML_VALUES) -> int:
    """Values of ``obj`` counted as if every alias were copied out (each shared container
    counted once per use, computed once: fast however large the expansion), capped at
    ``limit + 1``."""
    memo: dict = {}

    def size(o, depth=0) -> int:
        if not isinstance(o, (list, dict)):
            return 1
        if id(o) in memo:
            return memo[id(o)]
        if depth > 200:                     # deeper than any scene: count it as too big
            return limit + 1
        memo[id(o)] = limit + 1             # a cycle (a recursive alias) is too big
        items = o.values() if isinstance(o, dict) else o
        n = 1
        for v in items:
            n += size(v, depth + 1)
            if n > limit:
                break
        memo[id(o)] = min(n, limit + 1)
        return memo[id(o)]

    return size(obj)


def read_yaml(path: str, field: str = "scene") -> object:
    """Parse a YAML file; any I/O or syntax problem, a key given twice, and a document that
    expands to more than :data:`MAX_YAML_VALUES` values (an alias bomb), becomes a one-line
    ConfigError."""
    if not os.path.isfile(path):
        raise ConfigError(field, path, "an existing YAML file")
    if path.endswith((".h5", ".hdf5")):
        raise ConfigError(field, path, "a YAML file (this is an HDF5 file: did you mean "
                          f"`fibril-campaign status {path}`?)")
    try:
        with open(path, encoding="utf-8") as fh:
            data = yaml.load(fh, Loader=_Loader)  # noqa: S506 (a SafeLoader)
    except RecursionError:
        raise ConfigError(field, path, "YAML nested less deeply") from None
    except _Duplicate as exc:
        raise ConfigError(field, path, f"each key once (line {exc.line} repeats "
                          f"{exc.key!r})") from None
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f" at line {mark.line + 1}" if mark is not None else ""
        raise ConfigError(field, path, f"valid YAML (parse error{where})") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise ConfigError(field, path, f"a readable UTF-8 file ({exc.__class__.__name__})") from None
    if expanded_size(data) > MAX_YAML_VALUES:
        raise ConfigError(field, path, f"YAML of at most {MAX_YAML_VALUES} values once its "
                          "aliases are expanded (an alias bomb?)")
    return data


def load_scene(path: str) -> Scene:
    """Read and validate a scene YAML file."""
    data = read_yaml(path)
    if data is None:                   # an empty file is a mistake, not the default scene
        raise ConfigError("scene", path, "a YAML mapping of scene fields (this file is empty; "
                          "write {} for the default scene)")
    for key in ("heights", "k_law"):
        if isinstance(data, dict) and is_height_file(data.get(key)):
            # a measured height/stiffness file is named relative to the scene file's folder
            data = {**data, key: os.path.join(os.path.dirname(os.path.abspath(path)),
                                              os.path.expanduser(data[key]))}
    return scene_from_dict(data)


def builtin_scene(name: str) -> Scene:
    """A built-in scene by name (``fibril-run --builtin``)."""
    if name not in BUILTIN_SCENES:
        raise ConfigError("--builtin", name, "one of " + ", ".join(BUILTIN_SCENES))
    return scene_from_dict(dict(BUILTIN_SCENES[name]))


def scene_to_yaml(scene: Scene) -> str:
    """The resolved scene as YAML text (every field, defaults included)."""
    return yaml.safe_dump(scene.to_dict(), sort_keys=False)
