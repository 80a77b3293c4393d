"""Peak resident memory of one simulate call against the padded FFT side m, beside the memory
check's estimate.

The memory model of ``fibril_hpc/inputs/limits.py`` comes from this. Usage:
``python benchmarks/scene_memory.py N_SIDE ELEMENTS_PER_DIAMETER [MAX_EVENTS [PRELOADS
[MAX_WALL_S]]]``: one preload (F~_P = 0.3), stopped after MAX_EVENTS contact events, 3 unless
given (the operator and the solver's arrays are all allocated by then); with PRELOADS > 1 a
grouped path through F~_P = 0.002, 0.004, ... (PRELOADS of them, one snapshot kept per preload
until its branch runs), stopped by MAX_WALL_S. Prints one line of ``key=value`` fields: the
grid, its active elements, the peak RSS of the whole process and its growth over the call, and
the estimate that ``fibril-run`` checks against the memory available.
"""

import resource
import sys
import time

from fibril_hpc import Scene, simulate
from fibril_hpc.inputs.limits import memory_estimate


def peak_rss() -> int:
    """Peak resident bytes of this process: ``VmHWM`` of /proc/self/status (reset by exec), or
    ``ru_maxrss`` where there is none (Linux keeps that one across exec: a child started by a
    large process, a test run, would report its parent's peak)."""
    try:
        with open("/proc/self/status") as fh:
            for line in fh:
                if line.startswith("VmHWM:"):
                    return int(line.split()[1]) * 1024
    except OSError:
        pass
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024


def main():
    """Print one line: the scene, m, peak RSS before/after, bytes per m^2 and the estimate."""
    n_side, epd = int(sys.argv[1]), float(sys.argv[2])
    events = int(sys.argv[3]) if len(sys.argv) > 3 else 3
    preloads = int(sys.argv[4]) if len(sys.argv) > 4 else 1
    wall = float(sys.argv[5]) if len(sys.argv) > 5 else 3600.0
    f_p = (0.3,) if preloads == 1 else tuple(0.002 * 2**i for i in range(preloads))
    sc = Scene(n_side=n_side, elements_per_diameter=epd, k_tilde=0.01, sigma_tilde=0.5,
               F_P=f_p, solver={"fft_threads": 1, "max_events": events, "max_wall_s": wall})
    est = memory_estimate(sc)[0]
    r0 = peak_rss()
    t = time.perf_counter()
    res = simulate(sc)
    r1 = peak_rss()
    d = res.discretisation
    m = d["fft_size"]
    print(f"n_side={n_side} epd={epd:g} preloads={preloads} grid={d['grid_side']} m={m} "
          f"active={d['n_active']} "
          f"rss_before_MiB={r0 / 2**20:.0f} rss_peak_MiB={r1 / 2**20:.0f} "
          f"growth_B_per_m2={(r1 - r0) / m**2:.1f} peak_B_per_m2={r1 / m**2:.1f} "
          f"estimate_MiB={est / 2**20:.0f} estimate_over_peak={est / r1:.2f} "
          f"wall_s={time.perf_counter() - t:.1f} status={res.status} "
          f"message={str(res.message)[:100].replace(' ', '_')}", flush=True)


if __name__ == "__main__":
    main()
