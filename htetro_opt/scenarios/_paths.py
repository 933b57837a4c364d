"""The one check of a file-path argument of the scenario readers and writers."""

from __future__ import annotations

import os
import reprlib
from pathlib import Path

from htetro_opt.errors import ScenarioError

__all__ = ["as_path"]


def as_path(value, name: str, error: type[Exception] = ScenarioError, *, expected: str = "a file path") -> Path:
    """``value`` as a Path if it is a ``str`` or an ``os.PathLike`` (``expected`` says what it names).

    Raises
    ------
    ScenarioError (or ``error``)
        Naming ``name`` and what it got.

    Examples
    --------
    >>> as_path(123, "path")
    Traceback (most recent call last):
    ...
    htetro_opt.errors.ScenarioError: path must be a file path (str or os.PathLike), got int 123
    """
    if isinstance(value, (str, os.PathLike)):
        return Path(value)
    raise error(f"{name} must be {expected} (str or os.PathLike), got {type(value).__name__} {reprlib.repr(value)}")
