"""``simulate(scene) -> SimulationResult``: scene -> grid -> model -> load path -> curves.

A solver failure (non-convergence, non-finite values) never escapes as garbage: it is caught here
and recorded in the result's ``status``/``message`` (per preload, and at top level).
"""

from __future__ import annotations

import logging
import math
import time

import numpy as np
from threadpoolctl import threadpool_limits

from .errors import NoConvergenceError
from .inputs.scene import Scene
from .io.results import (
    STATUS_FAILED,
    STATUS_OK,
    Curve,
    PillarState,
    PreloadResult,
    SimulationResult,
    software_versions,
)
from .model import Model, OperatorCache, build_scene_model, scene_lattice
from .path.criterion import footprint_factor
from .path.loading import PathDriver
from .path.machine import MachineDriver, machine_displacement, make_driver
from .path.records import CurveRecorder

log = logging.getLogger(__name__)


def _curve(model: Model, rec: CurveRecorder, start: int = 0, stop: int | None = None,
           k_machine: float = math.inf) -> Curve:
    d, F, n_att, n_pil = rec.arrays()
    sl = slice(start, stop)
    sc = model.scaling
    total = max(model.geometry.n_active, 1)
    c = Curve(d[sl] / sc.d_c, F[sl] / sc.F_c, n_att[sl] / total, n_pil[sl])
    if not math.isinf(k_machine):
        c.d_machine_tilde = machine_displacement(c.d_tilde, c.F_tilde, k_machine, sc)
    return c


def _with_point(rec: CurveRecorder, snap) -> CurveRecorder:
    """The loading points recorded before a snapshot, followed by the snapshot's own point."""
    out = CurveRecorder(rec.d[:snap.n_points], rec.F[:snap.n_points],
                        rec.n_attached[:snap.n_points], rec.n_pillars[:snap.n_points])
    out.add(*snap.point)
    return out


def _pillar_state(model: Model, d, p, att) -> PillarState:
    g = model.geometry
    sc = model.scaling
    att_b = att != 0
    labels = g.labels
    f = np.bincount(labels, weights=np.where(att_b, p, 0.0), minlength=g.n_groups) * g.h**2
    elong = np.zeros_like(f) if model.rigid else f / model.k
    # cast per element before the scatter: the n x n map is float32 from the start (a float64
    # map cast afterwards took three times its memory at once: 1.35 GB more at 10^6 pillars)
    pressure = g.to_map((np.where(att_b, p, 0.0) * sc.area / sc.F_c).astype(np.float32))
    return PillarState(force=f / sc.F_c, elongation=elong / sc.d_c,
                       contact_map=g.to_map(att_b.astype(np.uint8)), pressure_map=pressure,
                       d_tilde=d / sc.d_c)


def discretisation_info(model: Model) -> dict:
    """Resolution facts of a built model (grid, FFT size, pillar footprint), stored with results."""
    g = model.geometry
    grid = model.grid
    info = {
        "n_elements": g.n * g.n,
        "grid_side": g.n,
        "n_active": g.n_active,
        "fft_size": model.operator.m,
        "h": g.h,
        "phi_discrete": model.scaling.phi,
        "sigma_c": model.sigma_c,
        "footprint": "odd pitch, pillar centre on an element centre, element in pillar iff its "
                     "centre is within the nominal radius D/2",
    }
    if model.options.criterion != "mesh":
        info["criterion_factor"] = model.criterion_factor
    if grid is not None:
        info.update({
            "pitch_elements": grid.pitch,
            "elements_per_pillar": grid.elements_per_pillar,
            "elements_per_diameter": 2.0 * grid.r_eq / g.h,
            "r_eq_over_pitch": grid.r_eq / (grid.pitch * g.h),
        })
    return info


