"""Reading a campaign back: :func:`load_campaign` (also ``fibril_hpc.load_campaign``)."""

from __future__ import annotations

import functools
import json
import logging
import math

import numpy as np

from ...errors import ConfigError, StoreError
from ..plan.axes import record_n_side
from ..storage.grids import GridIndex, job_sweeps, stored_grids
from ..storage.record import COLUMNS, JobRecord
from ..storage.store import read_snapshot
from . import dataset
from .si import has_units, si_columns
from .variants import job_variant, show_value, swept_lab_fields

log = logging.getLogger(__name__)


class CampaignData:
    """A table of jobs (one row per job record) and their curves.

    Attributes
    ----------
    meta : dict
        Root attributes of the file (``campaign_yaml``, ``campaign_hash``, ``definitions`` ...).
    jobs : list of dict
        One dict per job, with the :data:`COLUMNS`, ``n_side`` (the brush size, from the job's
        stored scene; None without one) and ``loading``/``unloading`` curves (dicts of arrays
        ``d_tilde``, ``F_tilde``, ``contact_fraction``, ``n_pillars_in_contact``).
    pending_in_journal : int
        Records finished but not yet folded into the HDF5 file (read from the journal).
    corrupt : dict
        Job key -> why, for records of the file that failed their checksum or could not be
        read: they are *not* in :attr:`jobs` (a warning is logged; resume recomputes them).
    unchecked : set
        Keys of records without a checksum (nothing vouches for them): in :attr:`jobs` only
        when read with ``include_unchecked=True``.
    foreign : dict
        Name -> why, for members of ``/jobs`` that live elsewhere (links, external data) or are
        no job of the file's grids: never in :attr:`jobs`.
    """

    def __init__(self, meta, jobs, pending_in_journal=0, corrupt=None, unchecked=(),
                 foreign=None):
        self.meta = meta
        self.jobs = jobs
        self.pending_in_journal = pending_in_journal
        self.corrupt = dict(corrupt or {})
        self.unchecked = set(unchecked)
        self.foreign = dict(foreign or {})

    def __len__(self):
        return len(self.jobs)

    def __iter__(self):
        return iter(self.jobs)

    def column(self, name: str) -> np.ndarray:
        """One column over all jobs: a float array when every value is a number, else objects."""
        vals = [j.get(name) for j in self.jobs]
        if vals and all(isinstance(v, (int, float, np.number)) and not isinstance(v, bool)
                        for v in vals):
            return np.asarray(vals, dtype=float)
        return np.asarray(vals, dtype=object)

    @functools.cached_property
    def n_side_swept(self) -> bool:
        """Whether the brush size is an axis of this file: a grid of it sweeps ``n_side``
        (``sweep:``), or its jobs hold more than one brush size (e.g. a file extended by a grid
        of another n_side). Then :meth:`to_dataframe` and the CSV export carry an ``n_side``
        column and :meth:`to_xarray` an ``n_side`` dimension; else they are as they always
        were."""
        return grid_sweeps_n_side(self.meta) or len(
            {j.get("n_side") for j in self.jobs if j.get("n_side") is not None}) > 1

    @functools.cached_property
    def lab_sweeps(self) -> dict:
        """{field: [values]} of the lab fields the file's grid sweeps (``sweep:`` beyond
        ``n_side`` and ``k_machine``, in grid order; {} without). Every job then holds its value
        of each (None for a job of none of the listed combinations), and :meth:`to_dataframe`
        and :meth:`to_xarray` carry them as columns and dimensions: jobs of different variants
        share (k~, sigma~, preload, seed)."""
        return lab_fields(self.meta)

    def lab_column(self, name: str) -> list:
        """A swept lab field's values over the jobs as the table writes them: numbers as floats
        (NaN where unknown) when every listed value is a number, else their text ("" where
        unknown)."""
        vals = [j.get(name) for j in self.jobs]
        if all(_is_number(v) for v in self.lab_sweeps[name]):
            return [math.nan if v is None else float(v) for v in vals]
        return ["" if v is None else show_value(v) for v in vals]

    @property
    def table(self) -> dict:
        """Column name -> array (numeric columns as float arrays)."""
        return {c: self.column(c) for c in COLUMNS}

    def to_dataframe(self):
        """The jobs as a pandas DataFrame, one row per job, the columns of :data:`COLUMNS` typed
        as the fields of :class:`~fibril_hpc.campaign.storage.record.JobRecord` (float, int64,
        str; ``finished`` a UTC datetime), followed by ``n_side`` (int64) when the brush size is
        an axis of the file (:attr:`n_side_swept`), then by one column per swept lab field
        (:attr:`lab_sweeps`: float, or str for names and files), then, for a grid in physical
        units, by the SI columns of :data:`~fibril_hpc.campaign.analysis.si.SI_COLUMNS` (N, m,
        N/m); needs pandas (``pip install 'fibril-hpc[report]'``)."""
        try:
            import pandas as pd
        except ImportError:
            raise ConfigError("pandas", "not installed",
                              "pip install 'fibril-hpc[report]' for DataFrames") from None
        types = column_types()
        data = {}
        for name in COLUMNS:
            vals = [j.get(name) for j in self.jobs]
            t = types[name]
            if t is float:
                data[name] = np.array([math.nan if v is None else float(v) for v in vals],
                                      dtype=float)
            elif t is int and name in OPTIONAL_INTS:      # a missing value is <NA>, not 0
                data[name] = pd.array([None if v is None else int(v) for v in vals],
                                      dtype="Int64")
            elif t is int:
                data[name] = np.array([0 if v is None else int(v) for v in vals], dtype=np.int64)
            else:
                data[name] = ["" if v is None else str(v) for v in vals]
        data["finished"] = pd.to_datetime(data["finished"], utc=True, format="ISO8601")
        if self.n_side_swept:
            data["n_side"] = pd.array([j.get("n_side") for j in self.jobs], dtype="Int64")
        for name in self.lab_sweeps:
            data[name] = self.lab_column(name)
        if has_units(self.meta):
            data.update(si_columns(self.jobs))
        return pd.DataFrame(data, columns=list(data))

    #: the name of :meth:`to_dataframe` before it had the name pandas users expect
    frame = to_dataframe

    def to_xarray(self, curves: bool = True):
        """The jobs as an ``xarray.Dataset`` over (k_tilde, sigma_tilde, preload, seed), and
        ``n_side`` first when the brush size is an axis of the file (:attr:`n_side_swept`): see
        :func:`fibril_hpc.campaign.analysis.dataset.to_xarray`; needs xarray."""
        return dataset.to_xarray(self, curves=curves)

    @property
    def definitions(self) -> dict:
        """The file's normalisation definitions (JSON of the ``definitions`` attribute)."""
        return json.loads(self.meta.get("definitions", "{}"))

    def select(self, **where) -> list:
        """Jobs whose fields equal the given values, e.g. ``select(k_tilde=0.01, status="done")``."""
        out = []
        for j in self.jobs:
            ok = True
            for k, v in where.items():
                x = j.get(k)
                if isinstance(v, float) and isinstance(x, float):
                    ok = ok and (x == v or (math.isnan(x) and math.isnan(v)))
                else:
                    ok = ok and x == v
            if ok:
                out.append(j)
        return out


