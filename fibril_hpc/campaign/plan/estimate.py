"""A rough cost estimate for ``--dry-run`` (no job runs).

cost of one task ~ (FFT pairs per task) x (seconds per FFT pair on this grid x
``OVERHEAD[preset]`` + ``PAIR_FIXED_S``). Seconds per pair are timed here on the campaign's own
grid (about a second, CPU time); ``OVERHEAD`` is the CPU per pair of a whole path that grows with
the grid (CG, the coarse level) over the bare pair, ``PAIR_FIXED_S`` what does not (the event
search, local cascades, Python per step), which dominates small brushes. An ``F_P: auto`` path
adds its later rounds (:func:`later_rounds_seconds`).
Pairs per task are modelled per pillar of the 18 x 18 brush (``SIZE_REF``; other brushes by
the measured growth ``SIZE_GROWTH`` of pairs with the pillar count) per sqrt(element per
pillar) as

    PRESET_FACTOR[preset] x (PAIRS_LOADING + PAIRS_UNLOADING x sum_i min(1, F~_P,i / F_FULL)^(1/3))

(a loading path, then one unloading per preload, whose cost grows with the contact the preload
makes, slower than in proportion: small preloads still meet every event of their first contacts;
a ``d_tilde`` preload counts as a full one). Fitted to measured paths of this solver (local
cascades, one thread, benchmarks/NOTES.md "Dry-run model"): at the `default` preset the default
18 x 18 scene (one preload, F~_P = 4) and the paper grid's corners with the fixed twelve-preload
list (0.05 ... 6.5) and with ``F_P: auto`` (round 0: 0.001 ... 4); `fast` and `accurate` from the
same paths' ratio. Those fits were made with block Jacobi alone; what ``auto`` now does
(``two_level`` at `fast`, ``moments`` at `default` and `accurate` on 18 x 18, the direction
solved to 100 x cg_tol, the moment trust test) scales them by ``PRESET_FACTOR``, refitted on
the paper grid's eight sampled ``F_P: auto`` paths at `default` (measured pairs 0.57x the
previous fit of 0.55: 0.31), its four corners at `fast` (0.82x of 0.25) and at `accurate`
(benchmarks/NOTES.md §26). A scene with ``solver: {confirm: local}`` (the opt-in local
confirmation, docs/model.md §6) skips global solves: its pairs are scaled by
``CONFIRM_LOCAL_PAIRS[preset]``, the measured ratio to the reference path, and its CPU per pair
by ``CONFIRM_LOCAL_CPU_PER_PAIR`` (the confirmations' own work); one with ``far_field:
multipole`` likewise by ``MULTIPOLE_PAIRS`` and ``MULTIPOLE_CPU_PER_PAIR`` (both per
preset). Expect up to ~2x either way on single tasks (soft smooth brushes are cheaper than
the model, stiff smooth ones dearer), less on a whole grid. When the output file already holds
finished jobs, their measured mean wall time per task is used instead.
"""

from __future__ import annotations

import math
import time

import numpy as np

from ...elastic.halfspace import HalfSpace
from ...geometry.grid import Lattice, build_pillar_grid
from ...inputs.limits import memory_estimate

