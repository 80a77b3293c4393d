"""The dry-run's FFT pairs per task against what large brushes measured (issue 35, item 3).

    python benchmarks/price_large.py FILE.h5 [FILE.h5 ...]

Reads finished campaign files (any size and preset; their records carry each task's FFT pairs,
events and wall time, docs/files.md), groups the records into the tasks that ran them (one
loading path: the same k~, sigma~, seed, group size and counts), and prices each task as ``--dry-run`` does
(``campaign.plan.estimate.task_pairs`` on the task's scene with all its preloads). Prints
measured / modelled pairs per task and writes ``benchmarks/results/price-large-*.csv``, which
tests/test_price.py holds the model to.
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys

import yaml

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))

from benchmarks.common import write_results  # noqa: E402
from fibril_hpc.inputs.scene import scene_from_dict  # noqa: E402


def tasks_of(path: str) -> list:
    """One dict per task of the campaign file ``path``: its scene (all preloads) and counts."""
    from fibril_hpc.campaign.storage.store import read_records

    _, records, _ = read_records(path, curves=False)
    groups: dict = {}
    for a in records.values():
        if a["status"] != "done":
            continue
        tid = (float(a["k_tilde"]), float(a["sigma_tilde"]), int(a["seed"]),
               int(a["fft_pairs"]), int(a["cg_solves"]), int(a["group_size"]), float(a["wall_s"]))
        g = groups.setdefault(tid, {"scene_yaml": a["scene_yaml"], "preloads": [],
                                    "kind": a["preload_kind"]})
        g["preloads"].append(float(a["preload"]))
    out = []
    for (k, s, seed, pairs, solves, _size, wall), g in groups.items():
        pre = tuple(sorted(g["preloads"]))
        scene = scene_from_dict(yaml.safe_load(g["scene_yaml"])).replace(**{g["kind"]: pre})
        out.append({"file": os.path.basename(path), "n_side": scene.n_side,
                    "preset": scene.preset, "k_tilde": k, "sigma_tilde": s, "seed": seed,
                    "preload_kind": g["kind"], "preloads": ";".join(f"{x:g}" for x in pre),
                    "pairs": pairs, "cg_solves": solves, "wall_s": wall, "scene": scene})
    return out


def model_pairs(row: dict) -> float:
    """The dry-run's FFT pairs of the task ``row`` (its scene with all its preloads)."""
    from fibril_hpc.campaign.plan.estimate import task_pairs
    from fibril_hpc.geometry.grid import Lattice

    scene = row["scene"]
    lat = Lattice.of(scene.n_side, scene.phi, scene.elements_per_diameter, scene.lattice)
    return task_pairs(scene, lat.elements_per_pillar)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("files", nargs="+", help="finished campaign files (.h5)")
    a = ap.parse_args(argv)
    rows = []
    for path in a.files:
        for t in tasks_of(path):
            t["model_pairs"] = model_pairs(t)
            t["measured_over_model"] = t["pairs"] / t["model_pairs"]
            del t["scene"]
            rows.append(t)
    rows.sort(key=lambda r: (r["n_side"], r["preset"], r["k_tilde"], r["sigma_tilde"], r["seed"],
                             r["preloads"]))
    print(f"{'n':>4} {'preset':>8} {'k~':>9} {'s~':>7} {'seed':>4} {'preloads':>34} {'pairs':>7} "
          f"{'model':>7} {'meas/model':>10}")
    for r in rows:
        print(f"{r['n_side']:>4} {r['preset']:>8} {r['k_tilde']:>9.3g} {r['sigma_tilde']:>7.3g} "
              f"{r['seed']:>4} "
              f"{r['preloads']:>34} {r['pairs']:>7} {r['model_pairs']:>7.0f} "
              f"{r['measured_over_model']:>10.2f}")
    ratios = [r["measured_over_model"] for r in rows]
    print(f"{len(rows)} tasks: measured / modelled pairs median {statistics.median(ratios):.2f}, "
          f"range {min(ratios):.2f}-{max(ratios):.2f}")
    write_results(os.path.join(HERE, "results"), "price-large", rows,
                  {"meta": {"command": " ".join(sys.argv)}})
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
