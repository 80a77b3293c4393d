"""Job keys: the stable identity of a single-preload scene, and the campaign hash of a key set.

A job key is the SHA-256 (first 16 hex digits) of the scene's fields that define the result:
fields at their default are left out (so a field added to Scene later, with a default, changes no
existing key), the grid's axes (:data:`KEY_AXES`) are always in, provenance fields and resource
options never. Old campaign files are resumed by these keys: the rule is a contract (tests pin
keys of known scenes).
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import fields

from ...inputs.options import SolverOptions
from ...inputs.scene import Scene

#: scene fields that never enter a job key (provenance only, e.g. a height file's name)
KEY_EXCLUDED_SCENE = tuple(f.name for f in fields(Scene) if f.metadata.get("key") is False)
#: solver options that limit resources but do not define a result (left out of job keys):
#: the ``resource`` options of :class:`~fibril_hpc.inputs.options.SolverOptions`
KEY_EXCLUDED_SOLVER = SolverOptions.of_kind("resource")


def campaign_hash_of(keys) -> str:
    """SHA-256 (hex) of a set of job keys, independent of their order."""
    return hashlib.sha256("\n".join(sorted(keys)).encode()).hexdigest()


#: the fields every job key holds whatever their value (the grid's axes)
KEY_AXES = ("k_tilde", "sigma_tilde", "seed", "d_tilde", "F_P")


def key_fields(scene: Scene) -> dict:
    """What a job key is the hash of: the scene's fields off their default (and the axes
    :data:`KEY_AXES` always), provenance and resource options left out."""
    d = scene.to_dict()
    dflt = Scene().to_dict()
    solver = {k: v for k, v in d.pop("solver").items()
              if k not in KEY_EXCLUDED_SOLVER and v != dflt["solver"].get(k, object())}
    d = {k: v for k, v in d.items() if k not in KEY_EXCLUDED_SCENE and (
         k in KEY_AXES or v != dflt.get(k, object()))}
    d["solver"] = solver
    return d


def key_of_fields(d: dict) -> str:
    """The job key of :func:`key_fields`' mapping."""
    text = json.dumps(d, sort_keys=True, allow_nan=True)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def job_key(scene: Scene) -> str:
    """Stable key of a single-preload scene: fields at their default value are left out, so a
    field added to Scene later (with a default) does not change existing keys."""
    return key_of_fields(key_fields(scene))
