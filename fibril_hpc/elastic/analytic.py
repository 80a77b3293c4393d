"""Closed-form references (docs/model.md §8). Units: any consistent set; E* = contact modulus,
dgamma = work of adhesion. Signs: F > 0 compression, d > 0 indentation."""

from __future__ import annotations

import math


def punch_stiffness(a: float, e_star: float = 1.0) -> float:
    """Rigid flat circular punch of radius a: F/d = 2 E* a."""
    return 2.0 * e_star * a


def kendall_force(a: float, dgamma: float, e_star: float = 1.0) -> float:
    """Kendall (1971) pull-off force of a flat punch: sqrt(8 pi E* dgamma a^3)."""
    return math.sqrt(8.0 * math.pi * e_star * dgamma * a**3)


def kendall_displacement(a: float, dgamma: float, e_star: float = 1.0) -> float:
    """Displacement at Kendall pull-off: -sqrt(2 pi dgamma a / E*)."""
    return -math.sqrt(2.0 * math.pi * dgamma * a / e_star)


def brush_soft_limit(n_pillars: int, phi: float) -> float:
    """F~_A of independent, very soft pillars (k -> 0, sigma -> 0): (n phi)^(1/4)."""
    return (n_pillars * phi) ** 0.25


def single_pillar_F_A(phi_discrete: float) -> float:
    """F~_A of one rigid pillar (n_side = 1) with the discrete footprint: phi^(1/4)."""
    return phi_discrete**0.25


def jkr_max_tension(R: float, dgamma: float) -> float:
    """JKR sphere: largest tensile force 1.5 pi R dgamma."""
    return 1.5 * math.pi * R * dgamma


def jkr_force(a: float, R: float, dgamma: float, e_star: float = 1.0) -> float:
    """JKR force at contact radius a: 4E*a^3/(3R) - sqrt(8 pi dgamma E* a^3)."""
    return 4.0 * e_star * a**3 / (3.0 * R) - math.sqrt(8.0 * math.pi * dgamma * e_star * a**3)


def jkr_critical_radius(R: float, dgamma: float, e_star: float = 1.0) -> float:
    """Contact radius at the force minimum (force control): (9 pi R^2 dgamma / (8 E*))^(1/3)."""
    return (9.0 * math.pi * R**2 * dgamma / (8.0 * e_star)) ** (1.0 / 3.0)


def hertz_force(R: float, delta: float, e_star: float = 1.0) -> float:
    """Hertz: F = (4/3) E* sqrt(R) delta^(3/2)."""
    return 4.0 / 3.0 * e_star * math.sqrt(R) * max(delta, 0.0) ** 1.5


def jkr_pull_off_compliant(R: float, dgamma: float, k_machine: float,
                           e_star: float = 1.0) -> float:
    """JKR sphere pulled through a machine of stiffness k_m: the tension at the jump-off, where the
    contact's slope dF/ddelta reaches -k_m (k_m -> 0: 1.5 pi R dgamma, load control; k_m = inf:
    5/6 pi R dgamma, displacement control). Solved by bisection on the contact radius."""
    w = dgamma

    def slope(a):       # dF/ddelta along the JKR curve, from dF/da and ddelta/da
        dF = 4 * e_star * a * a / R - 1.5 * math.sqrt(8 * math.pi * w * e_star * a)
        dd = 2 * a / R - 0.5 * math.sqrt(2 * math.pi * w / (e_star * a))
        return dF / dd

    a_c = jkr_critical_radius(R, dgamma, e_star)              # slope 0 (the force minimum)
    a_d = (math.pi * w * R * R / (8 * e_star)) ** (1 / 3)    # slope -inf (ddelta/da = 0)
    if math.isinf(k_machine):
        a = a_d
    else:
        lo, hi = a_d * (1 + 1e-12), a_c      # slope falls from 0 at a_c to -inf at a_d
        for _ in range(200):
            mid = 0.5 * (lo + hi)
            if slope(mid) < -k_machine:
                lo = mid
            else:
                hi = mid
        a = 0.5 * (lo + hi)
    return -jkr_force(a, R, dgamma, e_star)
