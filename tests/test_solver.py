"""The constrained CG against a dense direct solve, from very soft to rigid springs."""

import math

import numpy as np
import pytest

from fibril_hpc.elastic.halfspace import HalfSpace
from fibril_hpc.errors import NoConvergenceError
from fibril_hpc.geometry.grid import build_pillar_grid
from fibril_hpc.solve.solver import ConstrainedCG


@pytest.fixture(scope="module")
def setup():
    geom = build_pillar_grid(3, 0.16, 6, 0.0, 0).geometry
    op = HalfSpace(geom, threads=1)
    return geom, op, op.dense()


@pytest.mark.parametrize("precond", ["block", "diagonal"])
@pytest.mark.parametrize("k_tilde", [1e-5, 1e-3, 1e-1, 1.0, 1e2, 1e5, math.inf])
def test_cg_matches_dense_solve(setup, k_tilde, precond):
    geom, op, K = setup
    rng = np.random.default_rng(11)
    att = (rng.random(geom.n_active) < 0.8).astype(np.uint8)
    S = np.flatnonzero(att)
    lab = geom.labels
    alpha = 0.0 if math.isinf(k_tilde) else geom.h**2 / k_tilde
    b = 1.0 - 0.3 * rng.random(geom.n_active)
    A = K[np.ix_(S, S)] + alpha * (lab[S][:, None] == lab[S][None, :])
    p_ref = np.linalg.solve(A, b[S])
    cg = ConstrainedCG(op, alpha, tol=1e-10, maxiter=2000, preconditioner=precond)
    p = np.zeros(geom.n_active)
    u = np.zeros(geom.n_active)
    its = cg.solve(att, b, p, u)
    assert 0 < its < 400
    assert np.all(p[att == 0] == 0)
    # pressure accurate even when the springs take nearly all of b (soft springs)
    err = np.linalg.norm(p[S] - p_ref) / np.linalg.norm(p_ref)
    assert err < 1e-7, err
    # u = K p on every active element, including free ones
    np.testing.assert_allclose(u, K[:, S] @ p[S], rtol=1e-8, atol=1e-12 * np.abs(u).max())


def test_warm_start_converges_immediately(setup):
    geom, op, K = setup
    att = np.ones(geom.n_active, np.uint8)
    b = np.ones(geom.n_active)
    cg = ConstrainedCG(op, geom.h**2 / 0.01, tol=1e-9, maxiter=500)
    p, u = np.zeros_like(b), np.zeros_like(b)
    cg.solve(att, b, p, u)
    assert cg.solve(att, b, p, u) == 0


def test_iteration_cap_raises(setup):
    geom, op, K = setup
    att = np.ones(geom.n_active, np.uint8)
    cg = ConstrainedCG(op, 0.0, tol=1e-12, maxiter=2)
    with pytest.raises(NoConvergenceError, match="did not converge"):
        cg.solve(att, np.ones(geom.n_active), np.zeros(geom.n_active), np.zeros(geom.n_active))


def test_non_finite_input_raises(setup):
    geom, op, K = setup
    att = np.ones(geom.n_active, np.uint8)
    b = np.ones(geom.n_active)
    b[3] = np.nan
    cg = ConstrainedCG(op, 0.0, tol=1e-8, maxiter=100)
    with pytest.raises(NoConvergenceError, match="non-finite"):
        cg.solve(att, b, np.zeros(geom.n_active), np.zeros(geom.n_active))


def test_block_preconditioner_is_the_exact_block_inverse(setup):
    from fibril_hpc.solve.precond import BlockPreconditioner

    geom, op, K = setup
    alpha = geom.h**2 / 0.01
    pc = BlockPreconditioner(geom, alpha)
    rng = np.random.default_rng(2)
    att = np.ones(geom.n_active, np.uint8)
    att[geom.starts[1]:geom.starts[2]] = rng.random(geom.starts[2] - geom.starts[1]) < 0.5
    att[geom.starts[2]:geom.starts[3]] = 0
    r = np.where(att != 0, rng.standard_normal(geom.n_active), 0.0)
    for _ in range(2):                       # second pass: cached inverses, same answer
        pc.update(att)
        z = np.zeros_like(r)
        rz = pc.apply(r, att, z)
        for g in range(geom.n_groups):
            sl = slice(geom.starts[g], geom.starts[g + 1])
            on = np.flatnonzero(att[sl]) + geom.starts[g]
            if len(on) == 0:
                assert np.all(z[sl] == 0)
                continue
            blk = K[np.ix_(on, on)] + alpha
            np.testing.assert_allclose(z[on], np.linalg.solve(blk, r[on]), rtol=1e-9, atol=1e-12)
        assert rz == pytest.approx(float(r @ z))


@pytest.mark.parametrize("threads", [None, 2])
def test_simulate_runs_blas_on_one_thread_and_restores_the_callers(monkeypatch, threads):
    """BLAS runs on one thread inside simulate, whatever the caller set and whatever
    solver.fft_threads says (its idle threads spin against the FFT pair's own), and the
    caller's setting comes back afterwards."""
    threadpoolctl = pytest.importorskip("threadpoolctl")
    import fibril_hpc.api as api
    from fibril_hpc import Scene, simulate

    def blas_threads():
        return [i["num_threads"] for i in threadpoolctl.threadpool_info()
                if i["user_api"] == "blas"]

    if not blas_threads():
        pytest.skip("no BLAS library loaded that threadpoolctl can see")
    seen = []
    build = api.build_scene_model

    def spy(*a, **kw):
        seen.append(blas_threads())
        return build(*a, **kw)

    monkeypatch.setattr(api, "build_scene_model", spy)
    with threadpoolctl.threadpool_limits(limits=3, user_api="blas"):
        r = simulate(Scene(n_side=1, elements_per_diameter=4, F_P=(0.5,),
                           solver={"fft_threads": threads}))
        after = blas_threads()
    assert r.status == "ok"
    assert seen and all(n == 1 for n in seen[0])
    assert all(n == 3 for n in after)
