"""The moment coarse level (``solver.preconditioner: moments``, :mod:`fibril_hpc.solve.moments`).

It must not change any recorded contact set, event count, let-go d~ or order, F~_A or F~_P beyond
the solver tolerance (tests/test_coarse.py runs the small brushes of tests/test_cascade.py against
block Jacobi with both coarse levels); it must be
an SPD preconditioner on partial sets (pillars with one or two attached elements keep the force
unknown only); F^-1 kept by low-rank updates must equal a fresh inverse (tested for both levels
in tests/test_coarse.py); the multipole blocks must
approximate the exact coarse couplings of well separated pillars.
"""

import numpy as np
import pytest
from test_coarse import as_matrix, traced_coarse_bytes

from fibril_hpc.solve.moments import MomentTwoLevelPreconditioner, multipole_couplings


def _awkward_set(geom, seed):
    """80 % of the elements attached, one pillar out of contact, one with a single attached
    element and one with two (no tilt unknowns there)."""
    rng = np.random.default_rng(seed)
    s = geom.starts
    att = (rng.random(geom.n_active) < 0.8).astype(np.uint8)
    att[s[2]:s[3]] = 0
    att[s[4]:s[5]] = 0
    att[s[4] + 3] = 1
    att[s[6]:s[7]] = 0
    att[s[6] + 1:s[6] + 3] = 1
    return att


def _check_spd(pc, geom, att):
    P = as_matrix(pc, geom, att)
    np.testing.assert_allclose(P, P.T, rtol=0, atol=1e-10 * np.abs(P).max())
    assert np.linalg.eigvalsh(0.5 * (P + P.T)).min() > 0.0


@pytest.mark.parametrize("k_tilde", [1e-5, 1e-1, 1e2, float("inf")])
def test_moments_is_spd_with_the_exact_diagonal_blocks(small_brush, k_tilde):
    geom, op, K = small_brush
    alpha = 0.0 if np.isinf(k_tilde) else geom.h**2 / k_tilde
    att = _awkward_set(geom, 3)
    pc = MomentTwoLevelPreconditioner(geom, alpha)
    pc.update(att)
    _check_spd(pc, geom, att)
    # tilt unknowns exactly where the attached elements span them; none off contact
    use = pc.coarse_unknowns()
    assert not use[2].any() and list(use[4]) == [True, False, False]
    assert list(use[6]) == [True, False, False] and use[0].all()
    # F_gg = D_g^-1 with D_g = C_g^T M_g^-1 C_g exactly: the unit-moment shapes' energy
    S = np.flatnonzero(att)
    lab = geom.labels
    A = K[np.ix_(S, S)] + alpha * (lab[S][:, None] == lab[S][None, :])
    shapes = pc.unit_moment_shapes()
    for g in (0, 4, 6):
        u = np.flatnonzero(use[g])
        zh = np.zeros((len(S), len(u)))
        rows = lab[S] == g
        zh[rows] = shapes[g][(att[geom.starts[g]:geom.starts[g + 1]] != 0)][:, u]
        np.testing.assert_allclose(zh.T @ A @ zh, pc.coarse_diagonal(g), rtol=1e-8,
                                   atol=1e-12 * np.abs(pc.coarse_diagonal(g)).max())


def test_state_round_trip_is_bitwise(small_brush):
    geom, op, K = small_brush
    pc = MomentTwoLevelPreconditioner(geom, geom.h**2 / 0.1)
    att = _awkward_set(geom, 1)
    pc.update(att)
    saved = pc.state()
    r = np.random.default_rng(0).random(geom.n_active)
    z0 = np.zeros(geom.n_active)
    pc.apply(r, att, z0)
    pc.update(_awkward_set(geom, 2))
    pc.set_state(saved)
    pc.update(att)
    z1 = np.zeros(geom.n_active)
    pc.apply(r, att, z1)
    assert np.array_equal(z0, z1)


