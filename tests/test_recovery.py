"""Every advised recovery recovers (issue 29, "Data loss"): a published campaign file cut
short, emptied or overwritten while its campaign runs stops the writer with exit 75 and one
line; the ``salvage`` it advises recovers every record of the journal and of the readable file
into a file the campaign resumes from. A flipped byte in the root attributes does not make
``salvage`` give up (the records under /jobs carry their own checksums)."""

from __future__ import annotations

import os
import shutil

import pytest
from campaign_helpers import write_grid

from fibril_hpc.campaign import load_spec
from fibril_hpc.campaign.run import runner
from fibril_hpc.campaign.run.runner import run_serial
from fibril_hpc.campaign.storage import journal as J
from fibril_hpc.campaign.storage.store import read_h5_records


def cli(args, capsys):
    from fibril_hpc.cli.campaign import main

    capsys.readouterr()
    code = main([str(a) for a in args])
    out, err = capsys.readouterr()
    return code, out, err


def one_line(err: str) -> str:
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert "Traceback" not in err and len(lines) == 1, err
    return lines[0]


def _cut(path):
    with open(path, "r+b") as fh:
        fh.truncate(os.path.getsize(path) // 2)


def _empty(path):
    open(path, "wb").close()


def _overwrite(path):
    with open(path, "w") as fh:
        fh.write("key,F_A\n0,1.0\n")


def _replace(path):                   # a new file renamed over it (a copy back from elsewhere)
    with open(path + ".tmp", "wb") as fh:
        fh.write(b"\x89HDF\r\n\x1a\n" + bytes(100))
    os.replace(path + ".tmp", path)


@pytest.mark.parametrize("checkpoint_s", [1e6, 0])
@pytest.mark.parametrize("damage", [_cut, _empty, _overwrite, _replace])
def test_a_published_file_changed_mid_run_is_75_and_salvage_recovers_it(
        tmp_path, capsys, monkeypatch, damage, checkpoint_s):
    grid = write_grid(tmp_path)
    out = str(tmp_path / "tiny.h5")
    real = runner.execute_task
    calls = []

    def task_then_damage(*a, **kw):
        recs = real(*a, **kw)
        calls.append(1)
        if len(calls) == 3:
            damage(out)
        return recs

    monkeypatch.setattr(runner, "execute_task", task_then_damage)
    code, _, err = cli([grid, "--no-progress", "--checkpoint-s", checkpoint_s], capsys)
    line = one_line(err)
    assert code == 75, err
    assert "changed under this campaign" in line and f"salvage {out} -o NEW.h5" in line
    monkeypatch.setattr(runner, "execute_task", real)
    in_journal = {r["key"]: r["record_id"] for r in J.read(J.journal_path(out))[0]}
    assert len(in_journal) >= 2 * (1 if checkpoint_s == 0 else len(calls))
    new = tmp_path / "new.h5"
    code, o, err = cli(["salvage", out, "-o", new], capsys)
    assert code == 0, err
    got = read_h5_records(str(new))[1]
    assert {k: got[k]["record_id"] for k in in_journal} == in_journal      # all of them
    code, _, err = cli([grid, "--no-progress", "--output", new], capsys)     # resumes
    assert code == 0, err
    after = read_h5_records(str(new))[1]
    assert len(after) == 16 and all(after[k]["record_id"] == r for k, r in in_journal.items())
    code, o, _ = cli(["verify", new], capsys)
    assert code == 0 and "16 record(s) verified" in o


@pytest.fixture(scope="module")
def finished(tmp_path_factory):
    d = tmp_path_factory.mktemp("finished")
    assert run_serial(load_spec(write_grid(d)), progress=False) == 0
    return d


@pytest.mark.parametrize("where", [b"fibril-hpc campaign", b"sigma_tilde:", b"  phi: 0.16"])
def test_one_flipped_byte_in_the_root_does_not_stop_salvage(finished, tmp_path, capsys, where):
    for name in ("grid.yaml", "tiny.h5"):
        shutil.copy(finished / name, tmp_path / name)
    f = tmp_path / "tiny.h5"
    data = bytearray(f.read_bytes())
    at = data.find(where)
    assert at > 0
    data[at + len(where) - 1] ^= 0x04
    f.write_bytes(bytes(data))
    want = {k: r["record_id"] for k, r in read_h5_records(str(finished / "tiny.h5"))[1].items()}
    new = tmp_path / "new.h5"
    code, o, err = cli(["salvage", f, "-o", new], capsys)
    assert code == 0, err
    assert {k: r["record_id"] for k, r in read_h5_records(str(new))[1].items()} == want
    code, _, err = cli([tmp_path / "grid.yaml", "--no-progress", "--output", new], capsys)
    assert code == 0, err
    code, o, _ = cli(["status", new], capsys)
    assert "16 done, 0 failed, 0 pending" in o


def test_salvage_of_a_file_that_never_was_a_campaign_is_one_line(tmp_path, capsys):
    f = tmp_path / "notes.h5"
    f.write_text("just text\n")
    code, _, err = cli(["salvage", f, "-o", tmp_path / "new.h5"], capsys)
    assert code == 2 and "what is left of one" in one_line(err)
    assert not (tmp_path / "new.h5").exists()
