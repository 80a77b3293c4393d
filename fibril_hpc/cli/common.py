"""What every command shares: the one-line argument parser, exit statuses, error printing."""

from __future__ import annotations

import argparse
import functools
import logging
import os
import signal
import sys
import threading

from .. import stops as _stops
from ..errors import EXIT_FAILED, EXIT_INTERRUPTED, EXIT_OK, EXIT_USAGE

__all__ = ["Parser", "error", "setup_logging", "memory_guard", "pipe_safe", "interruptible",
           "one_line", "Stopped", "STOP_SIGNALS", "stop_status",
           "versions_text", "add_version", "OUT_OF_MEMORY", "EXIT_OK", "EXIT_FAILED", "EXIT_USAGE",
           "EXIT_INTERRUPTED"]


class Parser(argparse.ArgumentParser):
    """argparse that reports a usage error as one line and exit status 2."""

    def error(self, message):
        """Print ``prog: error: message`` and exit with :data:`EXIT_USAGE`."""
        self.exit(EXIT_USAGE, f"{self.prog}: error: {message}\n")


#: longest error line printed (a hostile input must not print megabytes)
MAX_ERROR_CHARS = 500


def one_line(msg, limit: int = MAX_ERROR_CHARS) -> str:
    """``msg`` as one line of at most ``limit`` characters (newlines folded, the middle cut)."""
    text = " ".join(str(msg).split("\n"))
    if len(text) <= limit:
        return text
    half = (limit - 5) // 2
    return text[:half] + " ... " + text[-half:]


def error(prog: str, msg, code: int = EXIT_USAGE) -> int:
    """Print one error line for ``prog`` on stderr (capped at :data:`MAX_ERROR_CHARS`) and
    return ``code``."""
    print(one_line(f"{prog}: error: {msg}"), file=sys.stderr)
    return code


OUT_OF_MEMORY = ("out of memory (MemoryError): this input needs more memory than the process may "
                 "use (lower n_side or elements_per_diameter, or ask for more memory)")


def versions_text() -> str:
    """The versions of fibril-hpc and of the libraries its numbers depend on (two lines)."""
    from ..io.results import software_versions

    v = software_versions()
    return " ".join(f"{k}={v[k]}" for k in ("fibril_hpc", "numpy", "numba", "pyfftw", "fftw",
                                            "h5py", "hdf5", "python")) + f"\nrng: {v['rng']}"


class _Version(argparse.Action):
    def __init__(self, option_strings, dest, **kwargs):
        super().__init__(option_strings, dest, nargs=0, default=argparse.SUPPRESS,
                         help="print the versions of fibril-hpc and its libraries, and exit")

    def __call__(self, parser, namespace, values, option_string=None):
        from .._version import __version__

        print(f"fibril-hpc {__version__}\n{versions_text()}")
        parser.exit(EXIT_OK)


def add_version(parser: argparse.ArgumentParser) -> None:
    """Give ``parser`` a ``--version`` option (the versions, unwrapped, then exit 0)."""
    parser.add_argument("--version", action=_Version)


def pipe_safe(main):
    """Decorate a command's ``main``: a reader that closes the pipe early (``fibril-run ... |
    head``, ``--help | head -1``) ends the command quietly with status 0, as ``head`` meant,
    instead of a BrokenPipeError traceback (stdout is pointed at /dev/null so that the final
    flush cannot fail again)."""

    @functools.wraps(main)
    def guarded(*args, **kwargs):
        _names_print_as_given()
        try:
            code = main(*args, **kwargs)
            sys.stdout.flush()              # a closed pipe shows here, not at interpreter exit
            return code
        except SystemExit:                  # --help, --version: argparse exits after printing
            try:
                sys.stdout.flush()
            except BrokenPipeError:
                _stdout_to_devnull()
            raise
        except BrokenPipeError:
            _stdout_to_devnull()
            return EXIT_OK
    return guarded


def _names_print_as_given() -> None:
    """A file name that is not UTF-8 (``bad<0xff>.h5``) reaches Python as lone surrogates; let
    stdout print it back as the bytes the user gave (stderr already escapes them) instead of
    a UnicodeEncodeError traceback."""
    reconfigure = getattr(sys.stdout, "reconfigure", None)
    if reconfigure is not None and getattr(sys.stdout, "errors", None) == "strict":
        try:
            reconfigure(errors="surrogateescape")
        except (ValueError, OSError, TypeError):    # pragma: no cover - a closed or odd stream
            pass


def _stdout_to_devnull() -> None:
    try:
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
    except (OSError, ValueError):
        pass


def memory_guard(prog: str):
    """Decorate a command's ``main``: a MemoryError anywhere becomes one line, exit 2."""

    def wrap(main):
        @functools.wraps(main)
        def guarded(*args, **kwargs):
            try:
                return main(*args, **kwargs)
            except MemoryError:
                return error(prog, OUT_OF_MEMORY, EXIT_USAGE)
        return guarded
    return wrap


