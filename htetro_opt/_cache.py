"""A per-user on-disk cache of arrays that are slow to compute and never change between runs.

The model's swept-cell tables take about 0.2 s of pure Python to build, paid by every process that
plans; loaded from a ``.npz`` file they take milliseconds. An entry is named by what it holds and a
key: a hash of the package's version and of the source files the arrays are computed from, so an
upgrade or an edit of the model makes a new entry rather than loading a stale one. Entries are
written atomically (a temporary file beside them, renamed into place), so a process never reads a
half-written one. The cache is best effort: an entry that cannot be read (missing, corrupt,
truncated, of another layout) is rebuilt, and a folder that cannot be written is skipped; neither is
an error, the only cost is the time of the build.

The folder is ``$HTETRO_OPT_CACHE_DIR`` if set, else ``htetro-opt`` under the user's cache folder
(``$XDG_CACHE_HOME`` or ``~/.cache``; ``%LOCALAPPDATA%`` on Windows, ``~/Library/Caches`` on macOS).
``HTETRO_OPT_CACHE_DIR=off`` (or an empty value) turns the cache off.
"""

from __future__ import annotations

import hashlib
import os
import sys
import tempfile
import zipfile
from pathlib import Path

import numpy as np

from htetro_opt._interrupt import removed_on_exit

__all__ = ["cache_dir", "load_arrays", "source_key", "store_arrays"]

ENV = "HTETRO_OPT_CACHE_DIR"
"""The environment variable that moves the cache (or, set to ``off`` or empty, turns it off)."""


def cache_dir() -> Path | None:
    """The cache folder (not necessarily existing yet), or None when the cache is turned off."""
    given = os.environ.get(ENV)
    if given is not None:
        return None if given.strip() in ("", "off") else Path(given)
    if sys.platform == "win32":
        base = os.environ.get("LOCALAPPDATA") or os.path.join(os.path.expanduser("~"), "AppData", "Local")
    elif sys.platform == "darwin":
        base = os.path.join(os.path.expanduser("~"), "Library", "Caches")
    else:
        base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "htetro-opt"


def source_key(*files: str) -> str | None:
    """A short hash of the package's version and these files' bytes (None if one cannot be read: then
    nothing is cached, rather than cached under a key that would not see an edit)."""
    from htetro_opt import __version__

    digest = hashlib.sha256(__version__.encode())
    for name in files:
        try:
            digest.update(Path(name).read_bytes())
        except OSError:
            return None
    return digest.hexdigest()[:20]


def _path(name: str, key: str | None) -> Path | None:
    folder = cache_dir()
    return None if folder is None or key is None else folder / f"{name}-{key}.npz"


def load_arrays(name: str, key: str | None) -> dict[str, np.ndarray] | None:
    """The arrays stored under ``name`` and ``key``, or None if there is no readable entry."""
    path = _path(name, key)
    if path is None:
        return None
    try:
        with np.load(path, allow_pickle=False) as stored:
            return {k: stored[k] for k in stored.files}
    # Missing, unreadable, truncated or not a zip file at all: the caller builds the arrays again.
    except (OSError, ValueError, EOFError, KeyError, zipfile.BadZipFile):
        return None


def store_arrays(name: str, key: str | None, arrays: dict[str, np.ndarray]) -> bool:
    """Store ``arrays`` under ``name`` and ``key``, atomically; whether it was written (False when the
    cache is off or its folder cannot be written: never an error)."""
    path = _path(name, key)
    if path is None:
        return False
    tmp = None
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        handle, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
        with removed_on_exit(tmp), os.fdopen(handle, "wb") as out:  # also when a signal ends the process
            np.savez(out, **arrays)
        os.replace(tmp, path)
        return True
    except OSError:  # a read-only home, a full disk, a file where the folder should be: build next time
        return False
    finally:
        if tmp is not None and os.path.exists(tmp):
            os.unlink(tmp)
