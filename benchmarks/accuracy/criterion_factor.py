"""The footprint criterion's factor c (``fibril_hpc.path.criterion.footprint_factor``) and the lone
pillar's mesh-criterion error against Kendall (1/c - 1), square and hexagonal lattices.

    python benchmarks/accuracy/criterion_factor.py 4 5 6 8 10 12 16 20 25 32 40 48 64

One line per resolution and lattice: elements per diameter requested and nominal, elements per
footprint, c, the error, CPU seconds of the calibration solve. Asserts nothing.
"""

import os
import sys
import time

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")


def main(argv=None) -> int:
    from fibril_hpc import Scene
    from fibril_hpc.api import calibrate
    from fibril_hpc.model import scene_lattice

    for epd in [float(x) for x in (sys.argv[1:] if argv is None else argv)]:
        for lat in ("square", "hexagonal"):
            s = Scene(elements_per_diameter=epd, lattice=lat,
                      solver={"criterion": "footprint", "fft_threads": 1})
            t = time.process_time()
            c = calibrate(s)
            t = time.process_time() - t
            L = scene_lattice(s)
            print(f"{lat:9s} epd_in {epd:5.1f} epd {2 * L.radius:6.2f} elements "
                  f"{L.elements_per_pillar:5d} c {c:.5f} mesh_err {100 * (1 / c - 1):+.2f}% "
                  f"cpu {t:.2f}s", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
