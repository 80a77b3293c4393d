"""The trust boundary of campaign files (issue 18): a record is counted, published or re-signed
only when this code can vouch for it (checksum, key of the grid, data in the file, layout);
anything else is *unchecked* or *foreign*. Each test reproduces one numbered case of the issue.
"""

from __future__ import annotations

import os
import resource
import shutil
import subprocess
import sys

import h5py
import numpy as np
import pytest

from campaign_helpers import env, run, write_grid
from fibril_hpc import load_campaign
from fibril_hpc.campaign.storage import integrity
from fibril_hpc.campaign.storage import journal as J
from fibril_hpc.campaign import load_spec
from fibril_hpc.campaign.run.runner import run_serial
from fibril_hpc.campaign.storage.store import write_record
from fibril_hpc.errors import StoreError


@pytest.fixture(scope="module")
def finished(tmp_path_factory):
    """A finished 16-job campaign (copied by each test that changes it)."""
    d = tmp_path_factory.mktemp("finished")
    grid = write_grid(d)
    assert run_serial(load_spec(grid), progress=False) == 0
    return d


def copy_of(finished, tmp_path, name="tiny.h5") -> str:
    shutil.copy(finished / "grid.yaml", tmp_path / "grid.yaml")
    shutil.copy(finished / "tiny.h5", tmp_path / name)
    return str(tmp_path / name)


def one_line(stderr: str) -> str:
    lines = [ln for ln in stderr.strip().splitlines() if ln.strip()]
    assert "Traceback" not in stderr, stderr
    assert len(lines) == 1, stderr
    return lines[0]


def cli(args, capsys, caplog):
    """``fibril-campaign ARGS`` in this process: (exit status, stdout, warnings + stderr)."""
    from fibril_hpc.cli.campaign import main

    caplog.clear()
    capsys.readouterr()
    code = main([str(a) for a in args])
    out, err = capsys.readouterr()
    warn = "".join(r.getMessage() + "\n" for r in caplog.records if r.levelno >= 30)
    assert "Traceback" not in err
    return code, out, warn + err


def keys_of(path) -> list:
    with h5py.File(path, "r") as fh:
        return sorted(fh["jobs"])


def _text(path) -> str:
    with open(path) as fh:
        return fh.read()


def _bytes(path) -> bytes:
    with open(path, "rb") as fh:
        return fh.read()


# ------------------------------------------------------------------ 1: a record without checksum
def test_1_record_without_checksum_is_unchecked_everywhere(finished, tmp_path, capsys, caplog):
    out = copy_of(finished, tmp_path)
    k = keys_of(out)[0]
    with h5py.File(out, "r+") as fh:
        del fh["jobs"][k].attrs["checksum"]
        fh["jobs"][k].attrs["F_A"] = 9.99
    c = load_campaign(out)
    assert len(c) == 15 and k not in {j["key"] for j in c.jobs} and c.unchecked == {k}
    assert "1 unchecked record(s)" in caplog.text
    code, o, _ = cli(["status", out], capsys, caplog)
    assert code == 0 and "15 done" in o and "1 unchecked" in o
    code, o, _ = cli(["export", out, "--csv", tmp_path / "x.csv"], capsys, caplog)
    assert code == 0 and "15 jobs" in o and "9.99" not in _text(tmp_path / "x.csv")
    code, o, _ = cli(["export", out, "--csv", tmp_path / "y.csv", "--include-unchecked"],
                     capsys, caplog)
    assert code == 0 and "16 jobs" in o and "9.99" in _text(tmp_path / "y.csv")
    code, o, _ = cli(["verify", out], capsys, caplog)
    assert code == 1 and "1 unchecked" in o
    # merge: left out, or (asked for) copied without a checksum: never re-signed
    code, o, _ = cli(["merge", out, "-o", tmp_path / "m.h5"], capsys, caplog)
    assert code == 0 and "15 jobs" in o and "1 unchecked left out" in o
    code, o, _ = cli(["verify", tmp_path / "m.h5"], capsys, caplog)
    assert code == 0 and "15 record(s) verified" in o
    code, o, _ = cli(["merge", out, "-o", tmp_path / "m2.h5", "--include-unchecked"],
                     capsys, caplog)
    assert code == 0 and "16 jobs" in o
    code, o, _ = cli(["verify", tmp_path / "m2.h5"], capsys, caplog)
    assert code == 1 and "15 record(s) verified" in o and "1 unchecked" in o
    code, o, _ = cli(["salvage", out, "-o", tmp_path / "s.h5", "--keep-unchecked"], capsys, caplog)
    assert code == 0
    code, o, _ = cli(["verify", tmp_path / "s.h5"], capsys, caplog)
    assert code == 1 and "1 unchecked" in o


