import math

import numpy as np
import pytest

from fibril_hpc.elastic.greens import K00, kernel_spectrum, love, padded_size, wrapped_kernel


def naive_love(x, y, h):
    a = h / 2

    def F(xi, eta):
        r = math.hypot(xi, eta)
        return xi * math.log(eta + r) + eta * math.log(xi + r)

    return (F(x + a, y + a) - F(x + a, y - a) - F(x - a, y + a) + F(x - a, y - a)) / math.pi


def test_self_influence():
    assert love(0.0, 0.0, 1.0) == pytest.approx(1.12220, abs=1e-5)
    assert love(0.0, 0.0, 0.3) == pytest.approx(K00 * 0.3, rel=1e-14)


@pytest.mark.parametrize("x,y", [(1.0, 0.0), (2.0, 3.0), (5.0, 1.0), (7.5, 7.5)])
def test_matches_naive_formula_at_moderate_offsets(x, y):
    assert love(x, y, 1.0) == pytest.approx(naive_love(x, y, 1.0), rel=1e-9)


def test_even_and_far_field_point_load():
    h = 1.0
    for x, y in [(3.0, 4.0), (10.0, 2.0)]:
        v = love(x, y, h)
        assert love(-x, y, h) == v and love(x, -y, h) == v and love(-x, -y, h) == v
        assert love(y, x, h) == pytest.approx(v, rel=1e-13)
    # far away the element acts as a point force h^2 at distance r: u = h^2/(pi r)
    r = 400.0
    assert love(r, 0.0, h) == pytest.approx(h * h / (math.pi * r), rel=1e-5)
    assert love(r / math.sqrt(2), r / math.sqrt(2), h) == pytest.approx(h * h / (math.pi * r), rel=1e-5)


def test_padded_size_is_smooth_and_large_enough():
    for n in (1, 5, 23, 234, 414, 630):
        m = padded_size(n)
        assert m >= 2 * n - 1
        k = m
        for p in (2, 3, 5, 7):
            while k % p == 0:
                k //= p
        assert k == 1


def test_spectrum_is_real_for_even_kernel():
    n, m, h = 7, padded_size(7), 0.1
    k = wrapped_kernel(n, m, h)
    full = np.fft.rfft2(k)
    assert np.max(np.abs(full.imag)) < 1e-12 * np.max(np.abs(full.real))
    assert kernel_spectrum(n, m, h).dtype == np.float64


@pytest.mark.parametrize("n, m, block", [(7, 13, 4), (7, 14, 256), (100, 210, 16), (306, 640, 48)])
def test_spectrum_built_in_blocks_is_the_full_transform(n, m, block):
    """The blocked build (rows, then columns, ``block`` at a time; odd and even m, blocks that
    do not divide m) gives the numbers of one rfft2 of the whole wrapped kernel (bitwise on the
    numpy measured; 2e-15 here so that another FFT build cannot turn this red by rounding)."""
    h = 0.37
    full = np.fft.rfft2(wrapped_kernel(n, m, h)).real / (m * m)
    got = kernel_spectrum(n, m, h, block=block)
    assert got.shape == (m, m // 2 + 1) and got.flags.c_contiguous
    np.testing.assert_allclose(got, full, rtol=2e-15, atol=2e-15 * np.abs(full).max())
    assert np.array_equal(got, kernel_spectrum(n, m, h))     # the block size changes nothing


def test_spectrum_refuses_a_grid_too_small_for_the_linear_convolution():
    with pytest.raises(ValueError, match="2n-1"):
        kernel_spectrum(10, 18, 0.1)
    for block in (0, -3):
        with pytest.raises(ValueError, match="at least one"):
            kernel_spectrum(5, 9, 0.1, block=block)
