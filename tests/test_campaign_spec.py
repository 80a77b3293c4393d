"""Grid validation (one line, exit 2, nothing written) and stable job keys."""

import os

import pytest
import yaml
from campaign_helpers import TINY, run, write_grid

from fibril_hpc import ConfigError
from fibril_hpc.campaign import spec_from_dict
from fibril_hpc.cli.campaign import main


def _spec(**changes):
    d = dict(TINY)
    d.update(changes)
    return spec_from_dict(d, base_dir="/tmp")


def test_jobs_are_the_full_product():
    s = _spec()
    assert len(s.jobs) == 2 * 2 * 2 * 2
    assert len({j.key for j in s.jobs}) == len(s.jobs)
    assert len(s.tasks()) == 2 * 2 * 2          # grouped by (k, sigma, seed)
    assert all(len(t.jobs) == 2 for t in s.tasks())
    assert len(_spec(group_preloads=False).tasks()) == 16
    assert s.output == "/tmp/tiny.h5"


def test_keys_do_not_depend_on_list_order_or_other_jobs():
    a = _spec()
    b = _spec(k_tilde=[0.01, 1], sigma_tilde=[1.0, 0.3], F_P=[1.0, 0.3], seeds=[1, 0])
    assert a.campaign_hash == b.campaign_hash
    c = _spec(k_tilde=[1])
    assert {j.key for j in c.jobs} < {j.key for j in a.jobs}
    assert c.campaign_hash != a.campaign_hash
    # a resource option does not change keys; a numerical one does
    d = _spec(scene={**TINY["scene"], "solver": {"fft_threads": 2, "max_wall_s": 5}})
    assert d.campaign_hash == a.campaign_hash
    e = _spec(scene={**TINY["scene"], "solver": {"cg_tol": 1e-9}})
    assert e.campaign_hash != a.campaign_hash


