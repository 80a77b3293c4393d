"""Every compiled kernel against its NumPy float64 twin, on random inputs (hypothesis)."""

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from fibril_hpc.kernels import compiled as C
from fibril_hpc.kernels import reference as R

SETTINGS = settings(max_examples=60, deadline=None)


@st.composite
def problems(draw):
    sizes = draw(st.lists(st.integers(1, 9), min_size=1, max_size=7))
    starts = np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64)
    n = int(starts[-1])
    seed = draw(st.integers(0, 2**32 - 1))
    rng = np.random.default_rng(seed)
    att = (rng.random(n) < draw(st.floats(0.0, 1.0))).astype(np.uint8)
    vec = lambda: rng.standard_normal(n)  # noqa: E731
    return dict(starts=starts, n=n, att=att, x=vec(), y=vec(), z=vec(), w=vec(), rng=rng,
                alpha=draw(st.sampled_from([0.0, 1e-6, 0.3, 50.0])),
                sigma=draw(st.sampled_from([0.0, 0.2, 1.5])), sgn=draw(st.sampled_from([-1.0, 1.0])))


@SETTINGS
@given(problems())
def test_group_sums_and_counts(pb):
    ng = len(pb["starts"]) - 1
    a, b = np.zeros(ng), np.zeros(ng)
    C.group_sums(pb["x"], pb["att"], pb["starts"], a)
    R.group_sums(pb["x"], pb["att"], pb["starts"], b)
    np.testing.assert_allclose(a, b, rtol=1e-12, atol=1e-12)
    ca, cb = np.zeros(ng, np.int64), np.zeros(ng, np.int64)
    C.group_counts(pb["att"], pb["starts"], ca)
    R.group_counts(pb["att"], pb["starts"], cb)
    np.testing.assert_array_equal(ca, cb)


@SETTINGS
@given(problems())
def test_residual_springs_precondition(pb):
    s, att, al = pb["starts"], pb["att"], pb["alpha"]
    x = np.where(att != 0, pb["x"], 0.0)
    ra, rb = np.zeros(pb["n"]), np.zeros(pb["n"])
    va = C.residual(pb["y"], pb["z"], x, att, s, al, ra)
    vb = R.residual(pb["y"], pb["z"], x, att, s, al, rb)
    np.testing.assert_allclose(ra, rb, rtol=1e-12, atol=1e-12)
    assert np.isclose(va, vb, rtol=1e-12, atol=1e-12)
    qa, qb = np.zeros(pb["n"]), np.zeros(pb["n"])
    va = C.apply_springs(pb["w"], x, att, s, al, qa)
    vb = R.apply_springs(pb["w"], x, att, s, al, qb)
    np.testing.assert_allclose(qa, qb, rtol=1e-12, atol=1e-12)
    assert np.isclose(va, vb, rtol=1e-10, atol=1e-10)
    za, zb = np.zeros(pb["n"]), np.zeros(pb["n"])
    va = C.precondition(pb["y"], att, s, al, 1.1, za)
    vb = R.precondition(pb["y"], att, s, al, 1.1, zb)
    np.testing.assert_allclose(za, zb, rtol=1e-12, atol=1e-12)
    assert np.isclose(va, vb, rtol=1e-10, atol=1e-10)


@SETTINGS
@given(problems())
def test_preconditioner_inverts_its_matrix(pb):
    """P^-1 (c0 I + alpha B B^T) r = r on S (Sherman-Morrison is exact)."""
    s, att, al = pb["starts"], pb["att"], pb["alpha"]
    r = np.where(att != 0, pb["x"], 0.0)
    lab = np.repeat(np.arange(len(s) - 1), np.diff(s))
    sums = np.bincount(lab, weights=r, minlength=len(s) - 1)
    pr = np.where(att != 0, 0.7 * r + al * sums[lab], 0.0)
    z = np.zeros_like(r)
    C.precondition(pr, att, s, al, 0.7, z)
    np.testing.assert_allclose(z, r, rtol=1e-9, atol=1e-9)


