"""fibril-accuracy: the --quick machinery end to end (tables, plot, references, errors), resume,
and one-line errors with exit status 2."""

import csv
import math
import subprocess
import sys

import pytest

from fibril_hpc import accuracy
from fibril_hpc.cli.accuracy import main as accuracy_main
from fibril_hpc.inputs.presets import PRESETS


@pytest.fixture(scope="module")
def quick(tmp_path_factory):
    out = tmp_path_factory.mktemp("acc") / "study"
    assert accuracy_main(["--quick", "--out", str(out)]) == 0
    return out


def test_quick_writes_table_csv_and_plot(quick):
    with open(quick / "accuracy.csv", encoding="utf-8") as fh:
        rows = list(csv.DictReader(fh))
    planned = sum(len(accuracy.plan(c, True)) for c in ("pillar", "brush6"))
    assert len(rows) == planned
    assert {r["status"] for r in rows} == {"ok"}
    assert {r["kind"] for r in rows} >= {"resolution", "knob", "preset", "tight", "reference"}
    for r in rows:
        assert float(r["wall_s"]) > 0 and float(r["cpu_s"]) >= 0
        assert math.isfinite(float(r["F_A"])) and float(r["F_A"]) > 0
    png = (quick / "pareto.png").read_bytes()
    assert png[:8] == b"\x89PNG\r\n\x1a\n" and len(png) > 20_000
    md = (quick / "accuracy.md").read_text()
    assert "| case | kind |" in md and "`brush6` reference" in md
    every = md.split("All runs:")[1]               # one line per run there
    assert sum(line.startswith("| pillar") for line in every.splitlines()) == \
        sum(r["case"] == "pillar" for r in rows)


def test_quick_errors_are_the_exact_and_reference_errors(quick):
    rows = accuracy.read_rows(str(quick / "accuracy.csv"))
    refs = accuracy.add_errors(rows)
    pillar = [r for r in rows if r["case"] == "pillar"]
    for r in pillar:
        # exact Kendall and punch stiffness on the run's own discrete footprint
        assert r["F_A_exact"] == pytest.approx(r["phi_discrete"] ** 0.25, rel=1e-9)
        assert r["err_F_A"] == pytest.approx(r["F_A"] / r["phi_discrete"] ** 0.25 - 1, abs=1e-9)
        assert r["err_F_P"] == pytest.approx(r["F_P"] / (r["phi_discrete"] ** 0.5 * 1.0) - 1,
                                             abs=1e-9)
        assert abs(r["err_F_A"]) < 0.10          # the measured staircase, not garbage
    # the brush reference is its finest tight run, and its uncertainty comes from the others
    ref = refs["brush6"]
    assert ref["row"]["kind"] == "reference"
    finest = max(r["epd"] for r in rows if r["case"] == "brush6")
    assert ref["row"]["epd"] == finest
    assert ref["unc"]["F_A"] >= 0 or math.isnan(ref["unc"]["F_A"])
    for r in rows:
        if r["case"] == "brush6" and r is not ref["row"]:
            assert r["err_F_A"] == pytest.approx(r["F_A"] / ref["row"]["F_A"] - 1, abs=1e-12)
    # a knob row is compared with the tight run at its own resolution
    k = next(r for r in rows if r["case"] == "brush6" and r["kind"] == "knob")
    t = next(r for r in rows if r["case"] == "brush6" and r["kind"] == "tight"
             and r["epd"] == k["epd"])
    assert k["kerr_F_A"] == pytest.approx(k["F_A"] / t["F_A"] - 1, abs=1e-12)
    # tight knobs at the same resolution agree with the loose ones to a fraction of a percent
    assert abs(k["kerr_F_A"]) < 5e-3


def test_presets_in_the_study_are_the_presets(quick):
    rows = accuracy.read_rows(str(quick / "accuracy.csv"))
    names = {r["value"] for r in rows if r["kind"] == "preset"}
    assert names == set(PRESETS)
    # the default preset is the default knobs: its row reuses the resolution run's numbers
    for case in ("pillar", "brush6"):
        d = next(r for r in rows if r["case"] == case and r["value"] == "default")
        same = [r for r in rows if r["case"] == case and r["kind"] == "resolution"
                and r["epd_target"] == d["epd_target"]]
        if same:
            assert same[0]["F_A"] == d["F_A"] and same[0]["wall_s"] == d["wall_s"]


