"""Every output file htetro-opt writes (tilesets, plots, study tables, JSON) goes through here.

:func:`atomic_path` gives a temporary file beside the target and renames it into place only when
writing succeeded, so no half-written file is ever left behind; an ``OSError`` on the way (a missing
folder, a folder in the way, no permission) becomes an :class:`~htetro_opt.errors.OutputError`
naming the file. :func:`check_output_path` makes the same checks before any work starts, so a long
run is not thrown away for a bad output path.
"""

from __future__ import annotations

import os
import tempfile
from contextlib import contextmanager
from pathlib import Path
from typing import Iterator

from htetro_opt._interrupt import removed_on_exit
from htetro_opt.errors import OutputError

__all__ = ["atomic_path", "check_output_path", "write_text"]


def _umask() -> int:
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def _reason(err: OSError) -> str:
    return err.strerror or str(err)


def check_output_path(path: str | os.PathLike, *, what: str = "output") -> Path:
    """``path`` as a Path if a file can be written there: its folder exists and is writable, and
    ``path`` is not a folder.

    Raises
    ------
    OutputError
        Naming ``what`` (e.g. "plot"), the path and the reason.

    Examples
    --------
    >>> check_output_path("/no/such/folder/x.png", what="plot")
    Traceback (most recent call last):
    ...
    htetro_opt.errors.OutputError: cannot write plot '/no/such/folder/x.png': folder '/no/such/folder' does not exist
    """
    path = Path(path)
    folder = path.parent if str(path.parent) else Path(".")
    if not folder.is_dir():
        raise OutputError(f"cannot write {what} {str(path)!r}: folder {str(folder)!r} does not exist")
    if path.is_dir():
        raise OutputError(f"cannot write {what} {str(path)!r}: it is a folder")
    if not os.access(folder, os.W_OK | os.X_OK) or (path.exists() and not os.access(path, os.W_OK)):
        raise OutputError(f"cannot write {what} {str(path)!r}: permission denied")
    return path


@contextmanager
def atomic_path(path: str | os.PathLike, *, what: str = "output") -> Iterator[Path]:
    """A temporary path beside ``path`` to write to; on success it replaces ``path`` in one step.

    The temporary file gets an ordinary file's mode (``mkstemp`` makes it private), and it is removed
    if writing fails or is interrupted, so ``path`` never holds a half-written file and nothing is
    left behind.

    Raises
    ------
    OutputError
        If the file cannot be created or put in place (``what`` names it in the message).

    Examples
    --------
    >>> target = Path(tempfile.mkdtemp()) / "out.txt"
    >>> with atomic_path(target) as tmp:
    ...     _ = tmp.write_text("done")
    >>> target.read_text()
    'done'
    """
    path = Path(path)
    try:
        handle, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    except OSError as err:
        raise OutputError(f"cannot write {what} {str(path)!r}: {_reason(err)}") from err
    os.close(handle)
    try:
        with removed_on_exit(tmp):  # also when a signal's helper thread ends the process (htetro_opt._interrupt)
            os.chmod(tmp, 0o666 & ~_umask())
            yield Path(tmp)
            os.replace(tmp, path)
    except OSError as err:
        raise OutputError(f"cannot write {what} {str(path)!r}: {_reason(err)}") from err
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)


def write_text(path: str | os.PathLike, text: str, *, what: str = "output") -> Path:
    """Write ``text`` (UTF-8) to ``path`` atomically; the path.

    Raises
    ------
    OutputError
        If the file cannot be written.
    """
    with atomic_path(path, what=what) as tmp:
        tmp.write_text(text, encoding="utf-8")
    return Path(path)