def _run_preloads(model: Model, scene: Scene, driver: PathDriver,
                  state: dict | None = None) -> list[PreloadResult]:
    sc = model.scaling
    kind = scene.preload_kind
    values = list(scene.preloads)
    if kind == "d_tilde":
        targets = [v * sc.d_c for v in values]
        load_kind = "d"
    else:
        targets = [v * sc.F_c for v in values]
        load_kind = "F"
    loading = CurveRecorder()
    out = []
    try:
        snaps = driver.load(targets, load_kind, loading)
    except NoConvergenceError as exc:
        return [PreloadResult(kind, v, STATUS_FAILED, f"loading: {exc}") for v in values]
    for i, (value, snap) in enumerate(zip(values, snaps)):
        if state is not None:
            state["preload"] = i
        res = PreloadResult(kind, value, STATUS_OK)
        res.loading = _curve(model, _with_point(loading, snap), 0, snap.n_points + 1,
                             scene.k_machine)
        res.d_tilde_max = snap.d / sc.d_c
        res.F_P = float(res.loading.F_tilde[-1])
        res.n_pillars_in_contact_max = int(res.loading.n_pillars_in_contact.max())
        res.at_preload = _pillar_state(model, snap.d, snap.p, snap.att)
        if not model.adhesion:
            # Frictionless, non-adhesive contact is path independent: unloading retraces loading.
            res.unloading = res.loading.reversed()
            res.F_A = 0.0
            res.d_tilde_at_F_A = math.nan
            res.at_pulloff = None
            res.let_go_d_tilde = None
            res.message = "non-adhesive: the unloading branch retraces the loading branch"
        else:
            jumps0 = getattr(driver, "jumps", None)
            try:
                br = driver.unload(snap)
            except NoConvergenceError as exc:
                res.status = STATUS_FAILED
                res.message = f"unloading: {exc}"
                out.append(res)
                continue
            res.unloading = _curve(model, br.curve, k_machine=scene.k_machine)
            if jumps0 is not None:
                res.jumps = driver.jumps - jumps0
                # the last step's pre-event point: where the plate leaves the surface
                res.F_jump = (max(0.0, -float(res.unloading.F_tilde[-2]))
                               if len(res.unloading) > 1 else 0.0)
            res.F_A = max(0.0, -br.F_min / sc.F_c)
            res.d_tilde_at_F_A = br.d_at_F_min / sc.d_c
            if jumps0 is not None:
                res.d_machine_tilde_at_F_A = float(machine_displacement(
                    res.d_tilde_at_F_A, br.F_min / sc.F_c, scene.k_machine, sc))
            res.at_pulloff = _pillar_state(model, br.d_at_F_min, br.p_at_min, br.att_at_min)
            res.let_go_d_tilde = br.let_go_d / sc.d_c
            res.events = br.events
        finite = all(np.all(np.isfinite(c.F_tilde)) for c in (res.loading, res.unloading))
        if not (finite and math.isfinite(res.F_A) and math.isfinite(res.F_P)):
            res.status = STATUS_FAILED
            res.message = "non-finite values in the curve"
        out.append(res)
    return out


def calibrate(scene: Scene) -> float:
    """The footprint criterion's factor of ``scene``, its calibration pillar solved by
    :func:`simulate` (:func:`fibril_hpc.path.criterion.footprint_factor`)."""
    return footprint_factor(scene, simulate)


def simulate(scene: Scene, *, model: Model | None = None,
             operators: OperatorCache | None = None, progress=None) -> SimulationResult:
    """Simulate one scene: load to every preload along one loading path, pull off from each.

    Parameters
    ----------
    scene : Scene
        The validated scene.
    model : Model, optional
        A model built by :func:`~fibril_hpc.model.build_scene_model` for this very scene.
    operators : OperatorCache, optional
        Reuse FFT plans and the kernel transform across scenes on the same grid (campaigns).
    progress : callable, optional
        Called after every recorded point of the path with a dict: ``phase`` ("loading" or
        "unloading"), ``preload`` (the index of the preload being pulled off, or None while
        loading), ``d_tilde``, ``F_tilde``, ``events`` (contact events so far),
        ``pillars_in_contact`` and ``n_pillars`` (a pull-off ends when no pillar is in contact).
        It only watches: the result does not depend on it.

    Returns
    -------
    SimulationResult
        ``status`` is ``"ok"`` when every preload succeeded, else ``"failed"`` with the reason.
    """
    # BLAS (the block preconditioner's products, the local cascades' dense solves) runs on one
    # thread, whatever fft_threads says: OpenBLAS would otherwise start one thread per core in
    # every process (a campaign runs one process per core: 1.4-2.2x the CPU time of a path for no
    # gain in wall time), and its idle threads spin against the FFT pair's own threads (two
    # threads for BLAS and FFT made a 36 x 36 scene 0.93x as fast as one; with BLAS on one, 1.33x:
    # benchmarks/NOTES.md). Scoped to this call; the caller's limits come back after.
    with threadpool_limits(limits=1, user_api="blas"):
        return _simulate(scene, model, operators, progress)


