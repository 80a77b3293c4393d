"""Mutation testing of the statistics and the search (issue 34): mutmut over a module list, each
module against a list of fast, targeted test files, and the score table.

    python benchmarks/mutation.py                       # the issue-34 scope (SCOPE below)
    python benchmarks/mutation.py --only precision      # the SCOPE entries whose module path
                                                        # holds this text (laws/verdict: that
                                                        # module; verdict: also verdict_text)
    python benchmarks/mutation.py --modules fibril_hpc/campaign/laws/size.py \
        --tests tests/test_campaign_size.py              # any module list against any test list
    python benchmarks/mutation.py --table               # the table of the last run, no rerun
    python benchmarks/mutation.py --rerun               # the last run's survivors against the
                                                        # checkout's tests now (same source)

Each run copies the checkout's files (tracked and untracked-but-not-ignored: fibril_hpc/,
tests/, pyproject.toml) to ``.mutation/<name>/`` (ignored by git), writes the ``[tool.mutmut]``
section of that copy's pyproject.toml (``only_mutate`` the modules, the test files as
``pytest_add_cli_args_test_selection``, ``-m "not slow"``, a timeout of 4 x the tests' time
plus 20 s of CPU), and runs ``mutmut run
--max-children 1`` there under ``nice -n 15`` (one worker: the machine is shared). mutmut
records which tests reach which function and runs, for each mutant, only those. The table
counts per module: killed, survived, timeout, no tests (no selected test reaches the function),
other (suspicious, segfault, not checked), and the score (killed + timeout) / total; survivors
named in ``benchmarks/mutation_equivalent.txt`` (one ``name  reason`` a line) are counted as
equivalent and the score without them is shown too. With ``--diffs`` the survivors are written
with their diffs to ``.mutation/<name>/survivors-<module>.txt``. Nothing of it is committed:
the dated scores go to benchmarks/NOTES.md ("Mutation testing (issue 34)").
"""

from __future__ import annotations

import argparse
import json
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
WORK = ROOT / ".mutation"
EQUIVALENT = ROOT / "benchmarks" / "mutation_equivalent.txt"

#: module -> the fast test files that guard it (seconds per mutant, not minutes)
SCOPE = {
    "fibril_hpc/campaign/plan/search.py": ["tests/test_mutants_search.py"],
    "fibril_hpc/campaign/laws/precision.py": ["tests/test_mutants_precision.py"],
    "fibril_hpc/campaign/laws/reading.py": ["tests/test_mutants_reading.py"],
    "fibril_hpc/campaign/laws/alphabeta.py": ["tests/test_mutants_alphabeta.py",
                                              "tests/test_report_verdict.py"],
    "fibril_hpc/campaign/laws/verdict.py": ["tests/test_mutants_verdict.py",
                                            "tests/test_report_verdict.py"],
    "fibril_hpc/campaign/laws/size_loss.py": ["tests/test_mutants_size_loss.py"],
    # split out of size_loss.py (the pillar variables and the drift with N): its tests as before
    "fibril_hpc/campaign/laws/size_drift.py": ["tests/test_mutants_size_loss.py"],
    "fibril_hpc/campaign/analysis/verdict_text.py": ["tests/test_mutants_verdict_text.py"],
    "fibril_hpc/campaign/analysis/zero_cell.py": ["tests/test_mutants_verdict_text.py"],
    "fibril_hpc/campaign/analysis/loss_page.py": ["tests/test_mutants_verdict_text.py"],
    "fibril_hpc/campaign/analysis/size_loss_page.py": ["tests/test_mutants_size_loss_page.py"],
    "fibril_hpc/campaign/analysis/headline.py": ["tests/test_mutants_headline.py"],
    "fibril_hpc/campaign/laws/loss.py": ["tests/test_mutants_loss.py",
                                         "tests/test_report_loss.py"],
    "fibril_hpc/campaign/laws/intervals.py": ["tests/test_mutants_intervals.py"],
    "fibril_hpc/campaign/laws/study.py": ["tests/test_mutants_study.py", "tests/test_report_loss.py",
                                          "tests/test_report_laws.py",
                                          "tests/test_report_verdict.py"],
}

