"""Prototype: the row-pruned FFT pair with its column stage on a transposed (w x m) array, so that
the big c2c transforms are contiguous; compared with fibril's FFTPair (same output to rounding), one
thread, CPU time.

    python -m benchmarks.transposed_pair 15 17 29 35    # pitches of an 18 x 18 brush

Used in benchmarks/NOTES.md (optimisation 8). Nothing here asserts a timing.
"""
import sys

import numpy as np
import pyfftw

from benchmarks.fibril_bench import timing
from fibril_hpc.model import build_scene_model


class TransposedPair:
    """Row-pruned pair whose column stage runs on a transposed (w x m) array: contiguous c2c."""

    def __init__(self, m, rows, planner="estimate"):
        self.m, self.rows = m, np.asarray(rows)
        r, w = len(rows), m // 2 + 1
        z = pyfftw.zeros_aligned
        self.real_in = z((r, m))
        self.rows_hat = z((r, w), dtype=complex)
        self.T = z((w, m), dtype=complex)
        self.rows_back = z((r, w), dtype=complex)
        self.real_out = z((r, m))
        fl = ({"estimate": "FFTW_ESTIMATE", "measure": "FFTW_MEASURE"}[planner],)
        self.p1 = pyfftw.FFTW(self.real_in, self.rows_hat, axes=(1,), flags=fl, threads=1)
        self.p2 = pyfftw.FFTW(self.T, self.T, axes=(1,), flags=fl, threads=1)
        self.p3 = pyfftw.FFTW(self.T, self.T, axes=(1,), direction="FFTW_BACKWARD", flags=fl,
                              threads=1)
        self.p4 = pyfftw.FFTW(self.rows_back, self.real_out, axes=(1,), direction="FFTW_BACKWARD",
                              flags=fl + ("FFTW_DESTROY_INPUT",), threads=1)
        for a in (self.real_in, self.rows_hat, self.T, self.rows_back, self.real_out):
            a[...] = 0

    def convolve(self, kernel_hat_T):
        self.p1.execute()
        self.T[:, self.rows] = self.rows_hat.T
        self.p2.execute()
        np.multiply(self.T, kernel_hat_T, out=self.T)
        self.p3.execute()
        self.rows_back[...] = self.T[:, self.rows].T
        self.p4.execute()

for pitch in [int(x) for x in sys.argv[1:]]:
    model = build_scene_model(timing.bench_scene(18, pitch))
    op = model.operator
    pr = op.pair
    tp = TransposedPair(op.m, pr.rows)
    khT = np.ascontiguousarray(op.kernel_hat.T)
    x = np.random.default_rng(0).standard_normal(pr.real_in.shape)
    pr.real_in[...] = x
    tp.real_in[...] = x
    pr.convolve()                       # the operator's own kernel, loaded in its pair
    tp.convolve(khT)
    err = np.abs(pr.real_out - tp.real_out).max() / np.abs(pr.real_out).max()
    cur = pr.convolve
    a = timing.time_call(cur, 5)["cpu_median_s"] * 1e3
    b = timing.time_call(lambda tp=tp, kh=khT: tp.convolve(kh), 5)["cpu_median_s"] * 1e3
    a2 = timing.time_call(cur, 5)["cpu_median_s"] * 1e3
    print(f"m={op.m}: current {a:.2f}/{a2:.2f} ms, transposed {b:.2f} ms, "
          f"speedup {min(a, a2) / b:.2f}x, max rel diff {err:.1e}")
