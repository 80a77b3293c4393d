"""Accuracy presets: what they fill, what overrides them, and that every output records them."""

import dataclasses
import json

import h5py
import pytest

from fibril_hpc import ConfigError, Scene, SolverOptions, scene_from_dict
from fibril_hpc.cli.run import main as run_main
from fibril_hpc.inputs.presets import PRESETS


def test_default_preset_is_the_package_default():
    assert Scene() == Scene(preset="default")
    assert Scene().elements_per_diameter == PRESETS["default"]["elements_per_diameter"] == 8
    defaults = SolverOptions()
    for k, v in PRESETS["default"]["solver"].items():
        assert getattr(defaults, k) == v, k


@pytest.mark.parametrize("name", list(PRESETS))
def test_preset_fills_what_is_not_given(name):
    s = Scene(preset=name)
    assert s.elements_per_diameter == PRESETS[name]["elements_per_diameter"]
    for k, v in PRESETS[name]["solver"].items():
        assert getattr(s.solver, k) == v
    assert s.to_dict()["preset"] == name


def test_explicit_fields_override_the_preset():
    s = scene_from_dict({"preset": "fast", "elements_per_diameter": 12,
                         "solver": {"cg_tol": 1e-8, "fft_threads": 1}})
    assert s.elements_per_diameter == 12
    assert s.solver.cg_tol == 1e-8                       # given: wins, even at the default value
    assert s.solver.event_merge == PRESETS["fast"]["solver"]["event_merge"]   # not given: preset
    assert s.solver.fft_threads == 1
    # Python: a mapping overrides key by key; a SolverOptions object is complete and used as is
    p = Scene(preset="accurate", solver={"fft_threads": 1})
    assert p.solver == SolverOptions.from_preset("accurate", fft_threads=1)
    full = SolverOptions(fft_threads=1)
    assert Scene(preset="accurate", solver=full).solver == full
    # resolving is idempotent: copies and YAML round trips keep the knobs
    assert s.replace(seed=4).solver == s.solver
    assert scene_from_dict(s.to_dict()) == s
    assert dataclasses.replace(p).solver == p.solver


@pytest.mark.parametrize("data,field", [
    ({"preset": "fastest"}, "preset"), ({"preset": 1}, "preset"),
    ({"preset": "fast", "solver": {"cg_tol": 1.0}}, "solver.cg_tol"),
    ({"preset": "fast", "solver": {"bogus": 1}}, "solver.bogus"),
])
def test_bad_preset_input_names_the_field(data, field):
    with pytest.raises(ConfigError) as exc:
        scene_from_dict(data, where="scene.")
    assert exc.value.field == "scene." + field
    assert "\n" not in str(exc.value)


def test_cli_records_the_preset(tmp_path, capsys):
    scene = tmp_path / "s.yaml"
    scene.write_text("preset: fast\nn_side: 2\nF_P: 0.5\nsolver: {fft_threads: 1}\n")
    h5 = tmp_path / "r.h5"
    assert run_main([str(scene), "--json", "--out", str(h5)]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["scene"]["preset"] == "fast"
    assert out["scene"]["elements_per_diameter"] == 6
    assert out["scene"]["solver"]["event_merge"] == PRESETS["fast"]["solver"]["event_merge"]
    with h5py.File(h5, "r") as f:
        assert "preset: fast" in f.attrs["scene_yaml"]


def test_campaign_jobs_inherit_the_preset(tmp_path):
    from fibril_hpc.campaign.plan.spec import spec_from_dict

    spec = spec_from_dict({"output": "c.h5", "scene": {"preset": "fast", "n_side": 2},
                           "k_tilde": [0.01], "sigma_tilde": [0.5], "F_P": [1.0], "seeds": 1},
                          base_dir=str(tmp_path))
    scene = spec.tasks()[0].scene
    assert scene.preset == "fast" and scene.elements_per_diameter == 6
    assert scene.solver.cg_tol == PRESETS["fast"]["solver"]["cg_tol"]
    assert "preset: fast" in spec.resolved_yaml()


def test_no_preset_swallows_the_rise_of_a_smooth_brush():
    # sigma~ = 0.01: every pillar length within ~0.06 d_c. The loading batches are bounded by
    # the scene's own length spread (solver.load_merge_spread), so the first contacts are a few
    # pillars and F~_A rises with preload instead of sitting at the plateau from first contact
    # (a batch of 0.1 d_c put every pillar in one event); against the unbatched path
    # (load_event_merge 0) the smallest preloads' F~_A is within the documented 3 %.
    from fibril_hpc import simulate

    pre = [0.002, 0.008, 0.5]
    base = {"n_side": 6, "k_tilde": 1.0, "sigma_tilde": 0.01, "F_P": pre, "seed": 1,
            "preset": "fast"}
    fast = simulate(scene_from_dict({**base, "solver": {"fft_threads": 1}}))
    exact = simulate(scene_from_dict({**base, "solver": {"fft_threads": 1,
                                                         "load_event_merge": 0.0}}))
    swallowed = simulate(scene_from_dict({**base, "solver": {"fft_threads": 1,
                                                             "load_merge_spread": 100.0}}))
    fa = [r.F_A for r in fast.results]
    assert [r.F_P for r in fast.results] == pytest.approx(pre)
    assert fa[0] < 0.5 * fa[-1]                        # the rise is there
    for a, b in zip(fa, (r.F_A for r in exact.results)):
        assert a == pytest.approx(b, rel=0.03)
    # the old batching in d_c alone: one event reaches past the smallest preloads at the plateau
    assert swallowed.results[0].F_P > 2 * pre[0]
    assert swallowed.results[0].F_A == pytest.approx(swallowed.results[-1].F_A, rel=0.01)
    # the default scene's key is unchanged: the option is at its default, left out of keys
    assert "load_merge_spread" not in Scene().to_dict()["solver"]
