"""Measured cost of fibril's row-pruned FFT pair at every candidate padded size, beside the cost
model of ``greens.padded_size``.

    python benchmarks/padded_size.py 306 522        # grid sides n (18 x 18 brush at 8 and ~14 el/D)

For each n: every 7-smooth m in [2n - 1, 1.15 (2n - 1)], the pair timed (CPU, one thread,
FFTW_ESTIMATE, median of --repeat blocks of 20 pairs, candidates interleaved so they share the
machine's load) with 45 % of the rows active (a brush at phi = 0.16), the model's cost and its
rank. Nothing here asserts a timing.
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time

import numpy as np


def candidates(n):
    need = 2 * n - 1
    out = []
    for m in range(need, int(1.15 * need) + 1):
        k = m
        for p in (2, 3, 5, 7):
            while k % p == 0:
                k //= p
        if k == 1:
            out.append(m)
    return out


def main(argv=None) -> int:
    p = argparse.ArgumentParser()
    p.add_argument("n", type=int, nargs="+")
    p.add_argument("--repeat", type=int, default=7)
    args = p.parse_args(argv)
    from fibril_hpc.elastic.fft import FFTPair
    from fibril_hpc.elastic.greens import _fft_cost, padded_size

    print(f"load average {os.getloadavg()[0]:.1f}")
    for n in args.n:
        ms = candidates(n)
        pairs = {}
        for m in ms:
            rows = np.unique(np.linspace(0, n - 1, int(0.45 * n)).astype(int))
            pr = FFTPair(m, rows)
            pr.real_in[...] = np.random.default_rng(0).standard_normal(pr.real_in.shape)
            pairs[m] = (pr, np.random.default_rng(1).random((m, m // 2 + 1)))
        times = {m: [] for m in ms}
        for _ in range(args.repeat):
            for m in ms:
                pr, kh = pairs[m]
                t = time.process_time()
                for _ in range(20):
                    pr.convolve(kh)
                times[m].append((time.process_time() - t) / 20 * 1e3)
        med = {m: statistics.median(v) for m, v in times.items()}
        best = min(med, key=med.get)
        print(f"n = {n} (2n-1 = {2 * n - 1}); padded_size picks {padded_size(n)}; fastest measured {best}")
        print(f"{'m':>6s} {'ms/pair':>8s} {'x best':>7s} {'model':>10s} {'model x':>8s}")
        c0 = _fft_cost(best)
        for m in ms:
            print(f"{m:6d} {med[m]:8.2f} {med[m] / med[best]:7.2f} {_fft_cost(m):10.3g} "
                  f"{_fft_cost(m) / c0:8.2f}")
    print(f"load average {os.getloadavg()[0]:.1f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