def test_multipole_blocks_approximate_the_exact_couplings():
    """Against Zh_g^T K Zh_h from the dense influence matrix, in units of the pillars' own
    stiffness (F_ab / sqrt(F_gg,aa F_hh,bb)): the multipole blocks are within 2 % of the
    coupling for neighbours (measured 1.6 %) and far better apart; the matrix is symmetric."""
    from fibril_hpc.elastic.halfspace import HalfSpace
    from fibril_hpc.geometry.grid import build_pillar_grid

    geom = build_pillar_grid(5, 0.16, 8, 0.0, 0).geometry
    K = HalfSpace(geom, threads=1).dense()
    pc = MomentTwoLevelPreconditioner(geom, 0.0)
    pc.update(np.ones(geom.n_active, np.uint8))
    t = multipole_couplings(*pc.centres(), geom.h)
    np.testing.assert_array_equal(t, t.T)
    shapes = pc.unit_moment_shapes()
    s = geom.starts
    for g, h, tol in ((0, 1, 0.02), (0, 6, 0.02), (0, 4, 0.002), (2, 22, 0.002)):
        exact = shapes[g].T @ K[s[g]:s[g + 1], s[h]:s[h + 1]] @ shapes[h]
        approx = t[3 * g:3 * g + 3, 3 * h:3 * h + 3]
        unit = np.sqrt(np.outer(np.diag(pc.coarse_diagonal(g)), np.diag(pc.coarse_diagonal(h))))
        err = np.abs(approx - exact) / unit
        assert err.max() <= tol * np.abs(exact / unit).max(), (g, h, err.max())


def test_auto_picks_moments_where_the_fft_is_dear():
    """Where the FFT is dear the moment level pays; ``auto`` applies it by FFT on the pillar
    lattice (tests/test_lattice_coarse.py) and keeps the dense inverse for pillars off any
    lattice."""
    from fibril_hpc.geometry.grid import build_pillar_grid
    from fibril_hpc.solve.factory import make_preconditioner, prefers_moments
    from fibril_hpc.solve.lattice import LatticeMomentPreconditioner

    # the fast 18 x 18 scene (FFT 480) keeps the force level; the default one (640), its
    # accurate preset (1280), a 12 x 12 (420) and an 8 x 8 (280) brush take the moments
    assert not prefers_moments(480, 324)
    assert prefers_moments(640, 324) and prefers_moments(1280, 324)
    assert prefers_moments(420, 144) and prefers_moments(280, 64)
    geom = build_pillar_grid(3, 0.16, 6, 0.0, 0).geometry
    assert type(make_preconditioner(geom, 0.1, 1.0, "auto", fft_size=64)) is \
        LatticeMomentPreconditioner
    assert type(make_preconditioner(geom, 0.1, 1.0, "auto", fft_size=8)) not in \
        (MomentTwoLevelPreconditioner, LatticeMomentPreconditioner)
    assert type(make_preconditioner(geom, 0.1, 1.0, "moments", fft_size=8)) is \
        MomentTwoLevelPreconditioner

    class Scattered:      # the 3 x 3 brush's pillars moved off any common lattice step
        starts = geom.starts
        n_groups, n_active, h = geom.n_groups, geom.n_active, geom.h
        shift = np.repeat(np.array([0, 1, 5, 12, 20, 31, 44, 58, 73]), geom.starts[1])
        ix = geom.ix + shift
        iy = geom.iy

    assert type(make_preconditioner(Scattered(), 0.1, 1.0, "auto", fft_size=64)) is \
        MomentTwoLevelPreconditioner
    with pytest.raises(ValueError, match="regular lattice"):
        make_preconditioner(Scattered(), 0.1, 1.0, "lattice")


def test_memory_estimate_covers_the_moment_level():
    """limits.moment_bytes bounds what the moment level holds after a solve plus the peak of an
    update that rebuilds F^-1 (traced), and the scene estimate adds it where it is asked for."""
    from fibril_hpc import Scene
    from fibril_hpc.inputs.limits import memory_estimate, moment_bytes

    scene = Scene(n_side=8, elements_per_diameter=5,
                  solver={"fft_threads": 1, "preconditioner": "moments"})
    kept, peak, geom = traced_coarse_bytes(scene, MomentTwoLevelPreconditioner, 30)
    need = moment_bytes(geom.n_groups, geom.n_active)
    assert 3 * 8 * (3 * geom.n_groups)**2 < kept + peak <= need, (kept, peak, need)
    block = scene.replace(solver=scene.solver.replace(preconditioner="block"))
    assert memory_estimate(scene)[0] - memory_estimate(block)[0] == moment_bytes(
        64, geom.n_active)
