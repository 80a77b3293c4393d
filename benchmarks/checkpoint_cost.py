"""Checkpoint cost of a campaign file, side by side in one run.

Now (issue 12): the new file is built in memory and written once (temporary file + rename).
Before: the file was copied beside itself and h5py appended to the copy on disk. Both add 2
records to the same synthetic file of N records (2 x 400-point curves each), 5 times.
Usage: ``python benchmarks/checkpoint_cost.py N``.
"""

import os
import resource
import shutil
import statistics
import sys
import tempfile
import time
import uuid

import h5py
import numpy as np

from fibril_hpc.campaign.storage import store


def rec(i, n=400):
    """A synthetic done record with curves of n points."""
    rng = np.random.default_rng(i)
    c = {"d_tilde": rng.random(n), "F_tilde": rng.random(n), "contact_fraction": rng.random(n),
         "n_pillars_in_contact": rng.integers(0, 99, n)}
    return {"key": f"{i:016x}", "record_id": uuid.uuid4().hex, "campaign_hash": "a" * 64,
            "k_tilde": 1.0, "sigma_tilde": 0.5, "preload_kind": "F_P", "preload": 1.0,
            "seed": i, "status": "done", "message": "", "F_P": 1.0, "F_A": 0.5,
            "scene_yaml": "x: 1\n" * 40, "loading": c, "unloading": c}


def old_checkpoint(path, records):
    """The former checkpoint: copy on disk, append with h5py, fsync, rename."""
    fd, tmp = tempfile.mkstemp(prefix=".old-", dir=os.path.dirname(path))
    os.close(fd)
    shutil.copyfile(path, tmp)
    with h5py.File(tmp, "a") as fh:
        jobs = fh.require_group("jobs")
        for r in records:
            store.write_record(jobs, r)     # same record writer (with checksum) for both
        fh.attrs["updated"] = store.now()
    with open(tmp, "rb+") as fh:
        os.fsync(fh.fileno())
    os.replace(tmp, path)


def main():
    """Print the median checkpoint time of both ways and the peak resident memory."""
    n = int(sys.argv[1])
    d = tempfile.mkdtemp(prefix="ckbench-")
    base = os.path.join(d, "base.h5")
    store.checkpoint(base, {"program": store.PROGRAM}, [rec(i) for i in range(n)])
    size = os.path.getsize(base)
    res = {"new": [], "old": []}
    for rep in range(5):
        for kind in ("new", "old"):
            p = os.path.join(d, kind + ".h5")
            shutil.copyfile(base, p)
            add = [rec(n + 10 * rep + j) for j in range(2)]
            t = time.perf_counter()
            if kind == "new":
                store.checkpoint(p, {"program": store.PROGRAM}, add)
            else:
                old_checkpoint(p, add)
            res[kind].append(time.perf_counter() - t)
    new, old = statistics.median(res["new"]), statistics.median(res["old"])
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(f"records {n}, file {size / 2**20:.1f} MiB: median checkpoint in memory "
          f"{new * 1e3:.0f} ms, copy on disk {old * 1e3:.0f} ms, ratio {new / old:.2f}; "
          f"peak RSS {rss:.0f} MiB")
    shutil.rmtree(d)


if __name__ == "__main__":
    main()
