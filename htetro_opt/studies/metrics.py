"""Mean ± standard deviation over trial records (flat dicts), skipping what a trial could not measure.

A study's trials are flat records (one dict per run). A field a run could not measure (the reach
generation of a run that never reached, say) holds None; the helpers here skip such entries, and
report None rather than a number when nothing is left.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Hashable, Iterable, Mapping, Sequence
from typing import Any

import numpy as np

from htetro_opt._validation import check_int

__all__ = ["format_mean_std", "group_records", "mean_std", "values_of"]


def values_of(
    records: Iterable[Mapping[str, Any]],
    key: str,
    *,
    where: Callable[[Mapping[str, Any]], bool] | None = None,
) -> list[float]:
    """The finite numeric values of ``key`` over the records, skipping None, NaN and absent keys.

    Parameters
    ----------
    records : iterable of mapping
    key : str
    where : callable, optional, keyword-only
        Keep only the records for which it returns True.

    Returns
    -------
    list of float

    Examples
    --------
    >>> values_of([{"a": 1}, {"a": None}, {"b": 2}, {"a": True}], "a")
    [1.0, 1.0]
    """
    out = []
    for record in records:
        if where is not None and not where(record):
            continue
        value = record.get(key)
        if value is None:
            continue
        value = float(value)
        if math.isfinite(value):
            out.append(value)
    return out


def mean_std(values: Iterable[float | None], *, ddof: int = 1) -> tuple[float | None, float | None]:
    """Mean and standard deviation of the values that are not None.

    Parameters
    ----------
    values : iterable of float or None
    ddof : {0, 1}, keyword-only
        Delta degrees of freedom: 1 (default) for the sample standard deviation, 0 for the
        population one.

    Returns
    -------
    (mean, std)
        ``(None, None)`` when no value is left; ``std`` is None when there are no more values than
        ``ddof`` (a single value's sample spread is undefined).

    Raises
    ------
    ParameterError
        If ``ddof`` is not 0 or 1.

    Examples
    --------
    >>> mean_std([1.0, 2.0, 3.0, None])
    (2.0, 1.0)
    >>> mean_std([4.0])
    (4.0, None)
    >>> mean_std([])
    (None, None)
    """
    ddof = check_int(ddof, "ddof", minimum=0, maximum=1)
    data = np.array([float(v) for v in values if v is not None], dtype=float)
    if data.size == 0:
        return None, None
    mean = float(data.mean())
    std = float(data.std(ddof=ddof)) if data.size > ddof else None
    return mean, std


def format_mean_std(mean: float | None, std: float | None = None, *, digits: int = 2) -> str:
    """``"mean ± std"`` with ``digits`` decimals; ``"–"`` for a missing mean, the bare mean for a
    missing spread.

    Examples
    --------
    >>> format_mean_std(210.6, 27.56)
    '210.60 ± 27.56'
    >>> format_mean_std(0.5, None, digits=3), format_mean_std(None, None)
    ('0.500', '–')
    """
    if mean is None:
        return "–"
    if std is None:
        return f"{mean:.{digits}f}"
    return f"{mean:.{digits}f} ± {std:.{digits}f}"


def group_records(
    records: Iterable[Mapping[str, Any]], keys: Sequence[str]
) -> dict[tuple[Hashable, ...], list[Mapping[str, Any]]]:
    """Records grouped by the values of ``keys``, groups in order of first appearance.

    Examples
    --------
    >>> groups = group_records([{"e": "a", "n": 1}, {"e": "b", "n": 1}, {"e": "a", "n": 1}], ["e", "n"])
    >>> {k: len(v) for k, v in groups.items()}
    {('a', 1): 2, ('b', 1): 1}
    """
    groups: dict[tuple[Hashable, ...], list[Mapping[str, Any]]] = {}
    for record in records:
        groups.setdefault(tuple(record.get(k) for k in keys), []).append(record)
    return groups
