"""fibril-run end to end: JSON, HDF5, plot, versions, and one-line errors with exit status 2."""

import json
import os
import subprocess
import sys

import h5py
import pytest

from fibril_hpc.cli.run import main as run_main

SCENE = """\
n_side: 2
k_tilde: 0.05
sigma_tilde: 0.5
F_P: [0.5, 1.0]
elements_per_diameter: 5
solver: {fft_threads: 1}
"""


@pytest.fixture
def scene_file(tmp_path):
    p = tmp_path / "scene.yaml"
    p.write_text(SCENE)
    return p


def test_json_summary(scene_file, capsys):
    assert run_main([str(scene_file), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    for key in ("F_P", "F_A", "d_tilde_max", "n_pillars_in_contact_max", "phi_discrete",
                "n_elements", "wall_s", "cg_iterations", "fft_pairs", "status", "results", "versions"):
        assert key in out, key
    assert out["status"] == "ok"
    assert len(out["results"]) == 2 and out["results"][1]["F_P"] == pytest.approx(1.0)
    assert out["F_P"] == out["results"][1]["F_P"]
    for lib in ("fibril_hpc", "numpy", "numba", "pyfftw", "fftw", "h5py", "rng"):
        assert out["versions"][lib]


def test_hdf5_and_plot(scene_file, tmp_path, capsys):
    h5 = tmp_path / "curve.h5"
    png = tmp_path / "curve.png"
    assert run_main([str(scene_file), "--out", str(h5), "--plot", str(png)]) == 0
    assert "F~_A" in capsys.readouterr().out
    assert png.stat().st_size > 10_000
    with h5py.File(h5, "r") as f:
        assert f.attrs["status"] == "ok"
        assert "k_tilde: 0.05" in f.attrs["scene_yaml"]
        assert json.loads(f.attrs["versions"])["numba"]
        g = f["preloads/1"]
        assert g.attrs["F_P"] == pytest.approx(1.0)
        F = g["unloading/F_tilde"][()]
        assert -F.min() == pytest.approx(g.attrs["F_A"])
        assert g["at_preload/force"].shape == (4,)
        assert g["at_pulloff/contact_map"].ndim == 2
        assert g["let_go_d_tilde"].shape == (4,)
        assert f["pillars/xi"].shape == (4,)
    assert not [p for p in os.listdir(tmp_path) if p.endswith(".part")]


@pytest.mark.parametrize("content,field", [
    ("k_tilde: -1\n", "k_tilde"), ("n_side: [1\n", "scene"), ("bogus: 1\n", "bogus"),
    ("solver: {cg_tol: 2}\n", "solver.cg_tol"), ("- 1\n- 2\n", "scene"),
    ("preset: best\n", "preset"), ("solver: {criterion: kendall}\n", "solver.criterion"),
    ("tip: rounded\ntip_radius: 0.2\nsolver: {criterion: footprint}\n", "solver.criterion"),
    ("n_side: 37\nsolver: {preconditioner: two_level}\n", "solver.preconditioner"),
])
def test_bad_input_one_line_exit_2_nothing_written(tmp_path, content, field):
    bad = tmp_path / "bad.yaml"
    bad.write_text(content)
    out = tmp_path / "never.h5"
    proc = subprocess.run([sys.executable, "-m", "fibril_hpc.cli", str(bad), "--out", str(out)],
                          capture_output=True, text=True)
    assert proc.returncode == 2
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"fibril-run: error: {field}")
    assert "Traceback" not in proc.stderr
    assert not out.exists()


def test_missing_file_and_bad_output_folder(tmp_path, scene_file, capsys):
    assert run_main([str(tmp_path / "nope.yaml")]) == 2
    assert run_main([str(scene_file), "--out", str(tmp_path / "no" / "dir" / "x.h5")]) == 2
    err = capsys.readouterr().err
    assert "--out" in err and "Traceback" not in err


def test_version(capsys):
    assert run_main(["--version"]) == 0
    out = capsys.readouterr().out
    for lib in ("fibril_hpc", "numpy", "numba", "pyfftw", "fftw", "h5py", "rng"):
        assert lib in out


def test_builtin_single_pillar(capsys):
    assert run_main(["--builtin", "single-pillar", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["n_pillars_in_contact_max"] == 1
    assert out["F_A"] == pytest.approx(out["phi_discrete"] ** 0.25, rel=0.03)