# ------------------------------------------------------------------ 2: a journal frame off the grid
def test_2_journal_frame_with_a_key_off_the_grid_is_foreign(finished, tmp_path, capsys, caplog):
    out = copy_of(finished, tmp_path)
    rec = dict(load_campaign(out).jobs[0], type="job", key="ffffffffffffffff",
               record_id="stray", F_A=456.123456789)
    rec.pop("k_machine")
    with open(J.journal_path(out), "wb") as fh:
        fh.write(J.encode(integrity.seal(rec)))        # its checksum verifies: only the key is off
    code, o, e = cli(["status", out], capsys, caplog)
    assert code == 0 and "16 done, 0 failed, 0 pending" in o and "no job of the grid" in e
    assert 456.123456789 not in [j["F_A"] for j in load_campaign(out).jobs]
    code, o, _ = cli(["export", out, "--csv", tmp_path / "x.csv"], capsys, caplog)
    assert "16 jobs" in o and "456.123456789" not in _text(tmp_path / "x.csv")
    code, o, _ = cli(["verify", out], capsys, caplog)
    assert code == 1 and "no job of the grid" in o
    code, o, e = cli([tmp_path / "grid.yaml", "--no-progress"], capsys, caplog)     # resume
    assert code == 0, e
    assert "ffffffffffffffff" not in keys_of(out)
    assert os.path.getsize(J.quarantine_path(J.journal_path(out))) > 0      # kept aside
    code, o, _ = cli(["verify", out], capsys, caplog)
    assert code == 0 and "16 record(s) verified" in o


# ------------------------------------------------------------------ 3: an external link in /jobs
def test_3_external_links_are_never_followed(finished, tmp_path, capsys, caplog):
    out = copy_of(finished, tmp_path)
    other = copy_of(finished, tmp_path, "other.h5")
    k0 = keys_of(out)[0]
    with h5py.File(out, "r+") as fh:
        fh["jobs"]["eeeeeeeeeeeeeeee"] = h5py.ExternalLink(other, f"/jobs/{k0}")
    code, o, e = cli(["status", out], capsys, caplog)
    assert code == 0 and "16 done, 0 failed, 0 pending" in o and "1 foreign" in o
    code, o, _ = cli(["verify", out], capsys, caplog)
    assert code == 1 and "foreign eeeeeeeeeeeeeeee" in o and "external link" in o
    code, o, _ = cli(["merge", out, "-o", tmp_path / "m.h5"], capsys, caplog)
    assert code == 0 and "16 jobs" in o and "1 foreign left out" in o
    code, o, _ = cli(["salvage", out, "-o", tmp_path / "s.h5"], capsys, caplog)
    assert code == 0 and "1 foreign" in o
    for f in ("m.h5", "s.h5"):
        assert "eeeeeeeeeeeeeeee" not in keys_of(tmp_path / f)
        assert cli(["verify", tmp_path / f], capsys, caplog)[0] == 0
    # a link standing in for one of the grid's own jobs: not counted, recomputed by a resume
    with h5py.File(out, "r+") as fh:
        del fh["jobs"][k0]
        fh["jobs"][k0] = h5py.ExternalLink(other, f"/jobs/{k0}")
    code, o, e = cli(["status", out], capsys, caplog)
    assert "15 done, 0 failed, 1 pending" in o
    code, o, e = cli([tmp_path / "grid.yaml", "--no-progress"], capsys, caplog)
    assert code == 0, e
    with h5py.File(out, "r") as fh:
        assert fh["jobs"].get(k0, getlink=True).__class__ is h5py.HardLink


