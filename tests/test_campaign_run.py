"""Serial runs, resume, retry-failed, refusing another grid, export, merge, report, load_campaign."""

import csv
import json

import h5py
import numpy as np
import pytest
from campaign_helpers import TINY, results_by_key, same_numbers, write_grid

from fibril_hpc import load_campaign
from fibril_hpc.campaign import load_spec
from fibril_hpc.campaign.run.runner import run_serial
from fibril_hpc.cli.campaign import main


@pytest.fixture(scope="module")
def full(tmp_path_factory):
    """One uninterrupted serial run of the tiny grid (the reference)."""
    d = tmp_path_factory.mktemp("full")
    grid = write_grid(d)
    assert main([grid, "--no-progress"]) == 0
    return str(d / "tiny.h5")


def test_file_is_self_describing(full):
    with h5py.File(full, "r") as fh:
        a = fh.attrs
        assert a["program"] == "fibril-hpc campaign"
        assert "k_tilde" in a["campaign_yaml"] and len(a["campaign_hash"]) == 64
        assert "F_c" in json.loads(a["definitions"]) and "jobs/<key>" in a["layout"]
        assert a["n_jobs"] == 16 and len(fh["jobs"]) == 16
        g = fh["jobs"][next(iter(fh["jobs"]))]
        for k in ("k_tilde", "sigma_tilde", "preload", "seed", "F_P", "F_A", "status", "message",
                  "wall_s", "cg_iterations", "scene_yaml"):
            assert k in g.attrs
        assert g.attrs["status"] == "done"
        for br in ("loading", "unloading"):
            for c in ("d_tilde", "F_tilde", "contact_fraction", "n_pillars_in_contact"):
                assert g[br][c].shape[0] > 1
        # F_P of the record is the end of its loading curve
        assert g.attrs["F_P"] == g["loading/F_tilde"][-1]


def test_load_campaign_table(full):
    c = load_campaign(full)
    assert len(c) == 16 and c.pending_in_journal == 0
    t = c.table
    assert np.all(t["F_A"] > 0) and set(t["status"]) == {"done"}
    assert np.allclose(np.sort(np.unique(t["preload"])), [0.3, 1.0])
    j = c.select(k_tilde=0.01, sigma_tilde=1.0, seed=1, preload=1.0)[0]
    assert abs(j["F_P"] - 1.0) < 1e-6 and j["unloading"]["F_tilde"].min() == pytest.approx(-j["F_A"])


def test_resume_never_recomputes_and_matches_uninterrupted(full, tmp_path, capsys):
    grid = write_grid(tmp_path)
    spec = load_spec(grid)
    assert run_serial(spec, progress=False, max_tasks=3) == 75
    first = results_by_key(spec.output)
    assert len(first) == 6
    assert main(["status", spec.output, "--json"]) == 0
    st = json.loads(capsys.readouterr().out)
    assert (st["done"], st["failed"], st["pending"]) == (6, 0, 10)
    assert sum(v["pending"] for v in st["by_k_tilde"].values()) == 10
    assert main([grid, "--no-progress"]) == 0
    final = results_by_key(spec.output)
    assert len(final) == 16
    assert all(final[k]["record_id"] == first[k]["record_id"] for k in first)
    assert same_numbers(results_by_key(full), final) == []
    # a third run has nothing to do and changes nothing
    assert main([grid, "--no-progress"]) == 0
    assert {k: r["record_id"] for k, r in results_by_key(spec.output).items()} == \
        {k: r["record_id"] for k, r in final.items()}


def test_grouped_equals_ungrouped(full, tmp_path):
    grid = write_grid(tmp_path, group_preloads=False)
    assert main([grid, "--no-progress"]) == 0
    ung = results_by_key(str(tmp_path / "tiny.h5"))
    assert {r["group_size"] for r in ung.values()} == {1}
    assert same_numbers(results_by_key(full), ung) == []


def test_failed_jobs_are_recorded_then_retried(tmp_path, capsys):
    scene = {**TINY["scene"], "solver": {"fft_threads": 1, "max_events": 1}}
    grid = write_grid(tmp_path, scene=scene)
    assert main([grid, "--no-progress"]) == 1           # finished, with failed jobs
    r = results_by_key(str(tmp_path / "tiny.h5"))
    assert len(r) == 16 and {x["status"] for x in r.values()} == {"failed"}
    assert all("event" in x["message"] for x in r.values())
    # rerun without --retry-failed: nothing recomputed
    assert main([grid, "--no-progress"]) == 1
    assert {k: x["record_id"] for k, x in results_by_key(str(tmp_path / "tiny.h5")).items()} == \
        {k: x["record_id"] for k, x in r.items()}
    # lift the cap (not part of the job key) and retry
    write_grid(tmp_path)
    assert main([grid, "--no-progress", "--retry-failed"]) == 0
    r2 = results_by_key(str(tmp_path / "tiny.h5"))
    assert len(r2) == 16 and {x["status"] for x in r2.values()} == {"done"}
    out = capsys.readouterr()
    assert "Traceback" not in out.err


def test_exception_in_a_job_is_a_failed_record(tmp_path, monkeypatch):
    import fibril_hpc.campaign.run.execute

    def boom(scene, **kw):
        raise RuntimeError("synthetic failure")

    monkeypatch.setattr(fibril_hpc.campaign.run.execute, "simulate", boom)
    grid = write_grid(tmp_path, k_tilde=[1])
    assert main([grid, "--no-progress"]) == 1
    r = results_by_key(str(tmp_path / "tiny.h5"))
    assert len(r) == 8 and all("RuntimeError: synthetic failure" in x["message"] for x in r.values())


def test_another_grid_is_refused_unless_extend(full, tmp_path, capsys):
    import shutil

    out = tmp_path / "tiny.h5"
    shutil.copyfile(full, out)
    before = out.read_bytes()
    grid = write_grid(tmp_path, k_tilde=[1, 0.1])
    assert main([grid, "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "another grid" in err and "--extend" in err
    assert out.read_bytes() == before
    assert main([grid, "--no-progress", "--extend"]) == 0
    r = results_by_key(str(out))
    assert len(r) == 24            # 16 old (k 1, 0.01) + 8 new (k 0.1), k=1 not recomputed
    old = results_by_key(full)
    assert all(r[k]["record_id"] == old[k]["record_id"] for k in old)
    with h5py.File(out, "r") as fh:
        assert len(json.loads(fh.attrs["extended_from"])) == 1


def test_export_csv(full, tmp_path):
    out = tmp_path / "o.csv"
    assert main(["export", full, "--csv", str(out)]) == 0
    rows = list(csv.DictReader(out.read_text().splitlines()))
    assert len(rows) == 16
    ref = {j["key"]: j for j in load_campaign(full).jobs}
    for row in rows:
        assert float(row["F_A"]) == ref[row["key"]]["F_A"]


def test_merge_shards(full, tmp_path):
    a = write_grid(tmp_path, name="a.yaml", seeds=[0], output="a.h5")
    b = write_grid(tmp_path, name="b.yaml", seeds=[1], output="b.h5")
    assert main([a, "--no-progress"]) == 0 and main([b, "--no-progress"]) == 0
    out = str(tmp_path / "all.h5")
    assert main(["merge", str(tmp_path / "a.h5"), str(tmp_path / "b.h5"), "-o", out]) == 0
    merged = results_by_key(out)
    assert same_numbers(results_by_key(full), merged) == []
    assert main(["merge", str(tmp_path / "a.h5"), str(tmp_path / "b.h5"), "-o", out]) == 2
