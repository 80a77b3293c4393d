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
        super().__init__(f"{field}: got {_short_repr(value)}; allowed: {allowed}")


def unknown_key(field: str, value, known, what: str = "a known key") -> ConfigError:
    """The :class:`ConfigError` of a key that is none of ``known``: ``field`` is the key as the
    user wrote it (with its dotted prefix, e.g. ``scene.k_tlde``), and the allowed text names
    the closest known key first when one is close (``did you mean 'k_tilde'?``, by
    :func:`difflib.get_close_matches`), then every known key."""
    import difflib

    key = str(field).rsplit(".", 1)[-1]
    known = [str(k) for k in known]
    close = difflib.get_close_matches(key, known, n=1, cutoff=0.6) or \
        difflib.get_close_matches(key.lower(), [k.lower() for k in known], n=1, cutoff=0.6)
    if close and close[0] not in known:               # matched case-insensitively
        close = [next(k for k in known if k.lower() == close[0])]
    hint = f" (did you mean {close[0]!r}?)" if close else ""
    return ConfigError(field, value, f"{what}{hint}: " + ", ".join(known))


def _short_repr(value) -> str:
    """``repr`` of a value, bounded in size and depth (a YAML alias bomb must not become a
    message of hundreds of megabytes)."""
    import reprlib

    r = reprlib.Repr()
    r.maxlevel, r.maxstring, r.maxother, r.maxlong = 3, 200, 200, 60
    r.maxdict = r.maxlist = r.maxtuple = r.maxset = 8
    return r.repr(value)


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


class DamagedFileError(StoreError):
    """A file's HDF5 structure cannot be read (one line; ``fibril-campaign salvage`` helps)."""


class UnknownLayoutError(StoreError):
    """A file written in a layout version (``format_version``) newer than this code knows: every
    reader refuses it in one line (reading it as the old layout could misread every number)."""


class Interruption(StoreError):
    """A campaign run cannot go on writing, but nothing finished is lost: every rank stops and
    exits with :data:`EXIT_INTERRUPTED` (75) after one line saying what to do."""


class PublishedFileChanged(Interruption):
    """The published campaign file changed under its writer (cut short, emptied or replaced by
    another program): nothing more is published into it; every record finished since the last
    checkpoint stays in the journal, and ``salvage`` recovers them with what still reads.

    Parameters
    ----------
    path, journal : str
        The campaign file and its journal.
    detail : str
        What changed (sizes, or why it no longer reads).
    """

    def __init__(self, path, journal, detail=""):
        self.path = path
        self.journal = journal
        super().__init__(
            f"{path} changed under this campaign ({detail}; cut short, emptied or replaced by "
            f"another program): nothing more was written to it, and every record finished since "
            f"its last checkpoint is in {journal}; recover with `fibril-campaign salvage {path} "
            "-o NEW.h5` (it takes the journal too), then rerun with --output NEW.h5")


class DiskFull(Interruption):
    """No space (ENOSPC) or quota (EDQUOT) left while writing: an interruption, not a crash.

    Parameters
    ----------
    path : str
        The file being written.
    operation : str
        What was being done ("appending to the journal", "checkpoint copy", ...).
    detail : str
        The operating system's words (or the free-space arithmetic).
    """

    def __init__(self, path, operation, detail=""):
        self.path = path
        self.operation = operation
        self.detail = detail
        super().__init__(f"disk full during {operation} of {path}"
                         + (f" ({detail})" if detail else "")
                         + "; free space (or quota) and rerun the same command to resume")


#: errno values that mean "no room left" (ENOSPC, EDQUOT)
FULL_ERRNOS = (28, 122)
