"""Finite size at fixed pillars: the same pillars in ever larger brushes.

    python benchmarks/pillar_scale.py --out /tmp/pillar-scale                # 6 ... 36
    python benchmarks/pillar_scale.py --out /tmp/pillar-scale --sides 6 12 18 --ranks 1
    python benchmarks/pillar_scale.py --out DIR --sides 100 --sigma 0.1 --preloads 4 16
    python benchmarks/pillar_scale.py --out DIR --sides 100 --sigma 0.5 --far-field multipole

The model's variables are measured against the whole brush (docs/model.md §2): at fixed k~ and
sigma~ a brush of more pillars is a brush of smaller pillars, rougher and stiffer-springed at the
pillar scale (docs/finite-size.md). A real array grows by adding pillars of the same size, so this
study holds the pillar's own numbers fixed instead: for each (k~, sigma~) given at the reference
size (18 x 18 unless ``--reference``), the brush of n x n pillars runs at

    k~(n) = k~ * ref / n,        sigma~(n) = sigma~ * sqrt(ref / n)

(the pillar's spring over its own contact stiffness, k / (E* D), and its roughness over its own
Kendall displacement, sigma / d_c1, are then the reference brush's at every n). Its pull-off
force is compared through the adhesion efficiency

    eta = F~_A / (N_p phi)^(1/4) = F_A / (N_p F_c1),

the fraction of the force of N_p independent, equally loaded pillars (each of Kendall pull-off
F_c1); phi is the discrete filling ratio.

One campaign per size (``F_P: auto``, the given seeds, preset ``fast`` unless ``--preset``) is
written into ``--out`` as ``n<N>.yaml``/``n<N>.h5`` and run with ``fibril-campaign`` (under
``mpirun -n RANKS`` when RANKS > 1; a rerun resumes, nothing done is recomputed), then read by
the report (``n<N>-report/plateau.csv``). Prints the table of eta with its seed interval and its
change against the largest brush, and writes CSV and JSON into ``benchmarks/results/``.
"""

from __future__ import annotations

import argparse
import math
import os
import subprocess
import sys
import time

import yaml

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))

from benchmarks.common import write_results  # noqa: E402


def grid_of(n: int, ks, sigmas, ref: int, seeds: int, preset: str, phi: float,
            preloads=None, far_field: str = "exact") -> dict:
    """The campaign grid of the n x n brush of the reference pillars (``F_P: auto``, or the
    fixed ``preloads``; ``far_field: multipole`` where asked, the reference otherwise)."""
    grid = {
        "description": f"pillar-scale finite size: n_side {n}, the pillars of the {ref} x {ref} "
                       f"brush (k~ x {ref}/{n}, sigma~ x sqrt({ref}/{n}))",
        "output": f"n{n}.h5",
        "scene": {"n_side": n, "phi": phi, "preset": preset,
                  "solver": {"fft_threads": 1, "max_wall_s": 7200}},
        "k_tilde": [k * ref / n for k in ks],
        "sigma_tilde": [s * math.sqrt(ref / n) for s in sigmas],
        "F_P": "auto",
        "seeds": seeds,
    }
    if far_field != "exact":
        grid["scene"]["solver"]["far_field"] = far_field
        grid["description"] += f"; solver.far_field {far_field}"
    if preloads:
        grid["F_P"] = [float(x) for x in preloads]
        grid["description"] += ("; plateau preloads only (F~_P "
                                + " and ".join(f"{x:g}" for x in preloads)
                                + ", where 64 x 64 is flat)")
    return grid


def run_size(out: str, n: int, grid: dict, ranks: int) -> str:
    """Run (or resume) the campaign of one size; returns its report folder."""
    from fibril_hpc.campaign.analysis.report import write_report

    path = os.path.join(out, f"n{n}.yaml")
    with open(path, "w") as fh:
        yaml.safe_dump(grid, fh, sort_keys=False)
    cmd = ["fibril-campaign", path, "--no-progress"]
    cmd = ["mpirun", "-n", str(ranks)] + cmd if ranks > 1 else cmd + ["--serial"]
    t0 = time.perf_counter()
    subprocess.run(cmd, check=True)
    print(f"n_side {n}: campaign {time.perf_counter() - t0:.0f} s wall", flush=True)
    report = os.path.join(out, f"n{n}-report")
    write_report(os.path.join(out, f"n{n}.h5"), report)
    return report


