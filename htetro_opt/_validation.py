"""One check per kind of option, shared by every module (scikit-learn's ``check_scalar`` idea).

Each check takes the value and the name the user knows it by (a keyword, or a CLI flag), returns
the value in its canonical type, and raises :class:`~htetro_opt.errors.ParameterError` naming both
the option and the value. A name that is a flag (``--seed``) gets the command line's words: what can
be typed there, no None, no Generator. ``bool`` is never accepted as a number: ``True`` passed for a size is a
mistake, not a 1.

Randomness has one meaning everywhere (networkx's rule): ``seed=None`` draws fresh entropy; an int
or a ``numpy.random.Generator`` makes a run reproducible. :func:`as_rng` turns any of them into a
Generator, and :func:`derive_seed` into the plain integer that libraries with their own generators
need (pymoo's ``minimize``, DEAP's ``random.Random``, CP-SAT, OR-Tools).
"""

from __future__ import annotations

import math
import numbers

import numpy as np

from htetro_opt.errors import ParameterError

__all__ = ["check_int", "check_real", "check_probability", "check_time_limit", "check_bool", "as_rng",
           "derive_seed", "check_seed"]


def check_int(value, name: str, *, minimum: int | None = None, maximum: int | None = None,
              allow_none: bool = False) -> int | None:
    """An integer in ``[minimum, maximum]`` (either bound optional); None passes with ``allow_none``.

    Examples
    --------
    >>> check_int(5, "pop_size", minimum=2)
    5
    >>> check_int(True, "pop_size", minimum=2)
    Traceback (most recent call last):
    ...
    htetro_opt.errors.ParameterError: pop_size must be an integer of at least 2, got True
    """
    if value is None and allow_none:
        return None
    bad = isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Integral)
    if not bad:
        value = int(value)
        bad = (minimum is not None and value < minimum) or (maximum is not None and value > maximum)
    if bad:
        raise ParameterError(f"{name} must be {_int_range(minimum, maximum)}{_or_none(name, allow_none)}, "
                             f"got {value!r}")
    return value


def _or_none(name: str, allow_none: bool) -> str:
    """" or None" where None is a value the user can give (not on the command line, where it is a flag left out)."""
    return " or None" if allow_none and not name.startswith("--") else ""


def _int_range(minimum, maximum) -> str:
    if minimum is not None and maximum is not None:
        return f"an integer in [{minimum}, {maximum}]"
    if minimum is not None:
        return {0: "a non-negative integer", 1: "a positive integer"}.get(minimum, f"an integer of at least {minimum}")
    if maximum is not None:
        return f"an integer of at most {maximum}"
    return "an integer"


def check_real(value, name: str, *, minimum: float | None = None, maximum: float | None = None,
               include_minimum: bool = True, include_maximum: bool = True, finite: bool = True,
               allow_none: bool = False) -> float | None:
    """A real number within the given bounds (inclusive unless told otherwise), finite by default.

    Examples
    --------
    >>> check_real(0.5, "clearance", minimum=0)
    0.5
    >>> check_real(float("nan"), "speed", minimum=0, include_minimum=False)
    Traceback (most recent call last):
    ...
    htetro_opt.errors.ParameterError: speed must be a finite number > 0, got nan
    """
    if value is None and allow_none:
        return None
    ok = not isinstance(value, (bool, np.bool_)) and isinstance(value, numbers.Real)
    if ok:
        value = float(value)
        ok = not math.isnan(value) and (math.isfinite(value) or not finite)
        if ok and minimum is not None:
            ok = value >= minimum if include_minimum else value > minimum
        if ok and maximum is not None:
            ok = value <= maximum if include_maximum else value < maximum
    if not ok:
        bounds = []
        if minimum is not None:
            bounds.append(f"{'>=' if include_minimum else '>'} {minimum:g}")
        if maximum is not None:
            bounds.append(f"{'<=' if include_maximum else '<'} {maximum:g}")
        what = ("a finite number" if finite else "a number") + (" " + " and ".join(bounds) if bounds else "")
        raise ParameterError(f"{name} must be {what}{_or_none(name, allow_none)}, got {value!r}")
    return value


