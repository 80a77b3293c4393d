"""``seeds: auto`` on the report's page: which (k~, sigma~) ran up to the grid's maximum of seeds
without meeting its precision target, and what is still short.

A grid may leave the number of seeds to the campaign (``seeds: {auto: {start, max, width}}``):
a group gets seeds until its numbers are known to the relative ``width``, at most ``max``. The
report judges every group holding ``max`` seeds (or more) with the planner's own rule,
:func:`..laws.precision.group_precision` (the plateau and c within ``width``, or a lost group's
state decided), and names those that stopped at the maximum short of the target: their seed
intervals are as wide as the campaign could make them, not as wide as was asked.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..laws.precision import group_precision

def seeds_auto(meta) -> dict | None:
    """{start, max, width} of the file's grid when it says ``seeds: auto`` (read by the planner's
    own parser, :func:`..plan.search.parse_seeds`, defaults included), else None (a count or a
    list of seeds; a grid text that is missing, not YAML or not valid)."""
    import yaml

    from ...errors import ConfigError
    from ..plan.search import parse_seeds

    try:
        grid = yaml.safe_load((meta or {}).get("campaign_yaml") or "") or {}
        got = parse_seeds(grid.get("seeds")) if isinstance(grid, dict) else None
    except (yaml.YAMLError, ConfigError):
        return None
    return None if got is None else got.to_dict()


@dataclass
class SeedLimit:
    """One group at the maximum of seeds whose target is not met."""

    k_tilde: float
    sigma_tilde: float
    n_seeds: int
    max_seeds: int
    prec: object                    # :class:`..laws.precision.Precision`
    short: str                      # what is short, in words

    def what(self) -> str:
        """The page's words for this group (its table row's note)."""
        run = f"{self.n_seeds} seeds" + (f"; the maximum is {self.max_seeds}"
                                         if self.n_seeds != self.max_seeds else "")
        return f"stopped at the seeds: auto maximum ({run}) short of the target: {self.short}"


def shortfall(prec, width: float) -> str:
    """What of ``prec`` (a :class:`..laws.precision.Precision`) misses the relative ``width``."""
    parts = []
    for what, w in zip(prec.short, prec.widths):
        if what == "state":
            lo, hi = prec.plateau_ci
            ci = (f"[{lo:.3g}, {hi:.3g}]" if math.isfinite(lo) and math.isfinite(hi)
                  else "undefined")
            parts.append(f"the plateau's interval {ci} reaches the loss threshold "
                         f"{prec.threshold:.3g}: lost or not is undecided")
        else:
            parts.append(f"{what} interval {100 * w:.0f} % wide" if math.isfinite(w)
                         else f"{what} interval undefined")
    return "; ".join(parts) + f" (target {100 * width:.0f} %)"


def seed_limits(points: dict, floor: float, auto: dict | None) -> list:
    """The :class:`SeedLimit` of every group in ``points`` ({(k~, sigma~): (seed, preload, F_P,
    F_A)}) holding at least ``auto["max"]`` seeds whose target ``auto["width"]`` is not met; []
    without ``seeds: auto``."""
    if not auto:
        return []
    out = []
    for (k, s), pts in sorted(points.items(), key=lambda kv: (-kv[0][0], kv[0][1])):
        n = len(set(pts[0].tolist()))
        if n < auto["max"]:
            continue
        prec = group_precision(*pts, floor, auto["width"])
        if not prec.met:
            out.append(SeedLimit(float(k), float(s), n, int(auto["max"]), prec,
                                 shortfall(prec, auto["width"])))
    return out


__all__ = ["seeds_auto", "seed_limits", "SeedLimit", "shortfall"]
