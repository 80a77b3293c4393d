"""``verify`` checks every root attribute a reader relies on, and names the repair that works
(issue 36, item 4); a resume of a file whose stored hash is damaged is refused naming that
repair, never "another grid ... pass --extend"; after the repair the file verifies and merges.
And every message's advice works (item 3): on files with one byte damaged, whatever recovery the
readers and the resume name (resume, or salvage then rerun) recovers all 16 records, and a
refused run leaves no journal or lock behind."""

from __future__ import annotations

import os
import re
import shutil

import h5py
import pytest
from campaign_helpers import write_grid

from fibril_hpc.campaign import load_spec
from fibril_hpc.campaign.run.runner import run_serial
from fibril_hpc.campaign.storage.rootcheck import root_problem
from fibril_hpc.campaign.storage.store import read_h5_records


def cli(args, capsys, caplog):
    from fibril_hpc.cli.campaign import main

    caplog.clear()
    capsys.readouterr()
    code = main([str(a) for a in args])
    out, err = capsys.readouterr()
    return code, out, err + "".join(r.getMessage() + "\n" for r in caplog.records
                                    if r.levelno >= 30)


@pytest.fixture(scope="module")
def finished(tmp_path_factory):
    d = tmp_path_factory.mktemp("finished")
    assert run_serial(load_spec(write_grid(d)), progress=False) == 0
    return d


def copy_of(finished, tmp_path) -> str:
    for name in ("grid.yaml", "tiny.h5"):
        shutil.copy(finished / name, tmp_path / name)
    return str(tmp_path / "tiny.h5")


def _root(path) -> dict:
    with h5py.File(path, "r") as fh:
        return {k: fh.attrs[k] for k in fh.attrs}


def flip_in_root(path, attr: str, needle: bytes, offset: int = 0) -> None:
    """Flip one bit of the byte ``offset`` after ``needle`` where that changes the root
    attribute ``attr`` (the same text also lives in the records' own attributes)."""
    with open(path, "rb") as fh:
        data = bytearray(fh.read())
    before = _root(path)[attr]
    at = data.find(needle)
    while at >= 0:
        trial = bytearray(data)
        trial[at + offset] ^= 0x04
        with open(path, "wb") as fh:
            fh.write(trial)
        try:
            if _root(path).get(attr) != before:
                return
        except Exception:  # noqa: BLE001 - this flip broke more than the attribute
            pass
        at = data.find(needle, at + 1)
    with open(path, "wb") as fh:
        fh.write(data)
    raise AssertionError(f"{needle!r} not found in the root attribute {attr}")


def test_a_whole_root_has_no_problem(finished):
    assert root_problem(_root(finished / "tiny.h5")) == ""
    data = os.path.join(os.path.dirname(__file__), "data")
    for name in ("campaign_v1.h5", "real18_k1.h5"):            # old files stay whole
        assert root_problem(_root(os.path.join(data, name))) == ""


@pytest.mark.parametrize("attr,needle,offset", [
    ("campaign_hash", None, 5),
    ("campaign_yaml", b"sigma_tilde:", 11),
    ("campaign_yaml", b"  phi: 0.16", 10),
])
def test_a_flipped_byte_in_the_root_is_found_and_the_named_repair_works(
        finished, tmp_path, capsys, caplog, attr, needle, offset):
    out = copy_of(finished, tmp_path)
    grid = tmp_path / "grid.yaml"
    want = {k: r["record_id"] for k, r in read_h5_records(out)[1].items()}
    if needle is None:
        needle = str(_root(out)["campaign_hash"]).encode()
    flip_in_root(out, attr, needle, offset)
    code, o, err = cli(["verify", out], capsys, caplog)
    assert code == 1 and "root attributes damaged" in o and f"salvage {out} -o NEW.h5" in o, o
    assert "no damage found" not in o
    before = sorted(os.listdir(tmp_path))
    code, o, err = cli([grid, "--no-progress"], capsys, caplog)         # a resume
    if attr == "campaign_hash":        # refused as damaged, naming salvage, not --extend
        assert code == 2 and f"salvage {out} -o NEW.h5" in err and "--extend" not in err, err
        assert sorted(os.listdir(tmp_path)) == before                   # nothing left behind
    # the repair verify names: salvage, then rerun the grid with --output NEW.h5
    new = tmp_path / "new.h5"
    code, o, err = cli(["salvage", out, "-o", new], capsys, caplog)
    assert code == 0, err
    code, o, err = cli([grid, "--no-progress", "--output", new], capsys, caplog)
    assert code == 0, err
    code, o, err = cli(["verify", new], capsys, caplog)
    assert code == 0 and "no damage found" in o and "16 record(s) verified" in o, o
    assert {k: r["record_id"] for k, r in read_h5_records(str(new))[1].items()} == want
    code, o, err = cli(["merge", new, finished / "tiny.h5", "-o", tmp_path / "m.h5"], capsys,
                       caplog)
    assert code == 0, err


def test_verify_names_salvage_when_the_root_program_is_damaged(finished, tmp_path, capsys,
                                                                caplog):
    out = copy_of(finished, tmp_path)
    flip_in_root(out, "program", b"fibril-hpc campaign", 18)
    code, o, err = cli(["verify", out], capsys, caplog)
    assert code == 2 and f"salvage {out} -o NEW.h5" in err, err


# --------------------------------------------------------------- item 3: the advice works
POSITIONS = [0.05, 0.2, 0.35, 0.5, 0.65, 0.8, 0.9, 0.97]


def _says_resume(text: str) -> bool:
    """Whether a message promised that resuming recomputes what is damaged."""
    return re.search(r"resum\w* recomputes", text) is not None


@pytest.mark.parametrize("frac", [pytest.param(f, marks=pytest.mark.slow)
                                  if f not in (0.5, 0.8) else f for f in POSITIONS])
def test_the_recovery_every_message_names_recovers(finished, tmp_path, capsys, caplog, frac):
    """One byte damaged: the readers' advice (resume, or salvage then rerun) is followed, and
    it ends with all 16 records verified; a refused resume leaves nothing behind."""
    out = copy_of(finished, tmp_path)
    grid = tmp_path / "grid.yaml"
    with open(out, "rb") as fh:
        data = bytearray(fh.read())
    data[int(len(data) * frac)] ^= 0xFF
    with open(out, "wb") as fh:
        fh.write(bytes(data))
    said = ""
    for args in (["status", out], ["verify", out]):
        code, o, err = cli(args, capsys, caplog)
        said += o + err
    before = sorted(os.listdir(tmp_path))
    code, o, err = cli([grid, "--no-progress"], capsys, caplog)
    if code == 2:
        assert not _says_resume(said), (said, err)          # no promise broken
        assert "salvage" in err, err
        assert sorted(os.listdir(tmp_path)) == before, err     # no journal, no lock
        new = tmp_path / "new.h5"
        code, o, err = cli(["salvage", out, "-o", new], capsys, caplog)
        assert code == 0, err
        code, o, err = cli([grid, "--no-progress", "--output", new], capsys, caplog)
        out = str(new)
    assert code == 0, err
    code, o, err = cli(["verify", out], capsys, caplog)
    assert code == 0 and "16 record(s) verified" in o, o
