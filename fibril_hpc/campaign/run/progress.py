"""The live progress line of a running campaign (stderr)."""

from __future__ import annotations

import sys
import time


class Progress:
    """A live progress line with an ETA (carriage return on a terminal, a line every
    ``every_s`` seconds otherwise) on stderr."""

    def __init__(self, total_jobs: int, workers: int, stream=None, every_s: float = 10.0,
                 enabled: bool = True, done_before: int = 0, failed_before: int = 0):
        self.total = total_jobs
        #: jobs of the grid finished by earlier runs (counted in the line, not in the ETA)
        self.done_before = done_before
        self.failed_before = failed_before
        self.workers = max(1, workers)
        self.stream = stream or sys.stderr
        self.tty = getattr(self.stream, "isatty", lambda: False)()
        self.every_s = every_s
        self.enabled = enabled
        self.t0 = time.monotonic()
        self.done = self.failed = 0
        self._last = 0.0
        self.running = 0

    def update(self, records, running: int = 0, force: bool = False):
        """Count finished ``records`` (one task's), note the running tasks, maybe redraw."""
        for r in records:
            if r["status"] == "done":
                self.done += 1
            else:
                self.failed += 1
        self.running = running
        self.show(force)

    def line(self) -> str:
        """The progress text: jobs finished, done, failed, running, elapsed, ETA."""
        finished = self.done + self.failed
        before = self.done_before + self.failed_before
        left = self.total - before - finished
        el = time.monotonic() - self.t0
        if finished:
            rate = finished / el
            eta = left / rate if rate > 0 else float("inf")
            eta_s = time.strftime("%H:%M:%S", time.gmtime(eta)) if eta < 8.6e5 else ">10 d"
        else:
            eta_s = "?"
        return (f"fibril-campaign: {before + finished}/{self.total} jobs "
                f"({self.done_before + self.done} done, {self.failed_before + self.failed} "
                f"failed, {self.running} running; {finished} this run) "
                f"elapsed {time.strftime('%H:%M:%S', time.gmtime(el))} ETA {eta_s}")

    def show(self, force=False):
        """Redraw the line (on a terminal at most twice a second, else every ``every_s``)."""
        if not self.enabled:
            return
        now = time.monotonic()
        if self.tty:
            if force or now - self._last >= 0.5:
                self.stream.write("\r" + self.line() + "\x1b[K")
                self.stream.flush()
                self._last = now
        elif force or now - self._last >= self.every_s:
            self.stream.write(self.line() + "\n")
            self.stream.flush()
            self._last = now

    def finish(self):
        """End the line on a terminal."""
        if self.enabled and self.tty:
            self.stream.write("\n")
            self.stream.flush()


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
                    failed_before=before - done)


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