def check_probability(value, name: str) -> float:
    """A probability in [0, 1].

    Examples
    --------
    >>> check_probability(1, "crossover_rate")
    1.0
    """
    return check_real(value, name, minimum=0.0, maximum=1.0)


def check_bool(value, name: str) -> bool:
    """``True`` or ``False`` (numpy's too), nothing else.

    Examples
    --------
    >>> check_bool(np.True_, "memetic")
    True
    """
    if not isinstance(value, (bool, np.bool_)):
        raise ParameterError(f"{name} must be True or False, got {value!r}")
    return bool(value)


MAX_TIME_LIMIT = 1e7
"""Largest accepted time limit in seconds (about 116 days): beyond it the solvers' own timers
(OR-Tools', CP-SAT's) overflow, and no run here is meant to last longer."""


def check_time_limit(value, name: str = "time_limit") -> float | None:
    """A wall-clock budget in seconds: None (the method's default, which each method documents), or
    a positive finite number up to :data:`MAX_TIME_LIMIT`.

    One rule for every method: zero, negative, NaN and infinite budgets are refused (a search such as
    OR-Tools' guided local search never ends by itself, so "no limit" is not on offer).

    Examples
    --------
    >>> check_time_limit(None), check_time_limit(2)
    (None, 2.0)
    >>> check_time_limit(float("inf"))
    Traceback (most recent call last):
    ...
    htetro_opt.errors.ParameterError: time_limit must be a positive, finite number of seconds (at most 1e+07) or None, got inf
    """
    if value is None:
        return None
    ok = not isinstance(value, (bool, np.bool_)) and isinstance(value, numbers.Real) and 0 < value <= MAX_TIME_LIMIT
    if not ok:
        raise ParameterError(f"{name} must be a positive, finite number of seconds (at most {MAX_TIME_LIMIT:g})"
                             f"{_or_none(name, True)}, got {value!r}")
    return float(value)


def check_seed(seed, name: str = "seed"):
    """``seed`` unchanged if it is None, a non-negative integer or a ``numpy.random.Generator``.

    Examples
    --------
    >>> check_seed(-1)
    Traceback (most recent call last):
    ...
    htetro_opt.errors.ParameterError: seed must be None, a non-negative integer or a numpy.random.Generator, got -1
    """
    if seed is None or isinstance(seed, np.random.Generator):
        return seed
    if isinstance(seed, (bool, np.bool_)) or not isinstance(seed, numbers.Integral) or seed < 0:
        if name.startswith("--"):
            raise ParameterError(f"{name} must be a non-negative integer, got {seed!r}")
        raise ParameterError(f"{name} must be None, a non-negative integer or a numpy.random.Generator, got {seed!r}")
    return int(seed)


def as_rng(seed, name: str = "seed") -> np.random.Generator:
    """A ``numpy.random.Generator`` for ``seed``: fresh entropy for None, reproducible for an int; a
    Generator is returned as it is (so the caller's stream advances).

    Examples
    --------
    >>> float(as_rng(1).random()) == float(as_rng(1).random())
    True
    >>> g = np.random.default_rng(0); as_rng(g) is g
    True
    """
    seed = check_seed(seed, name)
    return seed if isinstance(seed, np.random.Generator) else np.random.default_rng(seed)


def derive_seed(seed, name: str = "seed") -> int:
    """A 31-bit integer seed for a library with its own generator (pymoo, DEAP's ``random.Random``,
    CP-SAT, OR-Tools): the int itself (reduced to 31 bits), one drawn from a Generator, fresh for None.

    Examples
    --------
    >>> derive_seed(7), derive_seed(2**40) == 2**40 % (2**31 - 1)
    (7, True)
    """
    seed = check_seed(seed, name)
    if isinstance(seed, int):
        return seed % (2**31 - 1)
    return int(as_rng(seed).integers(0, 2**31 - 1))
