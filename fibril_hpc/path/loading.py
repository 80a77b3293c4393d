"""Displacement-controlled loading to the preload(s), then pull-off until complete detachment.

The driver is event-driven (docs/model.md §6): on a fixed attached set S the solution is affine in the
plate displacement d, p(d) = p + (d - d0) p1 with A p1 = 1_S, and so are the tip forces and the
gaps of free elements. From a consistent state the driver therefore

1. solves once for the direction p1 (and u1 = K p1, f1, g1) on the current set,
2. finds exactly the next event along the path: an attached element reaching p = -sigma_c, or a
   free element's gap closing (or the target: a preload d or force F_P),
3. moves there without solving, records the pre-event point (exact: this is where the force
   minimum of a segment lies), flips the element(s) whose events fall within ``event_merge``
   (``load_event_merge`` while loading) as one batch,
4. relaxes at that d: solve on the new set, detach every supercritical element and attach every
   penetrating one (the reference policy), repeat until the set stops changing,
5. records the post-event point and goes back to 1.

The recorded curve is therefore the exact piecewise-affine path (to the CG tolerance), with
vertical jumps at events, and F_A = -min F is located without blind stepping. The loading path
does not depend on where it stops: all preloads of a scene are snapshots of one loading path, and
each unloading branch starts from its snapshot (with its direction already solved).
"""

from __future__ import annotations

import math
import time

import numpy as np

from ..errors import NoConvergenceError
from ..kernels import compiled as kern
from ..solve.cascade import LocalCascade
from ..solve.certify import ForceCertificate
from .confirm import ConfirmMixin
from .records import BranchResult, CurveRecorder, Snapshot
from .snapshots import SnapshotMixin

_MAX_RELAX_PASSES = 100_000