# ------------------------------------------------------------------ 4: external raw storage
def _external_f_tilde(group, name="F_tilde"):
    n = len(group[name])
    del group[name]
    group.create_dataset(name, shape=(n,), dtype="f8", external=[("/etc/passwd", 0, 8 * n)])


@pytest.fixture(scope="module")
def result_file(tmp_path_factory):
    """A small fibril-run result file."""
    from fibril_hpc.api import simulate
    from fibril_hpc.inputs.scene import Scene
    from fibril_hpc.io.store import write_result_file

    path = str(tmp_path_factory.mktemp("result") / "run.h5")
    write_result_file(path, simulate(Scene(n_side=2, elements_per_diameter=5, F_P=(1.0,))))
    return path


def test_4_external_raw_storage_is_refused(finished, tmp_path, capsys, caplog, result_file):
    out = copy_of(finished, tmp_path)
    k = keys_of(out)[0]
    with h5py.File(out, "r+") as fh:
        del fh["jobs"][k].attrs["checksum"]
        _external_f_tilde(fh["jobs"][k]["unloading"])
    c = load_campaign(out, include_unchecked=True)
    assert k not in {j["key"] for j in c.jobs} and "external file" in c.foreign[k]
    code, o, _ = cli(["verify", out], capsys, caplog)
    assert code == 1 and f"foreign {k}" in o
    from fibril_hpc.io.store import read_result_file

    bad = str(tmp_path / "run.h5")
    shutil.copy(result_file, bad)
    read_result_file(bad)
    with h5py.File(bad, "r+") as fh:
        _external_f_tilde(fh["preloads"]["0"]["unloading"])
    with pytest.raises(StoreError, match="external file"):
        read_result_file(bad)


# ------------------------------------------------------------------ 5: merge
def _set_root(path, **attrs):
    with h5py.File(path, "r+") as fh:
        for k, v in attrs.items():
            fh.attrs[k] = v


def test_5_merge_refuses_other_scenes_versions_and_conflicts(finished, tmp_path, capsys, caplog):
    a = copy_of(finished, tmp_path, "a.h5")
    grid3 = write_grid(tmp_path, name="grid3.yaml", output="n3.h5", k_tilde=1, sigma_tilde=0.3,
                       F_P=1.0, seeds=1,
                       scene={"n_side": 3, "elements_per_diameter": 5,
                              "solver": {"fft_threads": 1, "max_wall_s": 120}})
    assert run_serial(load_spec(grid3), progress=False) == 0
    code, _, e = cli(["merge", a, tmp_path / "n3.h5", "-o", tmp_path / "m.h5"], capsys, caplog)
    assert code == 1 and "different scenes (n_side differ)" in one_line(e)
    assert not os.path.exists(tmp_path / "m.h5")
    v2 = copy_of(finished, tmp_path, "v2.h5")
    _set_root(v2, format_version=2)
    code, _, e = cli(["merge", a, v2, "-o", tmp_path / "m.h5"], capsys, caplog)
    assert code == 2 and "(format_version) 2 is not one" in one_line(e)   # every reader
    b = copy_of(finished, tmp_path, "b.h5")
    k = keys_of(b)[0]
    rec = next(j for j in load_campaign(b).jobs if j["key"] == k)
    fa = rec["F_A"]
    with h5py.File(b, "r+") as fh:           # another cluster's (valid, signed) record
        other = dict(rec, F_A=42.0, record_id="elsewhere")
        other.pop("checksum")                 # computed there: signed by its own writer
        write_record(fh["jobs"], other)
    same = copy_of(finished, tmp_path, "same.h5")
    code, o, e = cli(["merge", a, same, "-o", tmp_path / "ok.h5"], capsys, caplog)
    assert code == 0 and "16 jobs" in o, e                      # equal numbers: no conflict
    code, _, e = cli(["merge", a, b, "-o", tmp_path / "m.h5"], capsys, caplog)
    line = one_line(e)
    assert code == 1 and k in line and "a.h5" in line and "b.h5" in line and "42.0" in line
    code, o, e = cli(["merge", a, b, "-o", tmp_path / "first.h5", "--on-conflict", "first"],
                     capsys, caplog)
    assert code == 0 and "1 conflict(s) resolved" in o, e
    code, o, e = cli(["merge", a, b, "-o", tmp_path / "pref.h5", "--prefer", b], capsys, caplog)
    assert code == 0, e
    got = {j["key"]: j["F_A"] for j in load_campaign(str(tmp_path / "first.h5")).jobs}
    assert got[k] == fa
    got = {j["key"]: j["F_A"] for j in load_campaign(str(tmp_path / "pref.h5")).jobs}
    assert got[k] == 42.0


