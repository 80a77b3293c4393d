"""What every benchmark records about the code it ran: the commit and modified files."""

from __future__ import annotations

import os
import subprocess

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def git_state(root: str = ROOT) -> dict:
    """Commit and the modified tracked files of the checkout at ``root`` ({} without git)."""
    try:
        head = subprocess.run(["git", "rev-parse", "HEAD"], cwd=root, capture_output=True,
                              text=True, timeout=30).stdout.strip()
        dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"],
                               cwd=root, capture_output=True, text=True, timeout=30).stdout
        return {"commit": head, "modified": [ln[3:] for ln in dirty.splitlines()]}
    except (OSError, subprocess.SubprocessError):
        return {}


def write_results(out_dir: str, name: str, rows: list, payload: dict) -> str:
    """Write ``rows`` as ``<out_dir>/<name>-<UTC stamp>.csv`` and ``payload`` (plus the rows,
    the commit, the stamp and the load at the end) as the ``.json`` beside it; returns the
    common path without extension."""
    import csv
    import json
    import time

    os.makedirs(out_dir, exist_ok=True)
    stamp = time.strftime("%Y-%m-%d-%H%M%S", time.gmtime())
    base = os.path.join(out_dir, f"{name}-{stamp}")
    with open(base + ".csv", "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    meta = {"git": git_state(), "utc": stamp, "load_end": list(os.getloadavg()),
            "cpus": os.cpu_count(), **payload.pop("meta", {})}
    with open(base + ".json", "w") as fh:
        json.dump({"meta": meta, "rows": rows, **payload}, fh, indent=1)
    print(f"wrote {base}.csv and {base}.json")
    return base
