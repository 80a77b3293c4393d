"""Run one fibril-hpc command whose output is held at a barrier just before it is written, so
that two commands started together reach their no-overwrite step at the same moment (the test
of races, tests/test_races.py).

``python race_hook.py BARRIER_DIR N PROGRAM TARGET ARGS...``: PROGRAM is ``campaign`` or
``run``; the command's first free-space check before writing a file (every atomic write
makes one) and its ``mkdir`` of TARGET wait until N processes have reached the barrier. Nothing
of the command's own logic is changed."""

from __future__ import annotations

import os
import sys
import time


def _wait(barrier: str, n: int) -> None:
    open(os.path.join(barrier, str(os.getpid())), "w").close()
    t0 = time.monotonic()
    while len(os.listdir(barrier)) < n and time.monotonic() - t0 < 60:
        time.sleep(0.0005)


def main() -> int:
    barrier, n, program, target, argv = (sys.argv[1], int(sys.argv[2]), sys.argv[3],
                                          os.path.abspath(sys.argv[4]), sys.argv[5:])
    from fibril_hpc.io import files

    held = []

    def once():
        if not held:
            held.append(1)
            _wait(barrier, n)

    real_free, real_mkdir = files.free_bytes, os.mkdir

    def free_bytes(folder):
        once()
        return real_free(folder)

    def mkdir(path, *a, **kw):
        if os.path.abspath(os.fspath(path)) == target:
            once()
        return real_mkdir(path, *a, **kw)

    files.free_bytes = free_bytes
    os.mkdir = mkdir
    if program == "run":
        from fibril_hpc.cli.run import main as cli
    else:
        from fibril_hpc.cli.campaign import main as cli
    return cli(argv)


if __name__ == "__main__":
    sys.exit(main())
