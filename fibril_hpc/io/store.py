"""HDF5 output of single simulations (the only module of the solver side that imports h5py).

Layout of one result group (a file root for ``fibril-run --out``, or a job group in a campaign)::

    attrs: program, fibril_hpc_version, status, message, scene_yaml, versions (JSON),
           definitions (JSON), discretisation (JSON), stats (JSON), created
    pillars/xi, pillars/zeta_tilde                      per pillar, row-major pillar order
    preloads/<i>/  attrs: preload_kind, preload, status, message, F_P, F_A, d_tilde_max,
                          d_tilde_at_F_A, n_pillars_in_contact_max, events
                          (+ jumps, F_jump with a compliant machine)
        loading/{d_tilde, F_tilde, contact_fraction, n_pillars_in_contact}
                (+ d_machine_tilde with a compliant machine, k_machine < inf)
        unloading/{...}
        at_preload/{force, elongation, contact_map, pressure_map}  (attrs: d_tilde)
        at_pulloff/{...}
        let_go_d_tilde                                   per pillar (nan: never touched)

Files are written to a temporary name beside the target and renamed into place, so a failure
leaves nothing behind and never a half-written file. :func:`read_result_file` reads a file back
into a :class:`~fibril_hpc.io.results.SimulationResult`.
"""

from __future__ import annotations

import datetime as _dt
import json

import numpy as np
import yaml

from .._version import __version__
from ..errors import StoreError
from ..inputs.config import scene_to_yaml
from ..inputs.scene import scene_from_dict
from ..inputs.limits import MAX_GRID_SIDE
from . import h5check
from .files import write_bytes_atomically
from .results import Curve, PillarState, PreloadResult, SimulationResult, json_safe

PROGRAM = "fibril-hpc"
CURVE_FIELDS = ("d_tilde", "F_tilde", "contact_fraction", "n_pillars_in_contact")
STATE_FIELDS = ("force", "elongation", "contact_map", "pressure_map")


def _attrs_json(obj) -> str:
    return json.dumps(json_safe(obj), sort_keys=True)


def _write_curve(group, name, curve):
    if curve is None:
        return
    g = group.create_group(name)
    for key in CURVE_FIELDS:
        g.create_dataset(key, data=np.asarray(getattr(curve, key)))
    if curve.d_machine_tilde is not None:
        g.create_dataset("d_machine_tilde", data=np.asarray(curve.d_machine_tilde))


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
    a["created"] = _dt.datetime.now(_dt.UTC).isoformat(timespec="seconds")
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
    """Write a result to ``path`` atomically: built in memory (libhdf5 never meets a full
    disk), then temporary file + rename; ENOSPC/EDQUOT -> one-line DiskFull."""
    import io

    import h5py

    buf = io.BytesIO()
    with h5py.File(buf, "w") as fh:
        write_result(fh, result)
    write_bytes_atomically(path, buf.getbuffer(), "writing the result", ".fibril-")


# ------------------------------------------------------------------------------------ reading
_NONFINITE = {"nan": float("nan"), "inf": float("inf"), "-inf": float("-inf")}


def _unsafe(obj):
    """Undo :func:`~fibril_hpc.io.results.json_safe`: "nan"/"inf"/"-inf" strings become floats."""
    if isinstance(obj, dict):
        return {k: _unsafe(v) for k, v in obj.items()}
    if isinstance(obj, list):
        return [_unsafe(v) for v in obj]
    if isinstance(obj, str) and obj in _NONFINITE:
        return _NONFINITE[obj]
    return obj


def _group(parent, name):
    return h5check.member(parent, name, h5check.Group)


def _curve(group, name):
    g = _group(group, name)
    if g is None:
        return None
    arrays = [h5check.read_dataset(g, k, h5check.INT if k == "n_pillars_in_contact" else
                                   h5check.FLOAT) for k in CURVE_FIELDS]
    if any(a is None for a in arrays):
        raise StoreError(f"{g.name}: a curve array is missing")
    if len({len(a) for a in arrays}) != 1:
        raise StoreError(f"{g.name}: curve arrays of different lengths")
    return Curve(*arrays, d_machine_tilde=h5check.read_dataset(g, "d_machine_tilde",
                                                               h5check.FLOAT))


