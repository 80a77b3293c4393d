"""The ``peers`` section: ContactMechanics and tamaas side by side with fibril, on their ground.

Non-adhesive rigid flat punches (Gaussian heights, phi = 0.16) at a fixed plate displacement;
answers are compared (force, contact set, pressures) and time ratios taken run by run. A peer
that is not installed (``pip install "fibril-hpc[bench]"``) is reported as skipped.
"""

from __future__ import annotations

import contextlib
import math
import os
import shutil
import statistics
import sys
import tempfile

import numpy as np

from fibril_hpc.model import build_scene_model
from fibril_hpc.path.loading import PathDriver

from .timing import Stopwatch, bench_scene, loadavg


@contextlib.contextmanager
def _capture_fds(path):
    """Redirect the C-level stdout and stderr (fds 1, 2) into ``path`` (tamaas logs there)."""
    sys.stdout.flush()
    sys.stderr.flush()
    saved = [os.dup(1), os.dup(2)]
    fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC)
    os.dup2(fd, 1)
    os.dup2(fd, 2)
    try:
        yield
    finally:
        sys.stdout.flush()
        sys.stderr.flush()
        os.dup2(saved[0], 1)
        os.dup2(saved[1], 2)
        for f in saved + [fd]:
            os.close(f)


def peer_availability() -> dict:
    """Version of each peer code, or None (with the import error) when it cannot be imported."""
    out = {}
    for mod, name in (("ContactMechanics", "contactmechanics"), ("tamaas", "tamaas")):
        try:
            m = __import__(mod)
            out[name] = getattr(m, "__version__", "") or "installed"
        except Exception as exc:  # noqa: BLE001 - any import failure means: skip this peer
            out[name] = None
            out[name + "_error"] = f"{type(exc).__name__}: {exc}"
    return out


class FibrilPeer:
    """fibril's fixed-d contact solve on the peers' ground (rigid, non-adhesive punches)."""

    def __init__(self, n_side, pitch, tol, planner, clock="cpu"):
        self.clock = clock
        self.scene = bench_scene(n_side, pitch, k_tilde=math.inf, sigma_tilde=0.5, adhesion=False,
                            solver={"cg_tol": tol, "fft_planner": planner})
        self.model = build_scene_model(self.scene)
        self.drv = PathDriver(self.model)

    def solve(self, d):
        """Solve at plate displacement d; time, iterations, force, contact, pressures."""
        m, sv = self.model, self.model.solver
        i0, p0 = sv.iterations, m.fft_pairs
        with Stopwatch(self.clock) as w:
            self.drv.solve_at(d)
        wall = w.t
        g = m.geometry
        p = np.zeros((g.n, g.n))
        p[g.iy, g.ix] = np.where(self.drv.att != 0, self.drv.p, 0.0)
        return {"time_s": wall, "clocks": (w.wall, w.cpu), "iterations": sv.iterations - i0,
                "fft_pairs": m.fft_pairs - p0, "force": self.drv.force(),
                "area": int(np.count_nonzero(p > 0)), "p": p}


class CMPeer:
    """ContactMechanics: FreeFFTElasticHalfSpace (grid 2N x 2N) + constrained CG at fixed offset."""

    def __init__(self, geometry, tol, d, clock="cpu"):
        self.clock = clock
        from ContactMechanics import FreeFFTElasticHalfSpace

        g = geometry
        self.g, self.tol = g, tol
        n, h = g.n, g.h
        self.sub = FreeFFTElasticHalfSpace((n, n), 1.0, physical_sizes=(n * h, n * h))
        self.calls = 0
        orig = self.sub.evaluate_disp

        def counted(f):
            self.calls += 1
            return orig(f)

        self.sub.evaluate_disp = counted
        big = 1e3 * (float(g.z0.max()) + abs(d) + 1.0)
        self.heights = np.full((n, n), -big)      # off the pillars: never reached
        self.heights[g.iy, g.ix] = -g.z0
        self.grid = tuple(int(s) for s in self.sub.nb_subdomain_grid_pts)

    def solve(self, d):
        from ContactMechanics.Optimization import constrained_conjugate_gradients

        g, n, h = self.g, self.g.n, self.g.h
        f0 = np.zeros(self.grid)
        pen = np.zeros((n, n), bool)
        pen[g.iy, g.ix] = (d - g.z0) > 0
        f0[:n, :n][pen] = -1e-3 * h * h * d        # small initial forces (see NOTES.md)
        self.calls = 0
        with Stopwatch(self.clock) as w:
            res = constrained_conjugate_gradients(self.sub, self.heights, offset=d,
                                                  initial_forces=f0, pentol=self.tol * d,
                                                  forcetol=1e-12, thermotol=self.tol,
                                                  maxiter=100000)
        wall = w.t
        p = np.asarray(res.jac) / (h * h)
        return {"time_s": wall, "clocks": (w.wall, w.cpu), "iterations": int(res.nit),
                "fft_pairs": self.calls, "force": float(res.jac.sum()),
                "area": int(np.count_nonzero(p > 0)), "p": p,
                "converged": bool(res.success), "message": str(res.message)}