#: mutmut's exit-code meaning (mutmut.stats.status_by_exit_code), grouped for the table
KILLED, SURVIVED, TIMEOUT, NO_TESTS = "killed", "survived", "timeout", "no tests"


def _files() -> list[str]:
    out = subprocess.run(["git", "ls-files", "-co", "--exclude-standard", "fibril_hpc", "tests",
                          "pyproject.toml"], cwd=ROOT, check=True, capture_output=True,
                         text=True).stdout.split("\n")
    return [f for f in out if f and (ROOT / f).is_file()]


def _toml_list(xs) -> str:
    return "[" + ", ".join(json.dumps(str(x)) for x in xs) + "]"


def prepare(work: Path, modules, tests) -> None:
    """A fresh copy of the checkout in ``work`` with the mutmut settings of this run."""
    if work.exists():
        shutil.rmtree(work)
    for f in _files():
        dst = work / f
        dst.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(ROOT / f, dst)
    write_config(work, modules, tests)


def write_config(work: Path, modules, tests) -> None:
    """The ``[tool.mutmut]`` section of the copy's pyproject.toml for this run."""
    py = work / "pyproject.toml"
    text = re.sub(r"(?ms)^\[tool\.mutmut\].*?(?=^\[|\Z)", "", py.read_text())
    text += ("\n[tool.mutmut]\n"
             'source_paths = ["fibril_hpc"]\n'
             f"only_mutate = {_toml_list(modules)}\n"
             f"pytest_add_cli_args_test_selection = {_toml_list(tests)}\n"
             'pytest_add_cli_args = ["-m", "not slow", "-p", "no:cacheprovider"]\n'
             "use_git_change_detection = false\n"
             # a mutant that loops forever (i += 1 -> i = 1) is a timeout after (its tests'
             # time + 5 s of pytest's own start) x 2 x 2 CPU seconds, not mutmut's x 15 x 2
             "timeout_multiplier = 2.0\n"
             "timeout_constant = 5.0\n")
    py.write_text(text)


def refresh_tests(work: Path, modules, tests) -> None:
    """Copy the checkout's tests into ``work`` for a rerun; refuse if a module changed since
    the run (its mutants and their names would differ: run it afresh)."""
    for m in modules:
        if (ROOT / m).read_bytes() != (work / m).read_bytes():
            raise SystemExit(f"{m} changed since the run in {work}: run it again without --rerun")
    for f in _files():
        if f.startswith("tests/"):
            shutil.copy2(ROOT / f, work / f)
    write_config(work, modules, tests)


def run_mutmut(work: Path, names=()) -> int:
    """``mutmut run [names]`` in ``work``: one worker, low priority, the copy's code on the
    path; ``names``: only these mutants (a rerun), else every one without a result."""
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    env.update(NUMBA_CACHE_DIR=str(work / ".numba_cache"), OMP_NUM_THREADS="1",
               OPENBLAS_NUM_THREADS="1", MKL_NUM_THREADS="1", NUMBA_NUM_THREADS="1")
    mutmut = Path(sys.executable).with_name("mutmut")
    cmd = ["nice", "-n", "15", str(mutmut), "run", "--max-children", "1", *names]
    return subprocess.run(cmd, cwd=work, env=env).returncode


def equivalents() -> dict:
    """{mutant name: why it is equivalent} from benchmarks/mutation_equivalent.txt."""
    out = {}
    if EQUIVALENT.exists():
        for line in EQUIVALENT.read_text().splitlines():
            line = line.strip()
            if line and not line.startswith("#"):
                name, _, why = line.partition(" ")
                out[name] = why.strip()
    return out


def statuses(work: Path, module: str) -> dict:
    """{mutant name: status} of one module from mutmut's record in ``work``."""
    from mutmut.stats import status_by_exit_code

    meta = work / "mutants" / (module + ".meta")
    if not meta.exists():
        return {}
    codes = json.loads(meta.read_text())["exit_code_by_key"]
    return {k: status_by_exit_code[v] for k, v in codes.items()}


