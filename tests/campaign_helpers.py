"""Shared helpers of the campaign tests: tiny grids and subprocess runners (always with timeouts)."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys

import yaml

BIN = os.path.dirname(sys.executable)
TINY = {
    "output": "tiny.h5",
    "scene": {"n_side": 2, "elements_per_diameter": 5,
              "solver": {"fft_threads": 1, "max_wall_s": 120}},
    "k_tilde": [1, 0.01],
    "sigma_tilde": [0.3, 1.0],
    "F_P": [0.3, 1.0],
    "seeds": 2,
}


def write_grid(folder, data=None, name="grid.yaml", **changes) -> str:
    d = dict(TINY if data is None else data)
    d.update(changes)
    path = os.path.join(str(folder), name)
    with open(path, "w") as fh:
        yaml.safe_dump(d, fh)
    return path


def finished_tiny(folder):
    """A finished one-path campaign (k~ 1, sigma~ 0.3, two preloads, one seed) in ``folder``,
    run in this process; returns its file."""
    from fibril_hpc.campaign import load_spec
    from fibril_hpc.campaign.run.runner import run_serial

    grid = write_grid(folder, k_tilde=[1], sigma_tilde=[0.3], F_P=[0.3, 1.0], seeds=1)
    assert run_serial(load_spec(grid), progress=False) == 0
    return folder / "tiny.h5"


def campaign_cmd() -> list:
    exe = shutil.which("fibril-campaign", path=BIN) or shutil.which("fibril-campaign")
    if exe:
        return [exe]
    return [sys.executable, "-m", "fibril_hpc.cli.campaign"]


def env() -> dict:
    e = dict(os.environ)
    from fibril_hpc.campaign.run.launcher import MARKER_VARS, RANK_VARS, SIZE_VARS

    for var in MARKER_VARS + SIZE_VARS + RANK_VARS:     # run as if no launcher started us
        e.pop(var, None)
    e.setdefault("NUMBA_CACHE_DIR", os.path.join(os.path.dirname(__file__), "..", ".numba_cache"))
    return e


def run(args, timeout=240, **kw):
    return subprocess.run(campaign_cmd() + list(args), capture_output=True, text=True,
                          timeout=timeout, env=kw.pop("env", env()), **kw)


def start(args, **kw):
    return subprocess.Popen(campaign_cmd() + list(args), stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, env=kw.pop("env", env()), **kw)


def results_by_key(path) -> dict:
    from fibril_hpc import load_campaign

    return {j["key"]: j for j in load_campaign(path).jobs}


def same_numbers(a: dict, b: dict) -> list:
    """Keys whose F_P, F_A, status or curves differ (bitwise)."""
    import numpy as np

    bad = []
    for k in a:
        x, y = a[k], b.get(k)
        if y is None:
            bad.append(k)
            continue
        if x["status"] != y["status"] or repr(x["F_A"]) != repr(y["F_A"]) or \
                repr(x["F_P"]) != repr(y["F_P"]):
            bad.append(k)
            continue
        for br in ("loading", "unloading"):
            cx, cy = x.get(br), y.get(br)
            if (cx is None) != (cy is None):
                bad.append(k)
            elif cx is not None and not all(np.array_equal(cx[c], cy[c]) for c in cx):
                bad.append(k)
    return bad
