"""The one hTetro robot model shared by every method (shared/MODEL.md): geometry, commands, sweeps,
workspaces, the batch simulator and the coverage motion model, and the continuous workspaces of
Nazarahari et al. 2019 (:mod:`~htetro_opt.model.continuous`; with the geometry that the path-bases
problem, its operators and the continuous planners share: the lattice and its APF initial paths,
:func:`apf_population`, and the visibility graph's shortest path, :func:`visibility_path`; all
loaded on first use: they import shapely). It imports nothing of htetro_opt above it (only its errors
and option checks)."""

from htetro_opt.model.commands import (
    COMMANDS,
    DIAGONAL_COMMANDS,
    SEED000_COMMANDS,
    SEED004_COMMANDS,
    TOKENS,
    Command,
    Timing,
    command_id,
    command_set,
    format_commands,
    parse_commands,
)
from htetro_opt.model.coverage import CoverageResult, simulate_coverage
from htetro_opt.model.robot import FOOTPRINTS, N_NAMED, N_STATES, SHAPES, STATE_NAMES, Pose, block_poses, shape_index
from htetro_opt.model.simulate import SimulationResult, Simulator, simulate, transitions_at
from htetro_opt.model.sweeps import SweepTables, sweep_tables
from htetro_opt.model.workspace import MovingObstacle, Workspace, grid_distance

_CONTINUOUS = {  # name → the module that defines it, loaded on first use (shapely)
    **{name: "continuous" for name in ("ContinuousGeometry", "Corners", "SAFETY_MARGIN", "as_polygon",
                                       "as_robot_radius", "enclosing_radius", "path_length", "path_smoothness",
                                       "robot_distance")},
    "lattice_graph": "_lattice",
    **{name: "_apf" for name in ("apf_depths", "apf_paths", "apf_population", "turning_points")},
    "visibility_path": "_visibility",
}

__all__ = [
    "COMMANDS", "DIAGONAL_COMMANDS", "SEED000_COMMANDS", "SEED004_COMMANDS", "TOKENS", "Command", "Timing",
    "command_id", "command_set", "format_commands", "parse_commands",
    "FOOTPRINTS", "N_NAMED", "N_STATES", "SHAPES", "STATE_NAMES", "Pose", "block_poses", "shape_index",
    "SimulationResult", "Simulator", "simulate", "transitions_at", "SweepTables", "sweep_tables",
    "MovingObstacle", "Workspace", "grid_distance",
    "CoverageResult", "simulate_coverage",
    *_CONTINUOUS,
]


def __getattr__(name: str):
    if name in _CONTINUOUS:  # shapely loads only when the continuous geometry is used
        from importlib import import_module

        return getattr(import_module(f"{__name__}.{_CONTINUOUS[name]}"), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
