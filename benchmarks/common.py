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


def graph_gap(a_d, a_F, b_d, b_F, d_scale, F_scale) -> float:
    """Largest distance from a point of curve a to the polyline of curve b, in (d / d_scale,
    F / F_scale): a jump (two points at one d) is a vertical segment, so a curve whose event
    moved by delta d is delta d / d_scale away there, not the height of the jump."""
    import numpy as np

    P = np.column_stack([a_d / d_scale, a_F / F_scale])
    Q = np.column_stack([b_d / d_scale, b_F / F_scale])
    if len(Q) == 1:
        return float(np.hypot(*(P - Q[0]).T).max())
    A, B = Q[:-1], Q[1:]
    AB = B - A
    L2 = np.maximum((AB * AB).sum(1), 1e-300)
    worst = 0.0
    for i in range(0, len(P), 256):         # blocks of points: memory 256 x len(Q), not P x Q
        Pb = P[i:i + 256]
        t = np.clip(((Pb[:, None, :] - A[None]) * AB[None]).sum(2) / L2[None], 0.0, 1.0)
        C = A[None] + t[..., None] * AB[None]
        worst = max(worst, float(np.sqrt(((Pb[:, None, :] - C) ** 2).sum(2)).min(1).max()))
    return worst
