"""htetro-opt: path and coverage planning for the hinged-Tetromino (hTetro) reconfigurable robot.

Five papers' planning jobs as formal, reusable problems on one robot model, each solved by one entry
point with ``method=`` (its methods, their options, defaults and capabilities declared once in the
task's spec, ``htetro_opt.solvers.<task>.SPEC``):

- :func:`htetro_opt.solvers.plan_path`: a path through a grid scenario's roadmap — the exact
  minimum-time plan (Dijkstra, A*), Cheng et al. 2020's hTetro-GA and pymoo's algorithms over motion-
  command chromosomes, Do et al. 2021's heat-conduction planner;
- :func:`htetro_opt.solvers.plan_continuous`: paths in a continuous workspace — Nazarahari et al.
  2019's enhanced GA, its baselines and the visibility-graph optimum;
- :func:`htetro_opt.solvers.tile_workspace` and :func:`htetro_opt.solvers.sequence_waypoints`: Le et
  al. 2018's tetromino tiling and its waypoints' TSP (exact, OR-Tools, the paper's GA, ILS, baselines);
- :func:`htetro_opt.solvers.plan_coverage`: Cheng et al. 2019's complete coverage by stripes of
  morphology layers, and its baselines.

Every result has ``method``, ``success``, ``message``, ``runtime_s``, ``info`` and ``as_dict()``
(:class:`htetro_opt.solvers.Result`). The layers, each importing only those below it:
:mod:`htetro_opt.model` (the grid, the robot's footprints and commands, the swept-area simulator; the
continuous geometry), :mod:`htetro_opt.scenarios` (scenario, tileset, ROS-map and TSPLIB files),
:mod:`htetro_opt.problems` and :mod:`htetro_opt.operators` (pymoo problems and operators),
:mod:`htetro_opt.algorithms`, :mod:`htetro_opt.solvers`, :mod:`htetro_opt.studies` (the papers'
experiments at scale), and on top :mod:`htetro_opt.viz` and the ``htetro-opt`` command line.

Every error the package raises on bad input is an :class:`HtetroError` (exported here); randomness
comes from one ``seed`` (None: fresh entropy; an int or a ``numpy.random.Generator``: reproducible;
0 by default). Importing the package imports no solver library.
"""

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