#: FFT pairs per pillar per sqrt(element per pillar) of the loading path of a task
PAIRS_LOADING = 2.9
#: ... and of one unloading from a preload that makes full contact
PAIRS_UNLOADING = 1.6
#: F~_P from which an unloading costs a full one (below it, as the cube root of F~_P / F_FULL)
F_FULL = 4.0
#: work of a preset relative to the block-Jacobi fit above, under the ``auto`` preconditioner
#: (looser tolerances and coarser batching at `fast`; the coarse levels everywhere)
PRESET_FACTOR = {"fast": 0.20, "default": 0.31, "accurate": 0.32}
#: FFT pairs of a ``confirm: local`` path over the same path's with ``confirm: global``, per
#: preset: the ratio of the summed pairs (a grid's total) on the issue-35 corner grid
#: (benchmarks/confirm_grid.py; benchmarks/results/confirm-grid-all.csv, columns
#: pairs_local / pairs_ref; k~ 0.001-10, sigma~ 0.01-2.1, n_side 18 and 36, seed 0, F~_P = 4: a
#: loading and one unloading each, so grids with many preloads are priced by the same ratio
#: unmeasured): `default` 0.747 (32 scenes; 0.73 at 18 x 18, 0.75 at 36 x 36 by their medians,
#: so no size dependence is modelled), `fast` 0.844 (32 scenes). `accurate` was not measured:
#: priced as the reference path (neither factor applies).
CONFIRM_LOCAL_PAIRS = {"fast": 0.84, "default": 0.75}
#: ... and its CPU per FFT pair over the reference path's: the local confirmations (exact sums
#: of the local change, the bound) cost CPU that no pair counts. On the same grid the summed CPU
#: fell to 0.855 (`default`) and 0.954 (`fast`) of the reference's, 1.145 and 1.130 x the pair
#: ratio. ``benchmarks/price_check.py``'s local twins of an 8 x 8 `default` and a 12 x 12
#: `fast` grid measured 1.34 and 1.19 x their price without it (the reference grids 1.07 and
#: 0.88 x), 1.10 and 0.80 x with 1.12 (the reference grids 1.14 and 0.83 x; one run each on a
#: shared machine; benchmarks/NOTES.md, issue 35 item 5).
CONFIRM_LOCAL_CPU_PER_PAIR = 1.14
#: FFT pairs of a ``far_field: multipole`` path over the reference path's, per preset, and its
#: CPU per pair over the reference's, per preset (the moment products and the lattice level's
#: inner solves, which no pair counts): the summed ratios of the same corner grid run with it.
#: Pairs 0.558 (`default`) and 0.498 (`fast`), with the loading's states held for 2 solves
#: (benchmarks/results/confirm-grid-multipole/confirm_grid-loading2.csv; 0.544 and 0.484
#: before). CPU per pair from the grid run with both paths side by side, 15 processes on a lent
#: 16-core machine, before that count (confirm_grid-exact-directions-device.csv): CPU 0.559 and
#: 0.546, so 1.03 and 1.13 x the pair ratio (an identical second run of the moments' path in
#: the same call gives 1.05 and 1.14; benchmarks/NOTES.md, "The certified stop of a direction,
#: measured side by side and taken out"). `accurate`: not measured, priced as the reference.
MULTIPOLE_PAIRS = {"fast": 0.50, "default": 0.56}
MULTIPOLE_CPU_PER_PAIR = {"fast": 1.13, "default": 1.03}
#: the brush the constants above were fitted on (18 x 18 pillars), and how a task's pairs grow
#: with the pillar count N_p away from it, per preset: ~ N_p^SIZE_GROWTH[p][0] below,
#: ~ N_p^SIZE_GROWTH[p][1] above. `default` (and `accurate`, not measured apart): the growth
#: table, one path per size: 8 -> 18 x 18 as N_p^0.87, 18 -> 64 x 64 as N_p^0.62 with the
#: lattice coarse level (benchmarks/NOTES.md, issue 21; it priced the 100 x 100 curve 1.12x its
#: 22 691 pairs). `fast` grows slower: 0.62 priced the 64 x 64 and 100 x 100 pillar-scale
#: paths (F~_P up to 4 and 16) 1.8x and 2.6x their pairs (geometric means) and the 316 x 316
#: curve about 3.8x; with 0.40 they measure 0.99x, 0.81x and about 0.93x of the price
#: (benchmarks/price_large.py, NOTES "The dry-run at large brushes"). Pairs in proportion to
#: N_p, as fitted before the coarse levels, gave a 64 x 64 path 2.6x its pairs.
SIZE_REF = 324
SIZE_GROWTH = {"fast": (0.87, 0.40), "default": (0.87, 0.62), "accurate": (0.87, 0.62)}
#: CPU per FFT pair of a campaign's path over the bare timed pair, per preset (CG vectors, the
#: coarse levels: work that grows with the grid as the pair does) ...
OVERHEAD = {"fast": 2.35, "default": 2.35, "accurate": 2.3}
#: ... plus seconds per FFT pair that do not grow with the grid (the event search, the local
#: cascades, Python per CG step): they dominate small brushes, where a model of FFT time alone
#: was 2-3x low at 8 x 8. Fitted with ``OVERHEAD`` (least squares of the relative error) on
#: whole serial campaigns at 8 x 8 (`fast` with ``F_P: auto``, `default` with three preloads),
#: 12 x 12 and 18 x 18 (`fast`, ``F_P: auto``) and one 36 x 36 `fast` job, the CPU time of the
#: whole run measured (``benchmarks/price_check.py``; benchmarks/NOTES.md "Dry-run prices,
#: measured"; `default` alone fitted 3.25 on one grid, which priced the paper grid's 18 x 18
#: `default` paths 2.4x their measured CPU, so both presets share `fast`'s 2.35). `accurate`
#: keeps its earlier FFT-only fit (2.3, on the paper grid's paths), not refitted.
PAIR_FIXED_S = 0.00096
#: ``F_P: auto``: the later rounds of a loading path, beyond round 0 (each a new loading path
#: with about one preload near the kink): measured 1.0-2.1 per path, 1.4 on README's 8 x 8 grid
#: (24 paths: 33 later tasks, 37 jobs; the paper grid at `fast`, 330 paths: 499 later jobs)
AUTO_LATER_TASKS = 1.4
#: the preload that prices a later round's unloading (the kink lies near 0.01-0.2)
AUTO_LATER_F_P = 0.06


