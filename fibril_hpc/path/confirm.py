"""Certified shortcuts of a load path (:class:`~fibril_hpc.path.loading.PathDriver` inherits
these methods), on the force bound of :mod:`fibril_hpc.solve.certify`:

* ``solver.confirm: local``: a local fixed point of the cascade ends a relaxation, and a locally
  solved direction is kept, when their force error bound is within ``confirm_tol``, instead of a
  global solve to full tolerance.
* ``solver.far_field: multipole``: the state that ends a relaxation is kept on its held field
  when its force error bound is within ``confirm_tol``; else the field is made exact first.
"""

from __future__ import annotations

import math

import numpy as np

from ..kernels import compiled as kern


class ConfirmMixin:
    """The certificate's decisions of a :class:`PathDriver` (which provides the state arrays,
    ``certificate``, ``solve_direction``, ``next_event`` and the field helpers)."""

    def _confirm_locally(self) -> bool:
        """``confirm: local``: end the relaxation at the local fixed point, without a global
        solve, if the update rule flips nothing on the whole grid (u made exact)
        and the force bound (:mod:`fibril_hpc.solve.certify`, with the direction solved here
        on the set) is within ``confirm_tol``; else the caller's global solve follows."""
        self._exact_field(self.p, self.p_ref, self.u)
        self._forces(self.p, self.f)
        self._gaps(self.u, self.f, self.d, 1.0, self.g)
        m = self.model
        if kern.update_contact_set(self.p.copy(), self.g, self.att.copy(), self.starts, m.sigma_c,
                                   self.tol_p, self.tol_g, self.worst_only) != (0, 0):
            return False
        self.solve_direction()
        cert = self.certificate
        self._fresh_direction = cert.accept(cert.bound(self.att, self._b, self.p, self.u,
                                                       self.p1, self.u1, self._ones))
        if self._fresh_direction:
            self.att_ref[:] = self.att
        return self._fresh_direction

    #: whether a direction may be kept on its certified bound (a path that moves one way to its
    #: next event; a compliant machine's jumps go either way and solve to full tolerance)
    LOCAL_DIRECTION = True

    def _direction_locally(self) -> bool:
        """``confirm: local``: keep the locally solved direction, without a global solve, if
        its certified force-slope error times the distance to the next event is within
        ``confirm_tol`` (:mod:`fibril_hpc.solve.certify`; u1 made exact first)."""
        if not self.LOCAL_DIRECTION:
            return False
        self._exact_field(self.p1, self.p1_ref, self.u1)
        self._forces(self.p1, self.f1)
        self._gaps(self.u1, self.f1, 1.0, 0.0, self.g1)
        reach = self.next_event(1.0 if self.phase == "loading" else -1.0)
        return self.certificate.accept_direction(self.att, self.p1, self.u1, self._ones, reach)

    def _held_certified(self) -> bool:
        """``far_field: multipole``: whether the state that ends a relaxation is kept on its held
        field. Its error e = (K - Ka)(p - p0) enters the force through p1 . e = w . (p - p0),
        w = (K - Ka) p1 = u1 - Ka p1 (K and Ka symmetric; u1 exact), and |e| on the set is at
        most the pillar bound of :meth:`~fibril_hpc.solve.farfield.MultipoleField.pillar_bound`:
        kept where the certified force bound (:meth:`ForceCertificate.held_bound`) is within
        ``confirm_tol``; else the field is made exact by the next solve (the caller goes on).
        A state still above it after two refreshes in one relaxation is kept and counted
        (``held_uncertified``; never seen in the measurements of benchmarks/NOTES.md)."""
        op, check = self.model.operator, self.held_check
        self.solve_direction()          # exact, on this set: the caller's (fresh below)
        op.apply_increment(self.p1, self._w)
        np.subtract(self.u1, self._w, out=self._w)
        change = self.p - self.p0
        shift = float(self._w @ change)
        ng = self.model.geometry.n_groups
        bound = op.pillar_bound(np.linalg.norm(change.reshape(ng, -1), axis=1))
        self.pillars_in_contact()       # counts per pillar of the set
        e_norm = float(np.linalg.norm(bound[self.counts > 0]))
        value = check.held_bound(self.att, self._b, self.p, self.u, self.p1, self.u1,
                                 self._ones, shift, e_norm)
        if check.accept(value):
            self._held_refreshes = 0
            self._fresh_direction = True
            # the recorded points up to the next event follow the direction: its slope bound
            # times that distance adds to theirs (reported, as under confirm: local)
            reach = self.next_event(1.0 if self.phase == "loading" else -1.0)
            if math.isfinite(reach):
                check.direction_worst = max(check.direction_worst, reach * check.slope_bound(
                    self.att, self.p1, self.u1, self._ones))
            return True
        if self._held_refreshes >= 2:
            self.held_uncertified += 1
            check.worst = max(check.worst, value)
            self._held_refreshes = 0
            self._fresh_direction = True
            return True
        self._held_refreshes += 1
        self._fresh_direction = False
        self._since_full = self.model.operator.refresh_every      # refresh at the next solve
        return False

    def _exact_field(self, x, x_ref, u):
        """u <- K x exactly (``confirm: local``, before a bound): direct sums of x - x_ref
        where cheaper than an FFT pair, else one pair (which also refreshes u); x_ref <- x."""
        idx = np.flatnonzero(x != x_ref)
        if self._since_full < self.model.operator.refresh_every and \
                self.model.operator.add_point_loads(u, idx, x[idx] - x_ref[idx]):
            self._since_full += 1
        else:
            self.model.operator.apply(x, u)
            self._since_full = 0
        x_ref[:] = x


__all__ = ["ConfirmMixin"]
