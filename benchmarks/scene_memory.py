"""Peak resident memory of one simulate call against the padded FFT side m.

The memory model of ``fibril_hpc/inputs/limits.py`` comes from this. Usage:
``python benchmarks/scene_memory.py N_SIDE ELEMENTS_PER_DIAMETER`` (one preload, stopped after 3
contact events: the operator and the solver's arrays are all allocated by then).
"""

import resource
import sys
import time

from fibril_hpc import Scene, simulate


def main():
    """Print n_side, elements per diameter, m, peak RSS before/after and bytes per m^2."""
    n_side, epd = int(sys.argv[1]), float(sys.argv[2])
    sc = Scene(n_side=n_side, elements_per_diameter=epd, k_tilde=0.01, sigma_tilde=0.5,
               F_P=(0.3,), solver={"fft_threads": 1, "max_events": 3})
    r0 = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
    t = time.perf_counter()
    res = simulate(sc)
    r1 = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
    m = res.discretisation["fft_size"]
    print(f"n_side {n_side}, epd {epd:g}: m {m}, peak RSS {r0 / 2**20:.0f} -> {r1 / 2**20:.0f} "
          f"MiB, +{(r1 - r0) / 1e6:.0f} MB = {(r1 - r0) / m**2:.0f} B per m^2, "
          f"{time.perf_counter() - t:.1f} s")


if __name__ == "__main__":
    main()
