"""What every command shares: the one-line argument parser, exit statuses, error printing."""

from __future__ import annotations

import argparse
import functools
import logging
import os
import sys

from ..errors import EXIT_FAILED, EXIT_INTERRUPTED, EXIT_OK, EXIT_USAGE

__all__ = ["Parser", "error", "setup_logging", "memory_guard", "pipe_safe", "interruptible",
           "one_line",
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


def interruptible(prog: str, what: str):
    """Decorate a command's ``main``: Ctrl-C (SIGINT, a KeyboardInterrupt anywhere in it) ends
    the command with one line on stderr, ``prog: interrupted (SIGINT); what``, and exit status
    :data:`EXIT_INTERRUPTED` (75, as an interrupted campaign), instead of a traceback and 130.
    ``what`` says what the user has and what to do (files are written atomically: whole or not
    at all)."""

    def wrap(main):
        @functools.wraps(main)
        def guarded(*args, **kwargs):
            try:
                return main(*args, **kwargs)
            except KeyboardInterrupt:
                print(one_line(f"{prog}: interrupted (SIGINT); {what}"), file=sys.stderr)
                return EXIT_INTERRUPTED
        return guarded
    return wrap


def setup_logging(verbose: bool) -> None:
    """INFO with ``-v``, else WARNING, one line per message on stderr."""
    logging.basicConfig(level=logging.INFO if verbose else logging.WARNING,
                        format="%(levelname)s %(name)s: %(message)s")