class Stopped(KeyboardInterrupt):
    """A stop signal (SIGINT or SIGTERM) that ends a command: a KeyboardInterrupt that knows
    which signal raised it (:func:`interruptible` names it and picks the exit status)."""

    def __init__(self, signum: int):
        super().__init__(signal.Signals(signum).name)
        self.signum = signum


def _raise_stopped(signum, frame):
    """The guard's handler: raise :class:`Stopped`, except where that is unsafe
    (:func:`fibril_hpc.stops.unsafe`):
    inside an import an exception can come out as another one (Python 3.11 turns it into
    "RuntimeError: Error calling __set_name__" in a class body that uses a descriptor) or not
    at all, and in llvmlite's callbacks it breaks numba's compiler. There the signal is sent
    again after :data:`fibril_hpc.stops.UNSAFE_RETRY_S`; a command imports its heavy
    libraries (numba, h5py, pyFFTW) lazily, and numba compiles on first use, inside its guard."""
    if frame is not None and _stops.unsafe(frame):
        _stops.send_again(signum, _stops.UNSAFE_RETRY_S)
        return
    raise Stopped(signum)


def _dropped(unraisable) -> None:
    """A ``sys.unraisablehook`` for a command that was stopped: destructor errors of objects
    cut off mid-construction are not reported (the command has said it was interrupted)."""


def _redeliver(previous):
    """A ``sys.unraisablehook`` that sends a :class:`Stopped` swallowed where Python cannot
    propagate it (raised inside a C library's callback, as numba's compiler makes while it
    caches a kernel: Python prints "Exception ignored ..." and goes on) to this process again,
    so that the command still stops, with its one line; anything else goes to ``previous``.
    The signal is sent from a short-lived thread: sent from the hook itself, its handler would
    run inside the hook and be swallowed there. Should it land in a callback again, the hook
    sends it again."""

    def hook(unraisable):
        exc = unraisable.exc_value
        if isinstance(exc, Stopped):
            _stops.send_again(exc.signum, 0.01)
            return
        previous(unraisable)
    return hook


#: the signals a command answers with one line: Ctrl-C, and ``kill`` / a scheduler's stop
STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM)


def stop_status(signum: int, code: int | None) -> int:
    """The exit status after stop signal ``signum``: ``code``, or the shell's 128 + signal
    (130 for Ctrl-C, 143 for SIGTERM) when ``code`` is None."""
    return 128 + int(signum) if code is None else code


def interruptible(prog: str, what: str, code: int | None = None):
    """Decorate a command's ``main``: Ctrl-C or SIGTERM anywhere in it ends the command with one
    line on stderr, ``prog: interrupted (SIGINT); what``, and exit status ``code`` (a campaign:
    :data:`EXIT_INTERRUPTED`, 75), or 128 + the signal (130, 143) when ``code`` is None, instead
    of a traceback or a silent death. ``what`` says what the user has and what to do (files are
    written atomically: whole or not at all). Signals the caller ignores (``nohup``, a
    background job) stay ignored; the previous handlers are put back on return. The console
    scripts (:mod:`.entry`) cover the imports before ``main`` is reached."""

    def wrap(main):
        @functools.wraps(main)
        def guarded(*args, **kwargs):
            old = _install(_raise_stopped)
            old_hook = sys.unraisablehook
            if old:
                sys.unraisablehook = _redeliver(old_hook)
            stopped = False
            try:
                return main(*args, **kwargs)
            except KeyboardInterrupt as exc:
                stopped = True
                # objects the signal cut off mid-construction (numba's compiler: an llvmlite
                # pass builder) fail in their destructors as the command ends; their "Exception
                # ignored" tracebacks would follow the one line: dropped from here on
                sys.unraisablehook = _dropped
                signum = getattr(exc, "signum", signal.SIGINT)
                print(one_line(f"{prog}: interrupted ({signal.Signals(signum).name}); {what}"),
                      file=sys.stderr)
                return stop_status(signum, code)
            finally:
                # for the rest of a stopped command's process; a host with a hook of its own
                # (an embedding program, a test runner) gets it back
                ending = stopped and old_hook is sys.__unraisablehook__
                sys.unraisablehook = _dropped if ending else old_hook
                _restore(old)
        return guarded
    return wrap


def _install(handler) -> dict:
    """Point the stop signals that are not ignored at ``handler`` (main thread only); returns
    the previous handlers for :func:`_restore`."""
    old = {}
    if threading.current_thread() is not threading.main_thread():
        return old
    for s in STOP_SIGNALS:
        prev = signal.getsignal(s)
        if prev is not signal.SIG_IGN:
            old[s] = signal.signal(s, handler)
    return old


def _restore(old: dict) -> None:
    for s, h in old.items():
        signal.signal(s, h if h is not None else signal.SIG_DFL)


def setup_logging(verbose: bool) -> None:
    """INFO with ``-v``, else WARNING, one line per message on stderr."""
    logging.basicConfig(level=logging.INFO if verbose else logging.WARNING,
                        format="%(levelname)s %(name)s: %(message)s")