class TamaasPeer:
    """tamaas: basic_2d model, non-periodic Boussinesq operator, PolonskyKeerRey, load control."""

    def __init__(self, geometry, tol, d, logdir, clock="cpu"):
        self.clock = clock
        import tamaas as tm

        g = geometry
        self.tm, self.g, self.tol, self.logdir = tm, g, tol, logdir
        n, h = g.n, g.h
        self.L = n * h
        big = 10.0 * (float(g.z0.max()) + abs(d) + 1.0)
        self.surface = np.full((n, n), -big)
        self.surface[g.iy, g.ix] = -g.z0
        tm.set_log_level(tm.LogLevel.info)
        self.model = tm.ModelFactory.createModel(tm.model_type.basic_2d, [self.L, self.L], [n, n])
        self.model.E = 1.0          # E* = E / (1 - nu^2) = 1, fibril's internal unit
        self.model.nu = 0.0
        tm.ModelFactory.registerNonPeriodic(self.model, "nonperiodic")
        self.solver = tm.PolonskyKeerRey(self.model, self.surface, tol)
        self.solver.setIntegralOperator("nonperiodic")
        self.solver.max_iter = 100000

    def solve(self, force):
        g, h = self.g, self.g.h
        logf = os.path.join(self.logdir, "tamaas.log")
        self.model.traction[...] = 0.0
        with _capture_fds(logf):
            with Stopwatch(self.clock) as w:
                err = self.solver.solve(force / (self.L * self.L))
        wall = w.t
        its = None
        with open(logf) as fh:
            for line in fh:
                parts = line.split()
                if len(parts) == 3 and parts[0].isdigit():
                    its = int(parts[0])
        p = np.array(self.model.traction, dtype=float).reshape(g.n, g.n)
        return {"time_s": wall, "clocks": (w.wall, w.cpu), "iterations": its,
                "force": float(p.sum() * h * h),
                "area": int(np.count_nonzero(p > 0)), "p": p, "error": float(err)}


def section_peers(cfg, floors, log):
    """fibril, ContactMechanics and tamaas side by side on one problem; answers compared."""
    avail = peer_availability()
    out = {"available": avail, "sizes": [], "tol": cfg["peer_tol"]}
    tmp = tempfile.mkdtemp(prefix="fibril-bench-peers-")
    try:
        for pitch in cfg["peer_pitches"]:
            fib = FibrilPeer(cfg["n_side"], pitch, cfg["peer_tol"], floors.planner, cfg["clock"])
            g = fib.model.geometry
            d = cfg["d_tilde"] * fib.model.scaling.d_c
            m = fib.model.operator.m
            fl = floors.seconds(m)
            peers = {}
            if avail.get("contactmechanics"):
                peers["contactmechanics"] = CMPeer(g, cfg["peer_tol"], d, cfg["clock"])
            if avail.get("tamaas"):
                peers["tamaas"] = TamaasPeer(g, cfg["peer_tol"], d, tmp, cfg["clock"])
            fib.solve(d)        # warm: JIT, block inverses of this grid
            runs = []
            for rep in range(cfg["peer_runs"]):
                r = {"fibril": fib.solve(d)}
                F = r["fibril"]["force"]
                for name, peer in peers.items():
                    r[name] = peer.solve(d) if name == "contactmechanics" else peer.solve(F)
                for v in r.values():
                    v["load"] = loadavg()
                runs.append(r)
                log(f"peers m={m} run {rep}: " + ", ".join(
                    f"{k} {v['time_s']:.2f} s/{v['iterations']} its" for k, v in r.items()))
            size = {"pitch": pitch, "N": g.n, "m": m, "n_active": g.n_active, "d_tilde":
                    cfg["d_tilde"], "floor_ms": 1e3 * fl, "codes": {}}
            ref = runs[-1]["fibril"]
            for name in ["fibril"] + list(peers):
                rs = [r[name] for r in runs]
                t = statistics.median(x["time_s"] for x in rs)
                its = rs[-1]["iterations"]
                c = {"time_s_median": t, "time_s": [x["time_s"] for x in rs],
                     "wall_and_cpu_s": [x["clocks"] for x in rs],
                     "wall_clock_s_median": statistics.median(x["clocks"][0] for x in rs),
                     "iterations": its, "force": rs[-1]["force"],
                     "contact_elements": rs[-1]["area"],
                     "per_iteration_ms": None if not its else 1e3 * t / its,
                     "per_iteration_floor_pairs": None if not its else t / its / fl}
                if "fft_pairs" in rs[-1]:
                    c["fft_pairs"] = rs[-1]["fft_pairs"]
                for k in ("converged", "message", "error"):
                    if k in rs[-1]:
                        c[k] = rs[-1][k]
                if name != "fibril":
                    pr = rs[-1]["p"]
                    c["force_rel_diff"] = rs[-1]["force"] / ref["force"] - 1.0
                    c["contact_elements_diff"] = rs[-1]["area"] - ref["area"]
                    c["contact_set_mismatch"] = int(np.count_nonzero((pr > 0) != (ref["p"] > 0)))
                    c["pressure_rel_l2_diff"] = float(np.linalg.norm(pr - ref["p"])
                                                      / np.linalg.norm(ref["p"]))
                    ratios = [r[name]["time_s"] / r["fibril"]["time_s"] for r in runs]
                    c["ratio_wall_vs_fibril_median"] = statistics.median(ratios)
                    c["ratio_wall_vs_fibril_runs"] = ratios
                if name == "contactmechanics":
                    c["fft_grid"] = list(peers[name].grid)
                    if c["fft_grid"][0] != m:
                        c["floor_ms_own_grid"] = 1e3 * floors.seconds(c["fft_grid"][0])
                size["codes"][name] = c
            out["sizes"].append(size)
        return out
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
