"""Clocks, repeated timing, the floor FFT pair, and the scenes of the benchmark.

The clock (``"cpu"``: this process's CPU time, robust on a shared machine; or ``"wall"``) is a
parameter of every function that reports a time; both clocks are always recorded.
"""

from __future__ import annotations

import math
import os
import statistics
import time

import numpy as np

from fibril_hpc import Scene
from fibril_hpc.geometry.grid import pitch_elements

PHI = 0.16
PIN_ENV = {"OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1", "MKL_NUM_THREADS": "1",
           "NUMBA_NUM_THREADS": "1"}
FLAG = {"estimate": "FFTW_ESTIMATE", "measure": "FFTW_MEASURE"}


class Stopwatch:
    """Wall and CPU seconds of a block; ``.t`` is the one ``clock`` selects."""

    def __init__(self, clock: str = "cpu"):
        self.clock = clock

    def __enter__(self):
        self._w, self._c = time.perf_counter(), time.process_time()
        return self

    def __exit__(self, *exc):
        self.wall = time.perf_counter() - self._w
        self.cpu = time.process_time() - self._c
        self.t = self.cpu if self.clock == "cpu" else self.wall
        return False


def epd_for_pitch(pitch: int, phi: float = PHI) -> float:
    """An ``elements_per_diameter`` whose pitch (nearest odd whole number) is ``pitch``."""
    e = pitch / math.sqrt(math.pi / (4.0 * phi))
    if pitch_elements(phi, e) != pitch:     # pragma: no cover - guards the formula
        raise ValueError(f"no elements_per_diameter gives pitch {pitch}")
    return e


def time_call(fn, runs: int = 5, min_s: float = 0.05, clock: str = "cpu") -> dict:
    """Seconds per call of ``fn`` over ``runs`` batches of >= ``min_s``: median and min of the
    wall clock, and median of this process's CPU time (robust when the machine is shared)."""
    fn()                                      # warm (page faults, caches)
    t0 = time.process_time()
    fn()
    one = max(time.process_time() - t0, 1e-6)
    k = max(1, int(min_s / one))
    per, cpu = [], []
    for _ in range(runs):
        t0, c0 = time.perf_counter(), time.process_time()
        for _ in range(k):
            fn()
        per.append((time.perf_counter() - t0) / k)
        cpu.append((time.process_time() - c0) / k)
    out = {"wall_median_s": statistics.median(per), "wall_min_s": min(per), "wall_samples_s": per,
           "cpu_median_s": statistics.median(cpu), "cpu_samples_s": cpu, "calls_per_sample": k}
    out["median_s"] = out["cpu_median_s" if clock == "cpu" else "wall_median_s"]
    return out


def loadavg() -> list:
    """The 1, 5 and 15 minute load averages (empty where unknown)."""
    try:
        return [round(x, 2) for x in os.getloadavg()]
    except OSError:  # pragma: no cover
        return []


def bench_scene(n_side, pitch, **kw) -> Scene:
    """An ``n_side`` x ``n_side`` scene of pitch ``pitch`` elements, one FFT thread."""
    solver = {"fft_threads": 1}
    solver.update(kw.pop("solver", {}))
    return Scene(n_side=n_side, phi=PHI, elements_per_diameter=epd_for_pitch(pitch),
                 solver=solver, **kw)


class FloorCache:
    """The measured floor pair per padded size (measured once per run of the bench)."""

    def __init__(self, planner: str, runs: int, clock: str = "cpu"):
        self.planner = planner
        self.runs = runs
        self.clock = clock
        self.data: dict = {}

    def get(self, m: int) -> dict:
        if m not in self.data:
            self.data[m] = floor_pair(m, self.planner, self.runs, self.clock)
        return self.data[m]

    def seconds(self, m: int) -> float:
        return self.get(m)["median_s"]


def floor_pair(m: int, planner: str = "estimate", runs: int = 5, clock: str = "cpu") -> dict:
    """A plain pyFFTW rfft2 + irfft2 pair on an m x m float64 grid, one thread."""
    import pyfftw

    a = pyfftw.empty_aligned((m, m), dtype=np.float64)
    spec = pyfftw.empty_aligned((m, m // 2 + 1), dtype=np.complex128)
    b = pyfftw.empty_aligned((m, m), dtype=np.float64)
    t0 = time.perf_counter()
    fwd = pyfftw.FFTW(a, spec, axes=(0, 1), flags=(FLAG[planner],), threads=1)
    inv = pyfftw.FFTW(spec, b, axes=(0, 1), direction="FFTW_BACKWARD",
                      flags=(FLAG[planner], "FFTW_DESTROY_INPUT"), threads=1)
    plan_s = time.perf_counter() - t0
    a[...] = np.random.default_rng(0).standard_normal((m, m))

    def pair():
        fwd.execute()
        inv.execute()

    out = time_call(pair, runs, clock=clock)
    out.update({"m": m, "planner": FLAG[planner], "threads": 1, "plan_s": plan_s,
                "what": "pyFFTW rfft2 + irfft2 (FFTW r2c + c2r, full m x m, unnormalised)"})
    return out
