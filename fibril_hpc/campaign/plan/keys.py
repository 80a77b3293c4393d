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


def keys_of_axes(template: dict, names, values) -> list:
    """The job keys of every combination of the values of the axes ``names`` (a product, the
    first axis outermost), each the :func:`key_of_fields` of ``template`` with the axes set to
    the combination's entries (``values[a][i]``: the key-field entry of axis a's value i).

    Equal to calling :func:`key_of_fields` per combination, but the canonical JSON is written
    once with a marker per axis and each entry is put in as its JSON text, and the SHA-256 of
    the text before each axis's entry is shared by every combination below it (copies of a
    hash state): about 1 us a key, where a JSON document and a hash each took 25 us."""
    names = list(names)
    marks = {n: f"@@fibril-axis-{i}@@" for i, n in enumerate(names)}
    text = json.dumps({**template, **marks}, sort_keys=True, allow_nan=True)
    places = sorted((text.index(f'"{m}"'), n) for n, m in marks.items())
    if text.count("@@fibril-axis-") != len(names) or \
            any(text.count(f'"{m}"') != 1 for m in marks.values()):
        raise ValueError("an axis marker occurs in the template")        # never in a scene
    pieces, at = [], 0
    for pos, n in places:                        # text = p0 v_a p1 v_b ... p_last
        pieces.append(text[at:pos].encode())
        at = pos + len(marks[n]) + 2
    tail = text[at:].encode()
    order = [names.index(n) for _, n in places]  # the axes in the order their entries appear
    texts = [[json.dumps(v, allow_nan=True).encode() for v in values[a]] for a in order]
    sizes = [len(values[a]) for a in range(len(names))]
    strides = [1] * len(names)                   # index of a combination in product order
    for a in range(len(names) - 2, -1, -1):
        strides[a] = strides[a + 1] * sizes[a + 1]
    out = [""] * (strides[0] * sizes[0])

    def fill(level, state, base):
        a = order[level]
        nxt = pieces[level + 1] if level + 1 < len(pieces) else tail
        if level == len(order) - 1:
            for i, t in enumerate(texts[level]):
                h = state.copy()
                h.update(t + nxt)
                out[base + i * strides[a]] = h.hexdigest()[:16]
            return
        for i, t in enumerate(texts[level]):
            h = state.copy()
            h.update(t + nxt)
            fill(level + 1, h, base + i * strides[a])

    if all(sizes):
        fill(0, hashlib.sha256(pieces[0]), 0)
    return out


def job_key(scene: Scene) -> str:
    """Stable key of a single-preload scene: fields at their default value are left out, so a
    field added to Scene later (with a default) does not change existing keys."""
    return key_of_fields(key_fields(scene))
