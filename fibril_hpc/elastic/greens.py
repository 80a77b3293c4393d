"""Love's influence coefficients and the transformed, zero-padded kernel (docs/model.md §3).

Pure functions: no plans, no state. The displacement at the centre of an element at offset
(X, Y) from a square element of side h carrying unit uniform pressure is (Love 1929)

    K(X, Y) = 1/(pi E*) [F(X+a, Y+a) - F(X+a, Y-a) - F(X-a, Y+a) + F(X-a, Y-a)],  a = h/2,
    F(xi, eta) = xi ln(eta + r) + eta ln(xi + r),  r = sqrt(xi^2 + eta^2).

It is evaluated at |X|, |Y| in an asinh form: ln(eta + r) = asinh(eta/|xi|) + ln|xi|, and the
ln|xi| (ln|eta|) parts cancel exactly between the pairs of terms sharing xi (eta), which removes the
catastrophic cancellation of the naive formula at large offsets.
"""

from __future__ import annotations

import math

import numpy as np

from ..geometry.scaling import E_STAR

#: K(0, 0) in units of h/E*: (4/pi) ln(1 + sqrt 2)
K00 = 4.0 / math.pi * math.log(1.0 + math.sqrt(2.0))


def _g(xi, eta):
    """xi asinh(eta/|xi|) + eta asinh(xi/|eta|), with the xi -> 0 and eta -> 0 limits (0)."""
    axi = np.abs(xi)
    aeta = np.abs(eta)
    t1 = np.where(axi > 0, xi * np.arcsinh(eta / np.where(axi > 0, axi, 1.0)), 0.0)
    t2 = np.where(aeta > 0, eta * np.arcsinh(xi / np.where(aeta > 0, aeta, 1.0)), 0.0)
    return t1 + t2


def love(x, y, h, e_star=E_STAR):
    """Surface displacement at offset (x, y) due to unit pressure on an h x h square.

    Parameters
    ----------
    x, y : array_like
        Offsets between element centres (any sign; K is even in both).
    h : float
        Element side.
    e_star : float
        Contact modulus E*.

    Returns
    -------
    ndarray
        K(x, y) (length / (pressure) units: u = K p).
    """
    x = np.abs(np.asarray(x, dtype=np.float64))
    y = np.abs(np.asarray(y, dtype=np.float64))
    a = 0.5 * h
    s = _g(x + a, y + a) - _g(x + a, y - a) - _g(x - a, y + a) + _g(x - a, y - a)
    return s / (math.pi * e_star)


#: Relative cost per radix pass of FFTW's codelets, fitted to the measured row-pruned pair at
#: every 7-smooth candidate for n = 306 and 522 (benchmarks/padded_size.py; benchmarks/NOTES.md
#: §11):
#: radix 3 is dearer (2.0, was 1.7) and 7 cheaper (3.4, was 3.6) than the first guess, which
#: picked 1080 for n = 522 where 1050 measured 1.15-1.21x faster.
_RADIX_COST = {2: 1.0, 3: 2.0, 5: 2.6, 7: 3.4}


def _fft_cost(m: int) -> float:
    """Rough cost model of a real 2-D FFT of side m: m^2 times the summed radix costs, with odd
    sides (slow real transforms) penalised."""
    k, total = m, 0.0
    for p, w in _RADIX_COST.items():
        while k % p == 0:
            k //= p
            total += w
    return m * m * total * (1.0 if m % 2 == 0 else 1.3)


def padded_size(n: int) -> int:
    """FFT side of the non-periodic product on n x n: the 7-smooth size >= 2n - 1 (at most 15 %
    above it) that the cost model ranks cheapest. Odd and 5^k-heavy sizes are avoided: at the
    default brush (2n - 1 = 611), 640 instead of 625 made a CG iteration 1.4-1.6x faster
    (measured by fibril-bench); at n = 522 it picks 1050 (1080 measured 1.15x slower)."""
    need = 2 * n - 1
    cands = []
    p2 = 1
    while p2 < 2 * need:
        p3 = p2
        while p3 < 2 * need:
            p5 = p3
            while p5 < 2 * need:
                p7 = p5
                while p7 < 2 * need:
                    if p7 >= need:
                        cands.append(p7)
                    p7 *= 7
                p5 *= 5
            p3 *= 3
        p2 *= 2
    smallest = min(cands)
    window = [m for m in cands if m <= max(smallest, int(1.15 * need))]
    return min(window, key=lambda m: (_fft_cost(m), m))


def wrapped_kernel(n: int, m: int, h: float, e_star=E_STAR) -> np.ndarray:
    """Love's kernel sampled on an m x m grid with wrapped offsets min(i, m - i) h.

    With m >= 2n - 1 the circular convolution with this kernel equals the linear
    (non-periodic) one on the n x n corner. The kernel is even in both axes, so its transform is
    real.
    """
    if m < 2 * n - 1:
        raise ValueError(f"padded size {m} < 2n-1 = {2 * n - 1}")
    i = np.arange(m)
    off = np.minimum(i, m - i) * h
    return love(off[:, None], off[None, :], h, e_star)


#: rows (then columns) per block of the kernel transform's build (see :func:`kernel_spectrum`)
BUILD_BLOCK = 256


def kernel_spectrum(n: int, m: int, h: float, e_star=E_STAR, block: int = BUILD_BLOCK) -> np.ndarray:
    """Real transform of the wrapped kernel, divided by m*m (folds the unnormalised inverse FFT).

    Shape (m, m//2 + 1), float64 (the imaginary part is zero to rounding and is dropped).
    Computed as ``np.fft.rfft2(wrapped_kernel(n, m, h)).real / (m * m)`` is, one 1-D transform
    per row and then one per column, with the same numbers (each line's transform is the same;
    tests/test_greens.py), but without the m x m kernel and its temporaries: the wrapped kernel's
    rows i and m - i are the same, so only the m/2 + 1 distinct rows are evaluated (``block``
    at a time) and transformed, and the columns are transformed ``block`` at a time from them.
    The build peaks at those row spectra and the result, about 8 bytes per m^2 in all (16 per
    m^2/4 and 8 per m^2/2), where the whole-array transform took a dozen m x m temporaries
    (benchmarks/NOTES.md, "The kernel transform built in blocks").
    """
    if m < 2 * n - 1:
        raise ValueError(f"padded size {m} < 2n-1 = {2 * n - 1}")
    if block < 1:
        raise ValueError(f"block = {block}: at least one row and column at a time")
    w = m // 2 + 1                          # columns of the result, and distinct rows 0 ... m // 2
    off = np.arange(m) * h
    off[w:] = off[1:m - w + 1][::-1]        # min(i, m - i) h
    rows = np.empty((w, w), dtype=np.complex128)
    for a in range(0, w, block):
        e = min(a + block, w)
        rows[a:e] = np.fft.rfft(love(off[a:e, None], off[None, :], h, e_star), axis=1)
    mirror = np.minimum(np.arange(m), m - np.arange(m))     # row i is distinct row mirror[i]
    out = np.empty((m, w))
    for c in range(0, w, block):
        out[:, c:c + block] = np.fft.fft(rows[mirror, c:c + block], axis=0).real
    del rows
    out /= m * m
    return out