def column_types() -> dict:
    """Column name -> float, int or str, from the annotations of
    :class:`~fibril_hpc.campaign.storage.record.JobRecord`."""
    from dataclasses import fields

    names = {"float": float, "int": int, "str": str}
    return {f.name: names.get(str(f.type).removesuffix(" | None"), str)
            for f in fields(JobRecord) if f.name in COLUMNS}


#: int columns that may be missing (record.py: stored only with a compliant machine, or with
#: ``solver.confirm: local``)
OPTIONAL_INTS = ("jumps", "confirmed_local", "confirmed_global")


def fill_k_machine(rec: dict) -> dict:
    """Set a record's missing ``k_machine`` (rigid-machine records and those written before the
    field existed) from its stored scene: the scene's ``k_machine``, ``inf`` if it names none."""
    if rec.get("k_machine") is None:
        text = rec.get("scene_yaml") or ""
        km = math.inf
        if "k_machine" in text:
            import yaml

            km = float((yaml.safe_load(text) or {}).get("k_machine", math.inf))
        rec["k_machine"] = km
    return rec


def grid_sweeps_n_side(meta: dict) -> bool:
    """Whether a grid stored in a file's root attributes (its own, or one it was extended from
    or merged from) sweeps ``n_side``."""
    import yaml

    for text in stored_grids(meta):
        try:
            grid = yaml.safe_load(text)
        except yaml.YAMLError:
            continue
        sweep = grid.get("sweep") if isinstance(grid, dict) else None
        if isinstance(sweep, dict) and "n_side" in sweep:
            return True
    return False


