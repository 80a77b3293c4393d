"""A campaign as an ``xarray.Dataset`` (written as netCDF by ``fibril-campaign export --netcdf``).

The dimensions are the grid's: ``k_tilde``, ``sigma_tilde``, ``preload`` (F~_P targets or d~,
as the grid gives them) and ``seed``, preceded by ``n_side`` when the brush size is an axis of
the file (a grid sweeping it: :attr:`~.data.CampaignData.n_side_swept`), and before that by one
dimension per lab field the grid sweeps (:attr:`~.data.CampaignData.lab_sweeps`, in grid order:
float coordinates, or text for names and files); other files give the Dataset they always gave.
Every column of the job table is a variable over them (NaN,
"" or NaT where the grid has no job: an ``F_P: auto`` grid chooses its preloads per path), with
CF-style ``long_name`` and ``units`` attributes ("1": dimensionless, docs/model.md §2); a grid
in physical units adds the SI variables (N, m, N/m). The curves are padded variables
``loading_<quantity>`` and ``unloading_<quantity>`` over the job dimensions and
``loading_point``/``unloading_point``, NaN after each curve's ``<branch>_n_points`` points.
"""

from __future__ import annotations

import math
from dataclasses import fields

import numpy as np

from ...errors import ConfigError
from ..storage.record import BRANCHES, COLUMNS, CURVE_KEYS, JobRecord
from .si import SI_COLUMNS, has_units, si_columns

DIMS = ("k_tilde", "sigma_tilde", "preload", "seed")
#: the dimension a file whose grid sweeps the brush size adds in front of :data:`DIMS`
SIZE_DIM = "n_side"
#: long names and units of the dimensions and curve quantities
DIM_ATTRS = {
    "n_side": ("pillars per side of the brush (n_side**2 pillars)", "1"),
    "k_tilde": ("pillar spring stiffness k/(E* L)", "1"),
    "sigma_tilde": ("standard deviation of the pillar lengths sigma/d_c", "1"),
    "seed": ("seed of the pillar lengths", "1"),
}
CURVE_ATTRS = {
    "d_tilde": ("plate displacement d/d_c", "1"),
    "F_tilde": ("force on the plate F/F_c (F > 0 compression)", "1"),
    "contact_fraction": ("attached area / total pillar-tip area", "1"),
    "n_pillars_in_contact": ("pillars in contact", "1"),
}
#: units of the columns that are not dimensionless
COLUMN_UNITS = {"wall_s": "s"}
#: text attributes of the file that travel into the Dataset
META_KEYS = ("program", "fibril_hpc_version", "campaign_hash", "campaign_yaml", "definitions",
             "key_definition", "units", "merged_from")


def _xarray():
    try:
        import xarray as xr
    except ImportError:
        raise ConfigError("xarray", "not installed", "pip install 'fibril-hpc[netcdf]' for "
                          "to_xarray() and export --netcdf") from None
    return xr


def _cells(jobs, dims):
    """(coordinates per dimension, cell index of every job), refusing two jobs in one cell."""
    kinds = {j.get("preload_kind") for j in jobs}
    if len(kinds) > 1:
        raise ConfigError("to_xarray", "preloads given as " + " and ".join(sorted(kinds)),
                          "one preload kind per Dataset (select the jobs of one first)")
    if SIZE_DIM in dims and any(j.get(SIZE_DIM) is None for j in jobs):
        raise ConfigError("to_xarray", "a job without a stored scene (no n_side)",
                          "jobs whose brush size is known (use to_dataframe())")
    coords = {d: np.array(sorted({j[d] for j in jobs})) for d in dims}
    index = {d: {v: i for i, v in enumerate(coords[d])} for d in dims}
    cells = [tuple(index[d][j[d]] for d in dims) for j in jobs]
    if len(set(cells)) != len(cells):
        raise ConfigError("to_xarray", "two jobs at the same (" + ", ".join(dims) + ")",
                          "one job per cell (use to_dataframe())")
    return coords, cells, (kinds.pop() if kinds else "F_P")


def _grid(values, cells, shape, kind):
    """Scatter per-job ``values`` onto the job grid (NaN / "" / NaT elsewhere)."""
    if kind is float:
        out = np.full(shape, math.nan)
    elif kind == "datetime":
        out = np.full(shape, np.datetime64("NaT"), dtype="datetime64[ns]")
    else:
        out = np.full(shape, "", dtype=object)
    for c, v in zip(cells, values):
        out[c] = v
    return out


