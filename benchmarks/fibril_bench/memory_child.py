"""Child process of the ``memory`` section: one build + contact solve, RSS read from /proc.

    python -m benchmarks.fibril_bench.memory_child N_SIDE PITCH D_TILDE PLANNER

Prints one JSON line: the VmRSS/VmHWM at each step (the peak is reset through
/proc/self/clear_refs after imports and JIT), and the arrays the solve holds.
"""

from __future__ import annotations

import json
import sys

from fibril_hpc.model import build_scene_model
from fibril_hpc.path.loading import PathDriver

from .memory import memory_arrays
from .timing import bench_scene


def status() -> dict:
    """VmRSS and VmHWM of this process, in bytes."""
    d = {}
    with open("/proc/self/status") as fh:
        for line in fh:
            if line.startswith(("VmRSS", "VmHWM")):
                k, v = line.split(":")
                d[k] = int(v.split()[0]) * 1024
    return d


def reset_peak() -> None:
    """Reset the peak (VmHWM) to the current RSS."""
    with open("/proc/self/clear_refs", "w") as fh:
        fh.write("5")


def main(argv) -> dict:
    """Measure one (n_side, pitch) scene; returns the JSON-able record."""
    n_side, pitch, d_tilde, planner = int(argv[0]), int(argv[1]), float(argv[2]), argv[3]
    # JIT / cache load and imports on a tiny model first
    m0 = build_scene_model(bench_scene(2, 5, solver={"fft_planner": planner}))
    PathDriver(m0).solve_at(1.0 * m0.scaling.d_c)
    del m0
    before = status()
    reset_peak()
    reset = status()
    model = build_scene_model(bench_scene(n_side, pitch, solver={"fft_planner": planner}))
    drv = PathDriver(model)
    built = status()
    reset_peak()
    built_reset = status()
    drv.solve_at(d_tilde * model.scaling.d_c)
    after = status()
    return {"before": before, "reset": reset, "built": built, "built_reset": built_reset,
            "after": after, "arrays": memory_arrays(model, drv),
            "N": model.geometry.n, "m": model.operator.m,
            "n_active": model.geometry.n_active, "n_attached": int(drv.att.sum())}


if __name__ == "__main__":
    print(json.dumps(main(sys.argv[1:])))
