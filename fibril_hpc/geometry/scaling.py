"""Every normalisation factor in one place (docs/model.md §2, §5).

Internal units: E* = 1, L = 1 (side of the nominal square A0), and the work of adhesion
``work_of_adhesion`` (default 1). All inputs and outputs of the package are dimensionless:

    a0 = sqrt(A0/pi),  F_c = sqrt(8 pi phi E* dgamma a0^3),  d_c = sqrt(2 pi phi dgamma a0 / E*)
    F~ = F/F_c,  d~ = d/d_c,  sigma~ = sigma/d_c,  k~ = k/(E* L)

with phi the *discrete* filling ratio (pillar elements x h^2 / A0). The Pohrt-Popov critical
stress of an element of side h is sigma_c = sqrt(E* dgamma / (kappa h)), kappa = 0.473201.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

#: kappa = (2/(3 pi)) [3 ln(1+sqrt 2) + 1 - sqrt 2]  (Pohrt & Popov 2015)
KAPPA = (2.0 / (3.0 * math.pi)) * (3.0 * math.log(1.0 + math.sqrt(2.0)) + 1.0 - math.sqrt(2.0))

E_STAR = 1.0
LENGTH = 1.0


def critical_stress(h: float, work_of_adhesion: float, e_star: float = E_STAR) -> float:
    """Mesh-dependent detachment stress sigma_c = sqrt(E* dgamma/(kappa h))."""
    return math.sqrt(e_star * work_of_adhesion / (KAPPA * h))


@dataclass(frozen=True)
class Scaling:
    """Normalisation of one discretised scene.

    Parameters
    ----------
    phi : float
        Filling ratio used for normalisation (the discrete one).
    work_of_adhesion : float
        dgamma in internal units.
    area : float
        Nominal area A0 (internal units; L**2 = 1 for brushes).
    """

    phi: float
    work_of_adhesion: float
    area: float = LENGTH * LENGTH

    @property
    def a0(self) -> float:
        """Radius of the disc of area A0: sqrt(A0/pi)."""
        return math.sqrt(self.area / math.pi)

    @property
    def F_c(self) -> float:
        """Force unit: Kendall's pull-off of a compact punch of area A0 with phi dgamma."""
        return math.sqrt(8 * math.pi * self.phi * E_STAR * self.work_of_adhesion * self.a0**3)

    @property
    def d_c(self) -> float:
        """Displacement unit (with F_c; docs/model.md §2)."""
        return math.sqrt(2 * math.pi * self.phi * self.work_of_adhesion * self.a0 / E_STAR)

    def k(self, k_tilde: float) -> float:
        """Dimensional spring stiffness from k~ (k~ = k/(E* L))."""
        return k_tilde * E_STAR * math.sqrt(self.area)

    def definitions(self) -> dict:
        """Human-readable definitions, stored in every output file."""
        return {
            "units": "E* = 1, L = 1 (side of the nominal square A0), dgamma = work_of_adhesion",
            "a0": "sqrt(A0/pi)",
            "F_c": "sqrt(8 pi phi_discrete E* dgamma a0^3): Kendall pull-off of a compact punch "
                   "of area A0 with dgamma -> phi dgamma; F_tilde = F/F_c",
            "d_c": "sqrt(2 pi phi_discrete dgamma a0 / E*); d_tilde = d/d_c, sigma_tilde = sigma/d_c",
            "k_tilde": "k/(E* L)",
            "sigma_c": "sqrt(E* dgamma/(kappa h)), kappa = 0.473201 (Pohrt & Popov 2015)",
            "sign": "F > 0 compression, F < 0 tension; d > 0 presses the brush in; d = 0 when the "
                    "longest pillar first touches",
        }