@SETTINGS
@given(problems())
def test_cg_step_and_direction(pb):
    att = pb["att"]
    arrs = [np.where(att != 0, pb[k], 0.0) for k in ("x", "y", "z", "w")]
    kd = pb["rng"].standard_normal(pb["n"])
    A = [a.copy() for a in arrs] + [kd]
    B = [a.copy() for a in arrs] + [kd]
    ua, ub = pb["rng"].standard_normal(pb["n"]), None
    ub = ua.copy()
    va = C.cg_step(A[0], ua, A[1], A[2], A[4], A[3], 0.37, att)
    vb = R.cg_step(B[0], ub, B[1], B[2], B[4], B[3], 0.37, att)
    np.testing.assert_allclose(ua, ub, rtol=1e-14)
    for a, b in zip(A, B):
        np.testing.assert_allclose(a, b, rtol=1e-14)
    np.testing.assert_allclose(va, vb, rtol=1e-12, atol=1e-14)
    da, db = A[2].copy(), A[2].copy()
    C.cg_direction(A[1], da, 0.4)
    R.cg_direction(A[1], db, 0.4)
    np.testing.assert_allclose(da, db, rtol=1e-15)
    assert np.isclose(C.masked_norm2(pb["x"], att), R.masked_norm2(pb["x"], att), rtol=1e-12)


@SETTINGS
@given(problems())
def test_gaps_and_events(pb):
    s, att, sig, sgn = pb["starts"], pb["att"], pb["sigma"], pb["sgn"]
    ng = len(s) - 1
    dl = pb["rng"].standard_normal(ng)
    z0 = np.abs(pb["w"])
    ga, gb = np.zeros(pb["n"]), np.zeros(pb["n"])
    C.gaps(pb["x"], s, z0, 1.0, 0.3, dl, ga)
    R.gaps(pb["x"], s, z0, 1.0, 0.3, dl, gb)
    np.testing.assert_allclose(ga, gb, rtol=1e-14, atol=1e-15)
    p = np.where(att != 0, np.abs(pb["y"]) - sig, 0.0)   # a consistent state: p >= -sigma
    g = np.abs(ga)
    p1, g1 = pb["z"], pb["w"]
    da = C.event_distance(p, p1, g, g1, att, sig, sgn)
    db = R.event_distance(p, p1, g, g1, att, sig, sgn)
    assert da == db or np.isclose(da, db, rtol=1e-14)
    for limit in (0.0, 0.5, 3.0):
        assert np.isclose(C.last_event_within(p, p1, g, g1, att, sig, sgn, limit),
                          R.last_event_within(p, p1, g, g1, att, sig, sgn, limit), rtol=1e-14)
        pa, pb_, aa, ab = p.copy(), p.copy(), att.copy(), att.copy()
        na = C.flip_events(pa, p1, g, g1, aa, sig, sgn, limit)
        nb = R.flip_events(pb_, p1, g, g1, ab, sig, sgn, limit)
        assert tuple(na) == tuple(nb)
        np.testing.assert_array_equal(aa, ab)
        np.testing.assert_array_equal(pa, pb_)


@SETTINGS
@given(problems(), st.booleans())
def test_update_contact_set(pb, worst):
    s, sig = pb["starts"], pb["sigma"]
    p = pb["x"] * 2.0
    g = pb["y"]
    aa, ab = pb["att"].copy(), pb["att"].copy()
    pa, pb_ = p.copy(), p.copy()
    na = C.update_contact_set(pa, g, aa, s, sig, 1e-9, 1e-9, worst)
    nb = R.update_contact_set(pb_, g, ab, s, sig, 1e-9, 1e-9, worst)
    assert tuple(na) == tuple(nb)
    np.testing.assert_array_equal(aa, ab)
    np.testing.assert_array_equal(pa, pb_)
    # invariants: no attached element beyond the threshold unless worst-only left it for later
    if not worst:
        assert not np.any((aa != 0) & (pa < -(sig + 1e-9)) & (pb["att"] != 0))


