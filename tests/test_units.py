"""Physical units (docs/units.md): the worked example by hand, keys, outputs in N and m."""

import json
import math

import h5py
import numpy as np
import pytest
from campaign_helpers import write_grid

from fibril_hpc import ConfigError, load_campaign, scene_from_dict, simulate
from fibril_hpc.campaign import load_spec
from fibril_hpc.cli.campaign import main as campaign_main
from fibril_hpc.inputs.config import load_scene
from fibril_hpc.io.store import read_result_file, write_result_file
from fibril_hpc.model import scene_lattice

# docs/units.md, "A worked example": PDMS-like pillars on a soft elastomer
PDMS = {"E": 3.0e6, "nu": 0.5, "dgamma": 0.05, "diameter": 20e-6, "pitch": 40e-6,
        "pillar_length": 60e-6, "pillar_modulus": 2.0e6, "sigma": 1.0e-6}
# the numbers of the page, worked by hand (6 x 6 pillars, 8 elements per diameter requested)
HAND = {"E_star": 4.0e6, "phi": 0.19635, "L": 240e-6, "k": 10.472, "k_unit": 960.0,
        "k_tilde": 0.010908, "phi_discrete": 61 / 289, "F_c": 1.6230e-3, "d_c": 1.4982e-6,
        "sigma_tilde": 0.66745}


def pdms_scene(**extra):
    return scene_from_dict({"n_side": 6, "F_P": [1.0], "physical": dict(PDMS), **extra})


def test_the_worked_example_of_the_docs():
    s = pdms_scene()
    si = s.physical.si(scene_lattice(s))
    assert s.phi == pytest.approx(HAND["phi"], rel=1e-4)
    assert si["E_star"] == pytest.approx(HAND["E_star"], rel=1e-12)
    assert si["L"] == pytest.approx(HAND["L"], rel=1e-12)
    assert si["k_unit"] == pytest.approx(HAND["k_unit"], rel=1e-12)
    assert si["phi_discrete"] == pytest.approx(HAND["phi_discrete"], rel=1e-12)
    assert s.k_tilde * si["k_unit"] == pytest.approx(HAND["k"], rel=1e-4)
    for key in ("k_tilde", "sigma_tilde"):
        assert getattr(s, key) == pytest.approx(HAND[key], rel=1e-4)
    for key in ("F_c", "d_c"):
        assert si[key] == pytest.approx(HAND[key], rel=1e-4)


def test_the_paper_biomaterial_example_holds_to_one_digit():
    """1 GPa pillars, 2 um long, 0.2 um across, 18 x 18 of them in 10 um x 10 um, E* = 1 GPa."""
    s = scene_from_dict({"n_side": 18, "F_P": [1.0], "physical": {
        "E_star": 1e9, "dgamma": 0.05, "diameter": 0.2e-6, "pitch": 10e-6 / 18,
        "pillar_length": 2e-6, "pillar_modulus": 1e9}})
    k = s.k_tilde * s.physical.si(scene_lattice(s))["k_unit"]
    assert k == pytest.approx(1e9 * math.pi * 0.1e-6**2 / 2e-6, rel=1e-12)     # E A / l
    assert k == pytest.approx(15.708, rel=1e-4)          # N/m = 0.0157 N/mm: "0.02 N/mm"
    assert s.k_tilde == pytest.approx(1.5708e-3, rel=1e-4)   # "0.002" to one digit
    assert s.phi == pytest.approx(0.1018, rel=1e-3)      # not the study's 0.16


def test_same_physics_same_key_and_normalised_scenes_keep_theirs(tmp_path):
    s = pdms_scene()
    plain = scene_from_dict({"n_side": 6, "F_P": [1.0], "phi": s.phi, "k_tilde": s.k_tilde,
                             "sigma_tilde": s.sigma_tilde})
    grid = {"output": "u.h5", "scene": {"n_side": 6, "physical": {
        k: v for k, v in PDMS.items() if k not in ("pillar_length", "pillar_modulus", "sigma")}},
        "k": [s.k_tilde * 960.0, 1.0], "sigma": [1.0e-6], "F_P": [1.0], "seeds": 1}
    a = load_spec(write_grid(tmp_path, grid, name="a.yaml"))
    b = load_spec(write_grid(tmp_path, {
        "output": "n.h5", "scene": {"n_side": 6, "phi": s.phi}, "k_tilde": list(a.k_tilde),
        "sigma_tilde": list(a.sigma_tilde), "F_P": [1.0], "seeds": 1}, name="b.yaml"))
    assert a.k_tilde[0] == pytest.approx(plain.k_tilde, rel=1e-12)
    assert sorted(j.key for j in a.jobs) == sorted(j.key for j in b.jobs)
    assert a.campaign_hash == b.campaign_hash
    assert plain.physical is None and "physical" not in plain.to_dict()
    assert scene_from_dict(s.to_dict()) == s            # the stored text reads back


@pytest.mark.parametrize("extra, field", [
    ({"k_tilde": 0.1}, "k_tilde"),
    ({"phi": 0.2}, "phi"),
    ({"physical": {**PDMS, "E_star": 1e6}}, "physical.E"),
    ({"physical": {**PDMS, "k": 3.0}}, "physical.pillar_length"),
    ({"physical": {**PDMS, "dgamma": "0.05"}}, "physical.dgamma"),
    ({"physical": {**PDMS, "nu": 0.6}}, "physical.nu"),
    ({"physical": {"E_star": 1e6, "diameter": 1e-5}}, "physical.dgamma"),
    ({"physical": {**PDMS, "sigma": 1.0}}, "physical.sigma"),
    ({"physical": {**PDMS, "mass": 1}}, "physical.mass"),
])
def test_bad_physical_blocks_are_one_line(extra, field):
    data = {"n_side": 6, "physical": dict(PDMS), **extra}
    with pytest.raises(ConfigError) as exc:
        scene_from_dict(data)
    assert exc.value.field == field and "\n" not in str(exc.value)


