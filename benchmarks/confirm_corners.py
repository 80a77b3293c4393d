"""One corner scene under ``confirm: global`` and ``confirm: local``, in one process, the
reference first (seed 0, F~_P = 4; the issue's corners are k~ 10, 1, 0.01, 0.001 and sigma~
0.01, 0.1, 0.5, 2.1):

    python benchmarks/confirm_corners.py N_SIDE PRESET K_TILDE SIGMA_TILDE

Prints one line: F~_A of both and their difference, FFT pairs, CPU seconds, events and the
relaxations kept locally. Nothing here asserts a time.
"""

from __future__ import annotations

import sys
import time


def main(argv=None) -> int:
    from fibril_hpc import Scene, simulate

    args = sys.argv[1:] if argv is None else argv
    n, preset, k, s = int(args[0]), args[1], float(args[2]), float(args[3])
    out = {}
    for confirm in ("global", "local"):
        scene = Scene(n_side=n, k_tilde=k, sigma_tilde=s, F_P=(4.0,), seed=0, preset=preset,
                      solver={"confirm": confirm})
        t = time.process_time()
        r = simulate(scene)
        t = time.process_time() - t
        out[confirm] = (r.main.F_A, r.stats["fft_pairs"], t, r.stats.get("confirmed_local", 0),
                        r.stats["events"], r.status)
    a, b = out["global"], out["local"]
    print(f"n {n} {preset} k~ {k:g} sigma~ {s:g}: F_A {a[0]:.8f} / {b[0]:.8f} rel "
          f"{(b[0] - a[0]) / a[0]:.1e} abs {b[0] - a[0]:.1e}; pairs {a[1]} / {b[1]} "
          f"({b[1] / a[1]:.2f}); CPU {a[2]:.1f} / {b[2]:.1f}; events {a[4]} / {b[4]}; "
          f"local {b[3]}; {a[5]} {b[5]}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
