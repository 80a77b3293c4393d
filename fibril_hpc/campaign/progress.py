"""The live progress line of a running campaign (stderr)."""

from __future__ import annotations

import sys
import time


class Progress:
    """A live progress line with an ETA (carriage return on a terminal, a line every
    ``every_s`` seconds otherwise) on stderr."""

    def __init__(self, total_jobs: int, workers: int, stream=None, every_s: float = 10.0,
                 enabled: bool = True):
        self.total = total_jobs
        self.workers = max(1, workers)
        self.stream = stream or sys.stderr
        self.tty = getattr(self.stream, "isatty", lambda: False)()
        self.every_s = every_s
        self.enabled = enabled
        self.t0 = time.monotonic()
        self.done = self.failed = 0
        self.task_walls = []
        self._last = 0.0
        self.running = 0

    def update(self, records, running: int = 0, force: bool = False):
        """Count finished ``records`` (one task's), note the running tasks, maybe redraw."""
        for r in records:
            if r["status"] == "done":
                self.done += 1
            else:
                self.failed += 1
        if records:
            self.task_walls.append(records[0]["wall_s"] / max(1, len(records)))
        self.running = running
        self.show(force)

    def line(self) -> str:
        """The progress text: jobs finished, done, failed, running, elapsed, ETA."""
        finished = self.done + self.failed
        left = self.total - finished
        el = time.monotonic() - self.t0
        if finished:
            rate = finished / el
            eta = left / rate if rate > 0 else float("inf")
            eta_s = time.strftime("%H:%M:%S", time.gmtime(eta)) if eta < 8.6e5 else ">10 d"
        else:
            eta_s = "?"
        return (f"fibril-campaign: {finished}/{self.total} jobs ({self.done} done, "
                f"{self.failed} failed, {self.running} running) "
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


__all__ = ["Progress"]
