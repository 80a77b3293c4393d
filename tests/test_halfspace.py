import numpy as np
import pytest

from fibril_hpc.elastic.fft import FFTPair
from fibril_hpc.elastic.halfspace import HalfSpace
from fibril_hpc.geometry.grid import build_pillar_grid


@pytest.fixture(scope="module")
def geom():
    return build_pillar_grid(3, 0.16, 5, 0.0, 0).geometry


def test_operator_equals_dense_sum(geom):
    op = HalfSpace(geom, backend="pyfftw", threads=1)
    dense = op.dense()
    rng = np.random.default_rng(3)
    p = rng.standard_normal(geom.n_active)
    u = np.empty_like(p)
    op.apply(p, u)
    np.testing.assert_allclose(u, dense @ p, rtol=1e-11, atol=1e-13 * np.abs(dense @ p).max())
    # symmetric positive definite
    np.testing.assert_allclose(dense, dense.T, rtol=1e-13, atol=0)
    assert np.linalg.eigvalsh(dense).min() > 0


def test_no_periodic_images(geom):
    """A load on one corner pillar must not appear at the opposite corner through wrap-around."""
    op = HalfSpace(geom, threads=1)
    p = np.zeros(geom.n_active)
    p[geom.starts[0]:geom.starts[1]] = 1.0
    u = np.empty_like(p)
    op.apply(p, u)
    np.testing.assert_allclose(u, op.dense() @ p, rtol=1e-11)


def test_backends_and_threads_agree(geom):
    rng = np.random.default_rng(5)
    p = rng.standard_normal(geom.n_active)
    outs = []
    q = rng.standard_normal(geom.n_active)
    for backend, threads, planner in (("numpy", 1, "estimate"), ("pyfftw", 1, "estimate"),
                                      ("pyfftw", 2, "estimate"), ("pyfftw", 1, "measure")):
        op = HalfSpace(geom, backend=backend, threads=threads, planner=planner)
        u = np.empty_like(p)
        op.apply(p, u)
        first = u.copy()
        op.apply(q, u)        # the row spectra are reused in place: nothing of q may stay
        op.apply(p, u)        # buffers reused: a later product gives the same answer
        assert np.array_equal(u, first)
        outs.append(u.copy())
        assert op.n_pairs == 3
    for u in outs[1:]:
        np.testing.assert_allclose(u, outs[0], rtol=1e-12, atol=1e-14)


@pytest.mark.parametrize("side", [3, 7])
def test_threaded_column_stage_is_bitwise_the_one_thread_product(side):
    """With fft_threads > 1 the column blocks are shared out between threads, each with its own
    plans and buffers: every column's transform is unchanged, so the product must be bitwise
    that of one thread (a brush of 7 x 7 has more blocks than threads, 3 x 3 few)."""
    g = build_pillar_grid(side, 0.16, 5, 0.0, 0).geometry
    p = np.random.default_rng(side).standard_normal(g.n_active)
    ref = HalfSpace(g, threads=1).apply(p, np.empty_like(p)).copy()
    for threads in (2, 3, 64):
        op = HalfSpace(g, threads=threads)
        for _ in range(3):                          # reused lanes and pool
            assert np.array_equal(op.apply(p, np.empty_like(p)), ref), threads
        op.pair.close()
        assert np.array_equal(op.apply(p, np.empty_like(p)), ref)       # works after close


def test_point_loads_equal_the_fft_product(geom):
    op = HalfSpace(geom, threads=1)
    rng = np.random.default_rng(9)
    idx = rng.choice(geom.n_active, 5, replace=False).astype(np.int64)
    vals = rng.standard_normal(5)
    p = np.zeros(geom.n_active)
    p[idx] = vals
    ref = np.empty_like(p)
    op.apply(p, ref)
    u = np.zeros_like(p)
    assert op.add_point_loads(u, idx, vals)
    np.testing.assert_allclose(u, ref, rtol=1e-11, atol=1e-14 * np.abs(ref).max())
    assert not op.add_point_loads(u, np.arange(op.max_direct + 1), np.ones(op.max_direct + 1))


def test_injected_padded_size_gives_the_same_product(geom):
    """Any padded size m >= 2n-1 is the same linear operator; below it wrap-around would alias."""
    p = np.random.default_rng(7).standard_normal(geom.n_active)
    ref = HalfSpace(geom, threads=1)
    u0, u1 = np.empty_like(p), np.empty_like(p)
    ref.apply(p, u0)
    big = HalfSpace(geom, threads=1, m=ref.m + 6)
    assert big.m == ref.m + 6
    big.apply(p, u1)
    np.testing.assert_allclose(u1, u0, rtol=1e-11, atol=1e-13 * np.abs(u0).max())
    with pytest.raises(ValueError, match="2n-1"):
        HalfSpace(geom, m=2 * geom.n - 2)


