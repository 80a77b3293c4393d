"""Trust (issue 29): a file of a layout version newer than this code knows is refused by every
reader in one line, never read as if it were the old layout."""

from __future__ import annotations

import os
import shutil

import h5py
import pytest
from campaign_helpers import write_grid

from fibril_hpc import load_campaign
from fibril_hpc.campaign import load_spec
from fibril_hpc.campaign.run.runner import run_serial
from fibril_hpc.errors import UnknownLayoutError


@pytest.fixture(scope="module")
def finished(tmp_path_factory):
    d = tmp_path_factory.mktemp("finished")
    grid = write_grid(d, k_tilde=[1], sigma_tilde=[0.3], F_P=[0.3, 1.0], seeds=1)
    assert run_serial(load_spec(grid), progress=False) == 0
    return d


@pytest.mark.parametrize("version", [999, 2, 0, "x"])
def test_every_reader_refuses_an_unknown_layout_version(tmp_path, finished, capsys, version):
    from fibril_hpc.cli.campaign import main

    shutil.copy(finished / "grid.yaml", tmp_path / "grid.yaml")
    f = tmp_path / "tiny.h5"
    shutil.copy(finished / "tiny.h5", f)
    with h5py.File(f, "a") as fh:
        fh.attrs["format_version"] = version
    before = f.read_bytes()
    for args in (["status", f], ["verify", f], ["export", f, "--csv", tmp_path / "x.csv"],
                 ["report", f, "--out", tmp_path / "rep"], ["merge", f, "-o", tmp_path / "m.h5"],
                 ["salvage", f, "-o", tmp_path / "s.h5"], [tmp_path / "grid.yaml"]):
        capsys.readouterr()
        code = main([str(a) for a in args])
        err = capsys.readouterr().err
        lines = [ln for ln in err.splitlines() if ln.strip()]
        assert code == 2 and len(lines) == 1 and "Traceback" not in err, (args, err)
        assert "format_version" in lines[0] and str(version) in lines[0], lines[0]
    with pytest.raises(UnknownLayoutError):
        load_campaign(str(f))
    assert f.read_bytes() == before
    assert sorted(os.listdir(tmp_path)) == ["grid.yaml", "tiny.h5"]      # nothing written


@pytest.fixture(scope="module")
def half(tmp_path_factory):
    """A campaign of 4 jobs (2 loading paths) with one path done: 2 done, 2 pending."""
    d = tmp_path_factory.mktemp("half")
    grid = write_grid(d, k_tilde=[1], sigma_tilde=[0.3], F_P=[0.3, 1.0], seeds=2)
    assert run_serial(load_spec(grid), progress=False, max_tasks=1) == 75
    return d


@pytest.mark.parametrize("how", ["no checksum", "a stale checksum"])
def test_a_journal_frame_is_counted_only_when_its_checksum_verifies(tmp_path, half, capsys,
                                                                     how):
    from fibril_hpc.campaign.storage import journal as J
    from fibril_hpc.campaign.storage.store import read_h5_records
    from fibril_hpc.cli.campaign import main

    for name in ("grid.yaml", "tiny.h5"):
        shutil.copy(half / name, tmp_path / name)
    f = str(tmp_path / "tiny.h5")
    spec = load_spec(str(tmp_path / "grid.yaml"))
    stored = read_h5_records(f)[1]
    missing = sorted({j.key for j in spec.jobs} - set(stored))
    assert len(missing) == 2
    forged = dict(next(iter(stored.values())), key=missing[0], F_A=999.125, record_id="forged",
                  type="job")
    if how == "no checksum":
        forged.pop("checksum")
    with open(J.journal_path(f), "wb") as fh:     # intact frame CRCs: only the checksum tells
        fh.write(J.encode(forged))

    def cmd(*args):
        capsys.readouterr()
        code = main([str(a) for a in args])
        return code, *capsys.readouterr()

    code, out, _ = cmd("status", f)
    assert code == 0 and "2 done, 0 failed, 2 pending" in out
    assert 999.125 not in [j["F_A"] for j in load_campaign(f).jobs]
    code, out, _ = cmd("export", f, "--csv", tmp_path / "x.csv")
    assert code == 0 and "999.125" not in (tmp_path / "x.csv").read_text()
    code, out, _ = cmd("verify", f)
    assert code == 1 and "no checksum or one that does not verify" in out
    for sub in ("merge", "salvage"):             # never re-signed into a new file
        new = tmp_path / f"{sub}.h5"
        code, out, err = cmd(sub, f, "-o", new)
        assert code == 0, err
        assert missing[0] not in read_h5_records(str(new))[1]
    code, _, err = cmd(tmp_path / "grid.yaml", "--no-progress")         # resume recomputes it
    assert code == 0, err
    got = read_h5_records(f)[1]
    assert got[missing[0]]["record_id"] != "forged" and got[missing[0]]["F_A"] != 999.125
    assert os.path.getsize(J.quarantine_path(J.journal_path(f))) > 0    # kept aside, not lost


def test_the_writer_journals_records_with_their_checksum(tmp_path):
    from fibril_hpc.campaign.storage import integrity
    from fibril_hpc.campaign.storage import journal as J

    grid = write_grid(tmp_path, k_tilde=[1], sigma_tilde=[0.3], F_P=[0.3], seeds=1)
    spec = load_spec(grid)
    from fibril_hpc.campaign.storage.writer import CampaignWriter

    w = CampaignWriter(spec, checkpoint_s=1e6)
    rec = {**spec.jobs[0].inputs(), "status": "failed", "message": "x", "record_id": "r1",
           "campaign_hash": spec.campaign_hash, "type": "job"}
    w.add([rec])
    recs, scan = J.read(J.journal_path(spec.output))
    assert scan.clean and len(recs) == 1 and integrity.check(recs[0]) == integrity.OK
    w.close()
