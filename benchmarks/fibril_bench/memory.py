"""The ``memory`` section: peak resident-set growth of a solve against the arrays it must hold.

The measurement runs in a fresh process (:mod:`.memory_child`) so that imports and JIT are paid
before the peak is reset.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys

import numpy as np

from .timing import PIN_ENV

#: the checkout root, from which ``python -m benchmarks...`` runs the child
ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def memory_arrays(model, drv) -> dict:
    """Bytes of the arrays a solve must hold, by category (counts stated), from the public
    ``work_arrays()`` of each object."""
    op, sv, pc, g = model.operator, model.solver, model.solver.precond, model.geometry
    n = g.n_active
    pair_arrays = op.pair.work_arrays()
    kernel = pair_arrays.pop("_kernel_blocks", None)        # the kernel transform, held once
    fft = list(pair_arrays.values())
    own = list(sv.work_arrays().values()) + list(drv.work_arrays().values())
    vectors = [a for a in own if a.ndim == 1 and a.dtype == np.float64 and len(a) == n]
    small = [a for a in own if not any(a is v for v in vectors)]
    small += [op.work_arrays()["index"], g.iy, g.ix, g.z0, g.starts]
    pre = list(pc.work_arrays().values()) if hasattr(pc, "work_arrays") else []
    table = op.work_arrays().get("table")
    cats = {
        "fft_buffers": fft,
        "kernel_transform": [] if kernel is None else [kernel],
        "real_space_kernel_table": [] if table is None else [table],
        "active_length_float_vectors": vectors,
        "index_and_small_vectors": small,
        "preconditioner_blocks": pre,
    }
    out = {k: {"count": len(v), "bytes": int(sum(a.nbytes for a in v))} for k, v in cats.items()}
    out["total_bytes"] = int(sum(c["bytes"] for c in out.values()))
    if hasattr(pc, "cache_stats"):
        st = pc.cache_stats()
        out["preconditioner_blocks"]["cached_partial_inverses"] = st["cached_partial_inverses"]
        out["preconditioner_blocks"]["block_elements"] = st["block_elements"]
    return out


def section_memory(cfg, floors, log):
    """Peak RSS growth of a build + solve in a fresh process against the arrays it holds."""
    rows = []
    env = dict(os.environ, **PIN_ENV)
    for pitch in cfg["memory_pitches"]:
        proc = subprocess.run([sys.executable, "-m", "benchmarks.fibril_bench.memory_child",
                               str(cfg["n_side"]), str(pitch), str(cfg["d_tilde"]),
                               floors.planner],
                              capture_output=True, text=True, env=env, timeout=1800, cwd=ROOT)
        if proc.returncode != 0:
            rows.append({"pitch": pitch, "error": proc.stderr.strip().splitlines()[-1:]})
            log(f"memory pitch {pitch}: failed: {proc.stderr.strip()[-300:]}")
            continue
        r = json.loads(proc.stdout.strip().splitlines()[-1])
        # peak over the process after imports and JIT: max of the build peak and the solve peak
        growth = max(r["built"]["VmHWM"], r["after"]["VmHWM"]) - r["reset"]["VmRSS"]
        solve_growth = r["after"]["VmHWM"] - r["reset"]["VmRSS"]
        need = r["arrays"]["total_bytes"]
        row = {"pitch": pitch, "N": r["N"], "m": r["m"], "n_active": r["n_active"],
               "n_attached": r["n_attached"],
               "rss_after_imports_jit_MB": r["before"]["VmRSS"] / 2**20,
               "peak_growth_MB": growth / 2**20, "arrays_MB": need / 2**20,
               "growth_over_arrays": growth / need, "arrays": r["arrays"],
               "build_peak_growth_MB": (r["built"]["VmHWM"] - r["reset"]["VmRSS"]) / 2**20,
               "solve_peak_growth_MB": solve_growth / 2**20,
               "solve_peak_over_arrays": solve_growth / need,
               "rss_after_build_MB": r["built"]["VmRSS"] / 2**20,
               "rss_end_MB": r["after"]["VmRSS"] / 2**20}
        log(f"memory m={r['m']}: peak growth {row['peak_growth_MB']:.1f} MB vs arrays "
            f"{row['arrays_MB']:.1f} MB ({row['growth_over_arrays']:.2f}x)")
        rows.append(row)
    return rows
