"""Each sequencing method's default time budget, sized to the instance.

A heuristic without a budget can run for many minutes on a large map (the plain GA went past ten
minutes on the 1004 waypoints of tiling_64x64); with these it ends in seconds to a minute, and
``time_limit`` overrides them. The exact method's and OR-Tools' defaults are theirs, the others are
``base + n / per`` seconds, capped; the geometric patterns take no budget (they are instant), nor
does ``lkh`` (elkai runs LKH for a number of runs).
"""

from __future__ import annotations

__all__ = ["default_time_limit", "TIME_LIMIT_TEXT"]

# method → (base seconds, waypoints per extra second, cap seconds)
_LINEAR = {"ga": (10.0, 50, 60.0), "ga-plain": (10.0, 50, 60.0), "greedy": (10.0, 100, 30.0),
           "local": (10.0, 100, 120.0), "fast-tsp": (0.5, 400, 30.0), "ils": (60.0, 20, 600.0)}

TIME_LIMIT_TEXT = ("exact: 60 s; ortools: 1 s up to 20 waypoints, rising to 30 s at 40 and beyond; "
                   "ga, ga-plain: 10 s + 1 s per 50 waypoints, at most 60 s; greedy: 10 s + 1 s per 100 "
                   "waypoints, at most 30 s; local: 10 s + 1 s per 100 waypoints, at most 120 s; "
                   "fast-tsp: 0.5 s + 1 s per 400 waypoints, at most 30 s; ils (a safety cap: its budget "
                   "is its kicks): 60 s + 1 s per 20 waypoints, at most 600 s; lkh: none (its runs); "
                   "zigzag, spiral: none (instant)")
"""The defaults of :func:`default_time_limit`, in words (the CLI's help shows it)."""


def default_time_limit(method: str, n: int) -> float | None:
    """The default wall-clock budget in seconds of ``method`` on ``n`` waypoints (None: none needed).

    Examples
    --------
    >>> default_time_limit("ga", 30), default_time_limit("ga", 1004), default_time_limit("greedy", 1004)
    (10.6, 30.08, 20.04)
    >>> default_time_limit("exact", 40), default_time_limit("ortools", 40), default_time_limit("zigzag", 10) is None
    (60.0, 30.0, True)
    """
    if method in _LINEAR:
        base, per, cap = _LINEAR[method]
        return round(min(cap, base + n / per), 6)
    if method == "exact":
        from htetro_opt.solvers.sequencing._spec import EXACT_TIME_LIMIT

        return EXACT_TIME_LIMIT
    if method == "ortools":
        from htetro_opt.solvers.sequencing._ortools import ortools_time_limit

        return ortools_time_limit(n)
    return None
