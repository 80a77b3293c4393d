"""Progress displays: a bar on a terminal, plain lines elsewhere, a total that grows with
``F_P: auto`` rounds, and a simulation whose result does not depend on being watched."""

import io
import os
import shutil
import subprocess
import sys

import pytest

from fibril_hpc import Scene, simulate
from fibril_hpc.campaign.run.progress import Progress
from fibril_hpc.io.progress import RunProgress


class FakeTerminal(io.StringIO):
    def isatty(self):
        return True


def test_simulate_reports_every_point_and_its_result_does_not_depend_on_it():
    scene = Scene(n_side=3, elements_per_diameter=5, sigma_tilde=0.5, F_P=(1.0, 2.0))
    seen = []
    watched = simulate(scene, progress=seen.append)
    plain = simulate(scene)
    assert watched.main.F_A == plain.main.F_A and watched.main.F_P == plain.main.F_P
    assert [r.F_A for r in watched.results] == [r.F_A for r in plain.results]
    events = [s["events"] for s in seen]
    assert events == sorted(events) and events[-1] == plain.stats["events"]
    phases = [(s["phase"], s["preload"]) for s in seen]
    assert phases[0] == ("loading", None)
    assert ("unloading", 0) in phases and ("unloading", 1) in phases
    n_points = len(plain.results[0].loading) + sum(len(r.unloading) for r in plain.results)
    assert len(seen) >= n_points - 2           # every recorded point (snapshots are extra)
    # the pillars in contact: the curves' own count at each point, none when a pull-off ends
    assert {s["n_pillars"] for s in seen} == {9}
    assert seen[-1]["pillars_in_contact"] == 0 == plain.results[-1].unloading.n_pillars_in_contact[-1]
    most = max(s["pillars_in_contact"] for s in seen)
    assert most == max(r.n_pillars_in_contact_max for r in plain.results) > 0


def test_run_progress_bar_on_a_terminal_lines_elsewhere():
    term = FakeTerminal()
    p = RunProgress(2, stream=term)
    p({"phase": "unloading", "preload": 1, "d_tilde": -1.5, "F_tilde": -0.25, "events": 42})
    p.close()
    assert "42 events" in term.getvalue() and "pull-off 2/2" in term.getvalue()
    log = io.StringIO()
    p = RunProgress(2, stream=log, every_s=0.0)
    p({"phase": "loading", "preload": None, "d_tilde": 3.0, "F_tilde": 1.0, "events": 7})
    p.close()
    line = log.getvalue()
    assert line.startswith("fibril-run: 7 events, loading, d~ 3, F~ 1, elapsed ")
    assert "\r" not in line and line.endswith("\n")
    log = io.StringIO()
    p = RunProgress(1, stream=log, every_s=0.0)
    p({"phase": "unloading", "preload": 0, "d_tilde": -1.0, "F_tilde": -0.5, "events": 9,
       "pillars_in_contact": 1234, "n_pillars": 99856})
    p.close()
    assert "pull-off 1/1, d~ -1, F~ -0.5, 1234 of 99856 pillars in contact, elapsed" in log.getvalue()
    quiet = io.StringIO()                        # a short run prints no line at all
    p = RunProgress(1, stream=quiet, every_s=10.0)
    p({"phase": "loading", "preload": None, "d_tilde": 0.0, "F_tilde": 0.0, "events": 1})
    p.close()
    assert quiet.getvalue() == ""
    off = FakeTerminal()
    p = RunProgress(1, stream=off, enabled=False)
    p({"phase": "loading", "preload": None, "d_tilde": 0.0, "F_tilde": 0.0, "events": 1})
    p.close()
    assert off.getvalue() == ""


def test_campaign_bar_total_grows_with_auto_rounds():
    term = FakeTerminal()
    p = Progress(10, 1, stream=term, done_before=2, growing=True)
    assert p.tty and p.bar.bar.total == 10 and p.bar.bar.n == 2
    p.update([{"status": "done"}] * 3, running=1, force=True)
    p.total += 8                                  # a new round of F_P: auto
    p.update([{"status": "failed"}], force=True)
    assert p.bar.bar.total == 18 and p.bar.bar.n == 6
    p.finish()
    out = term.getvalue()
    assert "6/18" in out and "auto round" in out      # the rest cut at the terminal's width
    assert "1 failed" in out
    log = io.StringIO()
    p = Progress(10, 1, stream=log, every_s=0.0, growing=True)
    p.update([{"status": "done"}], force=True)
    assert " ETA >= " in log.getvalue() and "the ETA is a lower bound" in log.getvalue()
    fixed = Progress(10, 1, stream=io.StringIO(), every_s=0.0)
    fixed.update([{"status": "done"}])
    assert " ETA >= " not in fixed.line() and "lower bound" not in fixed.line()


def test_campaign_lines_when_not_a_terminal():
    log = io.StringIO()
    p = Progress(4, 1, stream=log, every_s=0.0)
    p.update([{"status": "done"}], force=True)
    p.finish()
    assert log.getvalue().startswith("fibril-campaign: 1/4 jobs (1 done, 0 failed, 0 running; ")
    assert "\r" not in log.getvalue()


def test_campaign_line_counts_the_jobs_running(tmp_path, capsys):
    """"N running" is the jobs being computed: a serial run's line, printed as a task of two
    preloads starts, says 2 running; the line that closes the run says 0."""
    from campaign_helpers import write_grid

    from fibril_hpc.cli.campaign import main

    grid = write_grid(tmp_path, k_tilde=[1], sigma_tilde=[0.3], seeds=1)    # 1 task, 2 jobs
    assert main([grid]) == 0
    lines = [x for x in capsys.readouterr().err.splitlines() if " jobs (" in x]
    assert lines[0].startswith("fibril-campaign: 0/2 jobs (0 done, 0 failed, 2 running; "), lines
    assert lines[-1].startswith("fibril-campaign: 2/2 jobs (2 done, 0 failed, 0 running; "), lines
    p = Progress(4, 2, stream=io.StringIO(), every_s=0.0)
    p.set_running(3)
    p.update([{"status": "done"}])                # the count of running jobs is kept
    assert "1 done, 0 failed, 3 running" in p.line()


@pytest.mark.skipif(shutil.which("script") is None, reason="script(1) not installed")
def test_fibril_run_draws_a_bar_on_a_pseudo_terminal(tmp_path):
    exe = os.path.join(os.path.dirname(sys.executable), "fibril-run")
    r = subprocess.run(["script", "-qec", f"{exe} --builtin quick", os.devnull],
                       capture_output=True, text=True, timeout=300, cwd=tmp_path)
    assert r.returncode == 0, r.stdout + r.stderr
    assert "fibril-run: 0 events [" in r.stdout and " events/s, " in r.stdout   # the bar
    assert "status ok" in r.stdout