#: largest FFT side timed for the estimate; a larger grid is timed on fewer pillars (same
#: resolution) and scaled by m^2 log m, so ``--dry-run`` never allocates a large operator
MAX_TIMED_FFT = 2048


def fft_pair_seconds(scene, repeats: int = 20) -> tuple[float, int, int]:
    """(seconds per FFT pair, FFT size, elements per pillar) timed on ``scene``'s grid (on a
    smaller brush of the same resolution when its FFT side exceeds :data:`MAX_TIMED_FFT`)."""
    _, _, m = memory_estimate(scene)
    if m <= MAX_TIMED_FFT:
        return _timed_pair(scene, repeats)
    proxy = scene
    mp = m
    while mp > MAX_TIMED_FFT and proxy.n_side > 1:
        proxy = proxy.replace(n_side=max(1, int(proxy.n_side * MAX_TIMED_FFT / mp)))
        _, _, mp = memory_estimate(proxy)
    pair_s, mp, epp = _timed_pair(proxy, repeats)
    return pair_s * (m * m * math.log2(m)) / (mp * mp * math.log2(mp)), m, epp


def _timed_pair(scene, repeats: int) -> tuple[float, int, int]:
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


def task_pairs(scene, elements_per_pillar: int) -> float:
    """Modelled FFT pairs of one task: ``scene`` with its preloads (see the module docstring)."""
    weights = ([min(1.0, f / F_FULL) ** (1 / 3) for f in scene.F_P] if scene.F_P is not None
               else [1.0] * len(scene.d_tilde or ()))
    per = PRESET_FACTOR.get(scene.preset, 1.0) * (PAIRS_LOADING + PAIRS_UNLOADING * sum(weights))
    if scene.solver.confirm == "local":
        per *= CONFIRM_LOCAL_PAIRS.get(scene.preset, 1.0)
    if scene.solver.far_field == "multipole":
        per *= MULTIPOLE_PAIRS.get(scene.preset, 1.0)
    n_p = scene.n_side ** 2
    below, above = SIZE_GROWTH.get(scene.preset, SIZE_GROWTH["default"])
    grow = below if n_p < SIZE_REF else above
    return per * SIZE_REF * (n_p / SIZE_REF) ** grow * math.sqrt(elements_per_pillar)


def task_seconds(scene, pair_s: float, elements_per_pillar: int) -> float:
    """Modelled CPU seconds of one task (``scene`` with its preloads)."""
    per_pair = pair_s * OVERHEAD.get(scene.preset, OVERHEAD["default"]) + PAIR_FIXED_S
    if scene.solver.confirm == "local" and scene.preset in CONFIRM_LOCAL_PAIRS:   # measured
        per_pair *= CONFIRM_LOCAL_CPU_PER_PAIR
    if scene.solver.far_field == "multipole" and scene.preset in MULTIPOLE_PAIRS:
        per_pair *= MULTIPOLE_CPU_PER_PAIR[scene.preset]
    return task_pairs(scene, elements_per_pillar) * per_pair


def later_rounds_seconds(scene, pair_s: float, elements_per_pillar: int) -> float:
    """Modelled CPU seconds of the later ``F_P: auto`` rounds of one loading path whose round 0
    is ``scene`` (:data:`AUTO_LATER_TASKS` tasks of one preload near the kink)."""
    one = scene.replace(F_P=[AUTO_LATER_F_P])
    return AUTO_LATER_TASKS * task_seconds(one, pair_s, elements_per_pillar)
