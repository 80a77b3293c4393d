"""No command replaces a file the user did not offer (issue 29, "Data loss"): an existing file
only with ``--force``, and never a campaign file, a journal, or a file a running campaign holds.

A test per writing command: ``export`` (CSV, Parquet, netCDF), ``merge``, ``salvage``,
``example -o``, ``report --out``, ``fibril-run --out/--plot``, ``fibril-accuracy --out``. A
refusal is one line naming the option and the file, exit status 2, and nothing written.
"""

from __future__ import annotations

import fcntl
import os
import shutil

import h5py
import pytest
from campaign_helpers import finished_tiny

from fibril_hpc.campaign.analysis.export import netcdf_available, parquet_available


@pytest.fixture(scope="module")
def finished(tmp_path_factory):
    return finished_tiny(tmp_path_factory.mktemp("finished"))


def cli(args, capsys):
    from fibril_hpc.cli.campaign import main

    capsys.readouterr()
    code = main([os.fsdecode(a) if isinstance(a, bytes) else str(a) for a in args])
    out, err = capsys.readouterr()
    return code, out, err


def refused(code, err, path, *words):
    """One line, exit 2, naming the file (and ``words``)."""
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert code == 2 and len(lines) == 1 and "Traceback" not in err, err
    assert os.path.basename(str(path)) in lines[0], lines[0]
    for w in words:
        assert w in lines[0], lines[0]


def snapshot(folder) -> dict:
    out = {}
    for p in sorted(os.listdir(folder)):
        if os.path.isfile(os.path.join(folder, p)):
            with open(os.path.join(folder, p), "rb") as fh:
                out[p] = fh.read()
    return out


def victims(tmp_path, finished) -> dict:
    """The files a careless export could hit: the campaign itself, another campaign, a user's
    text file, someone else's HDF5 file."""
    shutil.copy(finished, tmp_path / "self.h5")
    shutil.copy(finished, tmp_path / "other.h5")
    (tmp_path / "notes.txt").write_text("a month of notes\n")
    with h5py.File(tmp_path / "theirs.h5", "w") as fh:
        fh["x"] = [1, 2, 3]
    return {"self": tmp_path / "self.h5", "campaign": tmp_path / "other.h5",
            "text": tmp_path / "notes.txt", "hdf5": tmp_path / "theirs.h5"}


FORMATS = ["--csv"] + (["--parquet"] if parquet_available() else []) \
    + (["--netcdf"] if netcdf_available() else [])


@pytest.mark.parametrize("fmt", FORMATS)
def test_export_never_replaces_a_file_unasked_nor_a_campaign_file_ever(tmp_path, finished,
                                                                      capsys, fmt):
    v = victims(tmp_path, finished)
    src = v["self"]
    for what, target in v.items():
        before = snapshot(tmp_path)
        code, _, err = cli(["export", src, fmt, target], capsys)
        refused(code, err, target, fmt, "--force" if what in ("text", "hdf5") else "never")
        assert snapshot(tmp_path) == before, what
    for what in ("self", "campaign"):           # --force does not reach a campaign file
        before = snapshot(tmp_path)
        code, _, err = cli(["export", src, fmt, v[what], "--force"], capsys)
        refused(code, err, v[what], "campaign file", "not even with --force")
        assert snapshot(tmp_path) == before
    for what in ("text", "hdf5"):               # the user said so
        code, _, err = cli(["export", src, fmt, v[what], "--force"], capsys)
        assert code == 0, err
        assert v[what].read_bytes() != b"a month of notes\n"
    code, out, err = cli(["status", src], capsys)
    assert code == 0 and "2 done" in out


