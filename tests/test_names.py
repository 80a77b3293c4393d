"""File names a user (or a careless script) gives (issue 29): not UTF-8, spaces, quotes, a
UTF-8 beyond ASCII. Every command (status, verify, export, report, merge, salvage) on
such a campaign file, and with such output names, ends without a traceback."""

from __future__ import annotations

import os
import shutil
import subprocess

import pytest
from campaign_helpers import campaign_cmd, env, finished_tiny


NAMES = [b"bad\xff\xfe name.h5", b"it's \"quoted\" $x;\xc3\xa9t\xc3\xa9.h5"]


@pytest.fixture(scope="module")
def finished(tmp_path_factory):
    return finished_tiny(tmp_path_factory.mktemp("finished"))


def _in_process(args):
    from fibril_hpc.cli.campaign import main

    return main([os.fsdecode(a) for a in args])      # as Python decodes argv


@pytest.mark.parametrize("name", NAMES, ids=repr)
def test_every_command_takes_any_file_name(tmp_path, finished, name, capfd):
    folder = os.fsencode(str(tmp_path))
    f = os.path.join(folder, name)
    shutil.copy(finished, f)
    stem = name[:-3]
    cmds = [[b"status", f], [b"status", f, b"--json"], [b"verify", f],
            [b"export", f, b"--csv", os.path.join(folder, stem + b".csv")],
            [b"report", f, b"--out", os.path.join(folder, stem + b" report"), b"--n-boot", b"20"],
            [b"merge", f, b"-o", os.path.join(folder, b"merged " + name)],
            [b"salvage", f, b"-o", os.path.join(folder, b"salvaged " + name)]]
    for args in cmds:
        code = _in_process(args)
        err = capfd.readouterr().err
        assert code == 0 and "Traceback" not in err and "Error" not in err, (args, err)
    assert os.path.isfile(os.path.join(folder, stem + b" report", b"report.html"))
    assert os.path.isfile(os.path.join(folder, b"salvaged " + name))


def test_a_name_that_is_not_utf8_through_a_real_command_line(tmp_path, finished):
    """The bytes reach Python's argv as surrogates and go back out on stdout unchanged."""
    folder = os.fsencode(str(tmp_path))
    name = NAMES[0]
    f = os.path.join(folder, name)
    shutil.copy(finished, f)
    for args in ([b"status", f], [b"export", f, b"--csv", f[:-3] + b".csv"]):
        r = subprocess.run(campaign_cmd() + args, capture_output=True, timeout=120, env=env())
        assert r.returncode == 0 and b"Traceback" not in r.stderr, (args, r.stderr)
        assert name[:-3] in r.stdout                   # the user's bytes, as given