def lab_fields(meta: dict) -> dict:
    """{field: [values]} of the swept lab fields of a file's grid that the job table carries
    (:func:`.variants.swept_lab_fields`, less any name the table has already)."""
    return {n: v for n, v in swept_lab_fields(meta).items() if n not in COLUMNS}


def fill_lab_values(meta: dict, jobs: list) -> None:
    """Set every job's value of each swept lab field (:func:`lab_fields`), read as the report
    reads it (:func:`.variants.job_variant`: from the key through the file's grid, else from the
    stored scene); None for a job of none of the listed combinations."""
    values = lab_fields(meta)
    if not values:
        return
    by_key = job_sweeps(meta.get("campaign_yaml"))
    for j in jobs:
        idx = job_variant(j, values, by_key)
        for i, (name, listed) in enumerate(values.items()):
            j[name] = None if idx is None else listed[idx[i]]


def _is_number(v) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool)


def fill_n_side(rec: dict) -> dict:
    """Set a record's ``n_side`` from its stored scene (:func:`.plan.axes.record_n_side`); a
    record without one gets it from its key when its grid sweeps n_side (:func:`load_campaign`)."""
    rec["n_side"] = record_n_side(rec)
    return rec


def _sort_key(j):
    return (j.get("n_side") or 0, j.get("k_tilde", 0.0), j.get("sigma_tilde", 0.0), j.get("seed", 0),
            j.get("preload", 0.0))


def load_campaign(path: str, curves: bool = True, include_unchecked: bool = False) -> CampaignData:
    """Read a campaign file (and the journal of a campaign still running) into a table.

    Only records this code can vouch for are returned (docs/robustness.md): records without a
    checksum (*unchecked*) are left out, with a warning, unless ``include_unchecked``; foreign
    and corrupt ones always (listed in :attr:`CampaignData.foreign` and ``corrupt``).

    Examples
    --------
    >>> c = load_campaign("results.h5")                      # doctest: +SKIP
    >>> done = c.select(status="done", k_tilde=0.01)        # doctest: +SKIP
    >>> [(j["F_P"], j["F_A"]) for j in done]                # doctest: +SKIP
    >>> df = c.to_dataframe()       # pandas DataFrame, one row per job  # doctest: +SKIP
    >>> ds = c.to_xarray()          # xarray Dataset over (k~, sigma~, preload, seed)  # doctest: +SKIP
    """
    snap = read_snapshot(path, curves=curves)
    if not snap.root:
        raise StoreError(f"{path}: no campaign file here")
    recs = snap.records
    if snap.unchecked_keys and not include_unchecked:
        recs = {k: r for k, r in recs.items() if k not in snap.unchecked_keys}
        log.warning("%s: %d unchecked record(s) (no checksum) left out; nothing vouches for "
                    "them (include them with include_unchecked=True / --include-unchecked)",
                    path, snap.unchecked)
    if snap.foreign:
        keys = sorted(snap.foreign)
        log.warning("%s: %d foreign member(s) of /jobs left out (%s%s): `fibril-campaign verify "
                    "%s` says why", path, len(keys), ", ".join(k[:40] for k in keys[:3]),
                    " ..." if len(keys) > 3 else "", path)
    jobs = [fill_n_side(fill_k_machine(r)) for r in recs.values()]
    if any(j["n_side"] is None for j in jobs) and grid_sweeps_n_side(snap.root):
        index = GridIndex.of_root(snap.root)     # no stored scene: the grid knows the key's size
        for j in jobs:
            if j["n_side"] is None:
                j["n_side"] = index.n_side_of(j)
    fill_lab_values(snap.root, jobs)
    lab = lab_fields(snap.root)         # the variants of one cell in the grid's order
    jobs.sort(key=lambda j: _sort_key(j) + tuple(
        next((i for i, v in enumerate(vs) if v is j[n] or v == j[n]), -1) for n, vs in lab.items()))
    return CampaignData(snap.root, jobs, snap.pending, snap.corrupt, snap.unchecked_keys,
                        snap.foreign)
