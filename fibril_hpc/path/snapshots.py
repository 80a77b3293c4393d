"""Preload snapshots of a load path: the driver's state saved, moved ahead and put back bit for
bit (:class:`~fibril_hpc.path.loading.PathDriver` inherits these methods)."""

from __future__ import annotations

from ..errors import NoConvergenceError
from ..kernels import compiled as kern
from .records import Snapshot

_MAX_SNAPSHOT_PASSES = 1000


class SnapshotMixin:
    """Saving, restoring and snapshotting the state of a :class:`PathDriver` (which provides
    ``move``, ``relax``, ``solve_direction``, ``force`` and the state arrays)."""

    _STATE = ("p", "u", "att", "g", "f", "p1", "u1", "g1", "f1", "p_ref", "p1_ref", "att_ref",
              "att1_ref", "p0")

    def _save(self) -> dict:
        out = {k: getattr(self, k).copy() for k in self._STATE}
        out["d"] = self.d
        out["_since_full"] = self._since_full
        out["_since_full1"] = self._since_full1
        out["_fresh_direction"] = self._fresh_direction
        out["_precond"] = self.model.solver.precond.state()
        return out

    def _load(self, saved: dict):
        for k in self._STATE:
            getattr(self, k)[:] = saved[k]
        self.d = saved["d"]
        self._since_full = saved["_since_full"]
        self._since_full1 = saved["_since_full1"]
        self._fresh_direction = saved["_fresh_direction"]
        self.model.solver.precond.set_state(saved["_precond"])

    def snapshot_ahead(self, dist: float, n_points: int, force_target: float | None = None
                       ) -> Snapshot:
        """The consistent state ``dist`` further along the path, without touching the path.

        The state is moved there on the current set; elements whose events lie *before* it (by
        more than 1e-9 d_c: passed inside an event batch) flip and the set is relaxed, so the
        preload state has no penetrating free element; an event exactly at the preload does not
        flip, so a request that lands on an event is met exactly instead of by rounding. For a
        force preload (``force_target``) the state is then moved along the new set until the force
        equals the request again (repeated while that passes further events). Finally every array
        (the preconditioner's state included) is put back bit for bit: the path does not depend on
        which preloads are requested, and grouped preloads give exactly what separate runs give.
        Each unloading branch starts with the preconditioner's history forgotten (``restore``).
        """
        saved = self._save()
        self.move(abs(dist), 1.0 if dist >= 0 else -1.0)
        passed = -1e-9 * self.model.scaling.d_c
        for _ in range(_MAX_SNAPSHOT_PASSES):
            if dist <= 0 or kern.flip_events(self.p, self.p1, self.g, self.g1, self.att,
                                             self.model.sigma_c, 1.0, passed) == (0, 0):
                break
            self.relax()
            self.solve_direction()
            f1 = float(self.f1.sum())
            if force_target is None or not f1 > 0:
                break
            step = (force_target - self.force()) / f1
            self.move(abs(step), 1.0 if step >= 0 else -1.0)
        else:
            raise NoConvergenceError("the preload state did not settle")
        snap = Snapshot(self.d, self.p.copy(), self.u.copy(), self.att.copy(), self.p1.copy(),
                        self.u1.copy(), n_points,
                        (self.d, self.force(), self.n_attached(), self.pillars_in_contact()),
                        self.p0.copy())
        self._load(saved)
        return snap

    def restore(self, snap: Snapshot):
        """Return to the state of a snapshot."""
        self.d = snap.d
        self.p[:] = snap.p
        self.u[:] = snap.u
        self.att[:] = snap.att
        self.p1[:] = snap.p1
        self.u1[:] = snap.u1
        self.p_ref[:] = snap.p
        self.p1_ref[:] = snap.p1
        self.p0[:] = snap.p if snap.p0 is None else snap.p0
        self.att_ref[:] = snap.att
        self.att1_ref[:] = snap.att
        self._since_full = 0
        self._since_full1 = 0
        self._fresh_direction = False
        self.model.solver.precond.set_state(None)     # a function of the set from here on
        self._forces(self.p, self.f)
        self._gaps(self.u, self.f, self.d, 1.0, self.g)
        self._forces(self.p1, self.f1)
        self._gaps(self.u1, self.f1, 1.0, 0.0, self.g1)


__all__ = ["SnapshotMixin"]
