"""Lab scenes in campaigns (issue 11): the compliant machine's results in job records, pillar
counts, sweeps over measured height files."""

import csv
import math
import os

import h5py
import numpy as np
import pytest

from fibril_hpc import load_campaign
from fibril_hpc.campaign.analysis.data import fill_k_machine
from fibril_hpc.campaign.analysis.export import export_csv
from fibril_hpc.campaign.plan.spec import spec_from_dict
from fibril_hpc.campaign.run.runner import run_serial
from fibril_hpc.campaign.storage.record import COLUMNS

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
    # export: today's columns in today's order, then the new ones (the machine's, then the
    # local confirmation's, issue 35: empty in these records, solved with confirm: global)
    export_csv(path, str(tmp_path / "m.csv"))
    with open(tmp_path / "m.csv") as fh:
        rows = list(csv.DictReader(fh))
    assert tuple(rows[0]) == COLUMNS and COLUMNS[-7:-3] == MACHINE
    assert COLUMNS[-3:] == ("confirmed_local", "confirmed_global", "force_bound_tilde")
    by = {r["key"]: r for r in rows}
    assert by[rigid["key"]]["k_machine"] == "inf" and by[rigid["key"]]["jumps"] == ""
    assert all(r[c] == "" for r in rows for c in COLUMNS[-3:])
    assert float(by[soft["key"]]["F_jump"]) == soft["F_jump"]
    df = c.to_dataframe()
    assert str(df["jumps"].dtype) == "Int64"
    assert df.set_index("key")["jumps"].isna()[rigid["key"]]


def test_old_files_open_with_the_machine_fields_missing(tmp_path):
    c = load_campaign(os.path.join(DATA, "campaign_v1.h5"), include_unchecked=True)
    for j in c.jobs:
        assert j["k_machine"] == math.inf and j.get("jumps") is None
    df = c.to_dataframe()
    assert list(df.columns) == list(COLUMNS)
    assert df["jumps"].isna().all() and df["F_jump"].isna().all()
    # a record of today's main for a compliant machine names its machine only in its scene
    assert fill_k_machine({"scene_yaml": "n_side: 2\nk_machine: 0.5\n"})["k_machine"] == 0.5
    assert fill_k_machine({"scene_yaml": "n_side: 2\n"})["k_machine"] == math.inf
    assert fill_k_machine({"k_machine": 2.0, "scene_yaml": "k_machine: 0.5\n"})["k_machine"] == 2


@pytest.mark.slow
def test_report_shows_the_jump_off_beside_the_peak_when_the_machine_is_swept(tmp_path):
    from fibril_hpc.campaign.analysis.report import write_report

    grid = {**GRID, "F_P": [1.0, 2.0]}
    spec = spec_from_dict({**grid, "sweep": {"k_machine": [".inf", 0.05]}},
                          base_dir=str(tmp_path))
    assert run_serial(spec, progress=False) == 0
    files = write_report(str(tmp_path / "m.h5"), str(tmp_path / "rep"), n_boot=20)
    assert str(tmp_path / "rep" / "machine.csv") in files
    assert str(tmp_path / "rep" / "machine.png") in files
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


# ------------------------------------------------------------------------------ pillar count
def test_a_pillar_count_is_the_scene_of_its_side():
    from fibril_hpc import Scene
    from fibril_hpc.campaign.plan.spec import job_key

    # keys computed by the tree before n_pillars existed (d71b20c, git archive export)
    assert job_key(Scene()) == "4c1f02b9c2643719"
    assert job_key(Scene(n_side=6, k_tilde=0.1, F_P=2.0)) == "d568cf103086c81f"
    assert job_key(Scene(n_side=7, lattice="hexagonal", F_P=1.0)) == "9a75aafcb51091c8"
    by_count = Scene(n_pillars=36, k_tilde=0.1, F_P=2.0)
    assert by_count == Scene(n_side=6, k_tilde=0.1, F_P=2.0) and by_count.n_pillars is None
    assert job_key(by_count) == "d568cf103086c81f" and "n_pillars" not in by_count.to_dict()
    assert job_key(Scene(n_pillars=49, lattice="hexagonal", F_P=1.0)) == "9a75aafcb51091c8"
    assert by_count.replace(n_pillars=49).n_side == 7 and by_count.replace(k_tilde=1).n_side == 6
    assert Scene(n_pillars=1).n_side == 1 and Scene(n_pillars=1000000, elements_per_diameter=3).n_side == 1000


@pytest.mark.parametrize("kw,text", [
    (dict(n_pillars=40), "the nearest are 36 (n_side 6) and 49 (n_side 7)"),
    (dict(n_pillars=50, lattice="hexagonal"), "lattice hexagonal): the nearest are 49"),
    (dict(n_pillars=36, n_side=6), "give n_side or n_pillars, not both"),
    (dict(n_pillars=0), "a square number n_side**2 in [1, 1000000]"),
    (dict(n_pillars=2.5), "a square number n_side**2 in [1, 1000000]"),
    (dict(n_pillars=True), "a square number n_side**2 in [1, 1000000]"),
])
def test_a_bad_pillar_count_is_one_line(kw, text):
    from fibril_hpc import Scene
    from fibril_hpc.errors import ConfigError

    with pytest.raises(ConfigError) as e:
        Scene(**kw)
    assert e.value.field == "n_pillars" and text in str(e.value) and "\n" not in str(e.value)


