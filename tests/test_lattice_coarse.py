"""The lattice coarse level (``solver.preconditioner: lattice``, :mod:`fibril_hpc.solve.lattice`).

The moment coarse level with its couplings applied by FFT on the pillar lattice and its coarse
system solved by inner CG. It must be the dense moment level's preconditioner to the inner
tolerance (so it inherits that level's SPD and its measured iteration counts), its FFT
couplings must be the dense multipole matrix exactly (to rounding) on square and hexagonal
lattices, and a whole path with it must pass through the same sets, events, let-go order and
F~_A as block Jacobi (tests/test_coarse.py runs the small brushes of tests/test_cascade.py with
every coarse level).
"""

import numpy as np
import pytest
from test_cascade import assert_same_path, run_path
from test_coarse import as_matrix
from test_moments import _awkward_set

from fibril_hpc.geometry.grid import build_pillar_grid
from fibril_hpc.solve.lattice import LatticeCouplings, LatticeMomentPreconditioner, PillarLattice
from fibril_hpc.solve.moments import MomentTwoLevelPreconditioner, multipole_couplings


def _geometry(n_side, lattice="square", epd=5):
    return build_pillar_grid(n_side, 0.16, epd, 0.0, 0, lattice=lattice).geometry


@pytest.mark.parametrize("lattice, n_side", [("square", 1), ("square", 5), ("hexagonal", 4),
                                             ("hexagonal", 5)])
def test_fft_couplings_equal_the_dense_multipole_matrix(lattice, n_side):
    geom = _geometry(n_side, lattice)
    m = geom.n_active // geom.n_groups
    lat = PillarLattice.of(geom, m)
    assert lat is not None
    ny, nx = lat.shape
    assert ny * nx <= 4 * geom.n_groups
    if lattice == "square":
        assert lat.shape == (n_side, n_side)
    pc = MomentTwoLevelPreconditioner(geom, 0.0)
    dense = multipole_couplings(*pc.centres(), geom.h)
    rng = np.random.default_rng(n_side)
    v = rng.standard_normal((geom.n_groups, 3))
    blocks = rng.standard_normal((geom.n_groups, 3, 3))
    use = (rng.random((geom.n_groups, 3)) < 0.7).astype(np.float64)
    out = np.empty_like(v)
    couplings = LatticeCouplings(lat, geom.h)
    couplings.apply(2.0 * v, blocks, use, out)
    want = use * ((dense @ v.reshape(-1)).reshape(-1, 3) + np.einsum("gab,gb->ga", blocks, v))
    np.testing.assert_allclose(out, 2.0 * want, rtol=0,
                               atol=2e-12 * max(np.abs(want).max(), 1e-300))
    # a second application sees nothing of the first (the input grid stays zero off pillars)
    couplings.apply(v, blocks, use, out)
    np.testing.assert_allclose(out, want, rtol=0, atol=1e-12 * max(np.abs(want).max(), 1e-300))


@pytest.mark.parametrize("shape, steps, fill", [((3, 7), (5, 9), 1.0), ((8, 2), (4, 3), 0.6),
                                                ((1, 6), (2, 7), 1.0), ((5, 5), (3, 3), 0.5),
                                                ((6, 4), (3, 5), 0.8), ((7, 3), (2, 2), 1.0)])
def test_fft_couplings_on_rectangular_lattices(shape, steps, fill):
    """Lattices of unequal sides and steps, partly empty, padded to 2 n - 1 and beyond (6 x 4:
    12 x 8; 7 x 3: 15 x 5): the row transforms pruned to the lattice rows and the spectra kept
    by their symmetry give the dense multipole matrix (to rounding)."""
    ny, nx = shape
    rng = np.random.default_rng(ny * 10 + nx)
    cells = np.flatnonzero(rng.random(ny * nx) < fill)
    if len(cells) == 0:
        cells = np.array([0])
    ib, ia = np.divmod(cells, nx)
    lat = PillarLattice(ia.astype(np.int64), ib.astype(np.int64), shape, steps)
    h = 0.03
    dense = multipole_couplings(ia * steps[0] * h, ib * steps[1] * h, h)
    g = len(cells)
    v = rng.standard_normal((g, 3))
    blocks = rng.standard_normal((g, 3, 3))
    use = (rng.random((g, 3)) < 0.8).astype(np.float64)
    out = np.empty_like(v)
    couplings = LatticeCouplings(lat, h)
    want = use * ((dense @ v.reshape(-1)).reshape(-1, 3) + np.einsum("gab,gb->ga", blocks, v))
    for _ in range(2):                          # the second sees nothing of the first
        couplings.apply(v, blocks, use, out)
        np.testing.assert_allclose(out, want, rtol=0,
                                   atol=1e-12 * max(np.abs(want).max(), 1e-300))


