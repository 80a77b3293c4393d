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
