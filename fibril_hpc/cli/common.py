"""What every command shares: the one-line argument parser, exit statuses, error printing."""

from __future__ import annotations

import argparse
import logging
import sys

from ..errors import EXIT_FAILED, EXIT_INTERRUPTED, EXIT_OK, EXIT_USAGE

__all__ = ["Parser", "error", "setup_logging", "EXIT_OK", "EXIT_FAILED", "EXIT_USAGE",
           "EXIT_INTERRUPTED"]


class Parser(argparse.ArgumentParser):
    """argparse that reports a usage error as one line and exit status 2."""

    def error(self, message):
        """Print ``prog: error: message`` and exit with :data:`EXIT_USAGE`."""
        self.exit(EXIT_USAGE, f"{self.prog}: error: {message}\n")


def error(prog: str, msg, code: int = EXIT_USAGE) -> int:
    """Print one error line for ``prog`` on stderr and return ``code``."""
    print(f"{prog}: error: {msg}", file=sys.stderr)
    return code


def setup_logging(verbose: bool) -> None:
    """INFO with ``-v``, else WARNING, one line per message on stderr."""
    logging.basicConfig(level=logging.INFO if verbose else logging.WARNING,
                        format="%(levelname)s %(name)s: %(message)s")
