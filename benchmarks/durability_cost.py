"""What two copies of every finished record cost (issue 36), side by side in one run.

* checkpoint: the checkpoint as it was (build in memory, temporary file, fsync, rename) against
  the checkpoint now (the same, plus reading the new copy back: its bytes, every record's
  ``record_id``, the new records whole with their checksums, before it is renamed into place,
  and keeping the old file as ``FILE.previous`` with a hard link), each adding 2 records to a
  synthetic file of N records (2 x 400-point curves);
* the start of a run on an existing file: copying it to ``FILE.previous``;
* one finished record: one fsync-ed journal frame (as before) against two (journal + mirror);
* disk: the file, its previous generation and the journal pair at their largest.

Usage: ``python benchmarks/durability_cost.py N [REPEATS]``; prints one table.
"""

import os
import shutil
import statistics
import sys
import tempfile
import time

from checkpoint_cost import rec

from fibril_hpc.campaign.storage import durable, store
from fibril_hpc.campaign.storage import journal as J
from fibril_hpc.campaign.storage.journal_writer import JournalWriter




def main():
    """Print medians of REPEATS side-by-side measurements."""
    n = int(sys.argv[1])
    reps = int(sys.argv[2]) if len(sys.argv) > 2 else 5
    d = tempfile.mkdtemp(prefix="durbench-")
    base = os.path.join(d, "base.h5")
    store.checkpoint(base, {"program": store.PROGRAM}, [rec(i) for i in range(n)])
    size = os.path.getsize(base)
    t = {"before": [], "now": [], "copy": [], "j1": [], "j2": []}
    old = {r["key"]: r["record_id"] for r in store.read_h5_records(base, curves=False)[1].values()}
    frame = J.encode(dict(rec(10**6), type="job"))
    for rep in range(reps):
        for kind in ("before", "now"):
            p = os.path.join(d, kind + ".h5")
            shutil.copyfile(base, p)
            add = [rec(n + 10 * rep + j) for j in range(2)]
            t0 = time.perf_counter()
            if kind == "before":
                store.checkpoint(p, {"program": store.PROGRAM}, add)
            else:
                expect = dict(old, **{r["key"]: r["record_id"] for r in add})
                store.checkpoint(p, {"program": store.PROGRAM}, add, keep_previous=True,
                                 verify=lambda tmp, e=expect, a=add: store.check_written(
                                     tmp, e, [r["key"] for r in a]))          # as the writer
            t[kind].append(time.perf_counter() - t0)
        p = os.path.join(d, "now.h5")
        t0 = time.perf_counter()
        durable.keep_copy(p)
        t["copy"].append(time.perf_counter() - t0)
        for kind, two in (("j1", False), ("j2", True)):
            jp = os.path.join(d, kind + ".journal")
            for f in (jp, J.mirror_path(jp)):
                if os.path.exists(f):
                    os.unlink(f)
            if two:
                w = JournalWriter(jp)
                t0 = time.perf_counter()
                for _ in range(10):
                    w.append(dict(rec(rep), type="job"))
                t[kind].append((time.perf_counter() - t0) / 10)
                w.close()
            else:
                fd = os.open(jp, os.O_WRONLY | os.O_CREAT | os.O_APPEND, 0o644)
                t0 = time.perf_counter()
                for _ in range(10):
                    os.write(fd, frame)
                    os.fsync(fd)
                t[kind].append((time.perf_counter() - t0) / 10)
                os.close(fd)
    m = {k: statistics.median(v) * 1e3 for k, v in t.items()}
    print(f"records {n}, file {size / 2**20:.1f} MiB, frame {len(frame) / 1024:.1f} KiB, "
          f"medians of {reps}")
    print(f"  checkpoint before {m['before']:.0f} ms, now {m['now']:.0f} ms "
          f"(ratio {m['now'] / m['before']:.2f})")
    print(f"  start of a run on the file: copy to FILE.previous {m['copy']:.0f} ms")
    print(f"  one record: one journal {m['j1']:.1f} ms, journal + mirror {m['j2']:.1f} ms "
          f"(ratio {m['j2'] / m['j1']:.2f})")
    print(f"  disk at the largest: file + previous = {2 * size / 2**20:.1f} MiB, plus the "
          "journal pair: 2 x the records of the last two checkpoint intervals")
    shutil.rmtree(d)


if __name__ == "__main__":
    main()