def to_xarray(data, curves: bool = True):
    """The jobs of a :class:`~fibril_hpc.campaign.analysis.data.CampaignData` as an
    ``xarray.Dataset`` (module docstring); ``curves=False`` leaves the curves out."""
    xr = _xarray()
    lab = tuple(data.lab_sweeps)
    jobs = data.jobs
    if lab:                      # the swept values as the table writes them (float or text)
        cols = {n: data.lab_column(n) for n in lab}
        for n, vals in cols.items():
            if any(v == "" or (isinstance(v, float) and math.isnan(v)) for v in vals):
                raise ConfigError("to_xarray", f"a job of none of the grid's {n} values",
                                  "jobs of the listed combinations of the swept values (use "
                                  "to_dataframe())")
        jobs = [{**j, **{n: cols[n][i] for n in lab}} for i, j in enumerate(jobs)]
    dims = lab + ((SIZE_DIM,) if data.n_side_swept else ()) + DIMS
    coords, cells, kind = _cells(jobs, dims)
    shape = tuple(len(coords[d]) for d in dims)
    docs = {f.name: f.metadata["doc"] for f in fields(JobRecord)}
    ds = xr.Dataset(coords={d: (d, coords[d]) for d in dims})
    for d, (name, unit) in DIM_ATTRS.items():
        if d in dims:
            ds[d].attrs.update(long_name=name, units=unit)
    ds["preload"].attrs.update(units="1", long_name="preload target: force F_P/F_c" if
                               kind == "F_P" else "preload target: indentation d/d_c")
    frame = data.to_dataframe()
    for d in lab:
        ds[d].attrs.update(long_name=f"scene.{d}, swept by the grid")
    for name in COLUMNS:
        if name in dims or name == "preload_kind":
            continue
        col = frame[name]
        if name == "finished":
            vals = col.dt.tz_convert(None).to_numpy(dtype="datetime64[ns]")
            ds[name] = (dims, _grid(vals, cells, shape, "datetime"))
            ds[name].attrs["long_name"] = docs[name] + " (UTC)"
            continue
        numeric = col.dtype.kind in "fiu" or str(col.dtype) == "Int64"
        vals = col.astype(float).to_numpy() if numeric else col.to_numpy()
        ds[name] = (dims, _grid(vals, cells, shape, float if numeric else str))
        ds[name].attrs["long_name"] = docs[name]
        if numeric:
            ds[name].attrs["units"] = COLUMN_UNITS.get(name, "1")
    if has_units(data.meta):
        for name, vals in si_columns(jobs).items():
            ds[name] = (dims, _grid(vals, cells, shape, float))
            ds[name].attrs.update(long_name=SI_COLUMNS[name][0], units=SI_COLUMNS[name][1])
    if curves:
        _add_curves(ds, jobs, cells, shape, dims)
    ds.attrs.update({k: str(data.meta[k]) for k in META_KEYS if data.meta.get(k)})
    ds.attrs["preload_kind"] = kind
    ds.attrs["Conventions"] = "CF-1.10"
    return ds


def _add_curves(ds, jobs, cells, shape, dims):
    for branch in BRANCHES:
        n = [len((j.get(branch) or {}).get("d_tilde", ())) for j in jobs]
        width = max(n, default=0)
        dim = f"{branch}_point"
        counts = _grid([float(x) for x in n], cells, shape, float)
        ds[f"{branch}_n_points"] = (dims, counts)
        ds[f"{branch}_n_points"].attrs.update(long_name=f"points of the {branch} curve",
                                              units="1")
        for key in CURVE_KEYS:
            arr = np.full(shape + (width,), math.nan)
            for c, j, m in zip(cells, jobs, n):
                if m:
                    arr[c + (slice(0, m),)] = j[branch][key]
            name = f"{branch}_{key}"
            ds[name] = (dims + (dim,), arr)
            long, unit = CURVE_ATTRS[key]
            ds[name].attrs.update(long_name=f"{long}, {branch} branch", units=unit)


def netcdf_available() -> bool:
    """Whether xarray and h5netcdf can be imported (netCDF export)."""
    try:
        import h5netcdf  # noqa: F401
        import xarray  # noqa: F401
    except ImportError:
        return False
    return True


__all__ = ["to_xarray", "netcdf_available", "DIMS", "SIZE_DIM"]
