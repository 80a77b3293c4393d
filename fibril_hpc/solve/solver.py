"""Preconditioned conjugate gradients on the attached set at one plate displacement (docs/model.md §4).

Solves A p = b on S, A = K_SS + alpha B B^T (alpha = h^2/k; alpha = 0 for rigid pillars, where the
spring work is skipped inside the kernels). The preconditioner is chosen by
``SolverOptions.preconditioner``: by default (``"auto"``) the exact per-pillar block Jacobi one
plus a coarse level wherever all pillars share one footprint (three moments per pillar in contact,
:mod:`fibril_hpc.solve.moments`, where the FFT is dear enough, applied by FFT on the pillar lattice
from 400 pillars on, :mod:`fibril_hpc.solve.lattice`; else one force, :mod:`fibril_hpc.solve.coarse`;
block Jacobi alone above ``coarse.MAX_PILLARS`` pillars off any lattice), else the
Sherman-Morrison diagonal one P = c0 I + alpha B B^T (see :mod:`fibril_hpc.solve.precond`). The
stopping test is measured against the half-space part of the operator, ||r|| <= tol ||K p||_S
(+ a floor of 1e3 eps ||b||), because for soft springs most of b goes into the springs and
||r|| <= tol ||b|| would be far too lax.

The solver also keeps u = K p on *every* active element (attached or not) up to date, since the
gaps of free elements need it. Warm start: ``x`` in, solution out (entries off S must be zero).
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import NoConvergenceError
from ..kernels import compiled as kern
from .factory import make_preconditioner

_EPS_FLOOR = 1e3 * np.finfo(np.float64).eps


class ConstrainedCG:
    """PCG with preallocated work vectors, bound to one half-space operator.

    Parameters
    ----------
    operator : HalfSpace or MultipoleField
        Provides ``apply(x, out)`` (the full field K x: one FFT pair), ``apply_increment(d,
        out)`` (the product the iterations use: the same for a HalfSpace, the far field by pillar
        moments for a :class:`~fibril_hpc.solve.farfield.MultipoleField`), ``c0``, ``geometry``
        and ``m`` (the FFT size, which ``auto`` weighs in choosing the preconditioner).
    alpha : float or ndarray
        h^2/k (0 for rigid pillars); an array of one value per pillar for per-pillar stiffness.
    tol : float
        Relative tolerance (see module docstring).
    maxiter : int
        Iteration cap; exceeding it raises :class:`NoConvergenceError`.
    """

    def __init__(self, operator, alpha: float, tol: float, maxiter: int,
                 preconditioner: str = "auto"):
        self.op = operator
        if preconditioner == "auto" and not operator.exact_increments:
            # far_field: multipole iterates with the operator the lattice level inverts exactly
            # (one iteration per solve; `auto`'s two_level took 1.4 and flipped an 18 x 18
            # `fast` corner's F~_A by 0.6 %: benchmarks/NOTES.md)
            preconditioner = "lattice"
        self.precond = make_preconditioner(operator.geometry, alpha, operator.c0, preconditioner,
                                           fft_size=operator.m)
        # one number, or one per pillar (per-pillar stiffnesses; the kernels take either)
        self.alpha = alpha if isinstance(alpha, np.ndarray) else float(alpha)
        self.tol = float(tol)
        self.maxiter = int(maxiter)
        g = operator.geometry
        self.starts = g.starts
        n = g.n_active
        self._r = np.zeros(n)
        self._z = np.zeros(n)
        self._d = np.zeros(n)
        self._kd = np.zeros(n)
        self._q = np.zeros(n)
        self.iterations = 0     # cumulative CG iterations
        self.solves = 0

    def work_arrays(self) -> dict:
        """The work vectors this solver owns, by name (for read-only use, e.g. memory
        accounting); arrays shared with the geometry are not included."""
        shared = {id(a) for a in vars(self.op.geometry).values() if isinstance(a, np.ndarray)}
        return {k: v for k, v in vars(self).items()
                if isinstance(v, np.ndarray) and id(v) not in shared}

    def solve(self, att, b, x, u, tol: float | None = None, u_valid: bool = False,
              exact: bool = False) -> int:
        """Solve A x = b on S = {att != 0} in place; u <- K x on every active element.

        ``tol`` overrides the relative tolerance for this solve. ``u_valid`` says that ``u``
        already holds K x (the caller kept it up to date), which saves the initial product.
        ``exact`` iterates with the operator's exact product (``apply``) even where its
        ``apply_increment`` is an approximation. Returns the iteration count of this solve.
        """
        op, starts, alpha = self.op, self.starts, self.alpha
        product = op.apply if exact else op.apply_increment
        tol = self.tol if tol is None else tol
        r, z, d, kd, q = self._r, self._z, self._d, self._kd, self._q
        self.solves += 1
        if not u_valid:
            op.apply(x, u)
        rr = kern.residual(b, u, x, att, starts, alpha, r)
        bb = kern.masked_norm2(b, att)
        uu = kern.masked_norm2(u, att)
        floor = _EPS_FLOOR * math.sqrt(bb)
        if not math.isfinite(rr):
            raise NoConvergenceError("non-finite residual at the start of a CG solve")
        if math.sqrt(rr) <= tol * math.sqrt(uu) + floor:
            return 0
        pc = self.precond
        pc.update(att)
        rz = pc.apply(r, att, z)
        d[:] = z
        for it in range(1, self.maxiter + 1):
            product(d, kd)
            dq = kern.apply_springs(kd, d, att, starts, alpha, q)
            if not (dq > 0.0 and math.isfinite(dq)):
                raise NoConvergenceError(
                    f"CG breakdown (d.Ad = {dq!r}) after {it} iterations on {int(att.sum())} "
                    "attached elements")
            a = rz / dq
            rr, uu = kern.cg_step(x, u, r, d, kd, q, a, att)
            self.iterations += 1
            if not math.isfinite(rr):
                raise NoConvergenceError(f"non-finite residual after {it} CG iterations")
            if math.sqrt(rr) <= tol * math.sqrt(uu) + floor:
                return it
            rz_new = pc.apply(r, att, z)
            kern.cg_direction(z, d, rz_new / rz)
            rz = rz_new
        raise NoConvergenceError(
            f"CG did not converge in {self.maxiter} iterations (relative residual "
            f"{math.sqrt(rr) / max(math.sqrt(uu), 1e-300):.3e} > tol {tol:g})")
