"""benchmarks/held_field_bound.py: the a priori bound of the held field's error under
``far_field: multipole`` holds pillar by pillar, is attained where one pillar changes, and the
study finds no pillar above it along a load path."""

from __future__ import annotations

import numpy as np
import pytest

from benchmarks import held_field_bound as hfb
from fibril_hpc import Scene
from fibril_hpc.model import build_scene_model


@pytest.fixture(scope="module")
def brush():
    scene = Scene(n_side=5, k_tilde=0.01, sigma_tilde=0.5, F_P=(4.0,), seed=3, preset="fast",
                  solver={"fft_threads": 1, "far_field": "multipole"})
    model = build_scene_model(scene)
    op = model.operator
    g = model.geometry
    lattice = op.couplings.lattice
    table = hfb.offset_norms(op, lattice, g.n_groups, op.footprint)
    return op, g, lattice, table


def remainder(op, x):
    """(K - Ka) x, exactly."""
    return op.exact.apply(x, np.empty_like(x)) - op.apply_increment(x, np.empty_like(x))


def test_the_table_is_zero_on_the_own_block_and_symmetric(brush):
    _, _, lattice, table = brush
    ny, nx = lattice.shape
    assert table.shape == (2 * ny - 1, 2 * nx - 1)
    assert table[ny - 1, nx - 1] == 0.0
    assert np.all(table[np.arange(2 * ny - 1) != ny - 1].max(axis=1) > 0.0)
    assert np.allclose(table, table[::-1, ::-1], rtol=1e-9)        # R_-s = R_s^T
    # the nearest neighbours couple most; far offsets decay
    assert table[ny - 1, nx] == pytest.approx(table.max(), rel=0.05)
    assert table[ny - 1, -1] < 0.2 * table[ny - 1, nx]


@pytest.mark.parametrize("draw", range(6))
def test_each_pillar_s_error_is_within_its_bound(brush, draw):
    op, g, lattice, table = brush
    ng, m = g.n_groups, op.footprint
    rng = np.random.default_rng(draw)
    x = rng.standard_normal(g.n_active)
    if draw % 3 == 1:
        x = np.abs(x)                                   # one sign everywhere: sums add up
    elif draw % 3 == 2:
        x[rng.random(ng).repeat(m) < 0.7] = 0.0         # a few pillars change
    e = np.linalg.norm(remainder(op, x).reshape(ng, m), axis=1)
    b = hfb.pillar_bound(table, lattice, np.linalg.norm(x.reshape(ng, m), axis=1))
    assert np.all(e <= b * (1 + 1e-9))
    assert np.all(b > 0.0)


def test_the_bound_is_attained_by_one_pillar_s_worst_change(brush):
    """A change on one pillar along the top right singular vector of its block to a chosen
    other pillar gives that pillar exactly its bound: the table is not inflated."""
    op, g, lattice, table = brush
    ng, m = g.n_groups, op.footprint
    src, dst = 0, ng - 1
    R = np.empty((m, m))
    for f in range(m):
        unit = np.zeros(g.n_active)
        unit[src * m + f] = 1.0
        R[:, f] = remainder(op, unit)[dst * m:(dst + 1) * m]
    _, sv, vt = np.linalg.svd(R)
    x = np.zeros(g.n_active)
    x[src * m:(src + 1) * m] = vt[0]
    e = np.linalg.norm(remainder(op, x)[dst * m:(dst + 1) * m])
    b = hfb.pillar_bound(table, lattice, np.linalg.norm(x.reshape(ng, m), axis=1))
    assert e == pytest.approx(sv[0], rel=1e-9)
    assert b[dst] == pytest.approx(e, rel=1e-6)


def test_along_a_load_path_no_pillar_is_above_its_bound():
    """Also: the held state's first-order force error p1 . e equals w . (p - p0) with
    w = u1 - Ka p1 (K and Ka symmetric), which needs no exact product of the state."""
    r = hfb.run(5, "fast", 0.01, 0.5, 3, 4.0)
    assert r["refreshes"] > 5 and r["violations"] == 0
    for key in ("median", "max"):
        assert r[f"F_w_first_over_tol_{key}"] == pytest.approx(r[f"F_err_over_tol_{key}"],
                                                                rel=1e-6)
        assert r[f"F_w_bound_over_tol_{key}"] >= r[f"F_w_first_over_tol_{key}"]
    assert 1.0 <= r["global_median"] <= r["global_max"]
    assert 1.0 <= r["worst_median"] <= r["worst_max"]