@SETTINGS
@given(problems())
def test_point_loads(pb):
    n = pb["n"]
    rng = pb["rng"]
    iy = rng.integers(0, 6, n)
    ix = rng.integers(0, 6, n)
    table = rng.random((6, 6))
    k = min(n, 3)
    idx = rng.choice(n, k, replace=False).astype(np.int64)
    vals = rng.standard_normal(k)
    ua, ub = pb["x"].copy(), pb["x"].copy()
    C.point_loads(ua, iy, ix, idx, vals, table)
    R.point_loads(ub, iy, ix, idx, vals, table)
    np.testing.assert_allclose(ua, ub, rtol=1e-13, atol=1e-14)


@SETTINGS
@given(st.integers(1, 9), st.integers(0, 2**31 - 1))
def test_lattice_kernels(n, seed):
    """The lattice coarse level's kernels (scatter, 3 x 3 products per pillar and per
    frequency, gather) against their NumPy twins."""
    rng = np.random.default_rng(seed)
    ny, nx = 3, 4
    cells = rng.choice(ny * nx, min(n, ny * nx), replace=False)
    ib, ia = (cells // nx).astype(np.int64), (cells % nx).astype(np.int64)
    g = len(cells)
    v = rng.standard_normal((g, 3))
    blocks = rng.standard_normal((g, 3, 3))
    use = (rng.random((g, 3)) < 0.7).astype(np.float64)
    out = [np.empty((g, 3)) for _ in range(2)]
    for mod, o in zip((C, R), out):
        mod.block3_apply(blocks, v, o)
    np.testing.assert_allclose(out[0], out[1], rtol=1e-13, atol=1e-14)
    grids = [np.full((3, ny, nx), 7.0) for _ in range(2)]
    for mod, grid in zip((C, R), grids):
        mod.lattice_scatter(v, ib, ia, grid)
    np.testing.assert_array_equal(grids[0], grids[1])
    for mod, o in zip((C, R), out):
        mod.lattice_gather(grids[0], ib, ia, blocks, v, use, o)
    np.testing.assert_allclose(out[0], out[1], rtol=1e-13, atol=1e-14)
    assert np.all(out[0][use == 0] == 0)
    # the symmetric product in place against the full complex 3 x 3 product per frequency
    ks = rng.standard_normal((6, 5))
    k3 = np.empty((3, 3, 5), np.complex128)
    k3[0, 0], k3[1, 1], k3[2, 2] = ks[0], ks[1], ks[2]
    k3[1, 2] = k3[2, 1] = ks[3]
    k3[0, 1], k3[1, 0] = 1j * ks[4], -1j * ks[4]
    k3[0, 2], k3[2, 0] = 1j * ks[5], -1j * ks[5]
    vh = rng.standard_normal((3, 5)) + 1j * rng.standard_normal((3, 5))
    want = np.einsum("abj,bj->aj", k3, vh)
    for mod in (C, R):
        sp = vh.copy()
        mod.spectral3_sym(ks, sp)
        np.testing.assert_allclose(sp, want, rtol=1e-13, atol=1e-14)


@SETTINGS
@given(st.integers(1, 6), st.integers(1, 5), st.integers(0, 2**31 - 1))
def test_scale_block(m, b, seed):
    """The FFT pair's column-block multiply by the real kernel transform against its NumPy
    twin and against the complex product (bitwise: one float64 multiply per part)."""
    rng = np.random.default_rng(seed)
    kernel = rng.standard_normal((m, b))
    hat = rng.standard_normal((m, b)) + 1j * rng.standard_normal((m, b))
    out = [hat.copy() for _ in range(2)]
    for mod, o in zip((C, R), out):
        mod.scale_block(o.view(np.float64).reshape(m, b, 2), kernel)
    np.testing.assert_array_equal(out[0], out[1])
    np.testing.assert_array_equal(out[0], hat * kernel)
