"""Named errors of fibril-hpc.

A user mistake is a :class:`ConfigError`; the command-line layer turns it into one line on
stderr and exit status 2. A solver that does not converge raises :class:`NoConvergenceError`,
which the load-path driver records in the result's ``status`` instead of returning garbage.
"""


class FibrilError(Exception):
    """Base class of every error raised on purpose by fibril-hpc."""


class ConfigError(FibrilError, ValueError):
    """An input field is invalid.

    Parameters
    ----------
    field : str
        Name of the offending field, exactly as the user writes it (YAML key / keyword).
    value : object
        The value that was given.
    allowed : str
        Human description of what is allowed.
    """

    def __init__(self, field, value, allowed):
        self.field = field
        self.value = value
        self.allowed = allowed
        super().__init__(f"{field}: got {value!r}; allowed: {allowed}")


class NoConvergenceError(FibrilError, RuntimeError):
    """The constrained CG or the contact-set iteration did not converge, or went non-finite."""


class StoreError(FibrilError, OSError):
    """An output file cannot be written or does not match what is about to be written."""


# Exit statuses of the commands (defined here once; the CLI and the campaign runners use them).
EXIT_OK = 0
#: some campaign jobs failed (recorded with their reason), or a run's status is not ok
EXIT_FAILED = 1
#: a user mistake (a :class:`ConfigError`): one line on stderr, nothing written
EXIT_USAGE = 2
#: interrupted by a stop signal (EX_TEMPFAIL): rerun the same command to resume
EXIT_INTERRUPTED = 75
