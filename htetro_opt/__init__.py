"""htetro-opt: path and coverage planning for the hinged-Tetromino (hTetro) reconfigurable robot."""

from htetro_opt.errors import (
    ConfigurationError,
    HtetroError,
    MapFormatError,
    OutputError,
    ParameterError,
    PlanningError,
    ScenarioError,
    TilesetFormatError,
    TilingError,
    UnknownCommandError,
    UnknownShapeError,
)

__version__ = "0.1.0"

__all__ = [
    "__version__",
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
    "OutputError",
]
