"""The continuous-path task, declared once: :func:`~htetro_opt.solvers.continuous.plan_continuous`'s
methods and options (Nazarahari et al. 2019).

:data:`SPEC` is what ``plan_continuous``, the command line's ``plan`` (on continuous scenarios) and the
study runner's ``plan`` task read (see :mod:`htetro_opt._spec`). Importing it loads no pymoo, shapely
or OMPL.
"""

from __future__ import annotations

from htetro_opt._spec import (
    Method,
    Option,
    Problem,
    TaskSpec,
    additions,
    at_most,
    bytes_text,
    choice,
    duration_text,
    integer,
    real,
    seed_option,
)
from htetro_opt._validation import check_bool, check_time_limit
from htetro_opt.algorithms.names import EGA_ADDITIONS  # plain data: the EGA's additions, named once
from htetro_opt.errors import ParameterError, ScenarioError

__all__ = ["SPEC", "EGA_ADDITIONS", "PATH_KINDS", "SAFETY_KINDS", "RRT_TIME_LIMIT"]

PATH_KINDS = ("linear", "spline")
"""How a chromosome's path bases are joined: straight segments, or a cubic spline through them."""

SAFETY_KINDS = ("paper", "min")
"""The safety term: eq. 5's sum of the path bases' clearances, or the smallest clearance along the path."""

RRT_TIME_LIMIT = 120.0
"""The paper's time limit of its B-RRT, in seconds per robot."""


def _weights(value, name):
    from htetro_opt.problems.path_bases import check_path_weights  # pymoo: loaded when checked

    if isinstance(value, str):  # the command line's "1,0,0"
        try:
            value = tuple(float(v) for v in value.split(","))
        except ValueError:
            raise ParameterError(f"{name} must be three comma-separated numbers W_L,W_S,W_R, got {value!r}") from None
    return None if value is None else check_path_weights(value, name)


def _radius(value, name):
    from htetro_opt.model.continuous import as_robot_radius  # shapely: loaded when checked

    if value is None:
        return None
    if isinstance(value, str):
        try:
            value = float(value)
        except ValueError:  # a morphology letter
            pass
    return as_robot_radius(value, name)


OPTIONS = (
    Option("robot_radius", _radius, "the robots' radius instead of the scenario's, a number or a morphology letter "
           "(the disc around that hTetro footprint, e.g. O)", metavar="R|SHAPE", stage="problem", reference=True,
           default_text="the scenario's"),
    Option("grid", real(0.0, above=True), "the lattice spacing (the APF "
           "lattice and the mutations' step of the GAs)", default=1.0, type=float, metavar="D"),
    Option("path", choice(PATH_KINDS), "straight between the path bases or a cubic spline", default="linear",
           choices=PATH_KINDS),
    Option("weights", _weights, "W_L,W_S,W_R of eq. 6", metavar="W_L,W_S,W_R", default_text="1,0,0"),
    Option("normalise", check_bool, "weights from three single-term runs (Nazarahari et al. 2019, §5.3) instead of "
           "--weights", default=False, type=bool),
    Option("safety", choice(SAFETY_KINDS), "eq. 5's sum of the path bases' clearances (paper) or the smallest "
           "clearance along the path (min)", default="paper", choices=SAFETY_KINDS),
    Option("pop_size", at_most(integer(2), 10_000, lambda v: "would hold that many initial APF paths and their "
                               f"path bases for every robot, about {bytes_text(v * 100_000)}"),
           "population size", default=10, type=int, metavar="N"),
    Option("max_gen", at_most(integer(0), 100_000, lambda v: f"generations would take {duration_text(v * 1e-2)} or "
                              "more at ten milliseconds each"), "generations", default=20, type=int, metavar="N"),
    seed_option(),
    Option("additions", additions(EGA_ADDITIONS), "the enhanced GA's additions of ours switched on: all, none, or "
           f"some of {', '.join(EGA_ADDITIONS)} (docs/papers/nazarahari2019.md)", metavar="NAMES"),
    Option("n", integer(1, none=True), "the roadmap's samples", flag="",
           default_text="the paper's per map"),
    Option("radius", real(0.0, above=True, none=True),
           "the roadmap's connection radius", flag="", default_text="the paper's per map"),
    Option("time_limit", check_time_limit, "seconds per robot before giving up", default=RRT_TIME_LIMIT, type=float,
           metavar="S"),
)

_GA = ("path", "safety", "grid", "pop_size", "max_gen", "seed")
_PAPER = "Nazarahari et al. 2019"

METHODS = (
    Method("exact", "._exact:plan_exact", "the shortest path of each robot alone over the visibility graph of the "
           "free space's corners (the optimum for a point robot)", exact=True, origin="reference"),
    Method("ega", "._ega:plan_ega", "the enhanced GA over path bases with our additions, all robots jointly",
           (*_GA, "weights", "normalise", "additions"), defaults={"additions": tuple(EGA_ADDITIONS)}, seeded=True,
           origin="ours", paper=_PAPER, family=("ga",)),
    # §4.3 as published: deletion of one roulette pick per generation in one sequential pass, every child kept,
    # the APF at step d only
    Method("ega-paper", "._ega:plan_ega_paper", "the same GA as published", (*_GA, "weights", "normalise", "additions"),
           defaults={"additions": ()}, seeded=True, origin="paper", paper=_PAPER, family=("ga",), revision=2),
    Method("nsga2", "._ega:plan_nsga2", "pymoo's NSGA-II over the same path bases, minimising (length, smoothness, "
           "-safety); the front in the JSON", _GA, defaults={"safety": "min"}, seeded=True, origin="library",
           family=("ga",)),
    Method("astar", "._astar:plan_astar", "A* on the --grid lattice, each robot alone", ("grid",), origin="baseline",
           paper=_PAPER),
    Method("prm", "._prm:plan_prm", "a roadmap of the paper's samples per map, then deletion, each robot alone",
           ("n", "radius", "seed"), seeded=True, origin="baseline", paper=_PAPER),
    Method("rrt", "._rrt:plan_rrt", "OMPL's RRTConnect (the paper's B-RRT), then deletion, each robot alone",
           ("time_limit", "seed"), seeded=True, origin="baseline", paper=_PAPER, requires="ompl"),
    Method("pso", "._pso:plan_pso", "pymoo's PSO over the path bases from the APF paths, each robot alone",
           ("pop_size", "max_gen", "grid", "seed"), seeded=True, origin="baseline", paper=_PAPER),
)


def _pose(scenario, *, label, robot_radius) -> Problem:
    """A continuous scenario (a bundled name, a file or a loaded one), with another robot radius if given."""
    from htetro_opt.scenarios import ContinuousScenario, load_scenario

    loaded = scenario if isinstance(scenario, ContinuousScenario) else load_scenario(scenario)
    if not isinstance(loaded, ContinuousScenario):
        raise ScenarioError(f"scenario {loaded.name!r} is a grid scenario; this task plans continuous ones")
    if robot_radius is not None:
        loaded = loaded.with_robot_radius(robot_radius)
    return Problem(loaded.name, (loaded,), scenario=loaded)


SPEC = TaskSpec(
    "continuous planning", package="htetro_opt.solvers.continuous", entry="._dispatch:plan_continuous",
    options=OPTIONS, methods=METHODS, default="exact", exact="exact",
    families={"ga": "the GA methods"}, common=("robot_radius",), pose=_pose,
)
"""The continuous-path task (see the module docstring)."""
