"""Pillar tip shapes as per-element height offsets inside the footprint (docs/model.md §9).

``tip: flat`` (default) gives no offsets at all (the grid keeps one set-back per pillar). A shaped
tip adds to every footprint element the set-back of its surface point from the tip's apex, at the
element centre's distance r from the pillar axis (D: the nominal pillar diameter):

* ``sphere``: a spherical cap of radius R = ``tip_radius`` D (>= D/2): R - sqrt(R**2 - r**2);
* ``rounded``: a flat tip whose edge is rounded with radius rho = ``tip_radius`` D (<= D/2): zero
  for r <= D/2 - rho, then rho - sqrt(rho**2 - (r - D/2 + rho)**2).

The attachment and detachment rules are the element-wise ones of §5, unchanged: an element of a
shaped tip attaches when its own gap closes.
"""

from __future__ import annotations

import numpy as np

from ..errors import ConfigError

TIPS = ("flat", "sphere", "rounded")


def check_tip(tip: str, radius) -> None:
    """``tip_radius`` fits ``tip`` (given for a shaped tip, in the range of its shape)."""
    if tip == "flat":
        if radius is not None:
            raise ConfigError("tip_radius", radius, "null for tip: flat")
    elif tip == "sphere" and (radius is None or radius < 0.5):
        raise ConfigError("tip_radius", radius, "a number >= 0.5 (cap radius over the pillar "
                          "diameter) for tip: sphere")
    elif tip == "rounded" and (radius is None or not 0 < radius <= 0.5):
        raise ConfigError("tip_radius", radius, "a number in (0, 0.5] (edge radius over the "
                          "pillar diameter) for tip: rounded")


def tip_offsets(tip: str, radius, footprint: tuple, radius_elements: float, h: float):
    """Offsets (internal units) of the footprint elements, or None for a flat tip.

    ``radius_elements``: the nominal pillar radius D/2 in elements; ``h``: the element side.
    """
    if tip == "flat":
        return None
    r = h * np.hypot(*np.array(footprint, dtype=np.float64).T)
    half_d = radius_elements * h
    if tip == "sphere":
        big = radius * 2.0 * half_d        # R - sqrt(R^2 - r^2), without cancellation
        return r * r / (big + np.sqrt(np.maximum(big * big - r * r, 0.0)))
    rho = radius * 2.0 * half_d
    x = np.maximum(r - (half_d - rho), 0.0)
    return x * x / (rho + np.sqrt(np.maximum(rho * rho - x * x, 0.0)))


__all__ = ["TIPS", "check_tip", "tip_offsets"]
