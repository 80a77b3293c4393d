"""Output-file safety shared by every writer: the early writability check, temporary files that
vanish on failure, and directory ``fsync`` after a rename."""

from __future__ import annotations

import contextlib
import os

from ..errors import FULL_ERRNOS, ConfigError, DiskFull, StoreError


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
def discard_on_failure(tmp: str, path: str, operation: str = "writing"):
    """Remove the temporary file ``tmp`` if the block fails (nothing half-written is left).

    An ``OSError`` becomes a one-line :class:`StoreError` naming ``path`` (a
    :class:`DiskFull` naming ``operation`` when no space or quota is left).
    """
    try:
        yield
    except OSError as exc:
        if os.path.exists(tmp):
            os.unlink(tmp)
        if isinstance(exc, StoreError):
            raise
        if exc.errno in FULL_ERRNOS:
            raise DiskFull(path, operation, exc.strerror or str(exc)) from None
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


def free_bytes(folder: str) -> int:
    """Bytes an unprivileged writer may still use in ``folder`` (-1 when unknown)."""
    try:
        st = os.statvfs(folder)
    except OSError:  # pragma: no cover
        return -1
    return st.f_bavail * st.f_frsize


def write_bytes_atomically(path: str, data: bytes, operation: str, tmp_prefix: str,
                           exclusive: str | None = None, before_publish=None) -> None:
    """Write ``data`` to a temporary file beside ``path``, ``fsync``, rename over ``path``.

    ``before_publish``: called with the temporary file's path once it is written and synced,
    before it gets its name; an exception there keeps the old ``path`` and removes the
    temporary file.

    The free space is checked first; ENOSPC/EDQUOT at any step becomes :class:`DiskFull`
    naming ``path`` and ``operation``, and the temporary file is removed. With ``exclusive``
    (the option that names ``path``) ``path`` must be a new file: the finished file gets its
    name only if no file has it yet, atomically (:func:`claim_new`), so that of two commands
    racing to one new name exactly one wins.
    """
    import tempfile

    folder = os.path.dirname(os.path.abspath(path)) or "."
    free = free_bytes(folder)
    margin = (64 << 10) + len(data) // 16        # file-system metadata and a little slack
    if 0 <= free < len(data) + margin:
        raise DiskFull(path, operation, f"{len(data) + margin} bytes needed, {free} free")
    try:
        fd, tmp = tempfile.mkstemp(prefix=tmp_prefix, dir=folder)
    except OSError as exc:
        if exc.errno in FULL_ERRNOS:
            raise DiskFull(path, operation, exc.strerror) from None
        raise StoreError(f"cannot write {path}: {exc}") from None
    with discard_on_failure(tmp, path, operation):
        try:
            umask = os.umask(0)
            os.umask(umask)
            os.fchmod(fd, 0o666 & ~umask)
            _write_all(fd, data)
            os.fsync(fd)
        finally:
            os.close(fd)
        if before_publish is not None:
            before_publish(tmp)
        if exclusive:
            claim_new(tmp, path, exclusive)
        else:
            os.replace(tmp, path)
        fsync_dir(folder)


def _write_all(fd: int, data) -> None:
    view = memoryview(data)
    while view:
        view = view[os.write(fd, view):]


#: errno values of a file system without hard links (EPERM, EXDEV, EMLINK, ENOSYS, ENOTSUP)
_NO_LINKS = (1, 18, 31, 38, 95)


def claim_new(tmp: str, path: str, field: str) -> None:
    """Give the finished file ``tmp`` the name ``path`` only if no file (or link) has it:
    ``link`` fails with EEXIST when one does, atomically (where hard links are not supported:
    the name is claimed with ``O_CREAT | O_EXCL``, then the file renamed over the claim). A
    name taken meanwhile is a one-line :class:`ConfigError` naming ``field``; ``tmp`` is then
    left for the caller to remove."""
    taken = ConfigError(field, path, "a new file name (another command created it while this "
                        "one ran; this one wrote nothing)")
    try:
        os.link(tmp, path)
    except FileExistsError:
        raise taken from None
    except OSError as exc:
        if exc.errno not in _NO_LINKS:
            raise
        try:
            os.close(os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600))
        except FileExistsError:
            raise taken from None
        os.replace(tmp, path)
        return
    os.unlink(tmp)


def make_new_folder(path: str, field: str) -> None:
    """Create the folder ``path``, which must not exist (``mkdir``, atomic: of two commands
    racing to one new folder exactly one creates it; the other gets a one-line
    :class:`ConfigError` naming ``field``)."""
    try:
        os.mkdir(path)
    except FileExistsError:
        raise ConfigError(field, path, "a new folder (another command created it while this "
                          "one ran; this one wrote nothing)") from None
    except OSError as exc:
        raise ConfigError(field, path, f"a folder that can be created ({exc.strerror})") \
            from None


def save_figure(fig, path: str, operation: str = "writing the plot",
                exclusive: str | None = None) -> None:
    """Render a matplotlib figure to PNG in memory, then write it atomically (a full disk
    leaves no empty PNG behind, only a one-line :class:`DiskFull`). The PNG is marked as
    written by fibril-hpc (see :func:`is_fibril_output`). ``exclusive``: see
    :func:`write_bytes_atomically`."""
    import io

    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110, metadata={"Software": PNG_MARK})
    write_bytes_atomically(path, buf.getvalue(), operation,
                           "." + os.path.basename(path) + ".part-", exclusive)


def write_text_atomically(path: str, text: str, operation: str = "writing",
                          exclusive: str | None = None) -> None:
    """UTF-8 ``text`` to ``path`` (temporary file + rename; ENOSPC/EDQUOT -> DiskFull). A file
    name that is not UTF-8 (``b"bad<0xff>.h5"`` reaches Python as lone surrogates) quoted in the
    text is written with backslash escapes, so the file stays valid UTF-8. ``exclusive``: see
    :func:`write_bytes_atomically`."""
    write_bytes_atomically(path, text.encode("utf-8", "backslashreplace"), operation,
                           "." + os.path.basename(path) + ".part-", exclusive)


PNG_MARK = "fibril-hpc"


def is_fibril_output(path: str) -> bool:
    """Whether the existing file ``path`` was written by fibril-hpc (an HDF5 file whose root
    ``program`` starts with "fibril-hpc", or a PNG carrying its mark)."""
    try:
        with open(path, "rb") as fh:
            head = fh.read(4096)
    except OSError:
        return False
    if head.startswith(b"\x89PNG\r\n\x1a\n"):
        return PNG_MARK.encode() in head
    if head.startswith(b"\x89HDF\r\n\x1a\n"):
        try:
            import h5py

            with h5py.File(path, "r") as fh:
                prog = fh.attrs.get("program", "")
            prog = prog.decode() if isinstance(prog, bytes) else str(prog)
            return prog.startswith("fibril-hpc")
        except Exception:  # noqa: BLE001 - unreadable: not provably ours
            return False
    return False


def check_not_clobbering(path: str, field: str, force: bool) -> None:
    """Refuse (ConfigError) to replace an existing file that fibril-hpc did not write,
    unless ``force``."""
    if not force and os.path.lexists(path) and not is_fibril_output(path):
        raise ConfigError(field, path, "a new file name or a file written by fibril-hpc (this "
                          "one is not; pass --force to replace it)")


__all__ = ["check_writable", "check_output_folder", "check_not_clobbering", "is_fibril_output", "save_figure",
           "write_text_atomically", "discard_on_failure", "fsync_dir", "free_bytes",
           "write_bytes_atomically", "claim_new", "make_new_folder"]
