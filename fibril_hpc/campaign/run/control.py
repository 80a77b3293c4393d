"""Stop signals of a running campaign: :class:`StopFlag` and :class:`Interrupted`.

SIGTERM, SIGINT and SIGUSR1 set a flag that the runners poll between jobs; a job that is
computing when the signal arrives is abandoned at once (it stays pending in the file).
"""

from __future__ import annotations

import signal

from ...stops import UNSAFE_RETRY_S, send_again, unsafe

STOP_SIGNALS = (signal.SIGTERM, signal.SIGINT, signal.SIGUSR1)


class Interrupted(Exception):
    """Raised inside a running job when a stop signal arrives (the job is abandoned)."""


class StopFlag:
    """Handlers for the stop signals that set :attr:`stop`.

    While :attr:`busy` (a job is computing) the handler raises :class:`Interrupted`, so that the
    job is abandoned at once (where raising is unsafe, :func:`fibril_hpc.stops.unsafe`, the
    signal is sent again a moment later). Use :meth:`install` and :meth:`restore` around a run.
    """

    def __init__(self):
        self.stop = False
        self.signum = None
        self.busy = False
        self._old = {}

    def _handler(self, signum, frame):
        self.stop = True
        self.signum = signum
        if self.busy:
            if frame is not None and unsafe(frame):
                # inside numba's compiler (an llvmlite callback) or an import, an exception is
                # swallowed or corrupts what runs below: the signal comes again shortly
                send_again(signum, UNSAFE_RETRY_S)
                return
            self.busy = False
            raise Interrupted(f"signal {signal.Signals(signum).name}")

    def install(self) -> StopFlag:
        """Install the handlers (the previous ones are kept for :meth:`restore`)."""
        for s in STOP_SIGNALS:
            self._old[s] = signal.signal(s, self._handler)
        return self

    def restore(self) -> None:
        """Put the previous handlers back."""
        for s, h in self._old.items():
            signal.signal(s, h)
        self._old = {}


def signal_name(signum) -> str:
    """``SIGTERM`` etc., or ``stop`` when no signal stopped the run."""
    return signal.Signals(signum).name if signum else "stop"


def interrupted_message(output: str, signum) -> str:
    """The one line a runner prints when it stops early."""
    return (f"fibril-campaign: interrupted ({signal_name(signum)}); finished results are in "
            f"{output}; rerun the same command to resume")


__all__ = ["StopFlag", "Interrupted", "STOP_SIGNALS", "signal_name", "interrupted_message"]