def test_export_refuses_journals_locks_and_a_file_a_running_campaign_holds(tmp_path, finished,
                                                                         capsys):
    live = tmp_path / "live.h5"
    shutil.copy(finished, live)
    lock = open(str(live) + ".lock", "w")
    fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)       # a campaign writing live.h5
    journal = tmp_path / "live.h5.journal"
    journal.write_bytes(b"")
    try:
        for target in (live, journal, tmp_path / "live.h5.lock"):
            before = snapshot(tmp_path)
            code, _, err = cli(["export", finished, "--csv", target, "--force"], capsys)
            refused(code, err, target, "never")
            assert snapshot(tmp_path) == before
        code, _, err = cli(["export", finished, "--csv", live], capsys)
        refused(code, err, live, "running campaign")
    finally:
        lock.close()
    # a new name, and the same name twice
    code, _, err = cli(["export", finished, "--csv", tmp_path / "a.csv",
                        "--parquet", tmp_path / "a.csv"], capsys)
    refused(code, err, "a.csv", "other than the other outputs")
    assert not (tmp_path / "a.csv").exists()
    code, _, err = cli(["export", finished, "--csv", tmp_path / "a.csv"], capsys)
    assert code == 0, err


@pytest.mark.parametrize("cmd", ["merge", "salvage"])
def test_merge_and_salvage_write_only_a_new_file(tmp_path, finished, capsys, cmd):
    v = victims(tmp_path, finished)
    for what, target in v.items():
        before = snapshot(tmp_path)
        args = [cmd, finished, "-o", target]
        code, _, err = cli(args, capsys)
        refused(code, err, target, "it exists")
        assert snapshot(tmp_path) == before, what
    code, _, err = cli([cmd, finished, "-o", tmp_path / "new.h5"], capsys)
    assert code == 0, err


def test_example_output_must_be_new(tmp_path, capsys):
    mine = tmp_path / "grid.yaml"
    mine.write_text("my grid\n")
    code, _, err = cli(["example", "demo", "-o", mine], capsys)
    refused(code, err, mine, "it exists")
    assert mine.read_text() == "my grid\n"


@pytest.mark.slow
def test_report_folder_needs_force_and_never_replaces_a_campaign_file(tmp_path, finished,
                                                                     capsys):
    src = tmp_path / "c.h5"
    shutil.copy(finished, src)
    mine = tmp_path / "project"
    mine.mkdir()
    (mine / "README.md").write_text("my project\n")
    code, _, err = cli(["report", src, "--out", mine, "--n-boot", "20"], capsys)
    refused(code, err, mine, "--force")
    assert snapshot(mine) == {"README.md": b"my project\n"}
    rep = tmp_path / "rep"
    code, _, err = cli(["report", src, "--out", rep, "--n-boot", "20"], capsys)
    assert code == 0, err
    code, _, err = cli(["report", src, "--out", rep, "--n-boot", "20"], capsys)
    assert code == 0, err                        # an earlier report of ours is rewritten
    shutil.copy(finished, rep / "alpha_beta.csv")   # a campaign file under a report's name
    before = snapshot(rep)
    code, _, err = cli(["report", src, "--out", rep, "--n-boot", "20", "--force"], capsys)
    refused(code, err, rep, "alpha_beta.csv", "not even with --force")
    assert snapshot(rep) == before
    code, _, err = cli(["report", src, "--out", mine, "--n-boot", "20", "--force"], capsys)
    assert code == 0, err


def test_fibril_run_never_replaces_a_campaign_file(tmp_path, finished, capsys):
    import yaml

    from fibril_hpc.cli.run import main

    scene = tmp_path / "scene.yaml"
    scene.write_text(yaml.safe_dump({"n_side": 2, "elements_per_diameter": 5, "F_P": 0.5}))
    camp = tmp_path / "c.h5"
    shutil.copy(finished, camp)
    before = camp.read_bytes()
    for opt in ("--out", "--plot"):
        capsys.readouterr()
        code = main([str(scene), opt, str(camp), "--force"])
        refused(code, capsys.readouterr().err, camp, opt, "campaign file")
    assert camp.read_bytes() == before


def test_fibril_accuracy_refuses_an_earlier_study_unless_told(tmp_path, capsys):
    from fibril_hpc.cli.accuracy import main

    out = tmp_path / "study"
    out.mkdir()
    (out / "accuracy.csv").write_text("a week of timings\n")
    capsys.readouterr()
    code = main(["--quick", "--out", str(out)])
    refused(code, capsys.readouterr().err, "accuracy.csv", "--force")
    assert (out / "accuracy.csv").read_text() == "a week of timings\n"