def test_work_arrays_are_the_owned_buffers(geom):
    op = HalfSpace(geom, threads=1)
    bufs = op.pair.work_arrays()
    assert "rows" not in bufs and all(isinstance(a, np.ndarray) for a in bufs.values())
    # real_in/out, the row spectra (one buffer: the column stage works in place in it), one
    # column lane's three block buffers; the kernel cut into column blocks, held once (the
    # operator keeps no copy of its own)
    assert len(bufs) == 7 and bufs["real_in"] is op.pair.real_in
    assert op.pair._rows_back is op.pair._rows_hat
    assert set(HalfSpace(geom, threads=3).pair.work_arrays()) - set(bufs) == {
        f"lane{i}_{k}" for i in (1, 2) for k in ("col_in", "col_hat", "col_out")}
    assert set(op.work_arrays()) == {"index"}
    assert op.pair._kernel_src is None
    table = op.table           # built lazily, on first use
    assert op.work_arrays()["table"] is table
    p = np.ones(geom.n_active)
    op.apply(p, np.empty_like(p))
    blocks = op.pair.work_arrays()["_kernel_blocks"]
    assert blocks is bufs["_kernel_blocks"]             # made once, at the build
    assert blocks.shape == (op.pair.n_blocks, op.m, len(bufs["lane0_col_in"][0]))
    assert blocks.nbytes == 8 * op.m * op.pair.n_blocks * blocks.shape[2]     # not per (re, im)



def test_stages_run_in_order_are_the_product(geom):
    """FFTPair.stages (what benchmarks/fft_stages.py times) must be the product convolve runs."""
    hs = HalfSpace(geom)
    rng = np.random.default_rng(3)
    p, q = rng.standard_normal((2, geom.n_active))
    want = hs.apply(p, np.empty_like(p)).copy()
    hs.apply(q, np.empty_like(q))                    # every internal buffer now holds q's product
    pair = hs.pair
    idx = hs.work_arrays()["index"]
    pair.real_in.reshape(-1)[idx] = p                # p's scatter, as apply does it
    pair.real_out[...] = 0
    for stage in pair.stages().values():
        stage()
    got = pair.real_out.reshape(-1)[idx]
    np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-15 * np.abs(want).max())


@pytest.mark.parametrize("backend", ["pyfftw", "numpy"])
def test_the_kernel_is_held_once_and_read_back_whole(geom, backend):
    """The operator hands its kernel transform to the pair and keeps none itself: the copy read
    back from the pair's column blocks is the transform itself (bitwise), its extremes are the
    ones the certificates read, and a product with the loaded kernel is the product with the
    array given explicitly (bitwise)."""
    from fibril_hpc.elastic.greens import kernel_spectrum
    hs = HalfSpace(geom, backend=backend)
    want = kernel_spectrum(geom.n, hs.m, geom.h)
    got = hs.kernel_hat
    assert got.shape == want.shape and np.array_equal(got, want)
    assert (hs.kernel_min, hs.kernel_max) == (float(want.min()), float(want.max()))
    assert not any(a is want for a in vars(hs).values())
    rng = np.random.default_rng(5)
    p = rng.standard_normal(geom.n_active)
    u = hs.apply(p, np.empty_like(p)).copy()
    hs.pair.convolve(want)                           # the same input rows, the kernel given
    v = hs.pair.real_out.reshape(-1)[hs.work_arrays()["index"]]
    assert np.array_equal(u, v)
    hs.pair.convolve(2.0 * want)                     # a kernel given is the one used
    v = hs.pair.real_out.reshape(-1)[hs.work_arrays()["index"]]
    np.testing.assert_allclose(v, 2.0 * u, rtol=1e-12, atol=1e-15 * np.abs(u).max())
    # read back whole where the column blocks pad the last block (m // 2 + 1 = 11, blocks of 12)
    pair = FFTPair(20, np.arange(3), backend=backend)
    k = rng.standard_normal((20, 11))
    pair.load_kernel(k)
    assert np.array_equal(pair.kernel_transform(), k)
    empty = FFTPair(hs.m, hs.pair.rows, backend=backend)
    with pytest.raises(ValueError, match="no kernel loaded"):
        empty.kernel_transform()
    with pytest.raises(ValueError, match="no kernel loaded"):
        empty.convolve()


def test_the_direct_sums_table_is_built_in_blocks_as_one_array():
    """The real-space table (built 256 rows at a time, no n x n temporaries) is Love's kernel on
    every offset of a grid wider than one block (n = 340)."""
    from fibril_hpc.elastic.greens import BUILD_BLOCK, love

    g = build_pillar_grid(20, 0.16, 8, 0.0, 0).geometry
    assert g.n > BUILD_BLOCK
    off = np.arange(g.n) * g.h
    np.testing.assert_array_equal(HalfSpace(g, threads=1).table,
                                  love(off[:, None], off[None, :], g.h))