# ------------------------------------------------------------------ 6: hostile campaign files
def test_6_hostile_campaign_files_are_one_line_or_named(finished, tmp_path, capsys, caplog):
    out = copy_of(finished, tmp_path)
    k0, k1 = keys_of(out)[:2]
    rec = next(j for j in load_campaign(out).jobs if j["key"] == k0)
    with h5py.File(out, "r+") as fh:
        jobs = fh["jobs"]
        bad = dict(rec, F_A="0.8")
        bad.pop("checksum")
        write_record(jobs, bad)                          # a text where a number is due, signed
        jobs["loop"] = h5py.SoftLink("/jobs")            # a soft-link loop
        g = jobs.create_group("0123456789abcdef")        # a group without k_tilde
        g.attrs["key"] = "0123456789abcdef"
        ds = jobs[k1]["loading"]["F_tilde"]              # a 2-D curve
        data = ds[()]
        del jobs[k1]["loading"]["F_tilde"]
        jobs[k1]["loading"].create_dataset("F_tilde", data=data[:, None])
    c = load_campaign(out)
    assert set(c.corrupt) == {k0, k1, "0123456789abcdef"}, c.corrupt
    assert len(c) == 14
    assert "F_A is a str" in c.corrupt[k0] and "loop" in c.foreign
    code, o, e = cli(["status", out], capsys, caplog)
    assert code == 0 and "14 done, 0 failed, 2 pending" in o and "1 foreign" in o
    code, o, _ = cli(["verify", out], capsys, caplog)
    assert code == 1 and f"corrupt {k0}" in o and "foreign loop: " in o and "soft link" in o
    code, o, e = cli(["merge", out, "-o", tmp_path / "m.h5"], capsys, caplog)
    assert code == 0 and "14 jobs" in o, e
    code, o, e = cli([tmp_path / "grid.yaml", "--no-progress"], capsys, caplog)    # resume
    assert code == 0, e
    assert len(load_campaign(out)) == 16


def _crafted(result_file, tmp_path, name, change):
    path = str(tmp_path / f"{name}.h5")
    shutil.copy(result_file, path)
    with h5py.File(path, "r+") as fh:
        change(fh)
    return path


def _huge(fh):
    del fh["pillars"]["xi"]
    fh["pillars"].create_dataset("xi", shape=(2_000_000_000,), dtype="f8", chunks=(1024,))


def _deep_json(fh):
    fh.attrs["stats"] = "[" * 200_000


def _loop(fh):
    fh["preloads"]["1"] = h5py.SoftLink("/preloads")


def _text_curve(fh):
    g = fh["preloads"]["0"]["loading"]
    n = len(g["F_tilde"])
    del g["F_tilde"]
    g.create_dataset("F_tilde", data=np.array(["x"] * n, dtype="S1"))


def _no_status(fh):
    del fh.attrs["status"]


def _array_attr(fh):
    fh["preloads"]["0"].attrs["F_A"] = np.zeros(3)


def _bad_yaml(fh):
    fh.attrs["scene_yaml"] = "n_side: [1, 2"


def _external_group(fh):
    del fh["pillars"]
    fh["pillars"] = h5py.ExternalLink("/etc/passwd", "/")


@pytest.mark.parametrize("change", [_huge, _deep_json, _loop, _text_curve, _no_status,
                                    _array_attr, _bad_yaml, _external_group])
def test_6_read_result_file_of_crafted_files_is_one_store_error(result_file, tmp_path, change):
    from fibril_hpc.io.store import read_result_file

    path = _crafted(result_file, tmp_path, change.__name__, change)
    with pytest.raises(StoreError) as info:
        read_result_file(path)
    msg = str(info.value)
    assert "\n" not in msg and len(msg) < 500 and path in msg