def test_grid_refuses_si_lists_without_units_and_both_forms(tmp_path):
    base = {"output": "x.h5", "scene": {"n_side": 2}, "sigma_tilde": 0.5, "F_P": 1.0}
    with pytest.raises(ConfigError, match="^k:"):
        load_spec(write_grid(tmp_path, {**base, "k": [1.0]}))
    with pytest.raises(ConfigError, match="absent when k_tilde"):
        load_spec(write_grid(tmp_path, {**base, "k_tilde": 1, "k": [1.0],
                                        "scene": {"physical": PDMS}}))


def test_single_run_file_carries_newtons_and_metres(tmp_path):
    s = scene_from_dict({"n_side": 2, "elements_per_diameter": 5, "F_P": [1.0],
                         "physical": {**PDMS, "sigma": 1e-7}})
    r = simulate(s)
    u = r.units
    summ = r.summary()
    assert summ["F_A_N"] == pytest.approx(r.main.F_A * u["F_c"], rel=1e-12)
    assert summ["results"][0]["d_max_m"] == pytest.approx(r.main.d_tilde_max * u["d_c"])
    path = str(tmp_path / "r.h5")
    write_result_file(path, r)
    with h5py.File(path) as fh:
        assert json.loads(fh.attrs["units"])["F_c"] == u["F_c"]
        assert fh["units/F_c"].attrs["units"] == "N" and fh["units/F_c"][()] == u["F_c"]
        g = fh["preloads/0/unloading"]
        assert g["F"].attrs["units"] == "N" and g["d"].attrs["units"] == "m"
        assert g["F_tilde"].attrs["units"] == "1" and g["F_tilde"].attrs["long_name"]
        assert np.array_equal(g["F"][()], g["F_tilde"][()] * u["F_c"])
        assert g["F_tilde"].dims[0].label == "point" and list(g["F_tilde"].dims[0].keys()) == ["point"]
        assert fh["preloads/0"].attrs["F_A_N"] == pytest.approx(summ["F_A_N"])
    back = read_result_file(path)
    assert back.units == u and back.main.F_A == r.main.F_A


def test_campaign_in_physical_units_has_si_columns_and_netcdf(tmp_path):
    xr = pytest.importorskip("xarray")
    grid = write_grid(tmp_path, {
        "output": "p.h5", "scene": {"n_side": 2, "elements_per_diameter": 5, "physical": {
            "E_star": 4e6, "dgamma": 0.05, "diameter": 20e-6, "pitch": 50e-6}},
        "k": [5.0, math.inf], "sigma": [1e-7], "F_P": [0.3, 1.0], "seeds": 1})
    assert campaign_main([grid, "--no-progress"]) == 0
    c = load_campaign(str(tmp_path / "p.h5"))
    df = c.to_dataframe()
    u = json.loads(c.meta["units"])
    assert np.allclose(df["F_A_N"], df["F_A"] * u["F_c"], rtol=1e-12)
    assert np.allclose(df["k_N_per_m"].sort_values(), [5.0, 5.0, math.inf, math.inf])
    assert np.allclose(df["sigma_m"], 1e-7)
    assert str(df["finished"].dtype).startswith("datetime64")
    ds = c.to_xarray()
    assert ds["F_A_N"].attrs["units"] == "N" and ds["F_A"].attrs["units"] == "1"
    assert ds.sizes["preload"] == 2 and ds.sizes["k_tilde"] == 2
    nc = tmp_path / "p.nc"
    assert campaign_main(["export", str(tmp_path / "p.h5"), "--netcdf", str(nc)]) == 0
    back = xr.open_dataset(nc, engine="h5netcdf").load()
    assert back.identical(ds)
    csv = tmp_path / "p.csv"          # CSV keeps the SI columns too, in the DataFrame's order
    assert campaign_main(["export", str(tmp_path / "p.h5"), "--csv", str(csv)]) == 0
    import pandas as pd

    back_csv = pd.read_csv(csv)
    assert list(back_csv.columns) == list(df.columns)
    for name in ("F_A_N", "k_N_per_m", "sigma_m", "F_c_N", "d_at_F_A_m"):
        assert np.array_equal(back_csv[name].to_numpy(), df[name].to_numpy(), equal_nan=True)
    one = ds.sel(k_tilde=ds.k_tilde[0], sigma_tilde=ds.sigma_tilde[0], seed=0, preload=1.0)
    n = int(one["unloading_n_points"])
    assert np.isfinite(one["unloading_F_tilde"][:n]).all()
    assert np.isnan(one["unloading_F_tilde"][n:]).all()


def test_scene_file_reads_1e6_as_a_number_and_refuses_repeated_keys(tmp_path):
    p = tmp_path / "s.yaml"
    p.write_text("n_side: 2\nphysical: {E_star: 1e6, dgamma: 5e-2, diameter: 2e-5}\n")
    assert load_scene(str(p)).physical.E_star == 1e6
    p.write_text("n_side: 2\nk_tilde: 0.1\nk_tilde: 0.2\n")
    with pytest.raises(ConfigError, match="line 3 repeats 'k_tilde'"):
        load_scene(str(p))
    p.write_text("k_tilde: '0.1'\n")
    with pytest.raises(ConfigError, match="not a quoted text"):
        load_scene(str(p))
