"""A compliant loading machine: the machine's end is driven, the plate follows (docs/model.md §6, §9).

The load train between the driven end (displacement Delta) and the backing plate (displacement d)
is a spring of stiffness k_m, so in equilibrium the plate force is F = k_m (Delta - d) and

    Delta = d + F / k_m.

On a fixed contact set the brush is affine, F = F0 + F1 (d - d0) with F1 = dF/dd > 0, so while the
machine is driven the plate moves with it, dDelta/dd = 1 + F1/k_m > 0, through exactly the states of
the displacement-controlled path. An event (a batch of elements flipping, then relaxed at fixed d)
changes F at fixed d; the machine end does not move back, so when the new state would need Delta to
move against the drive (sgn (Delta' - Delta) < 0: on unloading, the force rises towards zero as a
detachment releases tension), the state is not an equilibrium of the machine and the plate
**jumps** at fixed Delta: on the new set the machine's equilibrium is

    d* = d + (k_m (Delta - d) - F) / (F1 + k_m),

the plate moves towards it on the affine path (either way: an event may overshoot); an event on
the way (detachment or attachment) is flipped and relaxed at its d and the move goes on from
there, until a set's d* is reached before its next event. The landing is recorded: every point of
the curve is an equilibrium of the machine, Delta~ is stored beside d~ (``d_machine_tilde``), and a
jump shows as two consecutive points with one machine displacement. With no pillar attached the
plate lands on Delta (F = 0). Force control is the limit k_m -> 0 (k_m = 0 itself is not
allowed: the plate would have no position after full detachment). ``k_machine = inf`` uses the
plain :class:`~fibril_hpc.path.loading.PathDriver` and costs nothing.

What changes and what does not: the states the plate passes through are those of the
displacement-controlled path (a jump walks through them at fixed Delta), and during a jump the
force stays above the jump-off force. So the peak tension F_A = -min F, always reached at a
jump-off, does not depend on k_m; what does is where the plate leaves the surface: ``F_jump``,
the tension at the jump-off of the final separation (for a JKR sphere 5/6 pi R w under a rigid
machine, 3/2 pi R w = F_A under force control; for a flat punch F_A under any machine, Kendall),
and which states are skipped.

Preloads are reached along the machine's path: ``d_tilde`` targets are plate displacements, F_P
targets forces; a target passed inside a jump is taken at the landing.
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import NoConvergenceError
from ..kernels import compiled as kern
from .loading import PathDriver

_MAX_JUMP_EVENTS = 1_000_000


class MachineDriver(PathDriver):
    """A :class:`PathDriver` behind a load train of stiffness ``k_machine`` (internal units)."""

    #: a jump moves either way from a direction: directions are solved globally
    LOCAL_DIRECTION = False

    def __init__(self, model, k_machine: float):
        super().__init__(model)
        if not (k_machine > 0 and math.isfinite(k_machine)):
            raise ValueError("k_machine must be finite and > 0 (inf: use PathDriver)")
        self.k_machine = float(k_machine)
        self.jumps = 0              # jumps of the plate along every path of this driver
        self.jump_events = 0        # events met inside jumps

    def machine_position(self) -> float:
        """Delta = d + F/k_m of the current state."""
        return self.d + self.force() / self.k_machine

    def anchor(self) -> float:
        """The machine position before an event (held if the plate jumps)."""
        return self.machine_position()

    def settle(self, sgn: float, anchor: float) -> bool:
        """Jump to the machine's equilibrium at ``Delta = anchor`` if the relaxed state needs the
        machine to move back; returns whether the direction is solved at the end state."""
        if sgn * (self.machine_position() - anchor) >= 0.0:
            return False                          # the drive carries on through this event
        self.jumps += 1
        km = self.k_machine
        hair = 1e-12 * self.model.scaling.d_c
        for _ in range(_MAX_JUMP_EVENTS):
            self.solve_direction()
            F1 = float(self.f1.sum())
            dd = (km * (anchor - self.d) - self.force()) / (F1 + km)
            if dd == 0.0:
                return True
            s = 1.0 if dd > 0 else -1.0         # an event on the way may overshoot: either way
            dist = self.next_event(s)
            if dist >= abs(dd):
                self.move(abs(dd), s)
                return True
            self.move(dist, s)
            if kern.flip_events(self.p, self.p1, self.g, self.g1, self.att, self.model.sigma_c,
                                s, hair + 1e-12 * abs(dist)) == (0, 0):
                raise NoConvergenceError(f"no element flipped at an event of a jump "
                                         f"(d = {self.d:.6g})")
            self._count_event()
            self.jump_events += 1
            self.relax()
        raise NoConvergenceError("a jump of the plate did not land")


def make_driver(model, k_machine_tilde: float) -> PathDriver:
    """The load-path driver of a scene: :class:`PathDriver` for a rigid machine (``inf``), else
    a :class:`MachineDriver` with k_m = k_machine~ E* L."""
    if math.isinf(k_machine_tilde):
        return PathDriver(model)
    return MachineDriver(model, model.scaling.k(k_machine_tilde))


def machine_displacement(d_tilde, F_tilde, k_machine_tilde: float, scaling) -> np.ndarray:
    """Delta~ = d~ + F~ F_c / (k_m d_c) of recorded (machine-equilibrium) points."""
    km = scaling.k(k_machine_tilde)
    return np.asarray(d_tilde) + np.asarray(F_tilde) * (scaling.F_c / (km * scaling.d_c))


__all__ = ["MachineDriver", "make_driver", "machine_displacement"]