@pytest.mark.parametrize("shape, steps", [((6, 9), (4, 7)), ((5, 5), (3, 3)), ((1, 8), (2, 5)),
                                         ((7, 2), (6, 1))])
def test_the_spectra_have_the_symmetry_the_product_assumes(shape, steps):
    """K00, K11, K22, K12 = K21 real, K01 = -K10 and K02 = -K20 imaginary, on the padded sizes
    the couplings pick (next_fast_len, odd and even): what ``symmetric_rows`` keeps is the
    whole spectrum, up to its rounding."""
    ny, nx = shape
    ib, ia = np.divmod(np.arange(ny * nx), nx)
    lat = PillarLattice(ia, ib, shape, steps)
    couplings = LatticeCouplings(lat, 0.1)
    k = LatticeCouplings.spectra(lat, 0.1, couplings.fft_shape)
    tol = 1e-13 * np.abs(k).max()
    for a, b in ((0, 0), (1, 1), (2, 2), (1, 2)):
        assert np.abs(k[a, b].imag).max() <= tol
        np.testing.assert_allclose(k[b, a], k[a, b], rtol=0, atol=tol)
    for a, b in ((0, 1), (0, 2)):
        assert np.abs(k[a, b].real).max() <= tol
        np.testing.assert_allclose(k[b, a], -k[a, b], rtol=0, atol=tol)
    rows = LatticeCouplings.symmetric_rows(k)
    np.testing.assert_array_equal(rows[4], k[0, 1].imag)
    np.testing.assert_array_equal(rows[3], k[1, 2].real)


def test_a_brush_off_any_lattice_has_none():
    class Scattered:      # four pillars of one footprint at offsets with no common step
        n_groups = 4
        ix = np.repeat(np.array([0, 7, 30, 61]), 2) + np.tile([0, 1], 4)
        iy = np.repeat(np.array([0, 11, 53, 3]), 2)
    assert PillarLattice.of(Scattered(), 2) is None


@pytest.mark.parametrize("k_tilde", [1e-5, 1e-1, 1e2, float("inf")])
def test_lattice_is_the_dense_moment_level(small_brush, k_tilde):
    geom, op, K = small_brush
    alpha = 0.0 if np.isinf(k_tilde) else geom.h**2 / k_tilde
    att = _awkward_set(geom, 3)
    dense = MomentTwoLevelPreconditioner(geom, alpha)
    lat = LatticeMomentPreconditioner(geom, alpha)
    tight = LatticeMomentPreconditioner(geom, alpha)
    tight.INNER_TOL = 1e-12                     # the exact operator, to rounding
    for pc in (dense, lat, tight):
        pc.update(att)
    P = as_matrix(dense, geom, att)
    np.testing.assert_allclose(as_matrix(tight, geom, att), P, rtol=0, atol=1e-9 * np.abs(P).max())
    # at its own tolerance (1e-6 in the D-norm) it is the dense level to a few 1e-7
    Q = as_matrix(lat, geom, att)
    err = np.abs(Q - P).max() / np.abs(P).max()
    assert err <= 20 * LatticeMomentPreconditioner.INNER_TOL, err
    assert np.array_equal(lat.coarse_unknowns(), dense.coarse_unknowns())
    assert lat.update_counts()["coarse_inner_iterations"] > 0
    assert (tight.update_counts()["coarse_inner_iterations"]
            > lat.update_counts()["coarse_inner_iterations"])


