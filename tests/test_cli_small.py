"""What a user hits first: --version on every command, help text on every option, no
BrokenPipe traceback when a pager or head closes the pipe."""

import argparse
import os
import subprocess
import sys

import pytest

BIN = os.path.dirname(sys.executable)


def _parsers():
    from fibril_hpc.cli import accuracy, campaign, run

    out = []
    for mod in (run, campaign, accuracy):
        seen = []

        class Capture(Exception):
            pass

        def fake_parse(self, args=None, namespace=None, _seen=seen):
            _seen.append(self)
            raise Capture()

        orig = argparse.ArgumentParser.parse_args
        argparse.ArgumentParser.parse_args = fake_parse
        try:
            try:
                mod.main(["--help"] if mod is not campaign else ["status", "x.h5"])
            except Capture:
                pass
        finally:
            argparse.ArgumentParser.parse_args = orig
        out += seen
    return out


def _walk(parser, name):
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for sub_name, sub in action.choices.items():
                yield from _walk(sub, f"{name} {sub_name}")
            continue
        yield name, action


def test_every_option_and_argument_of_every_command_has_help():
    parsers = _parsers()
    assert len(parsers) == 3
    missing = [f"{name}: {a.option_strings or a.dest}" for p in parsers
               for name, a in _walk(p, p.prog) if not a.help or a.help == argparse.SUPPRESS]
    assert missing == []


@pytest.mark.parametrize("cmd", ["fibril-run", "fibril-campaign", "fibril-accuracy"])
def test_version(cmd):
    r = subprocess.run([os.path.join(BIN, cmd), "--version"], capture_output=True, text=True,
                       timeout=120)
    assert r.returncode == 0 and r.stdout.startswith("fibril-hpc ") and "numpy=" in r.stdout


@pytest.mark.parametrize("cmd", [
    "fibril-run --builtin quick --no-progress | true",      # the reader is gone before a byte
    "fibril-campaign --help | true",
    "fibril-run --builtin quick --no-progress | head -1",
    "fibril-campaign --help | head -1",
    "fibril-run --help | head -1",
    "fibril-campaign --version | head -1",
])
def test_closed_pipe_is_quiet(cmd):
    big = cmd.replace("fibril-", os.path.join(BIN, "fibril-"), 1)
    r = subprocess.run(["bash", "-o", "pipefail", "-c", big], capture_output=True, text=True,
                       timeout=300, env={**os.environ, "PYTHONUNBUFFERED": ""})
    assert "Traceback" not in r.stderr and "BrokenPipe" not in r.stderr, r.stderr
    assert r.returncode == 0, r.stderr


def _cpu_s(pid: int) -> float:
    with open(f"/proc/{pid}/stat") as fh:
        f = fh.read().rsplit(")", 1)[1].split()
    return (int(f[11]) + int(f[12])) / os.sysconf("SC_CLK_TCK")      # utime + stime


@pytest.mark.skipif(not os.path.exists("/proc/self/stat"), reason="needs /proc (Linux)")
def test_ctrl_c_on_fibril_run_is_one_line_and_130(tmp_path):
    """Ctrl-C on fibril-run inside the simulation: one line and exit 130 (the shell's status for
    SIGINT; a campaign's is 75), no traceback, no --out file (half-written or not)."""
    import signal
    import time

    out = tmp_path / "r.h5"
    p = subprocess.Popen([os.path.join(BIN, "fibril-run"), "--builtin", "default", "--no-progress",
                          "--out", str(out)], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                         text=True, cwd=tmp_path,
                         # a test run in the background (nohup, `&`) inherits SIGINT ignored
                         preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    try:
        deadline = time.monotonic() + 120
        while _cpu_s(p.pid) < 2.0 and p.poll() is None and time.monotonic() < deadline:
            time.sleep(0.1)              # past the imports (0.6 s CPU): inside the simulation
        p.send_signal(signal.SIGINT)
        _, err = p.communicate(timeout=60)
    finally:
        if p.poll() is None:
            p.kill()
            p.communicate()
    assert p.returncode == 130, err
    assert "Traceback" not in err and err.count("\n") == 1, err
    assert err.startswith("fibril-run: interrupted (SIGINT)")
    assert os.listdir(tmp_path) == []


ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SHIPPED = {"demo": "campaigns/demo.yaml", "paper": "campaigns/paper.yaml",
           "finite_size": "campaigns/finite_size.yaml",
           "critical_roughness": "campaigns/critical_roughness.yaml",
           "critical_roughness_seeds10": "campaigns/critical_roughness_seeds10.yaml",
           "campaign.sbatch": "slurm/campaign.sbatch", "array.sbatch": "slurm/array.sbatch",
           "chain.sh": "slurm/chain.sh"}


@pytest.mark.parametrize("name", sorted(SHIPPED))
def test_example_prints_the_repository_file(name, capsysbinary):
    from fibril_hpc.cli.campaign import main

    assert main(["example", name]) == 0
    with open(os.path.join(ROOT, SHIPPED[name]), "rb") as fh:
        assert capsysbinary.readouterr().out == fh.read()


def test_example_list_unknown_and_output_file(tmp_path, capsys):
    from fibril_hpc.cli.campaign import main

    assert main(["example"]) == 0
    listed = capsys.readouterr().out
    assert all(n in listed for n in ("demo.yaml", "paper.yaml", "campaign.sbatch", "chain.sh"))
    assert main(["example", "nope"]) == 2
    assert "name" in capsys.readouterr().err
    out = tmp_path / "job.sbatch"
    assert main(["example", "campaign.sbatch", "-o", str(out)]) == 0
    assert os.access(out, os.X_OK)
    assert main(["example", "demo", "-o", str(out)]) == 2       # never over an existing file


@pytest.mark.slow
def test_the_wheel_ships_the_examples(tmp_path):
    """`pip install fibril-hpc` alone is enough: the built wheel holds every grid and script,
    byte for byte, scripts executable."""
    import zipfile

    r = subprocess.run([sys.executable, "-m", "pip", "wheel", "-q", "--no-deps", "-w",
                        str(tmp_path), ROOT], capture_output=True, text=True, timeout=600)
    if r.returncode != 0 and "No matching distribution" in r.stderr:
        pytest.skip("no package index to build the wheel with")
    assert r.returncode == 0, r.stderr
    (whl,) = tmp_path.glob("fibril_hpc-*.whl")
    with zipfile.ZipFile(whl) as z:
        for rel in SHIPPED.values():
            member = "fibril_hpc/examples/" + ("grids/" if rel.startswith("campaigns") else
                                               "slurm/") + os.path.basename(rel)
            with open(os.path.join(ROOT, rel), "rb") as fh:
                assert z.read(member) == fh.read(), member
            if rel.startswith("slurm"):
                assert (z.getinfo(member).external_attr >> 16) & 0o111, member