def table(rows, equiv) -> str:
    """The score table: one row per module (rows: [(module, {name: status})])."""
    head = (f"{'module':40s} {'total':>5s} {'killed':>6s} {'surv.':>5s} {'t/o':>4s} "
            f"{'no t.':>5s} {'other':>5s} {'score':>6s} {'equiv.':>6s} {'score-eq':>8s}")
    lines = [head, "-" * len(head)]
    for module, st in rows:
        n = len(st)
        c = {k: sum(v == k for v in st.values()) for k in (KILLED, SURVIVED, TIMEOUT, NO_TESTS)}
        other = n - sum(c.values())
        eq = sum(1 for k, v in st.items() if v == SURVIVED and k in equiv)
        good = c[KILLED] + c[TIMEOUT]
        score = 100 * good / n if n else float("nan")
        score_eq = 100 * good / (n - eq) if n - eq else float("nan")
        lines.append(f"{module:40s} {n:5d} {c[KILLED]:6d} {c[SURVIVED]:5d} {c[TIMEOUT]:4d} "
                     f"{c[NO_TESTS]:5d} {other:5d} {score:5.1f}% {eq:6d} {score_eq:7.1f}%")
    return "\n".join(lines)


def survivors(work: Path, st: dict, equiv) -> str:
    """The diffs of the mutants not killed (``mutmut show``), marked where listed equivalent."""
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    mutmut = Path(sys.executable).with_name("mutmut")
    out = []
    for name, status in sorted(st.items()):
        if status in (KILLED, TIMEOUT):
            continue
        diff = subprocess.run([str(mutmut), "show", name], cwd=work, env=env,
                              capture_output=True, text=True).stdout
        mark = f"  [equivalent: {equiv[name]}]" if name in equiv else ""
        out.append(f"## {name}: {status}{mark}\n{diff}")
    return "\n".join(out)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--modules", nargs="+", help="module files to mutate (one mutmut run)")
    ap.add_argument("--tests", nargs="+", help="test files or node ids to run against them")
    ap.add_argument("--only", help="run the SCOPE entries whose module path contains this")
    ap.add_argument("--table", action="store_true", help="print the last runs' table, no run")
    ap.add_argument("--diffs", action="store_true", help="write the survivors' diffs to "
                    ".mutation/<name>/survivors-<module>.txt (mutmut show: seconds each)")
    ap.add_argument("--rerun", action="store_true", help="rerun the last runs' survivors (not "
                    "listed equivalent) and timeouts against the checkout's tests")
    args = ap.parse_args(argv)
    if bool(args.modules) != bool(args.tests):
        ap.error("--modules and --tests go together")
    if args.modules:
        plan = {"custom": (args.modules, args.tests)}
    else:
        plan = {Path(m).stem: ([m], t) for m, t in SCOPE.items() if args.only is None
                or args.only in m}
    equiv = equivalents()
    rows = []
    for name, (modules, tests) in plan.items():
        work = WORK / name
        if args.rerun:
            refresh_tests(work, modules, tests)
            left = sorted(k for m in modules for k, v in statuses(work, m).items()
                          if v != KILLED and k not in equiv)     # timeouts too: is it a loop?
            rc = run_mutmut(work, left) if left else 0
            if rc not in (0,):
                print(f"mutmut run in {work} exited {rc}", file=sys.stderr)
        elif not args.table:
            prepare(work, modules, tests)
            rc = run_mutmut(work)
            if rc not in (0,):
                print(f"mutmut run in {work} exited {rc}", file=sys.stderr)
        for m in modules:
            st = statuses(work, m)
            rows.append((m, st))
            if args.diffs and st:
                (work / f"survivors-{Path(m).stem}.txt").write_text(survivors(work, st, equiv))
    print(table(rows, equiv))
    for m, st in rows:
        left = sorted(k for k, v in st.items() if v not in (KILLED, TIMEOUT) and k not in equiv)
        if left:
            print(f"\n{m}: not killed, not listed equivalent:")
            print("\n".join(f"  {k}: {st[k]}" for k in left))
    return 0


if __name__ == "__main__":
    sys.exit(main())
