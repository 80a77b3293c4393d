"""HDF5 output of single simulations (the only module of the solver side that imports h5py).

Layout of one result group (a file root for ``fibril-run --out``, or a job group in a campaign)::

    attrs: program, fibril_hpc_version, status, message, scene_yaml, versions (JSON),
           definitions (JSON), discretisation (JSON), stats (JSON), created
    pillars/xi, pillars/zeta_tilde                      per pillar, row-major pillar order
    preloads/<i>/  attrs: preload_kind, preload, status, message, F_P, F_A, d_tilde_max,
                          d_tilde_at_F_A, n_pillars_in_contact_max, events
        loading/{d_tilde, F_tilde, contact_fraction, n_pillars_in_contact}
        unloading/{...}
        at_preload/{force, elongation, contact_map, pressure_map}  (attrs: d_tilde)
        at_pulloff/{...}
        let_go_d_tilde                                   per pillar (nan: never touched)

Files are written to a temporary name beside the target and renamed into place, so a failure
leaves nothing behind and never a half-written file.
"""

from __future__ import annotations

import datetime as _dt
import json
import os
import tempfile

import numpy as np

from .config import scene_to_yaml
from .files import discard_on_failure
from .results import SimulationResult, json_safe

PROGRAM = "fibril-hpc"


def _attrs_json(obj) -> str:
    return json.dumps(json_safe(obj), sort_keys=True)


def _write_curve(group, name, curve):
    if curve is None:
        return
    g = group.create_group(name)
    for key in ("d_tilde", "F_tilde", "contact_fraction", "n_pillars_in_contact"):
        g.create_dataset(key, data=np.asarray(getattr(curve, key)))


def _write_state(group, name, state):
    if state is None:
        return
    g = group.create_group(name)
    g.attrs["d_tilde"] = state.d_tilde
    g.create_dataset("force", data=state.force)
    g.create_dataset("elongation", data=state.elongation)
    g.create_dataset("contact_map", data=state.contact_map, compression="gzip")
    g.create_dataset("pressure_map", data=state.pressure_map, compression="gzip")


def write_result(group, result: SimulationResult) -> None:
    """Write one simulation into an (empty) h5py group."""
    from ._version import __version__

    a = group.attrs
    a["program"] = PROGRAM
    a["fibril_hpc_version"] = __version__
    a["status"] = result.status
    a["message"] = result.message
    a["scene_yaml"] = scene_to_yaml(result.scene)
    a["versions"] = _attrs_json(result.versions)
    a["definitions"] = _attrs_json(result.definitions)
    a["discretisation"] = _attrs_json(result.discretisation)
    a["stats"] = _attrs_json(result.stats)
    a["created"] = _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds")
    if result.xi is not None:
        pg = group.create_group("pillars")
        pg.create_dataset("xi", data=result.xi)
        pg.create_dataset("zeta_tilde", data=result.zeta_tilde)
    pre = group.create_group("preloads")
    for i, r in enumerate(result.results):
        g = pre.create_group(str(i))
        for key, value in r.summary().items():
            g.attrs[key] = value
        _write_curve(g, "loading", r.loading)
        _write_curve(g, "unloading", r.unloading)
        _write_state(g, "at_preload", r.at_preload)
        _write_state(g, "at_pulloff", r.at_pulloff)
        if r.let_go_d_tilde is not None:
            g.create_dataset("let_go_d_tilde", data=r.let_go_d_tilde)


def write_result_file(path: str, result: SimulationResult) -> None:
    """Write a result to ``path`` atomically (temporary file + rename)."""
    import h5py

    folder = os.path.dirname(os.path.abspath(path)) or "."
    fd, tmp = tempfile.mkstemp(prefix=".fibril-", suffix=".h5.part", dir=folder)
    os.close(fd)
    with discard_on_failure(tmp, path):
        with h5py.File(tmp, "w") as fh:
            write_result(fh, result)
        os.replace(tmp, path)