def beside_presets(quick, kind):
    """(rows, page text, [(case, preset, the preset's row, the row of ``kind``)]) of the quick
    study, for every case and preset."""
    rows = accuracy.read_rows(str(quick / "accuracy.csv"))
    accuracy.add_errors(rows)
    md = (quick / "accuracy.md").read_text()

    def row(case, k, name):
        return next(r for r in rows if r["case"] == case and r["kind"] == k
                    and r["value"] == name)

    pairs = [(case, name, row(case, "preset", name), row(case, kind, name))
             for case in ("pillar", "brush6") for name in PRESETS]
    return rows, md, pairs


def test_confirm_local_is_a_point_beside_each_preset(quick):
    rows, md, pairs = beside_presets(quick, "local")
    for case, name, g, loc in pairs:
        assert loc["epd"] == g["epd"] and loc["status"] == "ok"
        # its own run, with the confirmation on: the global path keeps no state locally
        assert g["confirmed_local"] == 0 and loc["confirmed_local"] > 0
        assert loc["F_A"] == pytest.approx(g["F_A"], rel=1e-3)
        assert math.isfinite(loc["err_F_A"]) and loc["fft_pairs"] <= g["fft_pairs"]
        assert f"| {name} + confirm: local |" in md
        assert f"| {case} | {name} + confirm: local | " in md   # against its preset
    # on the brush the local path skips global solves: fewer FFT pairs than its preset
    b = {r["kind"]: r for r in rows if r["case"] == "brush6" and r["value"] == "default"}
    assert b["local"]["fft_pairs"] < b["preset"]["fft_pairs"]


def test_far_field_by_moments_is_a_point_beside_each_preset(quick):
    rows, md, pairs = beside_presets(quick, "multipole")
    for case, name, g, far in pairs:
        assert far["epd"] == g["epd"] and far["status"] == "ok"
        assert far["F_A"] == pytest.approx(g["F_A"], rel=2e-3)
        # (one pillar: its direction's exact solve takes the pair or two that the
        # reference's local cascade does without)
        assert math.isfinite(far["err_F_A"]) and far["fft_pairs"] <= g["fft_pairs"] + 2
        assert f"| {name} + far_field: multipole |" in md
        assert f"| {case} | {name} + far_field: multipole | " in md
    b = {r["kind"]: r for r in rows if r["case"] == "brush6" and r["value"] == "default"}
    assert b["multipole"]["fft_pairs"] < b["preset"]["fft_pairs"]


def test_resume_and_report_only_run_nothing_new(quick, tmp_path):
    before = (quick / "accuracy.csv").read_text()
    assert accuracy_main(["--quick", "--out", str(quick), "--resume"]) == 0
    assert (quick / "accuracy.csv").read_text() == before
    assert accuracy_main(["--out", str(quick), "--report-only"]) == 0


def test_pareto_front():
    pts = [(1.0, 0.5), (2.0, 0.6), (3.0, 0.1), (0.5, 0.9), (4.0, 0.1), (5.0, 0.01)]
    assert accuracy.pareto(pts) == [(0.5, 0.9), (1.0, 0.5), (3.0, 0.1), (5.0, 0.01)]


@pytest.mark.parametrize("args,field", [
    (["--cases", "bogus"], "--cases"),
    (["--quick", "--cases", "brush18"], "--cases"),
    (["--report-only"], "--report-only"),
])
def test_bad_arguments_one_line_exit_2_nothing_written(tmp_path, args, field):
    out = tmp_path / "never"
    proc = subprocess.run([sys.executable, "-m", "fibril_hpc.cli.accuracy", "--out", str(out), *args],
                          capture_output=True, text=True)
    assert proc.returncode == 2
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"fibril-accuracy: error: {field}")
    assert not out.exists()


def test_missing_parent_folder(tmp_path, capsys):
    assert accuracy_main(["--quick", "--out", str(tmp_path / "no" / "dir")]) == 2
    assert "--out" in capsys.readouterr().err
    assert not (tmp_path / "no").exists()
