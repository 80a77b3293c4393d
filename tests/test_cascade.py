"""The local cascade path (``solver.cascade: local``, default) against the global reference.

On small brushes (a single pillar, 3 x 3 and 4 x 4; soft, stiff and rigid springs; smooth and
rough) both paths must pass through the same contact sets at every recorded point, let every
pillar go at the same d~ in the same order, and give the same F~_A and F~_P to the solver
tolerance.
"""

import math

import numpy as np
import pytest

from fibril_hpc import Scene, simulate
from fibril_hpc.model import build_scene_model
from fibril_hpc.solve.cascade import LocalCascade

TOL = 1e-11     # CG tolerance of both paths: the comparison is then limited by it, not by physics

CASES = [
    dict(n_side=1, elements_per_diameter=8, k_tilde=0.1, sigma_tilde=0.0),
    dict(n_side=3, elements_per_diameter=5, k_tilde=0.01, sigma_tilde=0.5),
    dict(n_side=3, elements_per_diameter=6, k_tilde=1e-4, sigma_tilde=2.0, F_P=(1.0, 4.0)),
    dict(n_side=4, elements_per_diameter=6, k_tilde=1.0, sigma_tilde=0.07, F_P=(2.0, 6.0)),
    dict(n_side=4, elements_per_diameter=6, k_tilde=math.inf, sigma_tilde=0.0),
    dict(n_side=4, elements_per_diameter=5, k_tilde=10.0, sigma_tilde=1.0, d_tilde=(1.5,)),
    # 7 x 7 at 4 elements per diameter: pillars beyond LocalCascade.NEAR radii exist (monopole)
    dict(n_side=7, elements_per_diameter=4, k_tilde=0.01, sigma_tilde=0.5),
    # the diagonal preconditioner (what "auto" picks when footprints differ) under both paths
    dict(n_side=3, elements_per_diameter=6, k_tilde=1.0, sigma_tilde=0.07, F_P=(2.0,),
         preconditioner="diagonal"),
    # per-pillar springs (issue 11): alpha_n = h^2/k_n in the dense blocks and the trust test
    dict(n_side=3, elements_per_diameter=5, k_tilde=0.01, sigma_tilde=0.5, k_law="lognormal",
         k_spread=1.0),
    dict(n_side=4, elements_per_diameter=6, k_tilde=1.0, sigma_tilde=0.07, k_law="lognormal",
         k_spread=0.5, F_P=(2.0, 6.0)),
    dict(n_side=2, elements_per_diameter=6, k_tilde=0.1, sigma_tilde=0.3,
         k_law=(1e-3, 0.1, 10.0, 0.05)),
]


def run_path(cascade, preconditioner="auto", direction_tol=TOL, **kw):
    # directions at the CG tolerance too: with loading batches bounded by the length spread
    # (solver.load_merge_spread) a batch ends on a located event, which carries the direction
    # solve's error (100 x cg_tol by default, about that times the step, ~3e-8 here); the
    # loose direction has its own test below
    r = simulate(Scene(**kw, solver={"fft_threads": 1, "cascade": cascade, "cg_tol": TOL,
                                     "preconditioner": preconditioner,
                                     "direction_tol": direction_tol}))
    assert r.status == "ok", r.message
    return r


def let_go_order(let_go):
    """Pillars in let-go order (ties, i.e. pillars leaving in one cascade, share a rank)."""
    v = np.nan_to_num(let_go, nan=np.inf)
    return np.unique(np.round(v, 6), return_inverse=True)[1]


def assert_same_path(ref, new, rel=1e-9):
    """Two results of one scene pass through the same contact sets at every recorded point, let
    every pillar go at the same d~ in the same order, and give the same F~_A, F~_P (to ``rel``;
    the curves to 100 ``rel``)."""
    assert len(ref.results) == len(new.results)
    for a, b in zip(ref.results, new.results):
        for ca, cb in ((a.loading, b.loading), (a.unloading, b.unloading)):
            # the same contact set at every recorded point: same counts of elements and pillars
            np.testing.assert_array_equal(ca.contact_fraction, cb.contact_fraction)
            np.testing.assert_array_equal(ca.n_pillars_in_contact, cb.n_pillars_in_contact)
            np.testing.assert_allclose(ca.d_tilde, cb.d_tilde, rtol=10 * rel, atol=0.1 * rel)
            np.testing.assert_allclose(ca.F_tilde, cb.F_tilde, rtol=100 * rel, atol=rel)
        assert a.events == b.events
        np.testing.assert_array_equal(a.at_pulloff.contact_map, b.at_pulloff.contact_map)
        np.testing.assert_array_equal(np.isnan(a.let_go_d_tilde), np.isnan(b.let_go_d_tilde))
        np.testing.assert_allclose(a.let_go_d_tilde, b.let_go_d_tilde, rtol=10 * rel,
                                   atol=0.1 * rel)
        np.testing.assert_array_equal(let_go_order(a.let_go_d_tilde),
                                      let_go_order(b.let_go_d_tilde))
        assert b.F_A == pytest.approx(a.F_A, rel=rel, abs=1e-3 * rel)
        assert b.F_P == pytest.approx(a.F_P, rel=rel, abs=1e-3 * rel)


@pytest.mark.parametrize("case", CASES, ids=lambda c: "-".join(f"{k}={v}" for k, v in c.items()))
def test_local_cascade_matches_global_reference(case):
    assert_same_path(run_path("global", **case), run_path("local", **case))