# ------------------------------------------------------------------ 7: hard links
def test_7_second_writer_through_a_hard_link_is_refused(finished, tmp_path, capsys, caplog):
    out = copy_of(finished, tmp_path)
    with h5py.File(out, "r+") as fh:       # one job left, so a writer has work to do
        del fh["jobs"][keys_of(out)[0]]
    os.link(out, tmp_path / "alias.h5")
    before = _bytes(out)
    for target in (out, tmp_path / "alias.h5"):
        code, _, e = cli([tmp_path / "grid.yaml", "--no-progress", "--output", target],
                         capsys, caplog)
        assert code == 2 and "2 hard links" in one_line(e)
    assert _bytes(out) == before
    os.unlink(tmp_path / "alias.h5")
    code, _, e = cli([tmp_path / "grid.yaml", "--no-progress"], capsys, caplog)
    assert code == 0, e


# ------------------------------------------------------------------ 9: memory guards
def _fake_cgroups(root, v1_limit=None, v2_limit=None):
    proc = root / "proc"
    (proc / "self").mkdir(parents=True)
    (proc / "meminfo").write_text("MemTotal: 100000000 kB\nMemAvailable: 50000000 kB\n")
    (proc / "self" / "status").write_text("VmSize: 1000 kB\n")
    lines = []
    sys_fs = root / "sys"
    if v1_limit is not None:
        lines.append("4:memory:/job/step")
        d = sys_fs / "memory" / "job" / "step"
        d.mkdir(parents=True)
        (d / "memory.limit_in_bytes").write_text(str(v1_limit))
        (d / "memory.usage_in_bytes").write_text(str(1 << 20))
        (sys_fs / "memory" / "memory.limit_in_bytes").write_text("9223372036854771712")
    if v2_limit is not None:
        lines.append("0::/slurm/job7")
        (sys_fs / "slurm" / "job7").mkdir(parents=True)
        (sys_fs / "cgroup.controllers").write_text("memory\n")
        (sys_fs / "memory.max").write_text("max\n")
        (sys_fs / "slurm" / "memory.max").write_text(str(v2_limit))        # the parent's
        (sys_fs / "slurm" / "job7" / "memory.max").write_text("max\n")
        (sys_fs / "slurm" / "job7" / "memory.current").write_text(str(1 << 20))
    (proc / "self" / "cgroup").write_text("\n".join(lines) + "\n")
    return str(proc), str(sys_fs)


def test_9_memory_guards_read_the_process_own_cgroup(tmp_path):
    from fibril_hpc.inputs.limits import available_memory

    proc, sys_fs = _fake_cgroups(tmp_path / "v1", v1_limit=3 << 30)
    assert available_memory(proc, sys_fs) == (3 << 30) - (1 << 20)
    proc, sys_fs = _fake_cgroups(tmp_path / "v2", v2_limit=2 << 30)
    assert available_memory(proc, sys_fs) == 2 << 30        # the parent's limit applies
    proc, sys_fs = _fake_cgroups(tmp_path / "none")
    assert available_memory(proc, sys_fs) == 50000000 * 1024


BIG = {"n_side": 200, "elements_per_diameter": 18, "solver": {"fft_threads": 1}}


def _limited(limit_bytes):
    def pre():
        resource.setrlimit(resource.RLIMIT_AS, (limit_bytes, limit_bytes))
    return pre