class PathDriver(SnapshotMixin, ConfirmMixin):
    """Owns the mutable state of one load path on a :class:`~fibril_hpc.model.Model`."""

    def work_arrays(self) -> dict:
        """The state and work vectors this driver owns, by name (for read-only use, e.g. memory
        accounting); arrays shared with the geometry are not included."""
        shared = {id(a) for a in vars(self.model.geometry).values() if isinstance(a, np.ndarray)}
        return {k: v for k, v in vars(self).items()
                if isinstance(v, np.ndarray) and id(v) not in shared}

    def __init__(self, model):
        self.model = model
        g = model.geometry
        self.starts = g.starts
        self.z0 = g.z0
        self.h2 = g.h * g.h
        self.inv_k = 0.0 if model.rigid else 1.0 / model.k
        n, ng = g.n_active, g.n_groups
        self.d = 0.0
        self.p = np.zeros(n)
        self.u = np.zeros(n)
        self.att = np.zeros(n, dtype=np.uint8)
        self.g = np.zeros(n)
        self.f = np.zeros(ng)
        self.p1 = np.zeros(n)
        self.u1 = np.zeros(n)
        self.g1 = np.zeros(n)
        self.f1 = np.zeros(ng)
        self.counts = np.zeros(ng, dtype=np.int64)
        # u = K p_ref and u1 = K p1_ref hold exactly; p, p1 differ from them only where elements
        # flipped since, which a direct sum corrects (no FFT) before the next solve
        self.p_ref = np.zeros(n)
        self.p1_ref = np.zeros(n)
        # far_field: multipole: u = K p0 + Ka (p - p0), p0 the pressure of the last exact
        # product of the state's field (moved along exactly with the direction)
        self.p0 = np.zeros(n)
        self._w = np.zeros(n)
        # attached sets of the last solve for p and for p1 (the local path re-solves, before a
        # global solve, the groups whose set changed since)
        self.att_ref = np.zeros(n, dtype=np.uint8)
        self.att1_ref = np.zeros(n, dtype=np.uint8)
        self.group_of = np.repeat(np.arange(ng), np.diff(self.starts))
        self._since_full = 0
        self._since_full1 = 0
        self._b = np.empty(n)
        self._ones = np.ones(n)
        self._dl = np.zeros(ng)
        self.events = 0
        #: called as ``observer(phase, d, F, events, pillars)`` after every recorded point
        #: (internal units; ``phase`` is "loading" or "unloading"; ``pillars``: the pillars in
        #: contact), or None: a progress display's hook
        self.observer = None
        self.phase = "loading"
        opts = model.options
        d_c = model.scaling.d_c
        self.merge = {-1.0: opts.event_merge * d_c,
                      +1.0: min(opts.load_event_merge * d_c,
                                opts.load_merge_spread * g.length_spread())}
        self.tol_p = 1e3 * opts.cg_tol * (model.sigma_c if model.adhesion else 1.0)
        self.tol_g = 1e3 * opts.cg_tol * d_c
        self.tol_dir = opts.direction_tolerance
        self.worst_only = opts.detach_policy == "worst"
        # not under far_field: multipole, whose global solves cost no element-grid FFT
        self.local = (LocalCascade(model) if opts.cascade == "local" and opts.far_field == "exact"
                      else None)
        #: ``confirm: local``: the force bound that lets a local fixed point end a relaxation
        self.certificate = (ForceCertificate(g, model.operator, model.solver.alpha,
                                             opts.confirm_tol * model.scaling.F_c)
                            if opts.confirm == "local" else None)
        #: ``far_field: multipole``: the force bound of a held state (path/confirm.py), which
        #: asks for an exact product where it exceeds ``confirm_tol`` (not on a compliant
        #: machine's path)
        self.held_check = (ForceCertificate(g, model.operator.exact, model.solver.alpha,
                                            opts.confirm_tol * model.scaling.F_c)
                           if opts.far_field == "multipole" and self.LOCAL_DIRECTION else None)
        self.held_uncertified = 0   # states kept above that bound (after two refreshes)
        self._held_refreshes = 0
        self._fresh_direction = False
        self.relaxations = 0        # calls of relax(): events, preload snapshots, solve_at
        self.deadline = (math.inf if opts.max_wall_s is None
                         else time.monotonic() + opts.max_wall_s)

    # -- derived quantities ---------------------------------------------------------------
    def _forces(self, p, out):
        kern.group_sums(p, self.att, self.starts, out)
        out *= self.h2

    def _gaps(self, u, f, d, zcoef, out):
        np.multiply(f, self.inv_k, out=self._dl)
        kern.gaps(u, self.starts, self.z0, zcoef, d, self._dl, out)

    def force(self) -> float:
        """Total force on the plate (internal units; > 0 compression)."""
        return float(self.f.sum())

    def n_attached(self) -> int:
        """Number of attached elements."""
        return int(np.count_nonzero(self.att))

    def pillars_in_contact(self) -> int:
        """Number of pillars with at least one attached element."""
        kern.group_counts(self.att, self.starts, self.counts)
        return int(np.count_nonzero(self.counts))

    def record(self, curve: CurveRecorder):
        """Append the current state to ``curve`` (and tell the observer, if any)."""
        F = self.force()
        pillars = self.pillars_in_contact()
        curve.add(self.d, F, self.n_attached(), pillars)
        if self.observer is not None:
            self.observer(self.phase, self.d, F, self.events, pillars)

    # -- solves -----------------------------------------------------------------------------
    def relax(self):
        """Solve at fixed d and update the contact set until it stops changing.

        ``cascade: global`` (the reference): every pass is a global solve. The first pass solves
        at the full ``cg_tol``; once the set changes, the passes in the middle of the cascade
        solve to ``relax_tol`` (looser), a set that is stable at that tolerance is confirmed by a
        solve at ``cg_tol``, and only a set stable at full tolerance ends the relaxation.

        ``cascade: local`` (default): before each global solve the pillars whose set or
        pressure changed since the last solve run their own cascade with exact dense solves and
        the rest of the grid held (:class:`~fibril_hpc.solve.cascade.LocalCascade`); the global solve
        at ``cg_tol`` then confirms, and a new local round starts only on the pillars it
        flips. Where the changed pillars are too many for a dense solve the pass is a global
        one with the reference's tolerances.
        """
        m = self.model
        self.relaxations += 1
        self._held_refreshes = 0        # refreshes the held states' bound asked for here
        np.subtract(self.d, self.z0, out=self._b)
        loose = max(m.options.relax_tol, m.options.cg_tol)
        tight = True
        for _ in range(_MAX_RELAX_PASSES):
            if self.local is not None:
                groups = self._changed_groups(self.p, self.p_ref, self.att_ref)
                if len(groups):
                    out = self.local.cascade(groups, self.d, self._b, self.p, self.p_ref, self.u,
                                             self.g, self.att, m.sigma_c, self.tol_p, self.tol_g,
                                             self.worst_only, m.solver.precond)
                    if out is not None and out[0]:
                        # the set changed: a local fixed point is confirmed at full tolerance
                        # at once; an untrusted proposal is an intermediate (loose) pass
                        tight = out[1] or loose == m.options.cg_tol
                    if out is not None and out[1] and self.certificate is not None \
                            and self._confirm_locally():
                        return
            tol = None if tight else loose
            self._solve(self._b, self.p, self.u, self.p_ref, tol)
            self.att_ref[:] = self.att
            self._forces(self.p, self.f)
            self._gaps(self.u, self.f, self.d, 1.0, self.g)
            nd, na = kern.update_contact_set(self.p, self.g, self.att, self.starts, m.sigma_c,
                                             self.tol_p, self.tol_g, self.worst_only)
            if nd == 0 and na == 0:
                # a set stable at the loose tolerance: confirmed at full tolerance, or on the
                # force bound (confirm: local); a held state (multipole) on its own bound
                if tol is None and self.held_check is not None and not self._held_certified():
                    continue            # the next solve makes the field exact first
                if tol is None or (self.certificate is not None and self._confirm_locally()):
                    return
                tight = True
            elif loose != m.options.cg_tol:
                tight = False
        raise NoConvergenceError(f"contact set did not settle in {_MAX_RELAX_PASSES} passes "
                                 f"at d = {self.d:.6g}")

    def _changed_groups(self, x, x_ref, att_ref):
        """Groups with an element whose value or attachment changed since the last solve."""
        diff = (x != x_ref) | (self.att != att_ref)
        return np.unique(self.group_of[diff])

    def _solve(self, b, x, u, x_ref, tol=None, exact=False) -> int:
        """Solve on the current set, keeping u = K x valid without a full product (one FFT
        pair) until the operator's ``refresh_every`` incrementally kept solves of the field
        (``loading_refresh_every`` while loading).
        ``exact``: iterate with the exact product, u kept exact (under ``far_field:
        multipole`` the direction's solve, whose field then counts on its own)."""
        op = self.model.operator
        name = "_since_full" if op.exact_increments or x_ref is self.p_ref else "_since_full1"
        since = getattr(self, name)
        valid = False
        if exact:
            every = op.exact_refresh_every
        elif self.phase == "loading":
            every = op.loading_refresh_every     # multipole: fewer held solves (farfield.py)
        else:
            every = op.refresh_every
        if since < every:
            idx = np.flatnonzero(x != x_ref)
            valid = op.add_point_loads(u, idx, x[idx] - x_ref[idx], exact=exact)
            if self.held_check is not None and u is self.u and len(idx) <= op.max_direct:
                self.p0[idx] += x[idx] - x_ref[idx]     # a direct sum: exact (multipole)
        setattr(self, name, since + 1 if valid else 0)
        if self.held_check is not None and not valid and u is self.u:
            self.p0[:] = x              # the solver's first product is exact
        its = self.model.solver.solve(self.att, b, x, u, tol, u_valid=valid, exact=exact)
        x_ref[:] = x
        return its

    def solve_direction(self):
        """p1 = A^-1 1_S, u1 = K p1, f1, g1 on the current set, to ``solver.direction_tol``
        (the state itself is relaxed to ``cg_tol`` at every event)."""
        if self._fresh_direction:           # solved on this set by the local confirmation
            self._fresh_direction = False
            return
        self.p1[self.att == 0] = 0.0
        if self.att.any():
            done = False
            if self.local is not None:
                # the set changed on a few pillars since the last direction: solve those
                # directly with the rest held, so the global solve only restores the coupling
                groups = self._changed_groups(self.p1, self.p1_ref, self.att1_ref)
                if len(groups):
                    self.local.solve(groups, self._ones, self.p1, self.p1_ref, self.u1, self.att)
                    done = self.certificate is not None and self._direction_locally()
            if not done:
                # exact under far_field: multipole too (solve/farfield.py says why)
                self._solve(self._ones, self.p1, self.u1, self.p1_ref, self.tol_dir, exact=True)
        else:
            self.u1[:] = 0.0
            self.p1_ref[:] = 0.0
        self.att1_ref[:] = self.att
        self._forces(self.p1, self.f1)
        self._gaps(self.u1, self.f1, 1.0, 0.0, self.g1)

    def move(self, dist: float, sgn: float):
        """Move along the affine path of the current set (no solve)."""
        s = sgn * dist
        if s == 0.0:
            return
        self.d += s
        self.p += s * self.p1
        self.p_ref += s * self.p1_ref
        if self.held_check is not None:
            self.p0 += s * self.p1_ref      # u1 = K p1_ref exactly
        self.u += s * self.u1
        self.f += s * self.f1
        self.g += s * self.g1

    def next_event(self, sgn: float) -> float:
        """Distance in d (direction ``sgn``) to the next contact-set event on the current set."""
        return kern.event_distance(self.p, self.p1, self.g, self.g1, self.att,
                                   self.model.sigma_c, sgn)

    def _count_event(self):
        self.events += 1
        if self.events > self.model.options.max_events:
            raise NoConvergenceError(f"more than {self.model.options.max_events} contact events "
                                     "along one path (solver.max_events)")
        if time.monotonic() > self.deadline:
            raise NoConvergenceError(f"wall-time cap of {self.model.options.max_wall_s:g} s "
                                     "exceeded (solver.max_wall_s)")

    def _step(self, sgn, dist, curve, on_point=None, on_batch=None):
        """Advance through the next batch of events and re-equilibrate.

        Moves to the first event (distance ``dist``) and records that exact pre-event point; the
        events within ``event_merge`` after it form one batch: the path moves on to the last of
        them on the old set, every element whose event has been reached flips (attached ones at
        p <= -sigma_c detach, free ones with a closed gap attach: no attraction across a gap), the
        set is relaxed, the post-event point recorded and the direction re-solved.
        ``on_batch(last)`` is called at the first event with the batch length (preload snapshots
        falling inside the batch are taken off the old set's affine path).
        """
        self.move(dist, sgn)
        self.record(curve)
        if on_point is not None:
            on_point()
        last = kern.last_event_within(self.p, self.p1, self.g, self.g1, self.att,
                                      self.model.sigma_c, sgn, self.merge[sgn])
        if on_batch is not None:
            on_batch(last)
        self.move(last, sgn)
        anchor = None if self.settle is None else self.anchor()
        # elements at their event (to rounding): remaining distance <= a hair
        hair = 1e-12 * self.model.scaling.d_c + 1e-12 * (abs(dist) + last)
        if kern.flip_events(self.p, self.p1, self.g, self.g1, self.att, self.model.sigma_c,
                            sgn, hair) == (0, 0):
            raise NoConvergenceError(f"no element flipped at a located event (d = {self.d:.6g})")
        self._count_event()
        self.relax()
        fresh = False if self.settle is None else self.settle(sgn, anchor)
        self.record(curve)
        if on_point is not None:
            on_point()
        if not fresh:
            self.solve_direction()

    #: hook of a compliant loading machine (:class:`~fibril_hpc.path.machine.MachineDriver`): after an
    #: event's relaxation, ``settle(sgn, anchor) -> bool`` moves the plate to where the machine
    #: holds it (and says whether the direction is solved there); None: displacement control,
    #: nothing to do
    settle = None

    def solve_at(self, d: float) -> None:
        """Equilibrium at plate displacement ``d`` by a plain active-set iteration from no contact
        (attach every penetrating element, solve, detach / attach, repeat): the fixed-d contact
        problem that FFT contact codes solve, without a load path. For frictionless contact it
        is path independent; with adhesion it is the state reached by a sudden indentation."""
        self._reset(d)
        self.att[self.g < 0.0] = 1
        self.relax()

    def _reset(self, d: float) -> None:
        """No contact, no load, at plate displacement d (gaps and direction consistent)."""
        self.d = float(d)
        for a in (self.p, self.u, self.p_ref, self.p1, self.u1, self.p1_ref, self.p0):
            a[:] = 0.0
        self.att[:] = 0
        self.att_ref[:] = 0
        self.att1_ref[:] = 0
        self._since_full = 0
        self._since_full1 = 0
        self._fresh_direction = False
        self.model.solver.precond.set_state(None)
        self._forces(self.p, self.f)
        self._gaps(self.u, self.f, self.d, 1.0, self.g)

    # -- paths ------------------------------------------------------------------------------
    def load(self, targets, kind: str, curve: CurveRecorder) -> list[Snapshot]:
        """Load from no contact through every target (sorted ascending); snapshot at each.

        kind is ``"d"`` (plate displacement, internal units) or ``"F"`` (force, internal units).
        """
        self._reset(0.0)
        self.phase = "loading"
        self.solve_direction()
        self.record(curve)
        snaps = []
        pending = list(targets)

        def distance_to(target):
            if kind == "d":
                dist = target - self.d
            else:
                f1 = float(self.f1.sum())
                dist = (target - self.force()) / f1 if f1 > 0 else math.inf
            # before first contact the path may also be followed backwards (d < 0 preloads)
            return dist if not self.att.any() else max(dist, 0.0)

        def take(reach):
            while pending and distance_to(pending[0]) <= reach:
                target = pending.pop(0)
                snaps.append(self.snapshot_ahead(distance_to(target), len(curve.d),
                                                 target if kind == "F" else None))

        while pending:
            dist = self.next_event(+1.0)
            take(dist)
            if not pending:
                break
            if not math.isfinite(dist):
                raise NoConvergenceError("loading path has no further event and never "
                                         "reaches the preload")
            self._step(+1.0, dist, curve, on_batch=take)
        return snaps

    def unload(self, snap: Snapshot) -> BranchResult:
        """Pull off from a preload snapshot until no element is attached."""
        self.restore(snap)
        self.phase = "unloading"
        curve = CurveRecorder()
        self.record(curve)
        ng = self.model.geometry.n_groups
        let_go = np.full(ng, np.nan)
        kern.group_counts(self.att, self.starts, self.counts)
        prev = self.counts.copy()
        best = [self.force(), self.d, self.f.copy(), self.p.copy(), self.att.copy()]
        events0 = self.events

        def consider():
            F = self.force()
            if F < best[0]:
                best[:] = [F, self.d, self.f.copy(), self.p.copy(), self.att.copy()]

        while self.att.any():
            dist = self.next_event(-1.0)
            if not math.isfinite(dist):
                raise NoConvergenceError("unloading path has no further event while elements "
                                         "are still attached")
            self._step(-1.0, dist, curve, consider)
            kern.group_counts(self.att, self.starts, self.counts)
            let_go[(prev > 0) & (self.counts == 0)] = self.d
            prev[:] = self.counts
        return BranchResult(curve=curve, F_min=best[0], d_at_F_min=best[1], f_at_min=best[2],
                            p_at_min=best[3], att_at_min=best[4], let_go_d=let_go,
                            events=self.events - events0)