def _observer(model: Model, progress, state: dict):
    """The path driver's observer that hands ``progress`` the point in normalised units."""
    sc = model.scaling
    n_pillars = model.geometry.n_groups

    def observe(phase, d, F, events, pillars):
        progress({"phase": phase, "preload": state.get("preload"), "d_tilde": d / sc.d_c,
                  "F_tilde": F / sc.F_c, "events": events, "pillars_in_contact": pillars,
                  "n_pillars": n_pillars})
    return observe


def _simulate(scene: Scene, model: Model | None, operators: OperatorCache | None,
              progress=None) -> SimulationResult:
    t0 = time.perf_counter()
    if model is None:
        model = build_scene_model(scene, operators, calibrate=calibrate)
    it0, pairs0, solves0 = model.solver.iterations, model.fft_pairs, model.solver.solves
    far0 = getattr(model.operator, "applications", 0)
    driver = make_driver(model, scene.k_machine)
    state: dict = {}
    if progress is not None:
        driver.observer = _observer(model, progress, state)
    results = _run_preloads(model, scene, driver, state)
    failed = [r for r in results if r.status != STATUS_OK]
    status = STATUS_FAILED if failed else STATUS_OK
    message = "; ".join(f"{r.preload_kind}={r.preload:g}: {r.message}" for r in failed)
    if not failed and results and results[-1].n_pillars_in_contact_max == 0:
        message = "the preload touches no pillar"
    sc = model.scaling
    grid = model.grid
    res = SimulationResult(
        scene=scene, status=status, message=message, results=results,
        discretisation=discretisation_info(model),
        xi=None if grid is None else grid.xi.copy(),
        zeta_tilde=None if grid is None else grid.zeta / sc.d_c,
        versions=software_versions(), definitions=sc.definitions(),
        units={} if scene.physical is None else scene.physical.si(scene_lattice(scene)))
    res.stats = {
        "wall_s": time.perf_counter() - t0,
        "cg_iterations": model.solver.iterations - it0,
        "cg_solves": model.solver.solves - solves0,
        "fft_pairs": model.fft_pairs - pairs0,
        "events": driver.events,
        "preconditioner": model.solver.precond.kind,
    }
    if model.options.far_field == "multipole":      # fibril_hpc.solve.farfield
        res.stats["far_field_products"] = model.operator.applications - far0
    held = driver.held_check
    if held is not None:        # its held states' force bound (fibril_hpc.path.confirm)
        res.stats.update(held_certified=held.local, held_refreshes=held.refused,
                         held_uncertified=driver.held_uncertified,
                         force_bound_tilde=float((held.worst + held.direction_worst) / sc.F_c))
    if isinstance(driver, MachineDriver):
        res.stats.update(jumps=driver.jumps, jump_events=driver.jump_events)
    cert = driver.certificate
    if cert is not None:        # confirm: local (fibril_hpc.solve.certify)
        res.stats.update(confirmed_local=cert.local,
                         confirmed_global=driver.relaxations - cert.local,
                         certificates_refused=cert.refused,
                         directions_local=cert.direction_local,
                         directions_refused=cert.direction_refused,
                         force_bound_tilde=float((cert.worst + cert.direction_worst) / sc.F_c))
    if status == STATUS_FAILED:
        log.warning("simulation failed: %s", message)
    return res
