"""The record of one campaign job: the ONE list of its fields.

The journal payload (:meth:`JobRecord.to_dict`), the HDF5 attributes and curve groups of
``/jobs/<key>`` (:data:`SCALAR_KEYS`, :data:`CURVE_KEYS`), the columns of
:func:`~fibril_hpc.campaign.analysis.data.load_campaign` and the CSV export (:data:`COLUMNS`) all derive
from the fields of :class:`JobRecord`. Adding an output quantity is one field here (plus the code
that fills it in :mod:`fibril_hpc.campaign.run.execute`).

The fields after ``unloading`` (``k_machine``, ``jumps``, ``F_jump``, ``d_machine_tilde_at_F_A``)
came with the compliant loading machine (issue 11). They are ``None`` (not stored: the HDF5 group,
journal frame and checksum are exactly those of a record written before they existed) unless the
job's machine is compliant (``k_machine < inf``); so a record without them is a rigid-machine job
or one written before they existed. :func:`~fibril_hpc.campaign.analysis.data.load_campaign` fills a
missing ``k_machine`` from the stored scene (``inf`` unless it names one); a missing ``jumps`` is
a missing value (pandas ``<NA>``, empty CSV cell), a missing float NaN.

The last three (``confirmed_local``, ``confirmed_global``, ``force_bound_tilde``, issue 35) are
stored, the same way, only for a job solved with ``solver.confirm: local``: how its
``simulate`` call ended its relaxations (kept on the certified force bound, or by a global
solve) and the largest bound it accepted; shared by the ``group_size`` jobs of that call.

Records travel as plain dicts (pickled to the MPI master, appended to the journal, read back from
HDF5); :class:`JobRecord` is their schema and constructor. The names and types are a contract
with every campaign file ever written (``tests/test_campaign_layout.py`` pins them).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields

NAN = math.nan
CURVE_KEYS = ("d_tilde", "F_tilde", "contact_fraction", "n_pillars_in_contact")
#: curve arrays stored only where the job has them (a compliant machine's ``d_machine_tilde``)
OPTIONAL_CURVE_KEYS = ("d_machine_tilde",)
BRANCHES = ("loading", "unloading")


def _field(default, doc: str, *, column: bool = True, curve: bool = False):
    return field(default=default, metadata={"doc": doc, "column": column, "curve": curve})


@dataclass
class JobRecord:
    """One finished (done or failed) job of a campaign.

    Every field is dimensionless (see the file's ``definitions`` attribute). ``wall_s`` and the
    solver counts belong to the ``simulate`` call that computed the job and are shared by the
    ``group_size`` jobs of that loading path.
    """

    key: str = _field("", "job key (see the file's key_definition)")
    k_tilde: float = _field(NAN, "pillar stiffness k~")
    sigma_tilde: float = _field(NAN, "height spread sigma~")
    preload_kind: str = _field("", "F_P or d_tilde: how the preload is given")
    preload: float = _field(NAN, "the preload of this job")
    seed: int = _field(0, "seed of the pillar heights")
    status: str = _field("failed", "done or failed")
    message: str = _field("", "why it failed (empty when done)")
    F_P: float = _field(NAN, "force at the end of loading, / F_c")
    F_A: float = _field(NAN, "pull-off force, / F_c")
    d_tilde_max: float = _field(NAN, "approach at the end of loading")
    d_tilde_at_F_A: float = _field(NAN, "approach at pull-off")
    n_pillars_in_contact_max: int = _field(0, "most pillars in contact")
    events: int = _field(0, "attach/detach events of the path")
    wall_s: float = _field(NAN, "wall time of the simulate call")
    cg_iterations: int = _field(0, "CG iterations of the simulate call")
    cg_solves: int = _field(0, "CG solves of the simulate call")
    fft_pairs: int = _field(0, "FFT pairs of the simulate call")
    group_size: int = _field(1, "jobs computed by that simulate call")
    rank: int = _field(0, "MPI rank that computed it")
    host: str = _field("", "host that computed it")
    finished: str = _field("", "UTC time it finished")
    record_id: str = _field("", "unique id of this record (a rerun gets a new one)")
    campaign_hash: str = _field("", "the grid it was computed for", column=False)
    scene_yaml: str = _field("", "the resolved single-preload scene", column=False)
    discretisation: str = _field("{}", "JSON of the discretisation", column=False)
    loading: dict | None = _field(None, "curve to the preload", column=False, curve=True)
    unloading: dict | None = _field(None, "curve to pull-off", column=False, curve=True)
    k_machine: float | None = _field(None, "machine stiffness k~_m (missing: inf, rigid)")
    jumps: int | None = _field(None, "plate jumps of the unloading branch (compliant machine)")
    F_jump: float | None = _field(None, "tension at the jump-off of the final separation, / F_c "
                                        "(compliant machine)")
    d_machine_tilde_at_F_A: float | None = _field(None, "machine displacement Delta~ at pull-off "
                                                        "(compliant machine)")
    confirmed_local: int | None = _field(None, "relaxations of the simulate call kept on their "
                                               "certified force bound (solver.confirm: local)")
    confirmed_global: int | None = _field(None, "relaxations of the simulate call ended by a "
                                                "global solve (solver.confirm: local)")
    force_bound_tilde: float | None = _field(None, "largest certified force bound of the "
                                                   "simulate call, / F_c (solver.confirm: local)")

    def to_dict(self) -> dict:
        """The plain dict stored in the journal and HDF5 (``type: job`` marks a job record)."""
        return {"type": "job", **{k: getattr(self, k) for k in FIELD_NAMES}}

    @classmethod
    def from_dict(cls, d: dict) -> JobRecord:
        """A record from a stored dict (unknown keys, e.g. ``type``, are ignored)."""
        return cls(**{k: d[k] for k in FIELD_NAMES if k in d})


FIELD_NAMES = tuple(f.name for f in fields(JobRecord))
#: HDF5 attributes of ``/jobs/<key>``
SCALAR_KEYS = tuple(f.name for f in fields(JobRecord) if not f.metadata["curve"])
#: the table of :func:`~fibril_hpc.campaign.analysis.data.load_campaign` and the CSV header
COLUMNS = tuple(f.name for f in fields(JobRecord) if f.metadata["column"])
#: the Python type of each HDF5 attribute of ``/jobs/<key>`` (float, int or str): what a reader
#: accepts (an int where a float is due is taken; anything else is a layout violation)
ATTR_TYPES = {f.name: {"float": float, "int": int, "str": str}[str(f.type).removesuffix(" | None")]
              for f in fields(JobRecord) if not f.metadata["curve"]}
#: the dtype kinds of the curve arrays (h5check kinds: "f" float, "iu" integer)
CURVE_KINDS = {"d_tilde": "f", "F_tilde": "f", "contact_fraction": "f",
               "n_pillars_in_contact": "iu", "d_machine_tilde": "f"}


#: attributes every record has (a group without them is not a job record)
REQUIRED = ("key", "status", "k_tilde", "sigma_tilde", "preload_kind", "preload", "seed",
            "record_id")
STATUSES = ("done", "failed")


def layout_problem(rec: dict) -> str:
    """What in the record ``rec`` (read from HDF5 or a journal frame) is not the layout's: a
    missing required field, a field of the wrong type, curves that are not 1-D arrays of the
    layout's dtypes and one length ("" when it is the layout)."""
    import numpy as np

    for k in REQUIRED:
        if rec.get(k) is None:
            return f"no {k}"
    for k, t in ATTR_TYPES.items():
        v = rec.get(k)
        if v is None:
            continue
        ok = (isinstance(v, str) if t is str else
              isinstance(v, (int, float)) and not isinstance(v, bool) if t is float else
              isinstance(v, int) and not isinstance(v, bool))
        if not ok:
            return f"{k} is a {type(v).__name__}, not a {t.__name__}"
    if rec["status"] not in STATUSES:
        return f"status {rec['status'][:20]!r} is not done or failed"
    for branch in BRANCHES:
        c = rec.get(branch)
        if c is None:
            continue
        if not isinstance(c, dict) or not set(CURVE_KEYS) <= set(c):
            return f"{branch} lacks a curve array"
        lengths = set()
        for name, a in c.items():
            kinds = CURVE_KINDS.get(name)
            if kinds is None:
                return f"{branch}/{name} is not a curve of the layout"
            if not isinstance(a, np.ndarray) or a.ndim != 1 or a.dtype.kind not in kinds:
                return f"{branch}/{name} is not a 1-D array of the layout's dtype"
            lengths.add(len(a))
        if len(lengths) != 1:
            return f"{branch} curves of different lengths"
    return ""


def curve_dict(c) -> dict | None:
    """The stored form of a :class:`~fibril_hpc.io.results.Curve` (None stays None): the
    :data:`CURVE_KEYS`, plus each of :data:`OPTIONAL_CURVE_KEYS` the curve has."""
    if c is None:
        return None
    out = {k: getattr(c, k) for k in CURVE_KEYS}
    out.update({k: getattr(c, k) for k in OPTIONAL_CURVE_KEYS if getattr(c, k) is not None})
    return out


__all__ = ["JobRecord", "SCALAR_KEYS", "ATTR_TYPES", "CURVE_KINDS",
           "REQUIRED", "layout_problem", "CURVE_KEYS", "OPTIONAL_CURVE_KEYS", "COLUMNS", "BRANCHES",
           "FIELD_NAMES", "curve_dict"]
