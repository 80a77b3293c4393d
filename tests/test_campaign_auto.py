"""F_P: auto: the campaign places preloads around the kink of each path, resumes after SIGKILL
with the same preloads and records, and leaves fixed-list grids exactly as they were."""

import math
import os
import signal
import time

import pytest
from campaign_helpers import TINY, results_by_key, run, same_numbers, start, write_grid

from fibril_hpc import load_campaign
from fibril_hpc.campaign import load_spec
from fibril_hpc.campaign.laws import fit
from fibril_hpc.campaign.laws.reading import path_plateau_reached
from fibril_hpc.campaign.plan import auto
from fibril_hpc.campaign.run.planner import FixedPlanner
from fibril_hpc.cli.campaign import main

AUTO = dict(TINY, k_tilde=[1, 0.01], sigma_tilde=[0.3], seeds=2, output="auto.h5",
            scene=dict(TINY["scene"], n_side=5),
            F_P={"auto": {"start": [0.002, 0.01, 0.05, 0.25, 1.0], "rounds": 5}})


def _paths(path):
    out: dict = {}
    for j in load_campaign(path, curves=False).jobs:
        out.setdefault((j["k_tilde"], j["sigma_tilde"], j["seed"]), []).append(j)
    return out


@pytest.fixture(scope="module")
def auto_run(tmp_path_factory):
    d = tmp_path_factory.mktemp("auto")
    grid = write_grid(d, AUTO)
    assert main([grid, "--no-progress", "--serial"]) == 0
    return grid, str(d / "auto.h5")


def test_auto_preloads_bracket_the_kink(auto_run):
    grid, path = auto_run
    spec = load_spec(grid)
    paths = _paths(path)
    assert set(paths) == set(spec.paths())
    added = 0
    for p, jobs in paths.items():
        pre = sorted(j["preload"] for j in jobs)
        assert all(j["status"] == "done" for j in jobs)
        assert set(spec.auto.start) <= set(pre), p
        res_all = {j["preload"]: (j["F_P"], j["F_A"]) for j in jobs}
        rp = auto.replay(spec.auto, res_all)
        assert sorted(rp.kink_tried + rp.plateau_tried) == pre
        # the plateau rounds ran until F~_A stopped rising at the largest preload (or max)
        top = sorted(jobs, key=lambda j: j["preload"])
        assert path_plateau_reached([j["F_P"] for j in top], [j["F_A"] for j in top]) or \
            pre[-1] >= spec.auto.max, (p, pre)
        # the kink rounds: judged on their own preloads (a plateau round moves the law's kink)
        jobs = [j for j in jobs if j["preload"] in rp.kink_tried]
        f = fit.fit_law([j["F_P"] for j in jobs], [j["F_A"] for j in jobs], fit.DEFAULT_LAW)
        js = sorted(jobs, key=lambda j: j["preload"])
        below = [j["preload"] for j in js if j["F_P"] < f.kink]
        above = [j["preload"] for j in js if j["F_P"] >= f.kink]
        floor = js[0]["F_A"] >= auto.FLOOR_RATIO * js[1]["F_A"]
        # it stopped on its criteria, not on the round limit: the kink is bracketed to within
        # `bracket`, enough preloads above it, and enough below it unless F_A hit its floor
        assert len(above) >= spec.auto.above and below, (p, pre, f)
        assert min(above) / max(below) <= spec.auto.bracket * 1.01, (p, pre, f)
        assert len(below) >= spec.auto.below or floor, (p, pre, f)
        added += len(pre) - len(spec.auto.start)
        # every record is an ordinary job: the key of its single-preload scene
        for j in jobs:
            task = spec.auto_task(p, [j["preload"]])
            assert task.jobs[0].key == j["key"]
        # the choice is a function of the records: replaying them asks for nothing more
        todo, rounds = auto.path_todo(spec.auto, res_all)
        assert todo == [] and rounds < spec.auto.rounds
    assert added >= len(paths)          # it placed preloads of its own


@pytest.mark.slow
def test_auto_resume_after_sigkill_same_preloads_and_records(auto_run, tmp_path):
    _, ref = auto_run
    grid = write_grid(tmp_path, AUTO)
    out = str(tmp_path / "auto.h5")
    journal = out + ".journal"
    p = start([grid, "--serial", "--no-progress", "--checkpoint-s", "1000"])
    t0 = time.monotonic()
    while time.monotonic() - t0 < 120 and p.poll() is None:
        if os.path.exists(journal) and os.path.getsize(journal) > 0:
            break
        time.sleep(0.005)
    killed = p.poll() is None
    if killed:
        p.send_signal(signal.SIGKILL)
    p.communicate(timeout=120)
    r = run([grid, "--serial", "--no-progress"], timeout=300)
    assert r.returncode == 0, r.stderr
    a, b = results_by_key(ref), results_by_key(out)
    assert set(a) == set(b)
    assert same_numbers(a, b) == []
    assert killed, "the run finished before it could be killed"


