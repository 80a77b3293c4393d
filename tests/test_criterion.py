"""``solver.criterion``: the mesh criterion (default, today's bit for bit) and the footprint one
(sigma_c calibrated so that one isolated rigid flat pillar meets Kendall)."""

import math

import numpy as np
import pytest

from fibril_hpc import Scene, simulate
from fibril_hpc.api import calibrate
from fibril_hpc.campaign.plan.keys import job_key
from fibril_hpc.elastic.analytic import single_pillar_F_A
from fibril_hpc.errors import ConfigError
from fibril_hpc.geometry.scaling import critical_stress
from fibril_hpc.inputs.scene import scene_from_dict
from fibril_hpc.model import OperatorCache, build_scene_model
from fibril_hpc.path.criterion import calibration_scene, footprint_factor

FP = {"fft_threads": 1, "criterion": "footprint"}


@pytest.mark.parametrize("epd,lattice", [(6, "square"), (8, "square"), (11, "square"),
                                         (12, "square"), (10, "hexagonal")])
def test_calibrated_single_pillar_meets_kendall(epd, lattice):
    """One solve and a ratio suffice: the calibrated pillar's pull-off is Kendall's to rounding
    (its unloading branch is linear in (d, sigma_c) jointly), while the mesh criterion's misses."""
    one = calibration_scene(Scene(elements_per_diameter=epd, lattice=lattice, solver=FP))
    assert one.solver.criterion == "mesh" and one.n_side == 1 and one.rigid
    mesh = simulate(one)
    cal = simulate(one.replace(solver=one.solver.replace(criterion="footprint")))
    kendall = single_pillar_F_A(cal.discretisation["phi_discrete"])
    c = cal.discretisation["criterion_factor"]
    assert abs(cal.main.F_A / kendall - 1) < 1e-9
    assert abs(mesh.main.F_A / kendall - 1) > 1e-3            # the staircase it corrects
    assert c == pytest.approx(kendall / mesh.main.F_A, rel=1e-12)
    # the whole branch scales by c: the pull-off displacement too
    assert cal.main.d_tilde_at_F_A == pytest.approx(c * mesh.main.d_tilde_at_F_A, rel=1e-9)


def test_factor_is_one_footprints_and_scales_sigma_c():
    # the factor depends on the footprint in elements, not on the brush or its springs
    a = footprint_factor(Scene(n_side=3, elements_per_diameter=6, solver=FP), simulate)
    b = calibrate(Scene(n_side=5, k_tilde=0.1, sigma_tilde=2, elements_per_diameter=6,
                        solver=FP))
    assert a == b and a == pytest.approx(1.0802, abs=1e-4)      # -7.4 % single-pillar error
    s = Scene(n_side=3, elements_per_diameter=6, solver=FP)
    m = build_scene_model(s, calibrate=calibrate)
    assert m.criterion_factor == a
    with pytest.raises(ValueError, match="calibrate="):     # the model cannot calibrate itself
        build_scene_model(s)
    assert m.sigma_c == critical_stress(m.geometry.h, 1.0) * a
    # no adhesion: no criterion, nothing to calibrate
    assert footprint_factor(s.replace(adhesion=False), simulate) == 1.0
    # a campaign's operator cache computes it once per lattice step and accuracy options, for
    # every brush size alike
    calls = []
    cache = OperatorCache()
    for n_side in (3, 3, 5, 2):
        got = cache.factor(s.replace(n_side=n_side),
                           lambda sc: calls.append(sc) or calibrate(sc))
        assert got == a
    assert len(calls) == 1


def test_mesh_default_is_todays_model_text_and_key(opts):
    s = Scene(n_side=3, elements_per_diameter=6, F_P=1.0, solver=opts)
    assert s.solver.criterion == "mesh"
    m = build_scene_model(s)
    assert m.criterion_factor == 1.0 and m.sigma_c == critical_stress(m.geometry.h, 1.0)
    # at its default the option is neither stored in the scene text nor part of job keys
    explicit = Scene(solver={"criterion": "mesh"})
    assert "criterion" not in Scene().to_dict()["solver"]
    assert explicit.to_dict() == Scene().to_dict() and job_key(explicit) == job_key(Scene())
    # the default scene's key and text are those of the code before the option (d71b20c)
    assert job_key(Scene()) == "4c1f02b9c2643719"
    assert job_key(Scene(F_P=1.0)) == "3c32b31a328a5179"
    assert job_key(Scene(preset="accurate", F_P=2.0)) == "173dcf1523bd61d8"
    r = simulate(s)
    assert "criterion_factor" not in r.discretisation
    # set, it is stored, keyed and read back
    f = Scene(solver={"criterion": "footprint"})
    assert f.to_dict()["solver"]["criterion"] == "footprint" and job_key(f) != job_key(Scene())
    assert scene_from_dict(f.to_dict()) == f


def test_footprint_changes_the_brush_through_sigma_c_only(opts):
    base = Scene(n_side=3, k_tilde=0.05, sigma_tilde=0.5, F_P=1.0, elements_per_diameter=6)
    mesh = simulate(base.replace(solver=opts))
    cal = simulate(base.replace(solver=opts.replace(criterion="footprint")))
    assert mesh.status == cal.status == "ok"
    # the same loading branch (sigma_c does not enter loading from a flat, adhesion-free start
    # until tension), a different pull-off
    assert np.array_equal(mesh.main.loading.F_tilde[:3], cal.main.loading.F_tilde[:3])
    assert cal.main.F_A != mesh.main.F_A and math.isfinite(cal.main.F_A)


def test_bad_values_are_refused():
    with pytest.raises(ConfigError, match="solver.criterion"):
        Scene(solver={"criterion": "kendall"})
    with pytest.raises(ConfigError, match=r"solver.criterion: .*mesh for tip: sphere"):
        Scene(tip="sphere", tip_radius=2.0, solver={"criterion": "footprint"})
