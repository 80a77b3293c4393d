"""How a crossing of a brush's plateau scales with the brush: the paper's variables in the
pillar's own, and how a crossing drifts with the number of pillars N (:mod:`.size_loss` reads
both for its page; its module text says why).

**The pillar's own variables.** sigma / d_c1 = sigma~ (phi N)^(1/4), k / (E* D) = k~ sqrt(pi N /
(4 phi)), and from them the spring force at the roughness over one pillar's pull-off, k sigma /
F_c1, and the roughness over one pillar's reach, sigma / (d_c1 + F_c1 / k).

**The drift.** q = d ln sigma~ / d ln N over the sizes whose crossing is bracketed, with an
interval from the crossings' bootstrap replicates, compared with the three limits: a loss at a
fixed sigma~ (q = 0), at a fixed sigma / d_c1 (q = -1/4), at a fixed k sigma / F_c1 (q = -3/4).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .intervals import expanded, percentile_interval

NAN2 = (math.nan, math.nan)
#: a crossing bracketed by the sigma~ run (the kind :func:`crossing_drift` reads)
BRACKET = "bracket"
#: d ln sigma~ / d ln N of a loss at a fixed pillar-scale roughness sigma / d_c1, and at a
#: fixed spring force at the roughness over one pillar's pull-off, k sigma / F_c1
Q_PILLAR, Q_SPRING = -0.25, -0.75
#: drift states: the limits (q, name) a drift is compared with, and the other states
FIXED_SIGMA, FIXED_PILLAR, FIXED_SPRING = "fixed sigma~", "fixed sigma/d_c1", "fixed k sigma/F_c1"
LIMITS = ((0.0, FIXED_SIGMA), (Q_PILLAR, FIXED_PILLAR), (Q_SPRING, FIXED_SPRING))
NEITHER, NOT_MEASURED = "none of the three", "not measured"


def pillar_sigma(sigma_tilde: float, n_side: int, phi: float) -> float:
    """The roughness one pillar sees: sigma / d_c1 = sigma~ (phi N)^(1/4), N = n_side^2."""
    return float(sigma_tilde) * (float(phi) * n_side * n_side) ** 0.25


def pillar_k(k_tilde: float, n_side: int, phi: float) -> float:
    """One pillar's spring against its own contact stiffness: k / (E* D) = k~ L / D,
    D = L sqrt(4 phi / (pi N))."""
    return float(k_tilde) * math.sqrt(math.pi * n_side * n_side / (4.0 * float(phi)))


def pillar_spring(sigma_tilde: float, k_tilde: float, n_side: int, phi: float) -> float:
    """The spring force at the roughness over one pillar's pull-off: k sigma / F_c1 =
    (k / (E* D)) (sigma / d_c1), since a flat punch's F_c1 = E* D d_c1."""
    return pillar_k(k_tilde, n_side, phi) * pillar_sigma(sigma_tilde, n_side, phi)


def pillar_reach(sigma_tilde: float, k_tilde: float, n_side: int, phi: float) -> float:
    """The roughness over one pillar's reach, sigma / (d_c1 + F_c1 / k): how far a pillar's
    end can be pulled back before it lets go is its contact's own detachment displacement
    d_c1 plus its spring's stretch at its pull-off force F_c1 (= E* D d_c1), so
    sigma / reach = (sigma / d_c1) / (1 + E* D / k)."""
    return pillar_sigma(sigma_tilde, n_side, phi) / (1.0 + 1.0 / pillar_k(k_tilde, n_side, phi))


@dataclass
class Drift:
    """How one threshold's crossing moves with the brush size: sigma~ ~ N^q (module text)."""

    n_sides: tuple = ()              # the sizes whose crossing is bracketed
    q: float = math.nan
    q_ci: tuple = NAN2
    state: str = NOT_MEASURED


def drift_state(q: float, ci: tuple) -> str:
    """The state of a measured drift ``q`` with interval ``ci`` (module text)."""
    lo, hi = ci
    if not (math.isfinite(q) and not math.isnan(lo) and not math.isnan(hi)):
        return NOT_MEASURED
    inside = [name for q_ref, name in LIMITS if lo <= q_ref <= hi]
    return " or ".join(inside) if inside else NEITHER


def keeps_falling(state: str) -> bool:
    """Whether a drift ``state`` names only limits whose crossing falls without end in sigma~
    (a fixed sigma / d_c1 or k sigma / F_c1, not a fixed sigma~): no size-free sigma~ then."""
    return FIXED_SIGMA not in state and (FIXED_PILLAR in state or FIXED_SPRING in state)


def crossing_drift(crossings) -> Drift:
    """q = d ln sigma~ / d ln N over the bracketed crossings of several sizes (module text)."""
    use = [c for c in crossings if c.kind == BRACKET and math.isfinite(c.sigma)]
    d = Drift(tuple(c.n_side for c in use))
    if len(use) < 2:
        return d
    x = np.log([float(c.n_side) ** 2 for c in use])
    w = (x - x.mean()) / np.sum((x - x.mean()) ** 2)       # slope = w . ln sigma~
    d.q = float(w @ np.log([c.sigma for c in use]))
    reps = [np.asarray(c.replicates, float) for c in use]
    if not all(r.size for r in reps):
        return d
    m = min(r.size for r in reps)
    with np.errstate(divide="ignore", invalid="ignore"):
        y = np.log(np.stack([r[:m] for r in reps], axis=1))      # 0 -> -inf, inf -> inf
        q = np.array([float(np.sum(w * row)) for row in y])    # mixed infinities -> NaN
    d.q_ci = expanded(d.q, percentile_interval(q), min(c.n_seeds for c in use))
    d.state = drift_state(d.q, d.q_ci)
    return d


__all__ = ["Drift", "crossing_drift", "drift_state", "keeps_falling", "Q_PILLAR", "Q_SPRING", "LIMITS",
           "FIXED_SIGMA", "FIXED_PILLAR", "FIXED_SPRING", "NEITHER", "NOT_MEASURED",
           "pillar_sigma", "pillar_k", "pillar_spring", "pillar_reach"]
