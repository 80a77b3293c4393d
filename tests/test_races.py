"""No-overwrite holds under concurrency (issue 36, item 2): two commands racing to one new
path, held at a barrier just before each writes (tests/race_hook.py), so that both passed
their early existence check: exactly one exits 0, the other exits 2 with one line naming the
option, and the path holds the winner's complete output. Real processes, many trials; without
the atomic step (link / mkdir) both won in most trials."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest
from campaign_helpers import env, finished_tiny

HOOK = os.path.join(os.path.dirname(__file__), "race_hook.py")


@pytest.fixture(scope="module")
def two(tmp_path_factory):
    """Two finished campaigns of one grid (their records differ: record ids, timings)."""
    a = finished_tiny(tmp_path_factory.mktemp("a"))
    b = finished_tiny(tmp_path_factory.mktemp("b"))
    return str(a), str(b)


def race(folder, program, target, argvs, timeout=300):
    """Start one process per argument list together; returns [(exit, stderr)]."""
    barrier = os.path.join(folder, f"barrier-{len(os.listdir(folder))}")
    os.mkdir(barrier)
    procs = [subprocess.Popen([sys.executable, HOOK, barrier, str(len(argvs)), program, target]
                              + [str(a) for a in argv], stdout=subprocess.PIPE,
                              stderr=subprocess.PIPE, text=True, env=env(), cwd=folder)
             for argv in argvs]
    out = []
    for p in procs:
        _, err = p.communicate(timeout=timeout)
        out.append((p.returncode, err))
    return out


def one_winner(results, option):
    """The index of the one process that exited 0; the other exited 2 with one line."""
    codes = [c for c, _ in results]
    assert sorted(codes) == [0, 2], results
    loser = results[codes.index(2)][1]
    lines = [ln for ln in loser.splitlines() if ln.strip()]
    assert len(lines) == 1 and "Traceback" not in loser, loser
    assert option in lines[0] and "another command created it" in lines[0], lines[0]
    return codes.index(0)


def test_export_csv_race_has_one_winner_with_its_whole_file(two, tmp_path):
    from fibril_hpc.campaign.analysis.export import export_csv

    want = []
    for i, f in enumerate(two):
        export_csv(f, str(tmp_path / f"want{i}.csv"))
        want.append((tmp_path / f"want{i}.csv").read_bytes())
    assert want[0] != want[1]
    for trial in range(4):
        target = tmp_path / f"race{trial}.csv"
        got = race(str(tmp_path), "campaign", target,
                   [["export", f, "--csv", target] for f in two])
        w = one_winner(got, "--csv")
        assert target.read_bytes() == want[w]
        assert not [n for n in os.listdir(tmp_path) if ".part-" in n]     # no temporaries


def test_example_race_has_one_winner_with_its_whole_file(tmp_path):
    from fibril_hpc import examples

    names = examples.names()[:2]
    for trial in range(3):
        target = tmp_path / f"g{trial}.yaml"
        got = race(str(tmp_path), "campaign", target,
                   [["example", n, "-o", target] for n in names])
        w = one_winner(got, "--output")
        assert target.read_text() == examples.text(examples.resolve(names[w]))


def test_salvage_race_has_one_winner_with_its_records(two, tmp_path):
    from fibril_hpc.campaign.storage.store import read_h5_records

    ids = [{k: r["record_id"] for k, r in read_h5_records(f)[1].items()} for f in two]
    for trial in range(2):
        target = tmp_path / f"s{trial}.h5"
        got = race(str(tmp_path), "campaign", target,
                   [["salvage", f, "-o", target] for f in two])
        w = one_winner(got, "--output")
        have = {k: r["record_id"] for k, r in read_h5_records(str(target))[1].items()}
        assert have == ids[w]


@pytest.mark.slow
@pytest.mark.parametrize("fmt", ["--parquet", "--netcdf"])
def test_export_binary_race_has_one_winner(two, tmp_path, fmt):
    from fibril_hpc.campaign.analysis import export as ex

    if fmt == "--parquet" and not ex.parquet_available():
        pytest.skip("pandas/pyarrow not installed")
    if fmt == "--netcdf" and not ex.netcdf_available():
        pytest.skip("xarray/h5netcdf not installed")
    for trial in range(3):
        target = tmp_path / f"race{trial}.out"
        got = race(str(tmp_path), "campaign", target,
                   [["export", f, fmt, target] for f in two])
        one_winner(got, fmt)
        assert target.stat().st_size > 0


@pytest.mark.slow
def test_merge_race_has_one_winner(two, tmp_path):
    from fibril_hpc.campaign.storage.store import read_h5_records

    for trial in range(3):
        target = tmp_path / f"m{trial}.h5"
        got = race(str(tmp_path), "campaign", target,
                   [["merge", *two, "-o", target, "--on-conflict", "first"],
                    ["merge", *two[::-1], "-o", target, "--on-conflict", "first"]])
        w = one_winner(got, "--output")
        first = two if w == 0 else two[::-1]
        want = {k: r["record_id"] for k, r in read_h5_records(first[0])[1].items()}
        assert {k: r["record_id"] for k, r in read_h5_records(str(target))[1].items()} == want


@pytest.mark.slow
def test_report_folder_race_has_one_winner(two, tmp_path):
    target = tmp_path / "rep"
    got = race(str(tmp_path), "campaign", target,
               [["report", f, "--out", target, "--n-boot", "20"] for f in two])
    one_winner(got, "--out")
    assert (target / "report.html").exists()


@pytest.mark.slow
def test_fibril_run_out_race_has_one_winner(tmp_path):
    import h5py

    for trial in range(2):
        target = tmp_path / f"r{trial}.h5"
        got = race(str(tmp_path), "run", target,
                   [["--builtin", "quick", "--out", target, "--no-progress"]] * 2)
        one_winner(got, "--out")
        with h5py.File(target, "r") as fh:       # whole: it opens
            assert len(fh.keys()) > 0