@pytest.mark.parametrize("changes, field", [
    ({"bogus": 1}, "bogus"),
    ({"k_tilde": [1, -2]}, "k_tilde"),
    ({"k_tilde": []}, "k_tilde"),
    ({"sigma_tilde": ["x"]}, "sigma_tilde"),
    ({"sigma_tilde": [0.3, 0.3]}, "sigma_tilde"),
    ({"seeds": True}, "seeds"),
    ({"seeds": 0}, "seeds"),
    ({"seeds": [0, -1]}, "seeds"),
    ({"d_tilde": [1.0]}, "F_P"),
    ({"F_P": [0.0]}, "F_P"),
    ({"output": "x.txt"}, "output"),
    ({"output": None}, "output"),
    ({"scene": {"k_tilde": 1}}, "scene.k_tilde"),
    ({"scene": {"n_side": 0}}, "scene.n_side"),
    ({"scene": {"solver": {"bogus": 1}}}, "scene.solver.bogus"),
    ({"group_preloads": "yes"}, "group_preloads"),
])
def test_bad_grid_one_line_exit_2_nothing_written(tmp_path, capsys, changes, field):
    with pytest.raises(ConfigError) as ei:
        _spec(**changes)
    assert ei.value.field == field
    grid = write_grid(tmp_path, **changes)
    before = sorted(os.listdir(tmp_path))
    assert main([grid]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and f"error: {field}:" in err and "allowed:" in err
    assert sorted(os.listdir(tmp_path)) == before


def test_missing_k_and_bad_yaml_and_missing_file(tmp_path, capsys):
    d = dict(TINY)
    d.pop("k_tilde")
    assert main([write_grid(tmp_path, d)]) == 2
    p = tmp_path / "bad.yaml"
    p.write_text("k_tilde: [1,\n")
    assert main([str(p)]) == 2
    assert main([str(tmp_path / "none.yaml")]) == 2
    errs = capsys.readouterr().err.strip().splitlines()
    assert len(errs) == 3 and all(e.startswith("fibril-campaign: error:") for e in errs)
    assert sorted(os.listdir(tmp_path)) == ["bad.yaml", "grid.yaml"]


def test_empty_grid_file_is_one_clear_line(tmp_path, capsys):
    for text in ("", "# nothing yet\n"):
        p = tmp_path / "empty.yaml"
        p.write_text(text)
        assert main([str(p), "--dry-run"]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and "error: grid:" in err and "this file is empty" in err
        assert "None" not in err


@pytest.mark.parametrize("changes, field, hint", [
    ({"k_tilda": [1]}, "k_tilda", "'k_tilde'"),
    ({"Seeds": 2}, "Seeds", "'seeds'"),
    ({"scene": {"n_sde": 4}}, "scene.n_sde", "'n_side'"),
    ({"scene": {"solver": {"cg_tl": 1e-8}}}, "scene.solver.cg_tl", "'cg_tol'"),
    ({"scene": {"physical": {"E_str": 1e6, "dgamma": 0.05, "diameter": 2e-5}}},
     "scene.physical.E_str", "'E_star'"),
    ({"sweep": {"n_sid": [2, 3]}}, "sweep.n_sid", "'n_side'"),
    ({"F_P": {"auto": {"rounds_": 3}}}, "F_P.auto.rounds_", "'rounds'"),
])
def test_a_typo_in_a_key_gets_a_did_you_mean(tmp_path, capsys, changes, field, hint):
    assert main([write_grid(tmp_path, **changes), "--dry-run"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and f"error: {field}:" in err
    assert f"(did you mean {hint}?)" in err
    with pytest.raises(ConfigError, match=r"did you mean"):        # the library says it too
        _spec(**changes)


def test_no_did_you_mean_when_nothing_is_close_and_scene_fields_belong_under_scene(tmp_path):
    with pytest.raises(ConfigError) as ei:
        _spec(zzz=1)
    assert "did you mean" not in str(ei.value) and "output, scene" in str(ei.value)
    with pytest.raises(ConfigError, match="n_side is a scene field: write it under scene:"):
        _spec(n_side=4)


@pytest.mark.slow
def test_cli_usage_errors_exit_2(tmp_path):
    for args in ([], ["report", "x.h5"], ["status", str(tmp_path / "none.h5")],
                 ["export", str(tmp_path / "none.h5"), "--csv", "o.csv"], ["run", "--bogus"],
                 ["merge", str(tmp_path / "a.h5"), "-o", str(tmp_path / "b.h5")]):
        r = run(args, timeout=60, cwd=tmp_path)
        assert r.returncode == 2, (args, r.stderr)
        assert r.stderr.strip().count("\n") <= 1 and "Traceback" not in r.stderr
    assert os.listdir(tmp_path) == []


def test_dry_run_writes_nothing(tmp_path, capsys):
    grid = write_grid(tmp_path)
    assert main([grid, "--dry-run"]) == 0
    out = capsys.readouterr().out
    assert "16 jobs" in out and "core-hours" in out
    assert os.listdir(tmp_path) == ["grid.yaml"]
    # the memory of one rank, the estimate the memory check compares (issue 35)
    from fibril_hpc.campaign.plan.spec import load_spec
    from fibril_hpc.inputs.limits import memory_estimate

    spec = load_spec(grid)
    need = memory_estimate(spec.base, spec.path_preloads())[0]
    line = next(ln for ln in out.splitlines() if ln.startswith("memory: "))
    assert f"about {need / 2**30:.2g} GiB per rank" in line and "available now" in line


def test_dry_run_after_editing_the_grid_refuses_as_the_run_does(tmp_path, capsys):
    """An output written from another grid: the run refuses and asks for --extend (exit 2), so
    the dry run says the same and exits 2; with --extend both go ahead."""
    one = {**TINY, "k_tilde": [1], "sigma_tilde": [0.3], "F_P": [0.3], "seeds": 1}
    grid = write_grid(tmp_path, one)
    assert main([grid, "--no-progress"]) == 0
    write_grid(tmp_path, {**one, "k_tilde": [1, 0.01]})          # the user edits the grid
    capsys.readouterr()
    assert main([grid, "--dry-run"]) == 2
    dry = capsys.readouterr()
    assert dry.out == "" and dry.err.count("\n") == 1 and "--extend" in dry.err
    before = sorted(os.listdir(tmp_path))
    assert main([grid, "--no-progress"]) == 2                       # the run: the same line
    assert capsys.readouterr().err == dry.err
    assert sorted(os.listdir(tmp_path)) == before
    assert main([grid, "--dry-run", "--extend"]) == 0
    assert "1 done, 0 failed, 1 to run" in capsys.readouterr().out


def test_a_fifo_is_refused_at_once_in_one_line(tmp_path, capsys):
    """A FIFO where a campaign file is read (the output, a file given to a reader) is one line
    at once, not a 'damaged HDF5 structure' after the reader's 15 s stall guard."""
    import time

    from fibril_hpc import StoreError, load_campaign

    fifo = tmp_path / "x.h5"
    os.mkfifo(fifo)
    grid = write_grid(tmp_path, output="x.h5")
    for extra in (["--dry-run"], ["--no-progress"]):
        t = time.monotonic()
        assert main([grid, *extra]) == 2
        err = capsys.readouterr().err
        assert time.monotonic() - t < 10 and err.count("\n") == 1, err
        assert "output" in err and "FIFO" in err and "damaged" not in err
    t = time.monotonic()
    with pytest.raises(StoreError, match="FIFO"):
        load_campaign(str(fifo))
    assert time.monotonic() - t < 10
    assert sorted(os.listdir(tmp_path)) == ["grid.yaml", "x.h5"]


def test_dry_run_model_follows_preloads_preset_and_grid():
    """The cost model's shape (campaign/plan/estimate.py): the default 18 x 18 scene it was fitted on,
    more and larger preloads cost more, `fast` less, a d_tilde preload counts as a full one."""
    from fibril_hpc import Scene
    from fibril_hpc.campaign.plan.estimate import task_pairs

    one = Scene(F_P=(4.0,))
    # measured with the defaults (moments, direction to 100 x cg_tol; NOTES, issue 8): 2 968
    # pairs, and 6 536 at the accurate preset (193 elements in a pillar's footprint)
    assert task_pairs(one, 45) == pytest.approx(2968, rel=0.05)
    assert task_pairs(Scene(F_P=(4.0,), preset="accurate"), 193) == pytest.approx(6536, rel=0.05)
    assert task_pairs(Scene(F_P=(0.01, 4.0)), 45) > task_pairs(one, 45)
    assert task_pairs(Scene(F_P=(0.01,)), 45) < task_pairs(Scene(F_P=(1.0,)), 45) \
        < task_pairs(one, 45) == task_pairs(Scene(F_P=(6.5,)), 45)
    assert task_pairs(Scene(d_tilde=(1.5,)), 45) == task_pairs(one, 45)
    assert task_pairs(Scene(F_P=(4.0,), preset="fast"), 25) < task_pairs(one, 25)
    # pairs grow with the pillar count as the growth table measured (N_p^0.87 below 18 x 18,
    # N_p^0.62 above: 1 535 pairs at 12 x 12, 7 156 at 36 x 36 and 14 465 at 64 x 64)
    for n, pairs in ((12, 1535), (36, 7156), (64, 14465)):
        assert task_pairs(Scene(n_side=n, F_P=(4.0,)), 45) == pytest.approx(pairs, rel=0.1), n


def test_output_relative_to_yaml_folder_and_override(tmp_path):
    sub = tmp_path / "sub"
    sub.mkdir()
    from fibril_hpc.campaign import load_spec

    grid = write_grid(sub)
    assert load_spec(grid).output == str(sub / "tiny.h5")
    assert load_spec(grid, output="o.h5").output == os.path.abspath("o.h5")
    assert yaml.safe_load(load_spec(grid).resolved_yaml())["k_tilde"] == [1.0, 0.01]


@pytest.mark.parametrize("changes", [
    {},
    {"d_tilde": [0.5, 2.0, 8.0], "F_P": None, "k_tilde": [float("inf"), 1, 1e-3]},
    {"scene": {"n_side": 3, "preset": "fast", "solver": {"cg_tol": 1e-9, "fft_threads": 2}},
     "seeds": [5, 0, 17]},
    {"scene": {"n_side": 2, "elements_per_diameter": 5, "lattice": "hexagonal", "tip": "sphere",
               "tip_radius": 2.0}, "sigma_tilde": [0.0, 0.3]},
])
def test_fast_enumeration_equals_a_scene_per_job(changes):
    """A grid's jobs are enumerated from one template (each axis value validated once): every
    key and every loading path's scene equal those of a validated Scene per job, the contract
    old campaign files are resumed by."""
    from fibril_hpc.campaign.plan.keys import job_key

    changes = {k: v for k, v in changes.items() if v is not None}
    d = {**TINY, **changes}
    if "d_tilde" in changes:
        d.pop("F_P")
    s = spec_from_dict(d, base_dir="/tmp")
    assert len(s.jobs) == len({j.key for j in s.jobs}) > 0
    for j in s.jobs:
        assert j.key == job_key(s.job_scene(j)), j
    for t in s.tasks():
        js = t.jobs
        ref = s.base.replace(k_tilde=js[0].k_tilde, sigma_tilde=js[0].sigma_tilde,
                             seed=js[0].seed, **{s.preload_kind: tuple(j.preload for j in js)})
        assert t.scene == ref and t.scene.to_dict() == ref.to_dict()


def test_a_million_jobs_is_the_cap_and_a_bad_value_is_still_named():
    from fibril_hpc.inputs.limits import MAX_JOBS

    assert MAX_JOBS == 10**6
    with pytest.raises(ConfigError, match="at most 1e\\+06 jobs"):
        _spec(k_tilde=[10.0**-i for i in range(101)], sigma_tilde=[0.1 * (i + 1) for i in range(100)],
              F_P=[0.1 * (i + 1) for i in range(10)], seeds=10)
    with pytest.raises(ConfigError, match="k_tilde"):      # each axis value still checked
        _spec(k_tilde=[1, 0.01, -3])


def test_keys_of_axes_equal_a_json_document_and_hash_per_job():
    import itertools

    from fibril_hpc.campaign.plan.keys import key_of_fields, keys_of_axes

    template = {"n_side": 6, "F_P": [1.0], "k_tilde": 1.0, "seed": 0, "sigma_tilde": 0.3,
                "solver": {"cg_tol": 1e-9}, "preset": "fast", "tip": "sphere"}
    names = ("k_tilde", "sigma_tilde", "seed", "F_P")
    values = [[1.0, 0.1, float("inf")], [0.3, 1e-7], [0, 1, 2**40], [[0.3], [1.0], [2.5]]]
    want = []
    for combo in itertools.product(*values):
        want.append(key_of_fields({**template, **dict(zip(names, combo))}))
    assert keys_of_axes(template, names, values) == want
    assert keys_of_axes(template, names, [[1.0], [], [0], [[1.0]]]) == []


@pytest.mark.slow
def test_dry_run_of_a_million_jobs_is_lean(tmp_path):
    """10^6 jobs, one per loading path: the dry run took 87 s and 1.7 GB (a Scene per path,
    a JSON document and a hash per key); benchmarks/NOTES.md has the numbers."""
    import subprocess
    import sys

    grid = write_grid(tmp_path, output="m.h5", k_tilde=[10.0 ** -i for i in range(10)],
                      sigma_tilde=[0.1 * (i + 1) for i in range(10)],
                      F_P=[0.1 * (i + 1) for i in range(100)], seeds=100, group_preloads=False)
    code = ("import resource, sys, time; from fibril_hpc.cli.campaign import main; "
            f"rc = main([{grid!r}, '--dry-run']); "
            "u = resource.getrusage(resource.RUSAGE_SELF); "
            "print('RUSAGE', rc, u.ru_maxrss, u.ru_utime + u.ru_stime)")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr
    assert "1000000 jobs" in r.stdout and "1000000 to run in 1000000 simulate calls" in r.stdout
    rc, maxrss_kb, cpu_s = r.stdout.split("RUSAGE")[1].split()
    assert rc == "0" and int(maxrss_kb) < 900_000, r.stdout      # 1.7 GB before
    assert float(cpu_s) < 60.0, r.stdout