def test_lattice_follows_set_changes_without_history(small_brush):
    """After a walk of set changes the lattice level equals one built on the last set alone,
    and a saved state put back reproduces an application bit for bit."""
    geom, op, K = small_brush
    alpha = geom.h**2 / 0.1
    walked = LatticeMomentPreconditioner(geom, alpha)
    for seed in (1, 2, 5, 1, 7):
        walked.update(_awkward_set(geom, seed))
    saved = walked.state()
    fresh = LatticeMomentPreconditioner(geom, alpha)
    att = _awkward_set(geom, 7)
    fresh.update(att)
    r = np.random.default_rng(0).random(geom.n_active)
    za, zb, zc = (np.zeros(geom.n_active) for _ in range(3))
    walked.apply(r, att, za)
    fresh.apply(r, att, zb)
    np.testing.assert_allclose(za, zb, rtol=0, atol=1e-12 * np.abs(zb).max())
    walked.update(_awkward_set(geom, 2))
    walked.set_state(saved)
    walked.update(att)
    walked.apply(r, att, zc)
    assert np.array_equal(za, zc)


@pytest.mark.parametrize("case", [
    dict(n_side=4, elements_per_diameter=6, k_tilde=1.0, sigma_tilde=0.07, F_P=(2.0, 6.0),
         lattice="hexagonal"),
    dict(n_side=5, elements_per_diameter=5, k_tilde=0.01, sigma_tilde=0.5, F_P=(3.0,)),
], ids=["hexagonal-stiff", "square-soft"])
def test_lattice_path_matches_block_jacobi_and_the_dense_moments(case):
    """The exact reference (block Jacobi): same sets, events and let-go order, F~_A to 1e-8
    (the dense moment level differs from block Jacobi by 1.7e-9 on the soft case); the dense
    moment level: the same path to 1e-12, in the same number of FFT pairs."""
    ref = run_path("local", preconditioner="block", **case)
    new = run_path("local", preconditioner="lattice", **case)
    dense = run_path("local", preconditioner="moments", **case)
    assert new.stats["preconditioner"] == "lattice"
    assert_same_path(ref, new, rel=1e-8)
    assert_same_path(dense, new, rel=1e-12)
    assert new.stats["fft_pairs"] == dense.stats["fft_pairs"]
    for a, b in zip(ref.results, new.results):
        assert abs(a.F_A - b.F_A) <= 1e-8 * abs(a.F_A)


def test_memory_estimate_covers_the_lattice_level():
    """limits.lattice_bytes bounds what the lattice level holds after a solve plus the peak of
    building it and of an update that recomputes every pillar (traced), and the scene estimate
    adds it where the lattice level is asked for."""
    import tracemalloc

    from fibril_hpc import Scene
    from fibril_hpc.inputs.limits import lattice_bytes, memory_estimate
    from fibril_hpc.model import build_scene_model
    from fibril_hpc.path.loading import PathDriver

    scene = Scene(n_side=12, elements_per_diameter=3,
                  solver={"fft_threads": 1, "preconditioner": "lattice"})
    model = build_scene_model(scene)
    geom = model.geometry
    tracemalloc.start()
    base = tracemalloc.get_traced_memory()[0]
    pc = LatticeMomentPreconditioner(geom, geom.h**2 / model.k)
    built = tracemalloc.get_traced_memory()[1] - base
    tracemalloc.stop()
    PathDriver(model).solve_at(1.0 * model.scaling.d_c)
    pc = model.solver.precond
    assert type(pc) is LatticeMomentPreconditioner
    kept = sum(a.nbytes for k, a in pc.work_arrays().items() if not k.startswith("block_"))
    kept += sum(a.nbytes for a in vars(pc.couplings).values() if isinstance(a, np.ndarray))
    pc.set_state(None)                                # the next update recomputes every pillar
    tracemalloc.start()
    base = tracemalloc.get_traced_memory()[0]
    pc.update(np.ones(geom.n_active, np.uint8))
    peak = tracemalloc.get_traced_memory()[1] - base
    tracemalloc.stop()
    need = lattice_bytes(geom.n_groups, geom.n_active)
    assert kept + max(built, peak) <= need, (kept, built, peak, need)
    assert kept + peak > need / 4, (kept, peak, need)
    # on the scene's own active elements and the 4 nodes per pillar of a square lattice
    block = scene.replace(solver=scene.solver.replace(preconditioner="block"))
    assert memory_estimate(scene)[0] - memory_estimate(block)[0] == lattice_bytes(
        144, geom.n_active, 4)
    assert lattice_bytes(144, geom.n_active, 4) < lattice_bytes(144, geom.n_active)
