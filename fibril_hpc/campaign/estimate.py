"""A rough cost estimate for ``--dry-run`` (no job runs).

cost of one task ~ (FFT pairs per task) x (seconds per FFT pair on this grid). Seconds per pair
are timed here on the campaign's own grid (about a second); pairs per task are modelled as
``PAIRS_PER_PILLAR_ELEMENT`` x pillars x sqrt(elements per pillar) x (1 + 0.15 (preloads - 1)),
a fit to measured tasks of this solver (benchmarks/paper_cost.py prints the measured counts);
expect it to be off by a factor of about 2-3 either way. When the output file already holds
finished jobs, their measured mean wall time per task is used instead.
"""

from __future__ import annotations

import math
import time

import numpy as np

#: FFT pairs per pillar per sqrt(element per pillar), from benchmarks/paper_cost.py
PAIRS_PER_PILLAR_ELEMENT = 30.0


def fft_pair_seconds(scene, repeats: int = 20) -> tuple[float, int, int]:
    """(seconds per FFT pair, FFT size, elements per pillar) timed on ``scene``'s grid."""
    from ..grid import Lattice, build_pillar_grid
    from ..halfspace import HalfSpace

    lat = Lattice.of(scene.n_side, scene.phi, scene.elements_per_diameter)
    fp = lat.footprint
    grid = build_pillar_grid(scene.n_side, scene.phi, scene.elements_per_diameter,
                             scene.sigma_tilde * lat.scaling(scene.work_of_adhesion).d_c,
                             scene.seed)
    op = HalfSpace.from_options(grid.geometry, scene.solver)
    p = np.ones(grid.geometry.n_active)
    out = np.empty_like(p)
    op.apply(p, out)
    t0 = time.perf_counter()
    for _ in range(repeats):
        op.apply(p, out)
    return (time.perf_counter() - t0) / repeats, op.m, len(fp)


def task_seconds(scene, n_preloads: int, pair_s: float, elements_per_pillar: int) -> float:
    """Modelled seconds of one task of ``n_preloads`` preloads (see the module docstring)."""
    pairs = (PAIRS_PER_PILLAR_ELEMENT * scene.n_side ** 2 * math.sqrt(elements_per_pillar)
             * (1 + 0.15 * (n_preloads - 1)))
    return pairs * pair_s
