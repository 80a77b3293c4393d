"""Which existing files a command may replace: :func:`check_output` (no MPI).

The rule every writing command follows (``export``, ``merge``, ``salvage``, ``example -o``,
``report --out``, ``fibril-run --out/--plot``, ``fibril-accuracy --out``):

1. a new name is always fine;
2. an existing file is replaced only when the user says so (``--force``);
3. never, not even with ``--force``: a campaign file (an HDF5 file whose root says it is one, or
   any file with a journal or a lock file beside it), a journal or its quarantine, a lock file,
   or a file that a running campaign holds (its lock is taken), or an HDF5 file whose structure
   cannot be read (it may be a damaged campaign file waiting for ``salvage``).

A refusal is a :class:`~fibril_hpc.errors.ConfigError` naming the option and the file (one line,
exit status 2, nothing written). The checks run before any work.
"""

from __future__ import annotations

import fcntl
import os

from ...errors import ConfigError, DamagedFileError, StoreError
from . import journal as _journal
from .h5read import read_root

#: suffixes of the files that live beside a campaign file
SIDE_SUFFIXES = (".journal", ".journal.quarantine", ".journal.rewrite", ".journal.mirror",
                 ".journal.mirror.quarantine", ".journal.mirror.rewrite", ".lock")
_HDF5_SIGNATURE = b"\x89HDF\r\n\x1a\n"


def lock_path(campaign: str) -> str:
    """The lock file the writer of ``campaign`` holds (beside its resolved path)."""
    return os.path.realpath(campaign) + ".lock"


def is_held(campaign: str) -> bool:
    """Whether a running writer holds the lock of ``campaign`` (its lock file is locked)."""
    try:
        fd = os.open(lock_path(campaign), os.O_RDONLY)
    except OSError:
        return False
    try:
        fcntl.flock(fd, fcntl.LOCK_SH | fcntl.LOCK_NB)
    except OSError:
        return True
    else:
        fcntl.flock(fd, fcntl.LOCK_UN)
        return False
    finally:
        os.close(fd)


def protected(path: str) -> str:
    """Why ``path`` may never be replaced by a command ("" when it may, with ``--force``)."""
    real = os.path.realpath(path)
    name = os.path.basename(real)
    for suffix in SIDE_SUFFIXES:
        base = real[: -len(suffix)]
        if name.endswith(suffix) and (os.path.exists(base) or suffix != ".lock"):
            return "a campaign's journal, previous copy or lock file"
    if is_held(real):
        return "a campaign file that a running campaign is writing"
    if any(os.path.exists(real + suffix) for suffix in (".journal", ".journal.mirror",
                                                          ".previous", ".lock")):
        return "a campaign file (it has a journal, previous copy or lock file beside it)"
    try:
        with open(real, "rb") as fh:
            head = fh.read(8)
    except OSError:
        return ""
    if head[:4] in (_journal.MAGIC, _journal.OLD_MAGIC):
        return "a campaign's journal"
    if head != _HDF5_SIGNATURE:
        return ""
    try:
        read_root(real)
    except DamagedFileError:
        return "an HDF5 file that cannot be read (perhaps a damaged campaign file: " \
                   "`fibril-campaign salvage` it, or remove it yourself)"
    except StoreError:
        return ""                         # an HDF5 file of someone else's: --force replaces it
    return "a campaign file"


def check_output(path: str, field: str, force: bool = False) -> None:
    """Refuse (one-line :class:`ConfigError` naming ``field`` and ``path``) to write ``path``
    where the rule of this module forbids it; a new name always passes."""
    path = os.fspath(path)
    if not os.path.lexists(path):
        return
    why = protected(path)
    if why:
        raise ConfigError(field, path, f"a new file name; this is {why}, never replaced, not "
                          "even with --force")
    if not force:
        raise ConfigError(field, path, "a new file name (it exists; pass --force to replace it)")


def check_new(path: str, field: str) -> None:
    """Refuse any existing ``path`` (commands whose output must be a new file: ``merge``,
    ``salvage``, ``example -o``), naming why when it is protected besides."""
    path = os.fspath(path)
    if os.path.lexists(path):
        why = protected(path)
        raise ConfigError(field, path, "a new file name (it exists" + (f": {why}" if why else "")
                          + ")")


#: the mark :mod:`fibril_hpc.campaign.analysis.page` puts in every ``report.html``
REPORT_MARK = "<meta name='generator' content='fibril-hpc report'>"
#: the kinds of file a report writes into its folder
REPORT_SUFFIXES = (".csv", ".png", ".md", ".html")


def is_report_folder(folder: str) -> bool:
    """Whether ``folder`` holds a report written by fibril-hpc (its ``report.html`` carries
    :data:`REPORT_MARK`)."""
    try:
        with open(os.path.join(folder, "report.html"), encoding="utf-8", errors="replace") as fh:
            return REPORT_MARK in fh.read(4096)
    except OSError:
        return False


def check_report_folder(folder: str, field: str, force: bool = False) -> None:
    """Refuse a report folder whose files could be replaced without the user saying so: a new
    or empty folder, or one holding an earlier report, is fine; any other needs ``force``; and a
    protected file (see :func:`protected`) of a kind the report writes is never replaced."""
    folder = os.fspath(folder)
    try:
        names = os.listdir(folder)
    except FileNotFoundError:
        return
    except OSError as exc:
        raise ConfigError(field, folder, f"a readable folder ({exc.strerror})") from None
    for name in names:
        p = os.path.join(folder, name)
        if name.endswith(REPORT_SUFFIXES):
            why = protected(p)
            if why:
                raise ConfigError(field, folder, f"a folder without {name!r}: it is {why}, "
                                  "never replaced, not even with --force")
    if names and not force and not is_report_folder(folder):
        raise ConfigError(field, folder, "a new or empty folder, or one holding an earlier "
                          "report (it holds other files, which the report could replace; pass "
                          "--force to write into it)")


__all__ = ["check_output", "check_new", "check_report_folder", "is_report_folder", "REPORT_MARK",
           "protected", "is_held", "lock_path", "SIDE_SUFFIXES"]