def _state(group, name):
    g = _group(group, name)
    if g is None:
        return None
    arrays = [h5check.read_dataset(g, k, h5check.NUMBER, ndim=None,
                                   max_elements=MAX_GRID_SIDE**2) for k in STATE_FIELDS]
    if any(a is None for a in arrays):
        raise StoreError(f"{g.name}: a pillar-state array is missing")
    d = h5check.read_attr(g, "d_tilde") if "d_tilde" in h5check.attr_names(g) else None
    if not isinstance(d, (int, float)) or isinstance(d, bool):
        raise StoreError(f"{g.name}@d_tilde: not a number")
    return PillarState(*arrays, d_tilde=float(d))


def _json_attr(a: dict, k: str):
    v = a.get(k)
    if not isinstance(v, str):
        raise StoreError(f"attribute {k}: not a JSON text")
    return _unsafe(json.loads(v))


def read_result(group) -> SimulationResult:
    """Read one simulation written by :func:`write_result` from an h5py group, through the
    checked path of :mod:`fibril_hpc.h5check` (hard links only, data in the file, dtypes and
    shapes checked before reading); anything else is one :class:`StoreError` line."""
    a = h5check.read_attrs(group)
    if a.get("program") != PROGRAM:
        raise StoreError(f"{group.file.filename}: not a fibril-run result file")
    for k in ("scene_yaml", "status", "message"):
        if not isinstance(a.get(k), str):
            raise StoreError(f"attribute {k}: missing or not a text")
    scene = yaml.safe_load(a["scene_yaml"])
    res = SimulationResult(scene=scene_from_dict(scene if scene is not None else {}),
                           status=a["status"], message=a["message"],
                           **{k: _json_attr(a, k)
                              for k in ("discretisation", "stats", "versions", "definitions")})
    pg = _group(group, "pillars")
    if pg is not None:
        res.xi = h5check.read_dataset(pg, "xi", h5check.NUMBER, ndim=None)
        res.zeta_tilde = h5check.read_dataset(pg, "zeta_tilde", h5check.NUMBER, ndim=None)
    pre = _group(group, "preloads")
    if pre is None:
        raise StoreError("no preloads group")
    names = h5check.names(pre)
    if not all(n.isdigit() and len(n) < 9 for n in names):
        raise StoreError("preloads: members other than 0, 1, 2 ...")
    for i in sorted(names, key=int):
        g = _group(pre, i)
        r = PreloadResult(**h5check.read_attrs(g))
        r.loading, r.unloading = _curve(g, "loading"), _curve(g, "unloading")
        r.at_preload, r.at_pulloff = _state(g, "at_preload"), _state(g, "at_pulloff")
        r.let_go_d_tilde = h5check.read_dataset(g, "let_go_d_tilde", h5check.FLOAT)
        res.results.append(r)
    return res


def read_result_file(path: str) -> SimulationResult:
    """Read a file written by ``fibril-run --out`` (or :func:`write_result_file`). Whatever the
    file holds, an error is one :class:`StoreError` line.

    Examples
    --------
    >>> r = read_result_file("out.h5")                  # doctest: +SKIP
    >>> r.main.F_A, r.main.unloading.F_tilde            # doctest: +SKIP
    """
    fh = h5check.open_file(path)
    try:
        with fh:
            return read_result(fh)
    except StoreError as exc:
        raise StoreError(f"{path}: {exc}") from None
    except MemoryError:
        raise StoreError(f"{path}: not enough memory to read it") from None
    except Exception as exc:  # noqa: BLE001 - a hostile file: whatever it makes the parsers say
        raise StoreError(f"{path}: not a readable fibril-run result file "
                         f"({h5check.describe(exc)})") from None
