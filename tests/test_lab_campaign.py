"""Lab scenes in campaigns (issue 11): the compliant machine's results in job records, pillar
counts, sweeps over measured height files."""

import csv
import math
import os

import h5py
import numpy as np
import pytest

from fibril_hpc import load_campaign
from fibril_hpc.campaign.data import fill_k_machine
from fibril_hpc.campaign.export import export_csv
from fibril_hpc.campaign.record import COLUMNS
from fibril_hpc.campaign.runner import run_serial
from fibril_hpc.campaign.spec import spec_from_dict

DATA = os.path.join(os.path.dirname(__file__), "data")
MACHINE = ("k_machine", "jumps", "F_jump", "d_machine_tilde_at_F_A")
GRID = {"output": "m.h5", "scene": {"n_side": 2, "elements_per_diameter": 5,
                                    "solver": {"fft_threads": 1}},
        "k_tilde": 0.1, "sigma_tilde": 0.5, "F_P": 1.5, "seeds": 1}


# ------------------------------------------------------------------------------ machine records
def test_machine_results_are_recorded_only_for_a_compliant_machine(tmp_path):
    spec = spec_from_dict({**GRID, "sweep": {"k_machine": [".inf", 0.05]}},
                          base_dir=str(tmp_path))
    assert run_serial(spec, progress=False) == 0
    path = str(tmp_path / "m.h5")
    with h5py.File(path, "r") as fh:
        groups = {g.attrs["key"]: g for g in fh["jobs"].values()}
        by_km = {}
        for g in groups.values():
            km = g.attrs.get("k_machine", math.inf)
            by_km[km] = (set(g.attrs), set(g["unloading"]), set(g["loading"]))
    rigid_attrs, rigid_curve, _ = by_km[math.inf]
    soft_attrs, soft_curve, soft_load = by_km[0.05]
    # rigid: today's record, nothing added; compliant: the four fields and the machine curve
    assert not rigid_attrs & set(MACHINE) and "d_machine_tilde" not in rigid_curve
    assert set(MACHINE) <= soft_attrs and soft_attrs - set(MACHINE) == rigid_attrs
    assert "d_machine_tilde" in soft_curve and "d_machine_tilde" in soft_load
    c = load_campaign(path)
    rigid = c.select(k_machine=math.inf)[0]
    soft = c.select(k_machine=0.05)[0]
    assert rigid.get("jumps") is None and rigid.get("F_jump") is None
    assert soft["jumps"] >= 1 and soft["status"] == "done"
    # F_A (the peak tension) does not depend on the machine; the final jump-off does, and is
    # never above the peak
    assert soft["F_A"] == pytest.approx(rigid["F_A"], rel=1e-9)
    assert 0 < soft["F_jump"] <= soft["F_A"] * (1 + 1e-12)
    u = soft["unloading"]
    i = int(np.argmin(u["F_tilde"]))
    assert soft["d_machine_tilde_at_F_A"] == pytest.approx(u["d_machine_tilde"][i], rel=1e-12)
    # under tension the stretched train leaves the machine end behind the plate (d > 0: towards
    # the surface)
    assert soft["d_machine_tilde_at_F_A"] < soft["d_tilde_at_F_A"]
    # export: today's columns in today's order, then the new ones
    export_csv(path, str(tmp_path / "m.csv"))
    with open(tmp_path / "m.csv") as fh:
        rows = list(csv.DictReader(fh))
    assert tuple(rows[0]) == COLUMNS and COLUMNS[-4:] == MACHINE
    by = {r["key"]: r for r in rows}
    assert by[rigid["key"]]["k_machine"] == "inf" and by[rigid["key"]]["jumps"] == ""
    assert float(by[soft["key"]]["F_jump"]) == soft["F_jump"]
    df = c.frame()
    assert str(df["jumps"].dtype) == "Int64"
    assert df.set_index("key")["jumps"].isna()[rigid["key"]]


def test_old_files_open_with_the_machine_fields_missing(tmp_path):
    c = load_campaign(os.path.join(DATA, "campaign_v1.h5"))
    for j in c.jobs:
        assert j["k_machine"] == math.inf and j.get("jumps") is None
    df = c.frame()
    assert list(df.columns) == list(COLUMNS)
    assert df["jumps"].isna().all() and df["F_jump"].isna().all()
    # a record of today's main for a compliant machine names its machine only in its scene
    assert fill_k_machine({"scene_yaml": "n_side: 2\nk_machine: 0.5\n"})["k_machine"] == 0.5
    assert fill_k_machine({"scene_yaml": "n_side: 2\n"})["k_machine"] == math.inf
    assert fill_k_machine({"k_machine": 2.0, "scene_yaml": "k_machine: 0.5\n"})["k_machine"] == 2


def test_report_shows_the_jump_off_beside_the_peak_when_the_machine_is_swept(tmp_path):
    from fibril_hpc.campaign.report import write_report

    grid = {**GRID, "F_P": [1.0, 2.0]}
    spec = spec_from_dict({**grid, "sweep": {"k_machine": [".inf", 0.05]}},
                          base_dir=str(tmp_path))
    assert run_serial(spec, progress=False) == 0
    files = write_report(str(tmp_path / "m.h5"), str(tmp_path / "rep"), n_boot=20)
    assert str(tmp_path / "rep" / "machine.csv") in files
    with open(tmp_path / "rep" / "machine.csv") as fh:
        rows = list(csv.DictReader(fh))
    c = load_campaign(str(tmp_path / "m.h5"))
    assert [(r["preload"], r["k_machine"]) for r in rows] == [
        ("1.0", "inf"), ("1.0", "0.05"), ("2.0", "inf"), ("2.0", "0.05")]
    for r in rows:
        (j,) = c.select(preload=float(r["preload"]), k_machine=float(r["k_machine"]))
        assert float(r["F_A"]) == j["F_A"]
        assert r["F_jump"] == ("" if r["k_machine"] == "inf" else repr(j["F_jump"]))
    page = (tmp_path / "rep" / "README.md").read_text()
    assert "## Loading machines" in page and "F̃_jump" in page
    # without a machine sweep: no machine table
    spec = spec_from_dict({**grid, "output": "r.h5"}, base_dir=str(tmp_path))
    assert run_serial(spec, progress=False) == 0
    files = write_report(str(tmp_path / "r.h5"), str(tmp_path / "rep2"), n_boot=20)
    assert not any("machine" in f for f in files)
