"""The records of a load path: its curve points, the snapshots preloads branch from, and the
result of one unloading branch (plain data; :mod:`.loading` fills them)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass
class CurveRecorder:
    """Points (d, F, contact elements, pillars in contact) in internal units."""

    d: list = field(default_factory=list)
    F: list = field(default_factory=list)
    n_attached: list = field(default_factory=list)
    n_pillars: list = field(default_factory=list)

    def add(self, d, F, n_att, n_pil):
        """Append one point."""
        self.d.append(d)
        self.F.append(F)
        self.n_attached.append(n_att)
        self.n_pillars.append(n_pil)

    def arrays(self):
        """(d, F, contact elements, pillars in contact) as arrays."""
        return (np.asarray(self.d, float), np.asarray(self.F, float),
                np.asarray(self.n_attached, np.int64), np.asarray(self.n_pillars, np.int64))


@dataclass
class Snapshot:
    """A consistent state with its direction (enough to resume the path without a solve)."""

    d: float
    p: np.ndarray
    u: np.ndarray
    att: np.ndarray
    p1: np.ndarray
    u1: np.ndarray
    n_points: int           # loading-curve points recorded before this state
    point: tuple            # (d, F, attached elements, pillars in contact) of this state
    #: the pressure of the state field's last exact product (far_field: multipole: u is exact
    #: only for it, held by Ka for the rest; None: u is exact)
    p0: np.ndarray | None = None


@dataclass
class BranchResult:
    """Unloading branch from one preload."""

    curve: CurveRecorder
    F_min: float
    d_at_F_min: float
    f_at_min: np.ndarray        # per-group tip force at the force minimum
    p_at_min: np.ndarray
    att_at_min: np.ndarray
    let_go_d: np.ndarray        # last d at which each group lost its last attached element
    #                             (nan: never attached)
    events: int


__all__ = ["CurveRecorder", "Snapshot", "BranchResult"]
