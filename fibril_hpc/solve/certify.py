"""A certified bound on the force error of a state that no global solve confirmed
(``solver.confirm: local``), or whose far field is held (``solver.far_field: multipole``).

After a contact event the local cascade (:mod:`fibril_hpc.solve.cascade`) solves the pillars
whose set changed exactly, with the pressure on every other pillar held. Its state ``x`` is not
the solution x* = A^-1 b of the attached set S (A = K_SS + alpha B B^T): the far pillars still
miss their response to the local change. The reference (``confirm: global``) removes that by a
global CG solve at ``cg_tol``. Here the error of what the path records, the plate force
F = h^2 1_S^T x, is bounded instead, from quantities that cost no FFT pair:

* the exact residual r = b - A x on S (u = K x kept exact by direct sums of the local change);
* the direction p1 = A^-1 1_S solved on the same set S (the path needs it anyway), with its own
  exact residual r1 = 1_S - A p1.

Then (dual-weighted residual, exact algebra for SPD A)

    F* - F = h^2 1_S^T A^-1 r = h^2 p1^T r + h^2 r1^T A^-1 r,
    |F* - F| <= h^2 (|p1^T r| + ||r1|| ||r|| / lambda_min(A)),

and lambda_min(A) >= lambda_min(K_SS) (the springs add a positive semidefinite term) >= the
smallest eigenvalue of the circulant whose principal submatrix K_SS is: the zero-padded FFT
operator's own kernel transform (:func:`fibril_hpc.elastic.greens.kernel_spectrum`, exact for
m >= 2n - 1), by Cauchy interlacing. Its minimum is positive (about 0.52 K(0, 0) on the default
grid) and computed once per grid; a non-positive minimum certifies nothing. The second term is
a product of two small residuals (the direction is solved to ``direction_tol``), so the bound is
essentially the first-order estimate |h^2 p1^T r|, which is itself exact for the exact p1.

Under ``far_field: multipole`` a state's u holds K x - e, e the held far field's error: the
exact residual is r - e, and with p1 . e and a bound of |e| on S given
(:mod:`fibril_hpc.path.confirm`) :meth:`ForceCertificate.held_bound` bounds that state's force
error the same way.

What is *not* bounded here: which elements the exact state would detach or attach. A local fixed
point is only proposed when the update rule, applied on the whole grid with the exact u, flips
nothing; the far field's effect on a near-critical far element is left to the cascade's trust
test and measured against the reference (benchmarks/NOTES.md, issue 35).
"""

from __future__ import annotations

import math

import numpy as np

from ..kernels import compiled as kern


def min_eigenvalue_bound(operator) -> float:
    """A lower bound of lambda_min(K_SS) for every set S of ``operator``'s active elements:
    the smallest eigenvalue of its circulant embedding (minus a rounding margin), or 0.0 where
    that is not positive."""
    m = operator.m
    # the circulant's eigenvalues are kernel_hat * m^2: their least and largest, kept by the
    # operator when it built the transform (scaling by m^2 > 0 keeps the order, rounding too).
    # The largest is the largest magnitude wherever the bound is not 0 (all of them positive)
    scale = float(m * m)
    lo = operator.kernel_min * scale
    margin = 64.0 * np.finfo(np.float64).eps * operator.kernel_max * scale
    return max(lo - margin, 0.0)


class ForceCertificate:
    """The bound of the module docstring, for one model, with counters of its use.

    Parameters
    ----------
    geometry : Geometry
        Supplies ``starts`` and the element side ``h``.
    operator : HalfSpace
        Its kernel transform's least and largest values (``kernel_min``, ``kernel_max``) give
        lambda_min's bound (:func:`min_eigenvalue_bound`).
    alpha : float or ndarray
        h^2/k (0 for rigid pillars), one value per pillar for per-pillar stiffnesses.
    tol : float
        Largest bound accepted (internal force units).
    """

    def __init__(self, geometry, operator, alpha, tol: float):
        self.starts = geometry.starts
        self.h2 = geometry.h * geometry.h
        self.alpha = alpha
        self.tol = float(tol)
        self.lam = min_eigenvalue_bound(operator)
        n = geometry.n_active
        self._r = np.zeros(n)
        self._r1 = np.zeros(n)
        self.local = 0          # states accepted on the bound
        self.refused = 0        # states whose bound was too large (a global solve followed)
        self.worst = 0.0        # largest accepted bound
        self.direction_local = 0        # directions kept on their bound
        self.direction_refused = 0      # directions whose bound was too large
        self.direction_worst = 0.0      # largest accepted slope bound times its reach

    def bound(self, att, b, x, u, p1, u1, ones) -> float:
        """|F* - F| bound of state ``x`` (``u`` = K x exactly) on set ``att``, with the
        direction ``p1`` (``u1`` = K p1) solved on the same set; ``b`` and ``ones`` are the two
        right-hand sides. inf where lambda_min's bound is not positive."""
        if self.lam <= 0.0:
            return math.inf
        rr = kern.residual(b, u, x, att, self.starts, self.alpha, self._r)
        rr1 = kern.residual(ones, u1, p1, att, self.starts, self.alpha, self._r1)
        first = abs(float(p1 @ self._r))
        return self.h2 * (first + math.sqrt(rr1) * math.sqrt(rr) / self.lam)

    def slope_bound(self, att, p1, u1, ones) -> float:
        """|F1* - F1| bound of the direction ``p1`` (``u1`` = K p1) on set ``att``:
        h^2 (|p1^T r1| + ||r1||^2 / lambda_min) (module docstring, with x = p1)."""
        if self.lam <= 0.0:
            return math.inf
        rr1 = kern.residual(ones, u1, p1, att, self.starts, self.alpha, self._r1)
        return self.h2 * (abs(float(p1 @ self._r1)) + rr1 / self.lam)

    def held_bound(self, att, b, x, u, p1, u1, ones, shift: float, e_norm: float) -> float:
        """|F* - F| bound of a state ``x`` whose ``u`` holds K x - e, e unknown but with
        p1 . e = ``shift`` and |e| <= ``e_norm`` on the set (``far_field: multipole``'s held
        field, :mod:`fibril_hpc.path.confirm`): the module docstring's bound with the exact
        residual r - e, h^2 (|p1 . r - shift| + |r1| (|r| + e_norm) / lambda_min)."""
        if self.lam <= 0.0:
            return math.inf
        rr = kern.residual(b, u, x, att, self.starts, self.alpha, self._r)
        rr1 = kern.residual(ones, u1, p1, att, self.starts, self.alpha, self._r1)
        first = abs(float(p1 @ self._r) - shift)
        return self.h2 * (first + math.sqrt(rr1) * (math.sqrt(rr) + e_norm) / self.lam)

    def accept_direction(self, att, p1, u1, ones, reach: float) -> bool:
        """Whether a direction is kept: its slope bound times ``reach`` (the distance the path
        will follow it, to its next event) is at most the tolerance; counts the decision."""
        value = self.slope_bound(att, p1, u1, ones) * reach
        if value <= self.tol:
            self.direction_local += 1
            self.direction_worst = max(self.direction_worst, value)
            return True
        self.direction_refused += 1
        return False

    def accept(self, value: float) -> bool:
        """Whether a state of bound ``value`` is accepted; counts the decision."""
        if value <= self.tol:
            self.local += 1
            self.worst = max(self.worst, value)
            return True
        self.refused += 1
        return False


__all__ = ["ForceCertificate", "min_eigenvalue_bound"]
