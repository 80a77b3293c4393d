import dataclasses
import math

import pytest

from fibril_hpc import ConfigError, Scene, SolverOptions, scene_from_dict


def test_defaults_are_the_default_scene():
    s = Scene()
    assert (s.n_side, s.phi, s.k_tilde, s.sigma_tilde, s.F_P, s.seed) == (18, 0.16, 0.01, 0.5, (4.0,), 0)
    assert s.adhesion and s.d_tilde is None and s.preload_kind == "F_P"


@pytest.mark.parametrize("field,value,snippet", [
    ("n_side", 0, "n_side"), ("n_side", 2.5, "n_side"), ("n_side", True, "n_side"),
    ("phi", 0.8, "phi"), ("phi", float("nan"), "phi"), ("phi", -0.1, "phi"),
    ("k_tilde", 0, "k_tilde"), ("k_tilde", -1, "k_tilde"), ("k_tilde", "soft", "k_tilde"),
    ("sigma_tilde", -0.1, "sigma_tilde"), ("sigma_tilde", float("inf"), "sigma_tilde"),
    ("d_tilde", [], "d_tilde"), ("d_tilde", [1, float("nan")], "d_tilde"), ("d_tilde", [1, 1], "d_tilde"),
    ("F_P", 0, "F_P"), ("F_P", [-1], "F_P"), ("seed", -1, "seed"), ("seed", 1.5, "seed"),
    ("elements_per_diameter", 1, "elements_per_diameter"), ("adhesion", "yes", "adhesion"),
])
def test_bad_fields_name_the_field_and_range(field, value, snippet):
    with pytest.raises(ConfigError) as ei:
        scene_from_dict({field: value})
    msg = str(ei.value)
    assert msg.startswith(snippet) and "allowed" in msg and "\n" not in msg


def test_unknown_keys_and_options_rejected():
    with pytest.raises(ConfigError, match=r"^k_tlide: .*\(did you mean 'k_tilde'\?\)"):
        scene_from_dict({"k_tlide": 1})
    with pytest.raises(ConfigError, match=r"^K_TILDE: .*\(did you mean 'k_tilde'\?\)"):
        scene_from_dict({"K_TILDE": 1})
    with pytest.raises(ConfigError, match="^solver.cg_tolerance"):
        scene_from_dict({"solver": {"cg_tolerance": 1e-3}})
    with pytest.raises(ConfigError, match="^solver.cg_tol"):
        scene_from_dict({"solver": {"cg_tol": 0.5}})
    with pytest.raises(ConfigError, match="^solver.fft_backend"):
        SolverOptions(fft_backend="cufft")
    with pytest.raises(ConfigError, match="^F_P"):
        scene_from_dict({"F_P": 1, "d_tilde": 1})


def test_inf_and_lists_are_accepted():
    s = scene_from_dict({"k_tilde": "inf", "d_tilde": [2, -1, 0.5]})
    assert math.isinf(s.k_tilde) and s.rigid
    assert s.d_tilde == (-1.0, 0.5, 2.0) and s.F_P is None
    assert scene_from_dict({"k_tilde": float("inf")}).rigid
    assert s.replace(F_P=3).d_tilde is None


def test_default_fft_threads_is_one():
    assert SolverOptions().threads == 1
    assert SolverOptions(fft_threads=3).threads == 3


def test_one_range_gives_the_check_and_the_text():
    from fibril_hpc.inputs.ranges import range_of

    for field, bad in (("phi", 0.9), ("k_tilde", 0), ("sigma_tilde", -1.0), ("seed", -1),
                       ("n_side", 0), ("elements_per_diameter", 1.0), ("F_P", -1.0)):
        rng = range_of(Scene, field)
        with pytest.raises(ConfigError) as e:
            Scene(**{field: bad})
        assert e.value.field == field and e.value.allowed.startswith(rng.allowed())
    assert range_of(Scene, "phi").allowed() == "a number in (0, 0.785)"
    assert range_of(Scene, "k_tilde").allowed(plural=True) == \
        "numbers > 0, or inf for rigid pillars"
    with pytest.raises(ConfigError, match=r"solver.fft_threads: .*null \(one thread\)"):
        SolverOptions(fft_threads=0)


def test_option_kinds_decide_keys_presets_and_operators():
    from fibril_hpc.campaign.plan.keys import KEY_EXCLUDED_SOLVER
    from fibril_hpc.inputs.presets import PRESETS

    # the job-key contract of existing campaign files: exactly these are left out
    assert set(KEY_EXCLUDED_SOLVER) == {"fft_threads", "max_wall_s", "max_events"}
    kinds = {k: set(SolverOptions.of_kind(k)) for k in ("accuracy", "backend", "resource")}
    assert set().union(*kinds.values()) == {f.name for f in dataclasses.fields(SolverOptions)}
    for p in PRESETS.values():
        assert set(p["solver"]) <= kinds["accuracy"]
    o = SolverOptions(fft_threads=None, fft_planner="measure")
    assert o.operator_settings() == {"backend": "pyfftw", "threads": 1, "planner": "measure"}
