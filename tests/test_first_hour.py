"""What a new user meets in the first hour (issue 36, item 9): a --plot name that lies about
its format is refused, an unknown option is named, one term for the resolution."""

import math
import os

import pytest

from fibril_hpc.cli.campaign import main as campaign_main
from fibril_hpc.cli.run import main as run_main

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


@pytest.mark.parametrize("name", ["p.xyz", "p.pdf", "p", "p.png.h5"])
def test_plot_with_another_suffix_is_refused(tmp_path, capsys, name):
    """The figure is a PNG: any other name is one line, exit 2, nothing written."""
    assert run_main(["--builtin", "single-pillar", "--plot", str(tmp_path / name)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--plot" in err and ".png" in err, err
    assert os.listdir(tmp_path) == []


@pytest.mark.parametrize("argv", [["--bogus"], ["run", "--bogus"], ["--dry-run", "--bogus"],
                                  ["status", "--bogus", "x.h5"]])
def test_an_unknown_option_is_named(capsys, argv):
    with pytest.raises(SystemExit) as exc:        # argparse exits; the status is what counts
        campaign_main(argv)
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert "--bogus" in err and err.count("\n") == 1, err


def test_run_without_a_grid_is_one_line(capsys):
    assert campaign_main(["--dry-run"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("fibril-campaign: error: grid:") and err.count("\n") == 1, err


def test_elements_per_pillar_diameter_means_one_thing(tmp_path, capsys):
    """``--dry-run`` and ``fibril-run`` state the resolution in one term, elements per pillar
    diameter (the presets' measure), with the same value for the same scene; the footprint's
    element count is called that."""
    grid = tmp_path / "g.yaml"
    grid.write_text("output: g.h5\nscene: {n_side: 4, preset: fast}\nk_tilde: [0.01]\n"
                    "sigma_tilde: [0.5]\nF_P: [1]\nseeds: 1\n")
    assert campaign_main([str(grid), "--dry-run"]) == 0
    dry = capsys.readouterr().out
    scene = tmp_path / "s.yaml"
    scene.write_text("n_side: 4\npreset: fast\nk_tilde: 0.01\nsigma_tilde: 0.5\nF_P: [1]\n")
    assert run_main([str(scene)]) == 0
    human = capsys.readouterr().out
    for text in (dry, human):
        assert "elements per pillar diameter" in text, text
        assert "elements per pillar," not in text and "pillar elements" not in text, text
    epd = [float(t.split(" elements per pillar diameter")[0].split()[-1]) for t in (dry, human)]
    assert epd[0] == epd[1] and 5.5 < epd[0] < 6.5, epd     # `fast`: 6 per diameter
    foot = int(dry.split(" in a pillar's footprint")[0].split("(")[-1])
    assert math.isclose(2 * math.sqrt(foot / math.pi), epd[0], abs_tol=0.005)
    assert f"({foot} in a pillar's footprint" in human


def test_readme_names_the_resolution_as_the_commands_do():
    with open(os.path.join(ROOT, "README.md"), encoding="utf-8") as fh:
        text = fh.read()
    assert "elements per pillar diameter" in text
    assert "elements per pillar," not in text and "elements per pillar)" not in text


def test_griffe_is_in_the_test_extra():
    """README's test install runs the API-reference docstring tests (they need griffe)."""
    import tomllib

    with open(os.path.join(ROOT, "pyproject.toml"), "rb") as fh:
        extras = tomllib.load(fh)["project"]["optional-dependencies"]
    assert any(r.split(">")[0].split("=")[0] in ("griffe", "griffelib") for r in extras["test"])


def test_readme_is_a_short_undated_guide():
    """README stays a user's guide under 10 000 characters with no dates (dated measurements
    live in benchmarks/NOTES.md)."""
    import re

    with open(os.path.join(ROOT, "README.md"), encoding="utf-8") as fh:
        text = fh.read()
    assert len(text) < 10_000, len(text)
    assert not re.search(r"\b20\d\d-\d\d-\d\d\b", text)