@pytest.mark.parametrize("case", CASES[1:7], ids=lambda c: "-".join(f"{k}={v}" for k, v in c.items()))
def test_loose_direction_keeps_the_path(case):
    """The direction solved to its default tolerance (100 x cg_tol) against one solved to cg_tol
    (the path before issue 8): the same sets, events and let-go order; F~_A, F~_P as close as
    the looser direction allows (it moves located events by ~direction_tol times the step)."""
    exact = run_path("local", direction_tol=TOL, **case)
    loose = run_path("local", direction_tol=None, **case)
    assert loose.scene.solver.direction_tolerance == pytest.approx(100 * TOL)
    assert_same_path(exact, loose, rel=1e-7)


@pytest.mark.parametrize("lab", [{}, dict(k_law="lognormal", k_spread=0.5)],
                         ids=["one-stiffness", "per-pillar"])
def test_local_path_does_less_work(lab):
    """The point of the local path: fewer CG iterations on a cascade-heavy brush."""
    case = dict(n_side=4, elements_per_diameter=6, k_tilde=1.0, sigma_tilde=0.07, **lab)
    ref = run_path("global", **case)
    new = run_path("local", **case)
    assert new.stats["cg_iterations"] < ref.stats["cg_iterations"]
    assert new.stats["fft_pairs"] < ref.stats["fft_pairs"]


@pytest.mark.parametrize("k_tilde,k_law", [(1e-3, "one"), (math.inf, "one"),
                                           (1e-3, tuple(np.geomspace(1e-4, 1e-2, 9)))])
def test_local_solve_is_exact_on_its_pillars(k_tilde, k_law):
    """With the rest held, the dense local solve zeroes the residual on the local pillars."""
    model = build_scene_model(Scene(n_side=3, elements_per_diameter=5, k_tilde=k_tilde,
                                    k_law=k_law, solver={"fft_threads": 1}))
    g = model.geometry
    rng = np.random.default_rng(1)
    att = (rng.random(g.n_active) < 0.7).astype(np.uint8)
    x_ref = np.where(att, rng.standard_normal(g.n_active), 0.0)
    u = np.empty(g.n_active)
    model.operator.apply(x_ref, u)
    b = rng.standard_normal(g.n_active)
    x = x_ref.copy()
    loc = LocalCascade(model)
    idx = loc.solve(np.array([1, 4]), b, x, x_ref, u, att)
    assert idx is not None
    # the residual of A x = b on the attached elements of groups 1 and 4 is zero
    ku = np.empty(g.n_active)
    model.operator.apply(x, ku)
    f = np.bincount(g.labels, weights=np.where(att, x, 0.0), minlength=g.n_groups)
    alpha = 0.0 if model.rigid else g.h**2 / model.k        # a number or one per pillar
    r = b - ku - (alpha * f)[g.labels]
    on = att[idx] != 0
    assert np.abs(r[idx][on]).max() <= 1e-10 * np.abs(b).max()
    # elsewhere x is untouched
    rest = np.setdiff1d(np.arange(g.n_active), idx)
    np.testing.assert_array_equal(x[rest], x_ref[rest])


def test_direction_tol_is_validated_and_kept_out_of_default_texts():
    from fibril_hpc.errors import ConfigError

    for bad in (0, -1e-6, 0.5, float("nan"), "x"):
        with pytest.raises(ConfigError, match="solver.direction_tol"):
            Scene(solver={"direction_tol": bad})
    assert "direction_tol" not in Scene().to_dict()["solver"]          # old texts and keys stand
    assert Scene(solver={"direction_tol": 1e-9}).to_dict()["solver"]["direction_tol"] == 1e-9
    assert Scene(preset="fast").solver.direction_tolerance == pytest.approx(1e-4)


def test_cascade_option_is_validated():
    from fibril_hpc.errors import ConfigError

    with pytest.raises(ConfigError, match="solver.cascade"):
        Scene(solver={"cascade": "fast"})


def test_point_loads_at_matches_reference_kernel():
    from fibril_hpc.kernels import compiled as C
    from fibril_hpc.kernels import reference as R

    rng = np.random.default_rng(3)
    n = 40
    iy, ix = rng.integers(0, 7, n), rng.integers(0, 7, n)
    table = rng.random((7, 7))
    idx = rng.choice(n, 9, replace=False).astype(np.int64)
    tgt = rng.choice(n, 5, replace=False).astype(np.int64)
    vals = rng.standard_normal(9)
    a0 = rng.standard_normal(5)
    a, b = a0.copy(), a0.copy()
    C.point_loads_at(a, tgt, iy, ix, idx, vals, table)
    R.point_loads_at(b, tgt, iy, ix, idx, vals, table)
    np.testing.assert_allclose(a, b, rtol=1e-13, atol=1e-14)
    full = np.zeros(n)
    C.point_loads(full, iy, ix, idx, vals, table)      # the all-targets kernel agrees
    np.testing.assert_allclose(a - a0, full[tgt], rtol=1e-12, atol=1e-14)
    # the point-force (1/r) field of the trust test's far pillars, centres off the grid
    cy, cx = rng.random(4) * 7, rng.random(4) * 7
    cy[0], cx[0] = iy[tgt[0]], ix[tgt[0]]               # one on a target: r clipped at 0.5
    f = rng.standard_normal(4)
    a, b = a0.copy(), a0.copy()
    C.point_forces_at(a, tgt, iy, ix, cy, cx, f)
    R.point_forces_at(b, tgt, iy, ix, cy, cx, f)
    np.testing.assert_allclose(a, b, rtol=1e-13, atol=1e-14)
    r = np.hypot(iy[tgt][:, None] - cy, ix[tgt][:, None] - cx)
    np.testing.assert_allclose(a - a0, (f / np.maximum(r, 0.5)).sum(axis=1), rtol=1e-13)
