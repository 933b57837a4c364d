"""The exception hierarchy of htetro-opt.

Every error the library raises on bad input derives from :class:`HtetroError`, so that callers (and
the CLI) can catch one type. Each subclass also derives from the closest built-in exception, so code
written against ``ValueError`` or ``KeyError`` keeps working.
"""

from __future__ import annotations

__all__ = [
    "HtetroError",
    "ScenarioError",
    "MapFormatError",
    "ConfigurationError",
    "UnknownShapeError",
    "UnknownCommandError",
    "PlanningError",
    "ParameterError",
    "TilesetFormatError",
    "TilingError",
    "TilingTimeLimitError",
    "TilingWorkLimitError",
    "OutputError",
    "StudyError",
    "WorkerLost",
    "DependencyError",
]


class HtetroError(Exception):
    """Base class of every error raised by htetro-opt on bad input or an impossible request."""


class ScenarioError(HtetroError, ValueError):
    """A scenario file or map cannot be read: malformed TOML/YAML, missing or mistyped keys."""


class MapFormatError(ScenarioError):
    """A grid or image map is malformed: ragged rows, unknown characters, a bad PGM header."""


class ConfigurationError(HtetroError, ValueError):
    """A robot configuration is impossible: outside the map, colliding, or not a legal pose."""


class UnknownShapeError(HtetroError, KeyError):
    """A morphology name is not one of the robot's shapes."""

    def __str__(self) -> str:  # KeyError quotes its message; keep it readable
        return str(self.args[0]) if self.args else ""


class UnknownCommandError(HtetroError, KeyError):
    """A motion-command token is not in the command vocabulary of shared/MODEL.md §3."""

    def __str__(self) -> str:
        return str(self.args[0]) if self.args else ""


class PlanningError(HtetroError, RuntimeError):
    """A planner was asked something it cannot do (e.g. an empty roadmap)."""


class TilesetFormatError(MapFormatError):
    """A labelled tileset (Le et al. 2018) is malformed: an unknown token, a tile without one of its blocks a–d."""


class TilingError(PlanningError):
    """A workspace cannot be tiled with the allowed tetrominoes (area, parity, an isolated region)."""


class TilingTimeLimitError(TilingError):
    """The time limit ran out before a tiling was found or proven impossible: the map may still be
    tileable (unlike a plain :class:`TilingError`, which is a proof that it is not).

    Attributes
    ----------
    time_limit : float
        The limit, in seconds, that ran out.
    method : str
        The tiling method that ran.
    """

    def __init__(self, message: str, *, time_limit: float, method: str) -> None:
        super().__init__(message)
        self.time_limit = time_limit
        self.method = method


class TilingWorkLimitError(TilingTimeLimitError):
    """A work budget (``max_steps``, ``max_deterministic_time``) ran out before a tiling was found or
    proven impossible: as a :class:`TilingTimeLimitError`, whose subclass it is, the map may still be
    tileable; unlike the time limit, the budget ends the search at the same point on every machine.

    Attributes
    ----------
    budget : str
        The option that ran out.
    limit : float
        Its value.
    time_limit, method
        As in :class:`TilingTimeLimitError` (the time limit in force, which did not run out).
    """

    def __init__(self, message: str, *, budget: str, limit: float, time_limit: float, method: str) -> None:
        super().__init__(message, time_limit=time_limit, method=method)
        self.budget = budget
        self.limit = limit


class ParameterError(HtetroError, ValueError):
    """An option has an invalid value: a negative clearance or duration, an empty command set."""


class OutputError(HtetroError, OSError):
    """An output file (a tileset, plot, study table) cannot be written: a missing folder, a folder in
    the way, no permission, a full disk."""


class StudyError(ParameterError):
    """A study (a TOML file or a :class:`~htetro_opt.studies.Study` built in Python) is invalid: the
    message names the file, the method entry (``methods[i]``, counted from 0) and the key."""


class WorkerLost(HtetroError, RuntimeError):
    """A worker process of a study's ``processes`` executor died (killed, out of memory): the trials
    recorded so far are kept, and ``resume=True`` continues the study."""


class DependencyError(HtetroError, ImportError):
    """A core dependency of htetro-opt is missing or cannot be imported (a broken install): the
    message names it and how to install it."""