def test_fixed_grid_is_planned_exactly_as_before(tmp_path):
    spec = load_spec(write_grid(tmp_path))
    assert spec.auto is None and spec.resolved()["F_P"] == TINY["F_P"]

    class W:
        def keys_to_run(self, retry_failed):
            return [j.key for j in spec.jobs]

    tasks = FixedPlanner(spec, W(), False).initial()
    assert [t.keys for t in tasks] == [t.keys for t in spec.tasks()]
    assert FixedPlanner(spec, W(), False).after(tasks[0], []) == []


@pytest.mark.parametrize(("value", "field"), [
    ("autox", "F_P"), ({"auto": {"below": 1}}, "F_P.auto.below"),
    ({"auto": {"start": [0.1]}}, "F_P.auto.start"), ({"auto": {"x": 1}}, "F_P.auto.x"),
    ({"auto": {"min": 1, "max": 0.5}}, "F_P.auto.min")])
def test_bad_auto_settings_are_one_line(tmp_path, capsys, value, field):
    grid = write_grid(tmp_path, AUTO, F_P=value)
    assert main([grid, "--dry-run"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and field in err[0]
    assert not (tmp_path / "auto.h5").exists()


def test_next_preloads_rules():
    a = auto.AutoPreloads(start=(0.01, 0.1, 1.0), below=3, above=2, bracket=2.0)
    # kink at 0.5 (c = 2, plateau 1): bisect [0.1, 1], extend below 0.01 and above 1
    res = {p: (p, min(2 * p, 1.0)) for p in (0.01, 0.1, 1.0)}
    nxt = auto.next_preloads(a, [0.01, 0.1, 1.0], res)
    assert nxt == [0.0025, 0.316, 4.0]
    # all on the plateau: extend downwards only... unless the two smallest agree (a floor)
    res = {p: (p, 1.0) for p in (0.01, 0.1, 1.0)}
    assert auto.next_preloads(a, [0.01, 0.1, 1.0], res) == []
    # all linear: extend upwards
    res = {p: (p, 0.5 * p) for p in (0.01, 0.1, 1.0)}
    assert auto.next_preloads(a, [0.01, 0.1, 1.0], res) == [4.0, 16.0]
    assert math.isclose(auto.path_todo(a, {})[0][0], 0.01)


def test_shipped_grids_load():
    here = os.path.join(os.path.dirname(__file__), "..", "campaigns")
    specs = {n: load_spec(os.path.join(here, n)) for n in os.listdir(here) if n.endswith(".yaml")}
    assert {"demo.yaml", "paper.yaml", "report_example.yaml"} <= set(specs)
    paper = specs["paper.yaml"]
    # soft pillars bend near F_P = 0.01 (docs/report.md): the paper grid starts far below
    assert paper.auto is not None and paper.auto.start[0] <= 0.001 and paper.auto.min <= 1e-4
    assert specs["report_example.yaml"].campaign_hash.startswith("062ebf3df2b0")


@pytest.mark.slow
def test_auto_shards_merge_into_the_same_records(auto_run, tmp_path):
    _, ref = auto_run
    for s in (0, 1):
        grid = write_grid(tmp_path, AUTO, name=f"s{s}.yaml", seeds=[s], output=f"s{s}.h5")
        assert main([grid, "--no-progress", "--serial"]) == 0
    out = str(tmp_path / "all.h5")
    assert main(["merge", str(tmp_path / "s0.h5"), str(tmp_path / "s1.h5"), "-o", out]) == 0
    a, b = results_by_key(ref), results_by_key(out)
    assert set(a) == set(b) and same_numbers(a, b) == []
    assert main(["status", out]) == 0


def test_status_counts_the_current_round_of_an_unfinished_auto_path(auto_run, tmp_path):
    import shutil

    import h5py

    from fibril_hpc.campaign.analysis.status import file_status

    _, ref = auto_run
    assert file_status(ref).totals["pending"] == 0
    path = str(tmp_path / "part.h5")
    shutil.copy(ref, path)
    with h5py.File(path, "a") as fh:
        last = max(fh["jobs"], key=lambda k: fh["jobs"][k].attrs["preload"])
        del fh["jobs"][last]                      # a start preload (the largest): round 0
    st = file_status(path)
    assert st.totals["pending"] == 1 and st.totals["done"] == len(results_by_key(ref)) - 1
