"""A rough cost estimate for ``--dry-run`` (no job runs).

cost of one task ~ (FFT pairs per task) x (seconds per FFT pair on this grid) x ``OVERHEAD``.
Seconds per pair are timed here on the campaign's own grid (about a second); ``OVERHEAD`` is the
all-in CPU per pair of a whole curve over the bare pair (CG, event search, local cascades); pairs
per task are modelled as ``PAIRS_PER_PILLAR_ELEMENT`` x pillars x sqrt(elements per pillar) x
(1 + ``PAIRS_PER_EXTRA_PRELOAD`` (preloads - 1)), fitted to measured curves of this solver (local
cascades, default preset): 6 x 6 and 8 x 8 brushes at (k~, sigma~) = (0.01, 0.5), (1, 0.07),
(0.001, 2.1), (10, 0.07) with one preload (F~_P = 4: 2.0-4.9 per pillar sqrt element) and the
paper grid's 12 (13.6-29.4), and the default 18 x 18 scene (4.5 with one preload); expect it to
be off by up to ~1.7x either way on single tasks, less on a whole grid. When the output file already holds
finished jobs, their measured mean wall time per task is used instead.
"""

from __future__ import annotations

import math
import time

import numpy as np

#: FFT pairs per pillar per sqrt(element per pillar) of a one-preload task (see the docstring)
PAIRS_PER_PILLAR_ELEMENT = 4.0
#: growth of the pairs per extra preload of a task (12 preloads measured 5.5-6.1x one)
PAIRS_PER_EXTRA_PRELOAD = 0.45
#: all-in CPU per FFT pair of a curve over the bare timed pair (measured ~1.5-1.6)
OVERHEAD = 1.5


def fft_pair_seconds(scene, repeats: int = 20) -> tuple[float, int, int]:
    """(seconds per FFT pair, FFT size, elements per pillar) timed on ``scene``'s grid."""
    from ..grid import Lattice, build_pillar_grid
    from ..halfspace import HalfSpace

    lat = Lattice.of(scene.n_side, scene.phi, scene.elements_per_diameter, scene.lattice)
    fp = lat.footprint
    grid = build_pillar_grid(scene.n_side, scene.phi, scene.elements_per_diameter,
                             scene.sigma_tilde * lat.scaling(scene.work_of_adhesion).d_c,
                             scene.seed, lattice=scene.lattice)
    op = HalfSpace.from_options(grid.geometry, scene.solver)
    p = np.ones(grid.geometry.n_active)
    out = np.empty_like(p)
    op.apply(p, out)
    # CPU time, best of 3 blocks: the estimate is in core-hours, and wall time on a shared
    # machine inflated it (3.9 ms instead of 1.4 ms per pair at load 3-5)
    best = math.inf
    for _ in range(3):
        t0 = time.process_time()
        for _ in range(repeats):
            op.apply(p, out)
        best = min(best, (time.process_time() - t0) / repeats)
    return best, op.m, len(fp)


def task_seconds(scene, n_preloads: int, pair_s: float, elements_per_pillar: int) -> float:
    """Modelled seconds of one task of ``n_preloads`` preloads (see the module docstring)."""
    pairs = (PAIRS_PER_PILLAR_ELEMENT * scene.n_side ** 2 * math.sqrt(elements_per_pillar)
             * (1 + PAIRS_PER_EXTRA_PRELOAD * (n_preloads - 1)))
    return pairs * pair_s * OVERHEAD
