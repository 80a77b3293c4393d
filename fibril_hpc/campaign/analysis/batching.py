"""Which records were loaded in batches wider than today's bound (a tenth of the brush's own
length spread), so that their rise of F~_A with preload, and c read from it, is biased.

While loading, contacts whose plate displacements lie within one batch are made in one step.
Until loading batches were bounded by the scene's length spread (``solver.load_merge_spread``,
first in the code at :data:`SPREAD_BOUND_FROM`), a batch was ``load_event_merge`` d_c alone
(0.1 d_c at ``fast``): on a brush with sigma~ < ``load_event_merge`` / 0.1 many pillars
touched in one step, the first contact overshot the smallest preloads, and F~_A on the rise
came out higher than on the resolved path. Measured on the same seeds with both batchings
(18 x 18, ``fast``, k~ = 1, 0.01, 0.001 at the paper's sigma~ = 0.07 ... 2.1; the unbounded
run reproduces tests/data/real18_k1.h5 bitwise; benchmarks/NOTES.md, "c against the paper"):
the plateau is the same to 3 digits, c moves by up to +25 %, and every reading of c moves by
15-46 % on some group (secants to 50, 70 and 90 % of the plateau: 25, 24, 26 %; the chord 15 %;
the stage's slope 46 %); alpha(0.001)/alpha(1) of c falls from 27.2 to 22.8. So no choice of
reading makes c robust to it; the report names the groups.

The job keys, scene texts and version strings of such records are those of today's (the rerun
has the campaign hash of the old file), so what tells them apart is the record's finish time
or a scene that sets the bound, never a guess from the numbers (the overshoot of asked preloads
overlaps: today's batching overshoots some by up to 36 % near sigma~ = 1):

* its scene text sets ``load_merge_spread`` above :data:`BOUND` (a user's choice); or
* its scene text has no ``load_merge_spread`` (the default) and the record *finished* before
  :data:`SPREAD_BOUND_FROM`: no code that bounded batches existed then. A record with no
  ``finished`` time is not named (its batching is unknown, and the report does not guess).

In both cases only where the batch exceeded the bound: ``min(load_event_merge, spread sigma~)``
above ``BOUND sigma~`` (the length spread of the realised heights sigma~ (max xi - xi_n) is
sigma~ times the sample sd of xi, about 1; the bound is read at sd 1).
"""

from __future__ import annotations

import math
from datetime import datetime

#: the largest rise of c measured on one group when its batches were not bounded (same seeds,
#: same code otherwise; benchmarks/NOTES.md, "c against the paper")
C_BIAS = 0.25
#: today's default bound: a loading batch spans at most this fraction of the length spread
BOUND = 0.1
#: when loading batches were first bounded by the length spread (the commit that added
#: ``solver.load_merge_spread``, UTC): a record finished before it was loaded without the bound
SPREAD_BOUND_FROM = datetime.fromisoformat("2026-11-25T21:39:05+00:00")


def _solver(job) -> dict | None:
    import yaml

    try:
        scene = yaml.safe_load(job.get("scene_yaml") or "") or {}
    except yaml.YAMLError:
        return None
    solver = scene.get("solver") if isinstance(scene, dict) else None
    return solver if isinstance(solver, dict) else None


def _finished(job) -> datetime | None:
    t = job.get("finished")
    try:
        d = datetime.fromisoformat(str(t)) if t else None
    except ValueError:
        return None
    return d if d is None or d.tzinfo else None


def coarse_loading(job) -> bool:
    """True where the record's loading batches spanned more than :data:`BOUND` of the brush's
    length spread, by what the record says (module text); False where they did not or the
    record does not tell."""
    text = job.get("scene_yaml") or ""
    if "load_merge_spread" not in text:             # the default: only the finish time tells
        done = _finished(job)
        if done is None or done >= SPREAD_BOUND_FROM:
            return False                            # (no scene text parsed: reports stay quick)
    solver = _solver(job)
    sigma = job.get("sigma_tilde")
    if solver is None or not isinstance(sigma, (int, float)) or not sigma > 0:
        return False
    lem = solver.get("load_event_merge")
    if not isinstance(lem, (int, float)):
        return False
    spread = solver.get("load_merge_spread")
    if spread is None:
        done = _finished(job)
        if done is None or done >= SPREAD_BOUND_FROM:
            return False
        spread = math.inf
    batch = min(float(lem), float(spread) * float(sigma))
    return batch > BOUND * float(sigma) * (1 + 1e-9)


def coarse_groups(jobs) -> list:
    """The (k~, sigma~) with at least one done record loaded in coarse batches, sorted."""
    return sorted({(float(j["k_tilde"]), float(j["sigma_tilde"])) for j in jobs
                   if j.get("status") == "done" and coarse_loading(j)})
