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
