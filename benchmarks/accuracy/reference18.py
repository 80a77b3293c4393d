"""One resolution of the converged-reference study of the default 18 x 18 scene.

    python benchmarks/accuracy/reference18.py 20          # elements per diameter (input value)
    python benchmarks/accuracy/reference18.py 10 local footprint   # cascade, solver.criterion

Runs the default scene (Scene() with the default preset's solver knobs, one FFT thread) at the
given ``elements_per_diameter`` through the public API and appends one JSON line (F~_A, F~_P,
d~_max, the discrete elements per diameter, counts, CPU and wall seconds, load averages, git
commit, the command) to benchmarks/accuracy/reference18.jsonl. Nothing here asserts anything.
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
    epd = int(argv[0])
    cascade = argv[1] if len(argv) > 1 else "local"
    criterion = argv[2] if len(argv) > 2 else "mesh"
    from fibril_hpc import Scene, simulate

    load0 = os.getloadavg()
    t0 = time.process_time()
    r = simulate(Scene(elements_per_diameter=epd, solver={"fft_threads": 1, "cascade": cascade,
                                                              "criterion": criterion}))
    cpu = time.process_time() - t0
    head = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=HERE, capture_output=True,
                          text=True).stdout.strip()
    row = {"command": "python benchmarks/accuracy/reference18.py " + " ".join(argv),
           "status": r.status, "elements_per_diameter_input": epd,
           "elements_per_diameter": r.discretisation.get("elements_per_diameter"),
           "fft_size": r.discretisation.get("fft_size"), "cascade": cascade,
           "criterion": criterion,
           "criterion_factor": r.discretisation.get("criterion_factor", 1.0),
           "F_A": r.main.F_A, "F_P": r.main.F_P, "d_tilde_max": r.main.d_tilde_max,
           "cpu_s": cpu, **r.stats, "load_start": list(load0), "load_end": list(os.getloadavg()),
           "git": head, "utc": time.strftime("%Y-%m-%dT%H:%MZ", time.gmtime())}
    with open(os.path.join(HERE, "reference18.jsonl"), "a") as fh:
        fh.write(json.dumps(row) + "\n")
    print(json.dumps(row))
    return 0 if r.status == "ok" else 1


if __name__ == "__main__":
    sys.exit(main())
