"""HDF5 output of single simulations (the only module of the solver side that imports h5py).

Layout of one result group (a file root for ``fibril-run --out``, or a job group in a campaign)::

    attrs: program, fibril_hpc_version, status, message, scene_yaml, versions (JSON),
           definitions (JSON), discretisation (JSON), stats (JSON), created,
           units (JSON; only for a scene given in physical units, docs/units.md)
    units/{E_star, dgamma, pitch, diameter, L, A0, F_c, d_c, k_unit, phi_discrete}
                 scalars with their SI unit (only for a scene in physical units)
    pillars/xi, pillars/zeta_tilde                      per pillar, row-major pillar order
    preloads/<i>/  attrs: preload_kind, preload, status, message, F_P, F_A, d_tilde_max,
                          d_tilde_at_F_A, n_pillars_in_contact_max, events
                          (+ jumps, F_jump with a compliant machine)
        loading/{d_tilde, F_tilde, contact_fraction, n_pillars_in_contact}, point
                (+ d_machine_tilde with a compliant machine, k_machine < inf;
                 + d [m] and F [N] for a scene in physical units)
        unloading/{...}
        at_preload/{force, elongation, contact_map, pressure_map}  (attrs: d_tilde)
        at_pulloff/{...}
        let_go_d_tilde                                   per pillar (nan: never touched)

Every dataset carries CF-style ``long_name`` and ``units`` attributes ("1": dimensionless) and
HDF5 dimension scales (``point``, ``pillar``, ``row``/``column``), so netCDF readers
(``xarray.open_dataset(path, engine="h5netcdf", group="preloads/0/unloading")``) name the axes.
The preload attributes gain F_P_N, F_A_N, d_max_m, d_at_F_A_m for a scene in physical units.

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
from ..inputs.physical import SI_UNITS
from ..inputs.scene import scene_from_dict
from ..inputs.limits import MAX_GRID_SIDE
from . import h5check, isolate
from .files import write_bytes_atomically
from .results import (
    SI_FIELDS,
    Curve,
    PillarState,
    PreloadResult,
    SimulationResult,
    json_safe,
    si_summary,
)

PROGRAM = "fibril-hpc"
CURVE_FIELDS = ("d_tilde", "F_tilde", "contact_fraction", "n_pillars_in_contact")
STATE_FIELDS = ("force", "elongation", "contact_map", "pressure_map")

#: CF-style (long_name, units) of every dataset ("1": dimensionless; docs/model.md §2)
CF = {
    "d_tilde": ("plate displacement d/d_c (d > 0 presses the pillars in)", "1"),
    "F_tilde": ("force on the plate F/F_c (F > 0 compression)", "1"),
    "contact_fraction": ("attached area / total pillar-tip area", "1"),
    "n_pillars_in_contact": ("pillars in contact", "1"),
    "d_machine_tilde": ("machine displacement Delta/d_c", "1"),
    "d": ("plate displacement d", "m"),
    "F": ("force on the plate F", "N"),
    "force": ("pillar force f_n/F_c", "1"),
    "elongation": ("spring compression of the pillar, Delta l_n/d_c", "1"),
    "contact_map": ("1 where an element is attached", "1"),
    "pressure_map": ("contact pressure p A0/F_c (p > 0 compression)", "1"),
    "let_go_d_tilde": ("d/d_c at which the pillar let go (nan: never touched)", "1"),
    "xi": ("standard normal draw of the pillar length", "1"),
    "zeta_tilde": ("set-back of the pillar from the longest one, zeta_n/d_c", "1"),
    "point": ("index of the point along the branch", "1"),
    "pillar": ("pillar index (row-major)", "1"),
    "row": ("element row", "1"),
    "column": ("element column", "1"),
}


def _dataset(group, name, data, dims=(), **kw):
    """A dataset with its CF ``long_name``/``units`` and its dimension scales attached."""
    ds = group.create_dataset(name, data=data, **kw)
    ds.attrs["long_name"], ds.attrs["units"] = CF[name]
    for axis, dim in enumerate(dims):
        if dim not in group:
            scale = group.create_dataset(dim, data=np.arange(ds.shape[axis]))
            scale.attrs["long_name"], scale.attrs["units"] = CF[dim]
            scale.make_scale(dim)
        ds.dims[axis].attach_scale(group[dim])
        ds.dims[axis].label = dim
    return ds


def _write_units(group, units: dict) -> None:
    """The ``units`` group: one scalar dataset per SI scale, with its unit."""
    g = group.create_group("units")
    g.attrs["long_name"] = "SI value of every unit of this result (docs/units.md)"
    for key, value in units.items():
        ds = g.create_dataset(key, data=float(value))
        ds.attrs["units"] = SI_UNITS.get(key, "")


def _attrs_json(obj) -> str:
    return json.dumps(json_safe(obj), sort_keys=True)


def _write_curve(group, name, curve, units):
    if curve is None:
        return
    g = group.create_group(name)
    for key in CURVE_FIELDS:
        _dataset(g, key, np.asarray(getattr(curve, key)), ("point",))
    if curve.d_machine_tilde is not None:
        _dataset(g, "d_machine_tilde", np.asarray(curve.d_machine_tilde), ("point",))
    if units:                   # the same branch in newtons and metres
        _dataset(g, "d", np.asarray(curve.d_tilde) * units["d_c"], ("point",))
        _dataset(g, "F", np.asarray(curve.F_tilde) * units["F_c"], ("point",))


def _write_state(group, name, state):
    if state is None:
        return
    g = group.create_group(name)
    g.attrs["d_tilde"] = state.d_tilde
    _dataset(g, "force", state.force, ("pillar",))
    _dataset(g, "elongation", state.elongation, ("pillar",))
    _dataset(g, "contact_map", state.contact_map, ("row", "column"), compression="gzip")
    _dataset(g, "pressure_map", state.pressure_map, ("row", "column"), compression="gzip")


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
    if result.units:
        a["units"] = _attrs_json(result.units)
        _write_units(group, result.units)
    if result.xi is not None:
        pg = group.create_group("pillars")
        _dataset(pg, "xi", result.xi, ("pillar",))
        _dataset(pg, "zeta_tilde", result.zeta_tilde, ("pillar",))
    pre = group.create_group("preloads")
    for i, r in enumerate(result.results):
        g = pre.create_group(str(i))
        summary = r.summary()
        if result.units:
            summary.update(si_summary(summary, result.units))
        for key, value in summary.items():
            g.attrs[key] = value
        _write_curve(g, "loading", r.loading, result.units)
        _write_curve(g, "unloading", r.unloading, result.units)
        _write_state(g, "at_preload", r.at_preload)
        _write_state(g, "at_pulloff", r.at_pulloff)
        if r.let_go_d_tilde is not None:
            _dataset(g, "let_go_d_tilde", r.let_go_d_tilde, ("pillar",))


def write_result_file(path: str, result: SimulationResult, exclusive: str | None = None) -> None:
    """Write a result to ``path`` atomically: built in memory (libhdf5 never meets a full
    disk), then temporary file + rename; ENOSPC/EDQUOT -> one-line DiskFull. ``exclusive``
    (the option naming ``path``): ``path`` must be new, checked atomically as it is written
    (see :func:`fibril_hpc.io.files.write_bytes_atomically`)."""
    import io

    import h5py

    buf = io.BytesIO()
    with h5py.File(buf, "w") as fh:
        write_result(fh, result)
    write_bytes_atomically(path, buf.getbuffer(), "writing the result", ".fibril-", exclusive)


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
                              for k in ("discretisation", "stats", "versions", "definitions")},
                           **({"units": _json_attr(a, "units")} if "units" in a else {}))
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
        r = PreloadResult(**{k: v for k, v in h5check.read_attrs(g).items() if k not in SI_FIELDS})
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
    h5check.check_regular_file(path)   # a FIFO, device or folder: one line at once, no stall
    return isolate.run_isolated(_read_result_file, path, what=path)


def _read_result_file(path: str) -> SimulationResult:
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