@pytest.mark.slow
def test_9_memory_guards_under_rlimit_as(tmp_path):
    grid = write_grid(tmp_path, output="big.h5", k_tilde=1, sigma_tilde=0.3, F_P=1.0, seeds=1,
                      scene=BIG)
    r = run([grid, "--dry-run"], preexec_fn=_limited(6_000_000 * 1024), timeout=120)
    assert r.returncode == 2 and "of memory available" in one_line(r.stderr)
    # the dry-run itself allocates nothing large (it timed a 2 GiB operator before)
    r = run([grid, "--dry-run", "--ignore-memory-check"], preexec_fn=_limited(6_000_000 * 1024),
            timeout=120)
    assert r.returncode == 0 and "FFT 16384^2" in r.stdout, r.stderr
    # running anyway meets a MemoryError: one line, exit 2 (a grid of 11 700^2, FFT 24 576^2: the
    # build alone passes the 6 GB limit; 200 x 200 at 18 now builds within it and fails later,
    # after a progress line, since the kernel transform is built in blocks)
    scene = tmp_path / "big_scene.yaml"
    scene.write_text("n_side: 300\nelements_per_diameter: 18\nsolver: {fft_threads: 1}\n")
    exe = shutil.which("fibril-run", path=os.path.dirname(sys.executable))
    r = subprocess.run([exe, str(scene), "--ignore-memory-check"], capture_output=True,
                       text=True, timeout=120, env=env(), preexec_fn=_limited(6_000_000 * 1024))
    assert r.returncode == 2 and "out of memory" in one_line(r.stderr)


def test_9_memory_error_anywhere_is_one_line(monkeypatch, tmp_path, capsys, caplog):
    import fibril_hpc.campaign.analysis.status as status

    def boom(path):
        raise MemoryError()

    monkeypatch.setattr(status, "file_status", boom)
    shutil.copy(os.path.join(os.path.dirname(__file__), "data", "campaign_v1.h5"), tmp_path)
    code, _, e = cli(["status", tmp_path / "campaign_v1.h5"], capsys, caplog)
    assert code == 2 and "out of memory" in one_line(e)


# ------------------------------------------------------------------ 10: hostile inputs
def test_10_yaml_alias_bomb_is_refused_in_one_short_line(tmp_path):
    lines = ['a0: &a0 ["lol","lol","lol","lol","lol","lol","lol","lol","lol"]']
    lines += [f"a{i}: &a{i} [" + ",".join([f"*a{i - 1}"] * 9) + "]" for i in range(1, 10)]
    grid = tmp_path / "bomb.yaml"
    grid.write_text("output: bomb.h5\nscene: {n_side: 2}\nk_tilde: 1\nsigma_tilde: 0.3\nF_P: 1\n"
                    "description:\n  " + "\n  ".join(lines) + "\n")
    r = run([str(grid), "--dry-run"], timeout=60)
    line = one_line(r.stderr)
    assert r.returncode == 2 and "alias" in line and len(line) <= 500


def test_10_error_lines_are_capped(capsys):
    from fibril_hpc.cli.common import error

    assert error("prog", "x" * 10_000) == 2
    err = capsys.readouterr().err
    assert len(err.strip()) <= 500 and err.count("\n") == 1


def test_10_empty_scene_and_infinite_d_tilde_are_refused(tmp_path, capsys):
    from fibril_hpc.cli.run import main

    (tmp_path / "empty.yaml").write_text("")
    (tmp_path / "inf.yaml").write_text("d_tilde: .inf\nn_side: 2\n")
    for name, want in (("empty.yaml", "this file is empty"), ("inf.yaml", "d_tilde")):
        capsys.readouterr()
        assert main([str(tmp_path / name)]) == 2
        assert want in one_line(capsys.readouterr().err)


def test_10_grid_with_infinite_d_tilde_is_refused_at_parse_time(tmp_path):
    grid = tmp_path / "g.yaml"
    grid.write_text("output: g.h5\nscene: {n_side: 2, elements_per_diameter: 5}\nk_tilde: 1\n"
                    "sigma_tilde: 0.3\nd_tilde: [0.5, .inf]\n")
    r = run([str(grid), "--dry-run"], timeout=60)
    assert r.returncode == 2 and "d_tilde" in one_line(r.stderr)


# ------------------------------------------------------------------ 11: rerun of a finished one
def test_11_rerunning_a_finished_campaign_leaves_the_file_untouched(finished, tmp_path, capsys,
                                                                     caplog):
    out = copy_of(finished, tmp_path)
    before = _bytes(out)
    st = os.stat(out)
    code, _, e = cli([tmp_path / "grid.yaml", "--no-progress"], capsys, caplog)
    assert code == 0 and "already finished" in e
    assert _bytes(out) == before and os.stat(out).st_ino == st.st_ino
