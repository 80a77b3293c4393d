"""Validation against closed-form contact mechanics (docs/model.md §8). Tolerances are the measured
discretisation bias at the resolution used (docs/scenes.md, "Validation"), not looser."""

import math

import numpy as np
import pytest

from fibril_hpc import Scene, simulate
from fibril_hpc.elastic import analytic
from fibril_hpc.geometry.grid import footprint
from fibril_hpc.geometry.scaling import Scaling
from fibril_hpc.geometry.shapes import punch_row, sphere
from fibril_hpc.model import build_model
from fibril_hpc.path.loading import CurveRecorder, PathDriver


def single_pillar(epd, opts):
    return simulate(Scene(n_side=1, k_tilde=math.inf, sigma_tilde=0.0, d_tilde=1.0,
                          elements_per_diameter=epd, solver=opts))


@pytest.mark.parametrize("epd,tol_FA,tol_d,tol_k", [(8, 0.03, 0.07, 0.04), (16, 0.025, 0.04, 0.02),
                                                   (32, 0.01, 0.015, 0.01)])
def test_single_rigid_pillar_kendall_and_stiffness(epd, tol_FA, tol_d, tol_k, opts):
    r = single_pillar(epd, opts)
    assert r.status == "ok"
    phi = r.discretisation["phi_discrete"]
    m = r.main
    # Kendall: F~_A = phi^(1/4) with the discrete footprint's equivalent radius
    assert m.F_A == pytest.approx(analytic.single_pillar_F_A(phi), rel=tol_FA)
    # the pull-off displacement d_K/d_c = -phi^(-1/4)
    assert m.d_tilde_at_F_A == pytest.approx(-phi ** -0.25, rel=tol_d)
    # flat punch stiffness F/d = 2 E* r_eq, i.e. F~/d~ = sqrt(phi); the discrete punch is softer
    stiff = m.F_P / m.d_tilde_max
    assert -tol_k < stiff / math.sqrt(phi) - 1 < 0
    # complete detachment: the last point has no contact and no force
    assert m.unloading.contact_fraction[-1] == 0 and m.unloading.F_tilde[-1] == 0


def test_punch_stiffness_converges(opts):
    errs = []
    for epd in (6, 12, 24):
        r = single_pillar(epd, opts)
        errs.append(abs(r.main.F_P / r.main.d_tilde_max / math.sqrt(r.discretisation["phi_discrete"]) - 1))
    assert errs[0] > errs[1] > errs[2]


def _drive(geom, k, adhesion, scaling, opts, targets, kind="d"):
    m = build_model(geom, k=k, adhesion=adhesion, work_of_adhesion=scaling.work_of_adhesion,
                    scaling=scaling, options=opts)
    drv = PathDriver(m)
    curve = CurveRecorder()
    snaps = drv.load(targets, kind, curve)
    return m, drv, curve, snaps


def jkr_error(ac_over_h, opts):
    R, dg = 1.0, 1.0
    ac = analytic.jkr_critical_radius(R, dg)
    h = ac / ac_over_h
    a_zero_load = 4 ** (1 / 3) * ac
    geom = sphere(R, int(math.ceil(1.3 * a_zero_load / h)), h)
    sc = Scaling(phi=1.0, work_of_adhesion=dg, area=math.pi * ac**2)
    m, drv, curve, snaps = _drive(geom, math.inf, True, sc, opts, [0.5 * a_zero_load**2 / R])
    br = drv.unload(snaps[0])
    return -br.F_min / analytic.jkr_max_tension(R, dg) - 1


@pytest.mark.slow
def test_jkr_sphere_pull_off_converges_from_above(opts):
    e6, e12 = jkr_error(6, opts), jkr_error(12, opts)
    # measured: +24 % at a_c/h = 6, +12.6 % at 12, +7.4 % at 24 (converges like h/a_c)
    assert 0 < e12 < e6
    assert e12 < 0.15


@pytest.mark.slow
def test_hertz_without_adhesion(opts):
    R = 1.0
    h = 0.01
    geom = sphere(R, 30, h)
    sc = Scaling(phi=1.0, work_of_adhesion=1.0, area=math.pi * (20 * h) ** 2)
    delta = (20 * h) ** 2 / R          # Hertz contact radius sqrt(R delta) = 20 elements
    m, drv, curve, snaps = _drive(geom, math.inf, False, sc, opts, [delta])
    assert snaps[0].point[1] == pytest.approx(analytic.hertz_force(R, delta), rel=0.02)
    # the contact area follows a = sqrt(R delta) (to about one element)
    area = np.count_nonzero(snaps[0].att) * h * h
    assert math.sqrt(area / math.pi) == pytest.approx(math.sqrt(R * delta), abs=1.5 * h)


def test_two_interacting_punches(opts):
    """Each of two punches at the brush pitch is ~0.873 as stiff as a lone punch (padding test)."""
    pitch = 21
    fp = footprint(pitch, 0.16)
    h = 1.0 / pitch
    stiff = []
    for count in (1, 2):
        geom = punch_row(fp, pitch, count, h)
        m, drv, curve, snaps = _drive(geom, math.inf, False, Scaling(0.16, 1.0), opts, [0.01])
        stiff.append(snaps[0].point[1] / 0.01 / count)
    assert stiff[1] / stiff[0] == pytest.approx(0.873, abs=0.01)
