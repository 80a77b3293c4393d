"""Output-file safety shared by every writer: the early writability check, temporary files that
vanish on failure, and directory ``fsync`` after a rename."""

from __future__ import annotations

import contextlib
import os

from .errors import ConfigError, StoreError


def check_writable(path: str, field: str = "--out") -> None:
    """Raise a :class:`ConfigError` naming ``field`` early if ``path`` cannot be created.

    Parameters
    ----------
    path : str
        The file to be written.
    field : str
        The name the user gave it under (an option or a YAML key), used in the message.
    """
    folder = os.path.dirname(os.path.abspath(path)) or "."
    if not os.path.isdir(folder):
        raise ConfigError(field, path, "a path in an existing folder")
    if not os.access(folder, os.W_OK):
        raise ConfigError(field, path, "a path in a writable folder")
    if os.path.isdir(path):
        raise ConfigError(field, path, "a file path, not a folder")


@contextlib.contextmanager
def discard_on_failure(tmp: str, path: str):
    """Remove the temporary file ``tmp`` if the block fails (nothing half-written is left).

    An ``OSError`` becomes a one-line :class:`StoreError` naming ``path``.
    """
    try:
        yield
    except OSError as exc:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise StoreError(f"cannot write {path}: {exc}") from None
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def check_output_folder(path: str, field: str = "--out") -> None:
    """Raise a :class:`ConfigError` naming ``field`` unless ``path`` is a folder, or can be
    created as one (its parent exists and it is not a file). Nothing is created here."""
    if os.path.exists(path) and not os.path.isdir(path):
        raise ConfigError(field, path, "a folder (it is a file)")
    if not os.path.isdir(os.path.dirname(os.path.abspath(path))):
        raise ConfigError(field, path, "a folder whose parent exists")


def fsync_dir(folder: str) -> None:
    """Make a rename inside ``folder`` durable (best effort)."""
    try:
        fd = os.open(folder, os.O_RDONLY)
    except OSError:  # pragma: no cover
        return
    try:
        os.fsync(fd)
    except OSError:  # pragma: no cover
        pass
    finally:
        os.close(fd)


__all__ = ["check_writable", "check_output_folder", "discard_on_failure", "fsync_dir"]
