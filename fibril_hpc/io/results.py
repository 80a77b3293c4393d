"""Results of a simulation: normalised curves, per-preload outcomes, provenance.

Normalisation (see :mod:`fibril_hpc.geometry.scaling`): d~ = d/d_c, F~ = F/F_c with the discrete filling
ratio; ``contact_fraction`` is the attached area over the total pillar-tip area; pressures in maps
are p A0 / F_c (nominal-pressure units); per-pillar forces f_n / F_c and spring elongations
Delta l_n / d_c.
"""

from __future__ import annotations

import math
import platform
import sys
from dataclasses import dataclass, field

import numpy as np

from .._version import __version__
from ..elastic.fft import FFTPair
from ..geometry.grid import RNG_NAME
from ..inputs.scene import Scene

STATUS_OK = "ok"
STATUS_FAILED = "failed"


@dataclass
class Curve:
    """One branch of a force-displacement curve, exact at its points and affine between them."""

    d_tilde: np.ndarray
    F_tilde: np.ndarray
    contact_fraction: np.ndarray
    n_pillars_in_contact: np.ndarray
    #: machine-end displacement Delta/d_c of a compliant machine (None: displacement control)
    d_machine_tilde: np.ndarray | None = None

    def __len__(self):
        return len(self.d_tilde)

    def reversed(self) -> Curve:
        """The same points in the opposite order (copies)."""
        return Curve(self.d_tilde[::-1].copy(), self.F_tilde[::-1].copy(),
                     self.contact_fraction[::-1].copy(), self.n_pillars_in_contact[::-1].copy(),
                     None if self.d_machine_tilde is None else self.d_machine_tilde[::-1].copy())


@dataclass
class PillarState:
    """Per-pillar quantities at one state (normalised)."""

    force: np.ndarray           # f_n / F_c
    elongation: np.ndarray      # Delta l_n / d_c (0 for rigid pillars)
    contact_map: np.ndarray     # uint8 N x N, 1 where attached
    pressure_map: np.ndarray    # float32 N x N, p A0 / F_c
    d_tilde: float


@dataclass
class PreloadResult:
    """Outcome of one preload: load to it, then pull off until complete detachment."""

    preload_kind: str           # "d_tilde" or "F_P"
    preload: float              # the requested value
    status: str
    message: str = ""
    F_P: float = math.nan
    d_tilde_max: float = math.nan
    F_A: float = math.nan
    d_tilde_at_F_A: float = math.nan
    n_pillars_in_contact_max: int = 0
    events: int = 0
    jumps: int | None = None    # plate jumps of the unloading branch (None: rigid machine)
    F_jump: float | None = None  # force at the jump-off of the final separation, / F_c (tension
    #                              > 0; None: rigid machine, where it is the last event's force)
    d_machine_tilde_at_F_A: float | None = None  # machine displacement Delta~ at pull-off (None:
    #                                              rigid machine, where it is d_tilde_at_F_A)
    loading: Curve | None = None
    unloading: Curve | None = None
    at_preload: PillarState | None = None
    at_pulloff: PillarState | None = None
    let_go_d_tilde: np.ndarray | None = None   # d~ at which each pillar let go (nan: never touched)

    def summary(self) -> dict:
        """The scalar outcome as a plain dict (the HDF5 attributes of a preload)."""
        return {
            "preload_kind": self.preload_kind,
            "preload": self.preload,
            "status": self.status,
            "message": self.message,
            "F_P": self.F_P,
            "F_A": self.F_A,
            "d_tilde_max": self.d_tilde_max,
            "d_tilde_at_F_A": self.d_tilde_at_F_A,
            "n_pillars_in_contact_max": self.n_pillars_in_contact_max,
            "events": self.events,
            **({} if self.jumps is None else {"jumps": self.jumps, "F_jump": self.F_jump,
                                              "d_machine_tilde_at_F_A":
                                                  self.d_machine_tilde_at_F_A}),
        }


@dataclass
class SimulationResult:
    """Everything :func:`fibril_hpc.simulate` returns."""

    scene: Scene
    status: str
    message: str
    results: list = field(default_factory=list)          # PreloadResult, ascending preload
    discretisation: dict = field(default_factory=dict)
    xi: np.ndarray | None = None                          # standard normal draw per pillar
    zeta_tilde: np.ndarray | None = None                  # set-back per pillar / d_c
    stats: dict = field(default_factory=dict)
    versions: dict = field(default_factory=dict)
    definitions: dict = field(default_factory=dict)
    #: SI value of every unit (:meth:`fibril_hpc.inputs.physical.Units.si`) when the scene was
    #: given in physical units, else empty
    units: dict = field(default_factory=dict)

    @property
    def main(self) -> PreloadResult | None:
        """The largest preload's result (the one summarised at top level)."""
        return self.results[-1] if self.results else None

    def summary(self) -> dict:
        """The JSON object of ``fibril-run --json``."""
        main = self.main
        out = {
            "status": self.status,
            "message": self.message,
            "F_P": main.F_P if main else math.nan,
            "F_A": main.F_A if main else math.nan,
            "d_tilde_max": main.d_tilde_max if main else math.nan,
            "n_pillars_in_contact_max": main.n_pillars_in_contact_max if main else 0,
            "phi_discrete": self.discretisation.get("phi_discrete"),
            "n_elements": self.discretisation.get("n_elements"),
        }
        out.update(self.stats)
        out["results"] = [r.summary() for r in self.results]
        if self.units:
            out.update(si_summary(out, self.units))
            for r in out["results"]:
                r.update(si_summary(r, self.units))
            out["units"] = self.units
        out["discretisation"] = self.discretisation
        out["scene"] = self.scene.to_dict()
        out["versions"] = self.versions
        return json_safe(out)


#: SI columns of a result in physical units: name -> (normalised name, unit scale, SI unit)
SI_FIELDS = {"F_P_N": ("F_P", "F_c", "N"), "F_A_N": ("F_A", "F_c", "N"),
             "d_max_m": ("d_tilde_max", "d_c", "m"), "d_at_F_A_m": ("d_tilde_at_F_A", "d_c", "m")}


def si_summary(values: dict, units: dict) -> dict:
    """The SI values (:data:`SI_FIELDS`) of a summary's normalised ``values``."""
    return {name: float(values[src]) * units[scale]
            for name, (src, scale, _) in SI_FIELDS.items() if src in values}


def json_safe(obj):
    """Replace non-finite floats by strings ("inf", "-inf", "nan") and numpy scalars by Python."""
    if isinstance(obj, dict):
        return {k: json_safe(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [json_safe(v) for v in obj]
    if isinstance(obj, (np.integer,)):
        return int(obj)
    if isinstance(obj, (float, np.floating)):
        v = float(obj)
        if math.isfinite(v):
            return v
        return "nan" if math.isnan(v) else ("inf" if v > 0 else "-inf")
    return obj


def software_versions() -> dict:
    """Versions of everything that determines a result, stored in every output."""
    import numba

    out = {"fibril_hpc": __version__, "python": platform.python_version(),
           "numpy": np.__version__, "numba": numba.__version__}
    out.update(FFTPair.library_versions())
    try:
        import h5py

        out["h5py"] = h5py.__version__
        out["hdf5"] = h5py.version.hdf5_version
    except ImportError:  # pragma: no cover
        out["h5py"] = ""
    out["rng"] = RNG_NAME
    out["platform"] = sys.platform
    return out
