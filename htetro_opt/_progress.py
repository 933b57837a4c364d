"""Progress reports from long computations, with one callable type for every solver.

A ``progress`` argument is None (silent) or a callable ``progress(done, total, note)``: ``done`` and
``total`` count the unit of work the solver knows (generations, iterations, seconds of a time
budget; ``total`` None when unknown), ``note`` says what was reached so far (e.g. the best cost).
The command line turns the calls into a progress bar on stderr; a notebook can pass ``tqdm``'s or
its own. Solvers report at most a few times per second of work that takes longer than that.
"""

from __future__ import annotations

from typing import Callable, Optional

from htetro_opt.errors import ParameterError

__all__ = ["Progress", "check_progress", "report"]

Progress = Optional[Callable[[float, Optional[float], str], None]]


def check_progress(progress, name: str = "progress") -> Progress:
    """``progress`` if it is None or callable.

    Examples
    --------
    >>> check_progress(None) is None
    True
    >>> check_progress(3)
    Traceback (most recent call last):
    ...
    htetro_opt.errors.ParameterError: progress must be None or a callable progress(done, total, note), got 3
    """
    if progress is not None and not callable(progress):
        raise ParameterError(f"{name} must be None or a callable progress(done, total, note), got {progress!r}")
    return progress


def report(progress: Progress, done: float, total: float | None = None, note: str = "") -> None:
    """Call ``progress`` if there is one."""
    if progress is not None:
        progress(done, total, note)