def plateau_rows(report: str) -> list:
    import csv

    with open(os.path.join(report, "plateau.csv")) as fh:
        return list(csv.DictReader(fh))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", required=True, help="work folder for the grids, files and reports")
    ap.add_argument("--sides", type=int, nargs="+", default=[6, 12, 18, 24, 36])
    ap.add_argument("--reference", type=int, default=18)
    ap.add_argument("--k", type=float, nargs="+", default=[1.0, 0.01],
                    help="k~ of the reference brush")
    ap.add_argument("--sigma", type=float, nargs="+", default=[0.1, 0.5],
                    help="sigma~ of the reference brush")
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--preset", default="fast")
    ap.add_argument("--phi", type=float, default=0.16)
    ap.add_argument("--ranks", type=int, default=2)
    ap.add_argument("--preloads", type=float, nargs="+", default=None,
                    help="fixed F~_P instead of F_P: auto (on the plateau: the report reads it "
                         "from these alone; 100 x 100 ran 4 16)")
    ap.add_argument("--far-field", choices=["exact", "multipole"], default="exact",
                    help="solver.far_field of every brush (exact: the reference)")
    a = ap.parse_args(argv)
    from fibril_hpc.geometry.grid import Lattice
    from fibril_hpc.inputs.presets import preset_values

    os.makedirs(a.out, exist_ok=True)
    epd = preset_values(a.preset)["elements_per_diameter"]
    rows = []
    for n in a.sides:
        grid = grid_of(n, a.k, a.sigma, a.reference, a.seeds, a.preset, a.phi, a.preloads,
                       a.far_field)
        got = plateau_rows(run_size(a.out, n, grid, a.ranks))
        phi_d = Lattice.of(n, a.phi, epd, "square").phi_discrete
        norm = (n * n * phi_d) ** 0.25
        for k_ref, k in zip(a.k, grid["k_tilde"]):
            for s_ref, s in zip(a.sigma, grid["sigma_tilde"]):
                r = next(r for r in got if math.isclose(float(r["k_tilde"]), k, rel_tol=1e-9)
                         and math.isclose(float(r["sigma_tilde"]), s, rel_tol=1e-9))
                rows.append({"k_ref": k_ref, "sigma_ref": s_ref, "n_side": n, "k_tilde": k,
                             "sigma_tilde": s, "plateau": float(r["plateau"]),
                             "plateau_lo": float(r["plateau_lo"]),
                             "plateau_hi": float(r["plateau_hi"]), "state": r["state"],
                             "independent": norm, "eta": float(r["plateau"]) / norm,
                             "eta_lo": float(r["plateau_lo"]) / norm,
                             "eta_hi": float(r["plateau_hi"]) / norm})
    big = max(a.sides)
    for r in rows:
        ref = next(q for q in rows if q["n_side"] == big and q["k_ref"] == r["k_ref"]
                   and q["sigma_ref"] == r["sigma_ref"])
        r["change"] = r["eta"] / ref["eta"] - 1.0
    print(f"\nadhesion efficiency eta = F~_A / (N_p phi)^(1/4) [seed interval], the pillars of the "
          f"{a.reference} x {a.reference} brush, preset {a.preset}; change against {big} x {big}")
    print(f"{'k~ref':>6} {'s~ref':>6} " + " ".join(f"{n:>26}" for n in a.sides))
    for k_ref in a.k:
        for s_ref in a.sigma:
            cells = []
            for n in a.sides:
                r = next(q for q in rows if q["n_side"] == n and q["k_ref"] == k_ref
                         and q["sigma_ref"] == s_ref)
                cells.append(f"{r['eta']:.3g} [{r['eta_lo']:.3g}, {r['eta_hi']:.3g}] "
                             f"{100 * r['change']:+.0f}%")
            print(f"{k_ref:>6g} {s_ref:>6g} " + " ".join(f"{c:>26}" for c in cells))
    write_results(os.path.join(HERE, "results"), "pillar-scale", rows,
                  {"meta": {"command": " ".join(sys.argv), "reference": a.reference,
                            "preset": a.preset, "seeds": a.seeds,
                            "far_field": a.far_field}})
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
