"""The 6 x 6 brush of ``fibril-accuracy`` (``brush6``: k~ = 0.01, sigma~ = 0.5, seed 0, d~ = 18)
with a given detachment criterion, at the given resolutions.

    python benchmarks/accuracy/criterion_brush6.py footprint 6 8 10 12 14 16 20

Appends one JSON line per resolution (F~_A, F~_P, the criterion factor, counts, CPU seconds, load,
git commit) to benchmarks/accuracy/criterion_brush6.jsonl. The mesh criterion's series of the same
scene is in benchmarks/accuracy/accuracy.csv (rows ``brush6,resolution``). Asserts nothing.
"""

import json
import os
import subprocess
import sys
import time

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
HERE = os.path.dirname(os.path.abspath(__file__))


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    criterion, epds = argv[0], [float(x) for x in argv[1:]]
    from fibril_hpc import Scene, simulate

    head = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=HERE, capture_output=True,
                          text=True).stdout.strip()
    bad = 0
    for epd in epds:
        load0 = os.getloadavg()
        t0 = time.process_time()
        r = simulate(Scene(n_side=6, k_tilde=0.01, sigma_tilde=0.5, seed=0, d_tilde=18.0,
                           elements_per_diameter=epd,
                           solver={"fft_threads": 1, "criterion": criterion}))
        cpu = time.process_time() - t0
        row = {"command": "python benchmarks/accuracy/criterion_brush6.py " + " ".join(argv),
               "status": r.status, "criterion": criterion, "elements_per_diameter_input": epd,
               "elements_per_diameter": r.discretisation.get("elements_per_diameter"),
               "criterion_factor": r.discretisation.get("criterion_factor", 1.0),
               "F_A": r.main.F_A, "F_P": r.main.F_P, "cpu_s": cpu, **r.stats,
               "load_start": list(load0), "load_end": list(os.getloadavg()), "git": head,
               "utc": time.strftime("%Y-%m-%dT%H:%MZ", time.gmtime())}
        with open(os.path.join(HERE, "criterion_brush6.jsonl"), "a") as fh:
            fh.write(json.dumps(row) + "\n")
        print(json.dumps(row), flush=True)
        bad += r.status != "ok"
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
