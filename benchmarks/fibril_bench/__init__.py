"""The developer benchmark of fibril-hpc: one table and one JSON file.

    python -m benchmarks.fibril_bench [--quick] [--only fft,cg,...] [--out DIR]

(from the root of a source checkout; it is not installed with the package).

Everything runs on one thread (FFT threads, numba, BLAS): the bench re-runs itself in a child
process with ``OMP_NUM_THREADS=OPENBLAS_NUM_THREADS=MKL_NUM_THREADS=NUMBA_NUM_THREADS=1`` and every
scene uses ``fft_threads=1``. Sections (``--only`` picks some):

``fft``
    Per padded size m: the *floor*, a plain pyFFTW ``rfft2`` + ``irfft2`` pair on the full m x m
    grid (aligned buffers, one thread, the FFTW planner flag stated), and fibril's row-pruned pair
    (:class:`~fibril_hpc.elastic.fft.FFTPair`) and operator product (scatter + pair + gather).
``cg``
    Per grid size (18 x 18 default brush, the pitch sets N and m): time per CG iteration inside a
    solve on a fixed attached set (each iteration is one operator product) over the floor, and the
    all-in cost of a fixed-d contact solve (``PathDriver.solve_at``: every pass, set update and
    preconditioner rebuild included) per CG iteration; scaling with N against m^2 log m.
``curves``
    The default 18 x 18 pull-off curve (``F_P = 4``) at each accuracy preset: wall time, CG
    iterations, solves, FFT pairs, events, F_A (``accurate`` only with ``--accurate``: it is long).
``memory``
    In a fresh process, after imports and JIT: growth of the peak resident set (VmHWM, reset
    through /proc/self/clear_refs) while a model is built and a contact solve runs, against the
    bytes of the arrays the solve must hold (listed and counted).
``campaign``
    Jobs per hour of a small campaign grid: ``fibril-campaign --serial``, ``mpirun -n 2``
    (one worker) and ``mpirun -n 3`` (two workers).
``peers``
    Side by side in one process, on the peers' ground (non-adhesive rigid flat punches, 18 x 18,
    Gaussian heights, phi = 0.16, fixed plate displacement): fibril ``solve_at(d)``,
    ContactMechanics (``FreeFFTElasticHalfSpace`` + ``constrained_conjugate_gradients(offset=d)``)
    and tamaas (non-periodic Boussinesq operator, ``PolonskyKeerRey`` under load control at the
    force fibril reaches); answers compared, ratios taken run by run, medians reported. Skipped
    (and said so) when a peer is not installed (``pip install "fibril-hpc[bench]"``).

``--quick`` runs every section on small grids in seconds (a smoke test, not a measurement).
Results: ``<out>/bench-<UTC date-time>.json`` (default out: ``benchmarks/results``).

Modules: :mod:`.timing` (clocks, floor pair), :mod:`.solver_sections` (fft, cg, curves, opts),
:mod:`.memory` + :mod:`.memory_child`, :mod:`.campaign_section`, :mod:`.peers`, :mod:`.table`,
:mod:`.cli` (arguments, section table, JSON).
"""
