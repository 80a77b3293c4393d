"""``seeds: {auto: {first: F}}``: a disjoint seed set of one search grid (issue 34, item 3).

The seeds of a group are first .. first + n - 1; ``first`` 0 (the default) is left out of the
resolved grid, so a search file written before ``first`` existed keeps its campaign hash and
resumes (tests/data/search_v0.h5, written by the code of main at 7f490cd from search_v0.yaml).
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys

import pytest
import yaml

from fibril_hpc.campaign.plan import search
from fibril_hpc.campaign.plan.spec import load_spec, spec_from_dict
from fibril_hpc.campaign.storage.store import read_records
from fibril_hpc.errors import ConfigError

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DATA = os.path.join(ROOT, "tests", "data")
SHIPPED = os.path.join(ROOT, "campaigns", "critical_roughness.yaml")
SEEDS10 = os.path.join(ROOT, "campaigns", "critical_roughness_seeds10.yaml")
#: the shipped search's campaign hash, computed by main at 7f490cd (before ``first``)
SHIPPED_HASH = "7bbb53b15f2263f7ca78ba7b2e356128b0ffe3a4290150a67a6fb3757f8fc909"


def _grid(path, **seeds_auto):
    with open(path) as fh:
        g = yaml.safe_load(fh)
    g["seeds"]["auto"].update(seeds_auto)
    return g


def test_the_shipped_search_keeps_its_hash_and_first_0_is_the_default():
    assert load_spec(SHIPPED).campaign_hash == SHIPPED_HASH
    g = _grid(SHIPPED, first=0)
    assert spec_from_dict(g).campaign_hash == SHIPPED_HASH
    assert "first" not in spec_from_dict(g).resolved()["seeds"]["auto"]
    assert spec_from_dict(_grid(SHIPPED, first=10)).campaign_hash != SHIPPED_HASH


def test_the_shipped_seeds10_variant_is_the_search_on_seeds_10_to_19():
    a, b = load_spec(SHIPPED), load_spec(SEEDS10)
    ra, rb = a.resolved(), b.resolved()
    assert rb["seeds"]["auto"].pop("first") == 10
    ra.pop("description"), rb.pop("description")
    assert ra == rb                         # the same search, only the seeds differ
    assert b.seeds == tuple(range(10, 20)) and a.seeds == tuple(range(10))
    todo = search.frontier(b, [])
    assert todo and {p[2] for p, _ in todo} == {10, 11, 12}
    assert {p[2] for p, _ in search.frontier(a, [])} == {0, 1, 2}


def test_first_bounds_the_paths_a_file_may_hold():
    b = load_spec(SEEDS10)
    assert b.holds_path((1.0, 0.4, 10)) and b.holds_path((1.0, 0.4, 19))
    assert not b.holds_path((1.0, 0.4, 9)) and not b.holds_path((1.0, 0.4, 20))
    sa = b.seeds_auto
    assert sa.seeds(sa.start) == [10, 11, 12] and sa.seeds(sa.max)[-1] == 19


@pytest.mark.parametrize("bad", [-1, 1.5, "ten", True, 10**9 + 1, None])
def test_a_bad_first_is_one_line_naming_the_field(bad):
    with pytest.raises(ConfigError) as e:
        spec_from_dict(_grid(SHIPPED, first=bad))
    assert e.value.field == "seeds.auto.first"
    assert "[0, 1e+09]" in str(e.value) and "\n" not in str(e.value)


def test_the_cli_refuses_a_bad_first_with_exit_2_and_writes_nothing(tmp_path):
    g = _grid(SHIPPED, first=-3)
    g["output"] = str(tmp_path / "x.h5")
    p = tmp_path / "g.yaml"
    p.write_text(yaml.safe_dump(g))
    r = subprocess.run([sys.executable, "-m", "fibril_hpc.cli.campaign", "run", str(p),
                        "--dry-run"], capture_output=True, text=True, timeout=120)
    assert r.returncode == 2
    assert "seeds.auto.first" in r.stderr and r.stderr.count("\n") == 1
    assert "Traceback" not in r.stderr and sorted(os.listdir(tmp_path)) == ["g.yaml"]


def test_an_old_search_file_still_resumes(tmp_path):
    """A search file written before ``first`` (tests/data/search_v0.h5): the same grid finds
    every job done and runs nothing; the same grid with first: 5 is another grid."""
    from fibril_hpc.cli.campaign import main

    out = tmp_path / "old.h5"
    shutil.copy(os.path.join(DATA, "search_v0.h5"), out)
    grid = os.path.join(DATA, "search_v0.yaml")
    assert main(["run", grid, "--output", str(out), "--no-progress"]) == 0
    spec = load_spec(grid)
    root, recs, _ = read_records(str(out), curves=False)
    assert root["campaign_hash"] == spec.campaign_hash
    assert len(recs) == 12 and search.frontier(spec, list(recs.values())) == []
    g = _grid(grid, first=5)
    g["output"] = str(out)
    p = tmp_path / "first5.yaml"
    p.write_text(yaml.safe_dump(g))
    assert main(["run", str(p), "--output", str(out), "--dry-run"]) == 2


def test_a_group_grows_from_first_upwards():
    """A group whose three seeds scatter too much grows to the count the widths predict, with
    the next seeds after them (13, 14, ...), never seeds below ``first``."""
    with open(os.path.join(DATA, "search_v0.yaml")) as fh:
        g = yaml.safe_load(fh)
    g["seeds"] = {"auto": {"start": 3, "max": 8, "width": 0.05, "first": 10}}
    spec = spec_from_dict(g)
    line, sigma = (1.0,), 0.1
    done = {}
    for seed, top in zip((10, 11, 12), (0.3, 0.6, 0.9)):     # plateaus scattered by +-50 %
        done[(1.0, sigma, seed)] = {0.25: (0.25, top * 0.98), 4.0: (4.0, top)}
    grp = search.replay_group(spec, line, sigma, done, {})
    assert grp.seeds[:3] == [10, 11, 12] and len(grp.seeds) > 3
    assert grp.seeds == list(range(10, 10 + len(grp.seeds)))
    assert {p[2] for p, _ in grp.todo} == set(range(13, 10 + len(grp.seeds)))
