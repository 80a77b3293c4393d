"""How tight is an a priori bound of the held field's error under ``far_field: multipole``?

    python benchmarks/held_field_bound.py [--sides 18 36] [--preset fast] [--k 0.01] [--sigma 0.5]

Under the moments a state's field between two exact products is u = K p0 + Ka (p - p0), p0 the
pressure at the last refresh (the load path keeps it: ``PathDriver.p0``), so its error is
e = (K - Ka)(p - p0). The remainder K - Ka couples two pillars by a block R_s (footprint by
footprint) that depends only on their lattice offset s (each pillar's own block is exact:
R_0 = 0), so per pillar g

    |e_g|_2 <= b_g = sum_h |R_(g-h)|_2 |p_h - p0_h|_2,

a convolution of the offset norms with the pillars' changes
(:meth:`fibril_hpc.solve.farfield.MultipoleField.pillar_bound`). The load path certifies the
state that ends each relaxation with it (:mod:`fibril_hpc.path.confirm`); this study measures,
at every refresh of the state (mid-relaxation states, the furthest from their last exact
product), how close b is to e and what the force bound would be there.

This study measures that factor on the growth scene (k~ 0.01, sigma~ 0.5, F~_P 4, seed 0 unless
given). The path runs with every change of the held field made by Ka (``max_direct`` 0, so e is exactly
(K - Ka)(p - p0)); at each refresh of the state the held field is compared with the exact one
(one extra FFT pair, not counted by the path). Printed per size: refreshes, and over them the
median and worst of |b|_2/|e|_2 (whole brush) and of max_g b_g / max |e| (the largest element
error), and the largest |e| against the update rule's gap tolerance (1e3 cg_tol d_c, in the same
units): where |e| stays far below it the held states flip no decision. Writes CSV and JSON into
``benchmarks/results/``. Nothing here asserts a time.
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))

from benchmarks.common import write_results  # noqa: E402


def run(n: int, preset: str, k: float, sigma: float, seed: int, F_P: float) -> dict:
    from fibril_hpc import Scene
    from fibril_hpc.model import build_scene_model
    from fibril_hpc.path.loading import PathDriver
    from fibril_hpc.kernels import compiled as kern
    from fibril_hpc.path.records import CurveRecorder
    from fibril_hpc.solve.certify import ForceCertificate

    scene = Scene(n_side=n, k_tilde=k, sigma_tilde=sigma, F_P=(F_P,), seed=seed, preset=preset,
                  solver={"fft_threads": 1, "far_field": "multipole"})
    model = build_scene_model(scene)
    op = model.operator
    g = model.geometry
    ng, m = g.n_groups, op.footprint
    table = op.remainder_norms(spectral=True)
    op.max_direct = 0                              # every held change through Ka
    driver = PathDriver(model)
    rows = []
    state = {"untracked": 0}
    solve = driver._solve
    exact_u, held = np.empty(g.n_active), np.empty(g.n_active)
    tol_g = driver.tol_g
    # the force certificate's tolerance (confirm_tol F_c) and the first-order force error of a
    # held state, h^2 p1_S . e_S (fibril_hpc.solve.certify), against its bound from b
    tol_F = model.options.confirm_tol * model.scaling.F_c
    h2 = g.h * g.h
    # the same first-order error without the pillar bound: p1 . (K - Ka) dp = w . dp with
    # w = (K - Ka) p1 = u1 - Ka p1 (K, Ka symmetric), one product of Ka per direction; its
    # second-order term h^2 |r1| |e_S| / lambda_min, |e_S| <= |b| (fibril_hpc.solve.certify)
    cert = ForceCertificate(g, op.exact, model.solver.alpha, tol_F)
    r1 = np.empty(g.n_active)

    def watched(b, x, u, x_ref, tol=None, exact=False):
        refresh = (u is driver.u and not exact and driver._since_full >= op.refresh_every)
        if refresh:
            held[:] = u + op.apply_increment(x - x_ref, np.empty_like(u))
            op.exact.apply(x, exact_u)
            e = (exact_u - held).reshape(ng, m)
            dx = x - driver.p0
            e2 = op.exact.apply(dx, np.empty_like(u)) - op.apply_increment(dx, np.empty_like(u))
            if np.abs(e.ravel() - e2).max() > 1e-9 * np.abs(e2).max():
                # the driver's p0 does not describe u (never seen: p0 follows the moves, the
                # lookaheads and the snapshots)
                state["untracked"] += 1
                return solve(b, x, u, x_ref, tol, exact)
            dp = np.linalg.norm(dx.reshape(ng, m), axis=1)
            bnd = op.pillar_bound(dp, spectral=True)
            en = np.linalg.norm(e, axis=1)
            # the last direction as solved (on its set; u1 = K p1 exactly)
            p1 = driver.p1.reshape(ng, m)
            f_true = h2 * abs(float(np.sum(p1 * e)))
            f_bound = h2 * float(np.linalg.norm(p1, axis=1) @ bnd)
            w = driver.u1 - op.apply_increment(driver.p1, np.empty_like(u))
            rr1 = kern.residual(driver._ones, driver.u1, driver.p1, driver.att, g.starts,
                                model.solver.alpha, r1)
            f_first = h2 * abs(float(w @ dx))
            f_w = f_first + h2 * np.sqrt(rr1) * float(np.linalg.norm(bnd)) / cert.lam
            if en.max() > 0.0:
                # above the bound beyond the exact product's rounding (e is a difference of
                # two fields of |u|'s size)
                scale = max(float(np.abs(exact_u).max()), float(np.abs(held).max()), 1e-300)
                floor = 1e-12 * scale
                rows.append({"violations": int(np.sum(en > bnd * (1 + 1e-9) + floor)),
                             "excess_over_u": float(np.max(en - bnd)) / scale,
                             "F_err_over_tol": f_true / tol_F, "F_bound_over_tol": f_bound / tol_F,
                             "F_w_bound_over_tol": f_w / tol_F, "F_w_first_over_tol": f_first / tol_F,
                             "global": float(np.linalg.norm(bnd) / np.linalg.norm(en)),
                             "worst": float(bnd.max() / np.abs(e).max()),
                             "e_max_over_tol_g": float(np.abs(e).max() / tol_g),
                             "b_max_over_tol_g": float(bnd.max() / tol_g)})
        return solve(b, x, u, x_ref, tol, exact)

    driver._solve = watched
    snaps = driver.load([F_P * model.scaling.F_c], "F", CurveRecorder())
    driver.unload(snaps[0])

    def med(key):
        return statistics.median(r[key] for r in rows)

    out = {"n_side": n, "preset": preset, "k_tilde": k, "sigma_tilde": sigma, "seed": seed,
           "refreshes": len(rows), "untracked": state["untracked"], "footprint": m,
           "nearest_norm": float(table.max())}
    out["violations"] = sum(r["violations"] for r in rows)      # pillars with |e_g| > b_g
    out["excess_over_u_max"] = max(r["excess_over_u"] for r in rows)   # max_g |e_g| - b_g
    for key in ("global", "worst", "e_max_over_tol_g", "b_max_over_tol_g", "F_err_over_tol",
                "F_bound_over_tol", "F_w_bound_over_tol", "F_w_first_over_tol"):
        out[f"{key}_median"] = med(key)
        out[f"{key}_max"] = max(r[key] for r in rows)
    return out


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--sides", type=int, nargs="+", default=[18, 36])
    p.add_argument("--preset", default="fast")
    p.add_argument("--k", type=float, default=0.01)
    p.add_argument("--sigma", type=float, default=0.5)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--F-P", type=float, default=4.0)
    p.add_argument("--out", default=os.path.join(HERE, "results"))
    a = p.parse_args(argv)
    rows = []
    for n in a.sides:
        r = run(n, a.preset, a.k, a.sigma, a.seed, a.F_P)
        rows.append(r)
        print(f"n {n} {a.preset}: {r['refreshes']} refreshes, {r['untracked']} where p0 did not "
              f"describe u left out ({r['violations']} pillars above "
              f"their bound); |b|/|e| median "
              f"{r['global_median']:.1f}, worst {r['global_max']:.1f}; max b / max |e| median "
              f"{r['worst_median']:.1f}, worst {r['worst_max']:.1f}; max |e| / tol_g median "
              f"{r['e_max_over_tol_g_median']:.2e}, worst {r['e_max_over_tol_g_max']:.2e}; "
              f"max b / tol_g median {r['b_max_over_tol_g_median']:.2e}; force error / "
              f"confirm_tol median {r['F_err_over_tol_median']:.2e} (bound "
              f"{r['F_bound_over_tol_median']:.2e}), worst {r['F_err_over_tol_max']:.2e} (bound "
              f"{r['F_bound_over_tol_max']:.2e}; by w: {r['F_w_bound_over_tol_median']:.2e}, "
              f"worst {r['F_w_bound_over_tol_max']:.2e}; its first-order term "
              f"{r['F_w_first_over_tol_median']:.2e}, worst {r['F_w_first_over_tol_max']:.2e})",
              flush=True)
    write_results(a.out, "held-field-bound", rows, {"args": vars(a)})
    return 0


if __name__ == "__main__":
    sys.exit(main())
