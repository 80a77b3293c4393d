"""Time each stage of fibril's row-pruned FFT pair (one thread, CPU time) next to the floor pair.

    python -m benchmarks.fft_stages 15 17 29 35    # pitches of an 18 x 18 brush

Used in benchmarks/NOTES.md (optimisation 2). Nothing here asserts a timing.
"""
import sys

import numpy as np

from benchmarks.fibril_bench import timing
from fibril_hpc.model import build_scene_model

for pitch in [int(x) for x in sys.argv[1:]]:
    model = build_scene_model(timing.bench_scene(18, pitch))
    op = model.operator
    pr = op.pair
    pr.real_in[...] = np.random.default_rng(0).standard_normal(pr.real_in.shape)
    st = pr.stages()                    # the operator's own kernel, loaded in its pair
    tot = 0
    res = {}
    for k, f in st.items():
        if k == "column blocks":
            # the column stage works in place on the row spectra: repeated alone it would
            # multiply by the kernel again and again (down to subnormals), so it is timed
            # after a fresh row stage each time, less that row stage's own time
            first = st["p1 r2c rows"]
            t = timing.time_call(lambda f=f, first=first: (first(), f()), 5, 0.05)
            t = t["cpu_median_s"] * 1e3 - res["p1 r2c rows"]
        else:
            t = timing.time_call(f, 5, 0.05)["cpu_median_s"] * 1e3
        res[k] = t
        tot += t
    fl = timing.floor_pair(op.m, "estimate", 5)["cpu_median_s"] * 1e3
    stages = ", ".join(f"{k} {v:.2f}" for k, v in res.items())
    print(f"m={op.m} R={len(pr.rows)} floor {fl:.2f} ms; stages sum {tot:.2f} ms: {stages}")
