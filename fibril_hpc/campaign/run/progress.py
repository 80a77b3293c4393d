"""The progress of a running campaign on stderr (a bar on a terminal, lines elsewhere) and
the lines that close a run."""

from __future__ import annotations

import time

from ...io.progress import Bar, clock


class Progress:
    """The progress of a running campaign on stderr: a tqdm bar on a terminal (jobs finished
    of the grid, rate, ETA, done/failed/running), a plain line every ``every_s`` seconds
    otherwise. ``total`` may grow (an ``F_P: auto`` round adds jobs): the bar and the ETA
    follow, and ``growing`` says that later rounds may add more, so that the ETA, which counts
    the jobs known so far, is a lower bound (``ETA >= ...``): a later round is a new loading path
    for about one more job each, 1.4 of them per path on average, so the jobs that such rounds
    add cost more than the jobs before them (``--dry-run`` prices them)."""

    def __init__(self, total_jobs: int, workers: int, stream=None, every_s: float = 10.0,
                 enabled: bool = True, done_before: int = 0, failed_before: int = 0,
                 growing: bool = False):
        self._total = total_jobs
        #: jobs of the grid finished by earlier runs (counted in the line, not in the ETA)
        self.done_before = done_before
        self.failed_before = failed_before
        self.workers = max(1, workers)
        self.growing = growing
        self.enabled = enabled
        self.t0 = time.monotonic()
        self.done = self.failed = 0
        self.running = 0
        self.bar = Bar("fibril-campaign", " jobs", total_jobs, done_before + failed_before,
                       self.line, stream, enabled, every_s)
        self.tty = self.bar.tty

    @property
    def total(self) -> int:
        """Jobs of the grid known so far."""
        return self._total

    @total.setter
    def total(self, value: int) -> None:
        self._total = value
        self.bar.set_total(value)

    def count(self, records) -> None:
        """Count finished ``records`` (one task's) without redrawing."""
        for r in records:
            if r["status"] == "done":
                self.done += 1
            else:
                self.failed += 1

    def set_running(self, jobs: int, force: bool = False) -> None:
        """Note the jobs being computed now (those of every task handed out and not yet
        back), maybe redraw."""
        self.running = jobs
        self.show(force)

    def update(self, records, running: int | None = None, force: bool = False):
        """Count finished ``records`` (one task's), note the running jobs (unchanged when
        None), maybe redraw."""
        self.count(records)
        if running is not None:
            self.running = running
        self.show(force)

    def counts(self) -> str:
        """Done, failed and running jobs (and whether rounds may add jobs)."""
        text = (f"{self.done_before + self.done} done, {self.failed_before + self.failed} "
                f"failed, {self.running} running")
        return text + ("; auto rounds may add jobs (the ETA is a lower bound)" if self.growing
                       else "")

    def line(self) -> str:
        """The progress text: jobs finished, done, failed, running, elapsed, ETA."""
        finished = self.done + self.failed
        before = self.done_before + self.failed_before
        left = self.total - before - finished
        el = time.monotonic() - self.t0
        eta = left / (finished / el) if finished and el > 0 else float("nan")
        return (f"fibril-campaign: {before + finished}/{self.total} jobs "
                f"({self.counts()}; {finished} this run) "
                f"elapsed {clock(el)} ETA {'>= ' if self.growing else ''}{clock(eta)}")

    def show(self, force=False):
        """Redraw the bar, or write the plain line when it is due (or ``force``)."""
        n = self.done_before + self.failed_before + self.done + self.failed
        self.bar.show(n, self.counts(), force)

    def finish(self):
        """End the bar on a terminal."""
        self.bar.close()


def for_planner(planner, n_todo: int, workers: int, enabled: bool) -> Progress:
    """The progress line of a run whose planner starts with ``n_todo`` jobs to run.

    Jobs finished by earlier runs are counted, so the numbers stay right across resumes. A fixed
    grid knows its total; an ``F_P: auto`` grid's total grows round by round (the runner adds each
    new round to ``total``).
    """
    c = planner.counts()
    total = c["jobs"] if planner.fixed else c["jobs"] + n_todo
    before = total - n_todo
    done = min(c["done"], before)
    return Progress(total, workers, enabled=enabled, done_before=done,
                    failed_before=before - done, growing=not planner.fixed)


def nothing_to_run(output: str, counts: dict) -> str:
    """The line of a rerun that finds every job of the grid finished."""
    line = (f"fibril-campaign: all {counts['jobs']} jobs of {output} are already finished "
            f"({counts['done']} done, {counts['failed']} failed); nothing to run")
    if counts["failed"]:
        line += "; rerun the failed ones with --retry-failed"
    return line


def finished_line(output: str, counts: dict) -> str:
    """The last line of a campaign that ran to its end: where the file is, what next."""
    line = (f"fibril-campaign: {counts['done']} done, {counts['failed']} failed, "
            f"{counts['pending']} pending of {counts['jobs']} jobs in {output}; next: "
            f"fibril-campaign status {output}; fibril-campaign report {output} --out REPORT_DIR")
    if counts["failed"]:
        line += "; rerun the failed jobs with --retry-failed"
    return line


__all__ = ["Progress", "for_planner", "nothing_to_run", "finished_line"]