@pytest.mark.parametrize("content", ["n_pillars: 10\n", "n_side: 3\nn_pillars: 9\n"])
def test_a_bad_pillar_count_exits_2_writing_nothing(tmp_path, capsys, content):
    from fibril_hpc.cli.campaign import main as campaign_main
    from fibril_hpc.cli.run import main as run_main

    scene = tmp_path / "scene.yaml"
    scene.write_text(content)
    out = tmp_path / "never.h5"
    assert run_main([str(scene), "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("fibril-run: error: n_pillars")
    grid = tmp_path / "grid.yaml"
    grid.write_text("output: never.h5\nk_tilde: 0.1\nsigma_tilde: 0.5\nF_P: 1\nscene:\n  "
                    + content.strip().replace("\n", "\n  ") + "\n")
    assert campaign_main([str(grid)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "scene.n_pillars" in err[0]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["grid.yaml", "scene.yaml"]


def test_a_grid_given_by_pillar_count_has_the_keys_of_its_side(tmp_path):
    side = spec_from_dict({**GRID, "scene": {**GRID["scene"], "n_side": 3}},
                          base_dir=str(tmp_path))
    count = spec_from_dict({**GRID, "scene": {"n_pillars": 9, "elements_per_diameter": 5,
                                              "solver": {"fft_threads": 1}}},
                           base_dir=str(tmp_path))
    assert [j.key for j in count.jobs] == [j.key for j in side.jobs]
    assert count.campaign_hash == side.campaign_hash and count.resolved() == side.resolved()


# ------------------------------------------------------------------------------ file sweeps
def _files(folder):
    (folder / "a.csv").write_text("0.0, 0.5\n1.0, 0.25\n")
    np.save(folder / "b.npy", np.array([0.2, 0.0, 0.7, 1.3]))
    (folder / "k.csv").write_text("0.1 0.2 0.05 0.1\n")


def test_a_grid_sweeps_measured_files_each_job_recording_its_hash(tmp_path):
    import hashlib

    import yaml

    _files(tmp_path)
    sweep = {"heights": ["gaussian", "a.csv", "b.npy"], "k_law": ["one", "k.csv"]}
    spec = spec_from_dict({**GRID, "sweep": sweep}, base_dir=str(tmp_path))
    assert len(spec.jobs) == 6 and len({j.key for j in spec.jobs}) == 6
    # a file swept is the file given in the scene: same job key
    fixed = spec_from_dict({**GRID, "scene": {**GRID["scene"], "heights": "b.npy",
                                              "k_law": "k.csv"}}, base_dir=str(tmp_path))
    assert fixed.jobs[0].key in {j.key for j in spec.jobs}
    # the law jobs are the plain grid's jobs (a law clears no source it never had)
    plain = spec_from_dict(GRID, base_dir=str(tmp_path))
    assert plain.jobs[0].key in {j.key for j in spec.jobs}
    assert run_serial(spec, progress=False) == 0
    c = load_campaign(str(tmp_path / "m.h5"))
    sha = {n: hashlib.sha256((tmp_path / n).read_bytes()).hexdigest()
           for n in ("a.csv", "b.npy", "k.csv")}
    seen = set()
    for j in c.jobs:
        assert j["status"] == "done"
        scene = yaml.safe_load(j["scene_yaml"])
        h, k = scene.get("heights_source", ""), scene.get("k_source", "")
        seen.add((h.rsplit("/", 1)[-1].split()[0] if h else scene.get("heights", "gaussian"),
                  k.rsplit("/", 1)[-1].split()[0] if k else "one"))
        for n, digest in sha.items():
            if (h + k).count(n):
                assert f"{n} sha256:{digest}" in h + k
        if h:
            assert scene["heights"] == (np.load(tmp_path / "b.npy").tolist() if "b.npy" in h
                                        else [0.0, 0.5, 1.0, 0.25])
    assert seen == {(x, y) for x in ("gaussian", "a.csv", "b.npy") for y in ("one", "k.csv")}
    # the law jobs of a base scene with a measured file drop its source
    over = spec_from_dict({**GRID, "scene": {**GRID["scene"], "heights": "a.csv"},
                           "sweep": {"heights": ["uniform", "b.npy"]}}, base_dir=str(tmp_path))
    scenes = [t.scene for t in over.tasks()]
    assert [s.heights_source.split()[0].rsplit("/", 1)[-1] if s.heights_source else s.heights
            for s in scenes] == ["uniform", "b.npy"]


@pytest.mark.parametrize("bad,text", [
    ("missing.csv", "an existing file"),
    ("nan.csv", "finite lengths >= 0 (value nan at pillar 1)"),
    ("three.csv", "one value per pillar: n_side**2 = 4 (the file holds 3)"),
])
def test_a_bad_file_in_a_sweep_is_one_line_exit_2_nothing_written(tmp_path, capsys, bad, text):
    from fibril_hpc.cli.campaign import main as campaign_main
    from fibril_hpc.errors import ConfigError

    _files(tmp_path)
    (tmp_path / "nan.csv").write_text("1 nan 1 1\n")
    (tmp_path / "three.csv").write_text("1 1 1\n")
    with pytest.raises(ConfigError) as e:
        spec_from_dict({**GRID, "sweep": {"heights": ["a.csv", bad]}}, base_dir=str(tmp_path))
    assert e.value.field == "sweep.heights" and e.value.value == bad and text in str(e.value)
    before = sorted(p.name for p in tmp_path.iterdir())
    grid = tmp_path / "grid.yaml"
    grid.write_text(f"output: never.h5\nk_tilde: 0.1\nsigma_tilde: 0.5\nF_P: 1\n"
                    f"scene: {{n_side: 2}}\nsweep: {{heights: [a.csv, {bad}]}}\n")
    assert campaign_main([str(grid)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "sweep.heights" in err[0] and bad in err[0]
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(before + ["grid.yaml"])
