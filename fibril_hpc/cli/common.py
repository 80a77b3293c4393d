"""What every command shares: the one-line argument parser, exit statuses, error printing."""

from __future__ import annotations

import argparse
import logging
import sys

from ..errors import EXIT_FAILED, EXIT_INTERRUPTED, EXIT_OK, EXIT_USAGE

__all__ = ["Parser", "error", "setup_logging", "memory_guard", "one_line", "OUT_OF_MEMORY",
           "EXIT_OK", "EXIT_FAILED", "EXIT_USAGE", "EXIT_INTERRUPTED"]


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


def memory_guard(prog: str):
    """Decorate a command's ``main``: a MemoryError anywhere becomes one line, exit 2."""
    import functools

    def wrap(main):
        @functools.wraps(main)
        def guarded(*args, **kwargs):
            try:
                return main(*args, **kwargs)
            except MemoryError:
                return error(prog, OUT_OF_MEMORY, EXIT_USAGE)
        return guarded
    return wrap


def setup_logging(verbose: bool) -> None:
    """INFO with ``-v``, else WARNING, one line per message on stderr."""
    logging.basicConfig(level=logging.INFO if verbose else logging.WARNING,
                        format="%(levelname)s %(name)s: %(message)s")
