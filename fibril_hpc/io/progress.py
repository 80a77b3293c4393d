"""Progress on stderr as people expect it: a tqdm bar on a terminal, plain lines every few
seconds elsewhere (a log file, a Slurm output, a pipe), nothing when switched off.

:class:`Bar` is the shared mechanism (terminal or not, bar or lines); :class:`RunProgress`
follows one simulation (``fibril-run``: contact events, the phase, d~ and F~), and the campaign
runner's progress (:mod:`fibril_hpc.campaign.run.progress`) counts jobs with it.
"""

from __future__ import annotations

import os
import stat
import sys
import time

from tqdm import tqdm


def _pty(path: str) -> bool:
    return path.startswith(("/dev/pts/", "/dev/tty"))


def reaches_terminal(fd: int = 2, depth: int = 4) -> bool:
    """Whether output on ``fd``, a pipe, ends on a terminal through the process that started
    this one: an MPI launcher (``mpirun``, Hydra's proxy) hands its ranks a pipe and copies it
    to its own terminal, where a bar renders as well. Linux only (``/proc``); False elsewhere
    or when unsure."""
    try:
        if not stat.S_ISFIFO(os.fstat(fd).st_mode):
            return False
        pid = os.getppid()
        for _ in range(depth):
            if pid <= 1:
                return False
            if _pty(os.readlink(f"/proc/{pid}/fd/2")):
                return True
            with open(f"/proc/{pid}/stat", encoding="ascii") as fh:
                pid = int(fh.read().rsplit(")", 1)[1].split()[1])
    except (OSError, ValueError, IndexError):
        return False
    return False


def is_terminal(stream) -> bool:
    """Whether ``stream`` is an interactive terminal, or stderr piped to one by a launcher
    (:func:`reaches_terminal`)."""
    try:
        if stream.isatty():
            return True
        return stream.fileno() == 2 and reaches_terminal(2)
    except (AttributeError, ValueError, OSError):
        return False


def _width(stream) -> int:
    try:
        return os.get_terminal_size(stream.fileno()).columns
    except (AttributeError, ValueError, OSError):
        return 0


def clock(seconds: float) -> str:
    """``seconds`` as H:MM:SS (or "?" when unknown, "> 10 d" when huge)."""
    if seconds != seconds or seconds < 0:
        return "?"
    if seconds >= 8.64e5:
        return "> 10 d"
    return time.strftime("%H:%M:%S", time.gmtime(seconds))


class Bar:
    """A counter shown as a tqdm bar on a terminal, or as a plain line every ``every_s``
    seconds elsewhere; ``line`` gives the plain line's text.

    Parameters
    ----------
    desc, unit : str
        The bar's label and the unit it counts.
    total : int or None
        The count at completion (None: unknown, the bar shows a count and a rate).
    initial : int
        Counted before this run (a resumed campaign): shown, not used for the rate.
    line : callable
        ``line() -> str``, the text of a plain line.
    stream : file, optional
        Where to write (stderr by default).
    enabled : bool
        False: show nothing.
    every_s : float
        Seconds between plain lines.
    quiet_start : bool
        The first plain line only after ``every_s`` (a short run prints none).
    """

    def __init__(self, desc: str, unit: str, total, initial: int, line, stream=None,
                 enabled: bool = True, every_s: float = 10.0, quiet_start: bool = False):
        self.stream = stream or sys.stderr
        self.enabled = enabled
        self.tty = enabled and is_terminal(self.stream)
        self.every_s = every_s
        self.line = line
        self._last = time.monotonic() if quiet_start else 0.0
        self.bar = None
        if self.tty:
            # follow the terminal's width; a pseudo-terminal without a size (script(1), a
            # launcher's pipe) gets 100 columns instead of tqdm's empty line
            width = _width(self.stream)
            self.bar = tqdm(total=total, initial=initial, desc=desc, unit=unit,
                            file=self.stream, dynamic_ncols=width > 0,
                            ncols=None if width > 0 else 100,
                            nrows=None if width > 0 else 24, mininterval=0.5,
                            smoothing=0.1, leave=True)

    def set_total(self, total) -> None:
        """A new total (an ``F_P: auto`` round added jobs): the bar's length and ETA follow."""
        if self.bar is not None:
            self.bar.total = total
            self.bar.refresh()

    def show(self, n: int, postfix: str = "", force: bool = False) -> None:
        """Count ``n`` in all (bar), or write the plain line when it is due (or ``force``)."""
        if not self.enabled:
            return
        if self.bar is not None:
            if postfix:
                self.bar.set_postfix_str(postfix, refresh=False)
            if n != self.bar.n:
                self.bar.update(n - self.bar.n)
            elif force:
                self.bar.refresh()
            return
        now = time.monotonic()
        if force or now - self._last >= self.every_s:
            self.stream.write(self.line() + "\n")
            self.stream.flush()
            self._last = now

    def close(self) -> None:
        """End the bar (its last state stays on the terminal)."""
        if self.bar is not None:
            self.bar.close()
            self.bar = None


class RunProgress:
    """The progress of one simulation, for :func:`fibril_hpc.api.simulate`'s ``progress``
    hook: contact events so far, the phase (loading, or the pull-off from preload i of n), the
    current d~ and F~, and the pillars in contact (a pull-off ends at none)."""

    def __init__(self, n_preloads: int, stream=None, enabled: bool = True,
                 every_s: float = 10.0, desc: str = "fibril-run"):
        self.n = max(1, n_preloads)
        self.desc = desc
        self.t0 = time.monotonic()
        self.info = {"phase": "loading", "preload": None, "d_tilde": 0.0, "F_tilde": 0.0,
                     "events": 0}
        self.bar = Bar(desc, " events", None, 0, self.line, stream, enabled, every_s,
                       quiet_start=True)

    def phase(self) -> str:
        """"loading", or "pull-off i/n"."""
        i = self.info["preload"]
        if self.info["phase"] == "loading" or i is None:
            return "loading"
        return f"pull-off {i + 1}/{self.n}"

    def state(self) -> str:
        """The phase with d~, F~ and the pillars in contact (of all)."""
        pc, n = self.info.get("pillars_in_contact"), self.info.get("n_pillars")
        return (f"{self.phase()}, d~ {self.info['d_tilde']:.4g}, "
                f"F~ {self.info['F_tilde']:.4g}"
                + (f", {pc} of {n} pillars in contact" if pc is not None and n else ""))

    def line(self) -> str:
        """The plain line: events, phase, d~, F~, elapsed."""
        return (f"{self.desc}: {self.info['events']} events, {self.state()}, "
                f"elapsed {clock(time.monotonic() - self.t0)}")

    def __call__(self, info: dict) -> None:
        """One recorded point of the path (see :func:`fibril_hpc.api.simulate`)."""
        self.info = info
        self.bar.show(int(info["events"]), self.state())

    def close(self) -> None:
        """End the display."""
        self.bar.close()


__all__ = ["Bar", "RunProgress", "clock", "is_terminal"]
