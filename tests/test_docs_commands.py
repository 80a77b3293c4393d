"""Every command of README.md and docs/ runs as written (issue 36, item 7).

The fenced ``bash`` blocks of each page run in order, line by line as a user pastes them, in a
fresh folder holding a copy of ``campaigns/`` and the files the page's own ``yaml`` blocks name
(a block whose first line is ``# NAME.yaml``), with this tree's console scripts first on PATH.
What cannot run here is in :data:`SKIP`, with the reason and, where one is meaningful, the
cheap command run instead (a ``--dry-run``); the fast test checks that every entry still
matches the pages exactly as often as it says, so the list cannot go stale. ``mpirun`` lines run
under mpirun where there is one, else serially (the same campaign, as the pages say).
The runs cost about 5 CPU minutes (the demo campaign, two small grids, five 18 x 18 scenes,
three reports), hence ``slow``; the demo campaign's file is computed once and reused.
"""

import glob
import os
import re
import shutil
import subprocess

import pytest

from console_scripts import ROOT, script_env, write_scripts

PAGES = ["README.md"] + sorted(os.path.relpath(p, ROOT)
                               for p in glob.glob(os.path.join(ROOT, "docs", "*.md")))

#: regex on one command (a line's part between ``&&``, its comment cut) -> (times it occurs in
#: the pages, why it is not run here, the command run instead or None)
SKIP = {
    r"^python3 -m venv \.venv$": (2, "the test runs in an environment with every extra", None),
    r"^\. \.venv/bin/activate$": (2, "the test runs in an environment with every extra", None),
    r"^pip install ": (6, "network and minutes; the environment has every extra", None),
    r"^pytest ": (2, "the test suite itself", None),
    r"^sbatch ": (4, "needs a Slurm cluster (tests/test_slurm.py runs the scripts on one)", None),
    r"^fibril-campaign merge \S+\.shard-\*-of-10\.h5 ": (2, "joins the Slurm array's shards", None),
    r"^fibril-campaign status campaigns/paper\.h5$": (1, "the Slurm run's file", None),
    r"^mpirun -n 3 fibril-campaign campaigns/critical_roughness\.yaml$":
        (1, "about 40 minutes on two cores",
         "fibril-campaign campaigns/critical_roughness.yaml --dry-run"),
    r"campaigns/critical_roughness\.h5": (3, "reads that 40-minute campaign's file", None),
    r"^fibril-accuracy --out benchmarks/accuracy ":
        (2, "8 and 20 CPU minutes; the --quick line runs the same code", None),
}

FILE_BLOCK = re.compile(r"^```yaml\n# ([\w.-]+\.yaml)\b.*?\n(.*?)^```", re.M | re.S)
BASH_BLOCK = re.compile(r"^```bash\n(.*?)^```", re.M | re.S)


def _commands(page: str) -> list:
    """The command lines of ``page``'s bash blocks: (line, [its commands]) in order."""
    with open(os.path.join(ROOT, page), encoding="utf-8") as fh:
        text = fh.read()
    out = []
    for block in BASH_BLOCK.findall(text):
        for line in block.splitlines():
            code = re.sub(r"\s+#\s.*$", "", line).strip()
            if code and not code.startswith("#"):
                out.append((code, [c.strip() for c in code.split(" && ")]))
    return out


def _skip(cmd: str):
    hits = [p for p in SKIP if re.search(p, cmd)]
    assert len(hits) <= 1, (cmd, hits)
    return hits[0] if hits else None


def test_the_skip_list_matches_the_pages():
    """Every entry of SKIP matches exactly as many commands as it says (a command renamed or
    removed from the pages must leave the list), and every page has something to run."""
    counts = dict.fromkeys(SKIP, 0)
    runs = 0
    for page in PAGES:
        for _, cmds in _commands(page):
            for c in cmds:
                p = _skip(c)
                if p is None:
                    runs += 1
                else:
                    counts[p] += 1
    assert counts == {p: v[0] for p, v in SKIP.items()}
    assert runs >= 25


@pytest.fixture(scope="module")
def env(tmp_path_factory):
    bin_dir = write_scripts(tmp_path_factory.mktemp("bin"))
    return script_env(bin_dir), tmp_path_factory.mktemp("cache")


def _script(page: str) -> str:
    mpirun = shutil.which("mpirun") is not None
    lines = ["set -e -o pipefail"]
    for line, cmds in _commands(page):
        run = []
        for c in cmds:
            p = _skip(c)
            if p is not None:
                c = SKIP[p][2] or "true"
            elif not mpirun:
                c = re.sub(r"^mpirun -n \d+ ", "", c)
            run.append(c)
        lines.append(f"echo {_quote('$ ' + line)} >&2")
        lines.append(" && ".join(run))
    return "\n".join(lines) + "\n"


def _quote(s: str) -> str:
    return "'" + s.replace("'", "'\\''") + "'"


@pytest.mark.slow
@pytest.mark.parametrize("page", PAGES)
def test_every_command_runs_as_written(env, tmp_path, page):
    environ, cache = env
    shutil.copytree(os.path.join(ROOT, "campaigns"), tmp_path / "campaigns", symlinks=False,
                    ignore=shutil.ignore_patterns("*.h5", "*.h5.*", ".*"))
    with open(os.path.join(ROOT, page), encoding="utf-8") as fh:
        for name, body in FILE_BLOCK.findall(fh.read()):
            (tmp_path / name).write_text(body)
    demo = cache / "demo.h5"
    if demo.exists():                  # computed by an earlier page: a resume finds it done
        shutil.copy(demo, tmp_path / "campaigns" / "demo.h5")
    script = _script(page)
    r = subprocess.run(["bash", "-c", script], cwd=tmp_path, env=environ, capture_output=True,
                       text=True, timeout=1200)
    assert r.returncode == 0, f"{page}: {r.stderr[-3000:]}"
    assert "Traceback" not in r.stderr, r.stderr[-3000:]
    if (tmp_path / "campaigns" / "demo.h5").exists() and not demo.exists():
        shutil.copy(tmp_path / "campaigns" / "demo.h5", demo)
