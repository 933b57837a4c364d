"""The tiling task, declared once: :func:`~htetro_opt.solvers.tiling.tile_workspace`'s methods and options
(Le et al. 2018).

:data:`SPEC` is what ``tile_workspace``, the command line's ``tile`` and the study runner's ``tile`` task
read (see :mod:`htetro_opt._spec`). Importing it loads no OR-Tools or numba.
"""

from __future__ import annotations

from htetro_opt._spec import Method, Option, Problem, TaskSpec, integer, real, seed_option, unchecked
from htetro_opt._validation import check_bool, check_time_limit
from htetro_opt.errors import ParameterError, ScenarioError

__all__ = ["SPEC", "DEFAULT_TIME_LIMIT", "shape_letters"]

DEFAULT_TIME_LIMIT = 60.0
"""The tiler's time limit in seconds when none is given: past it, a map neither tiled nor proven
untileable raises :class:`~htetro_opt.errors.TilingTimeLimitError`."""


def shape_letters(value, name):
    """Morphology letters (``"TZ"``, or a list of names), or None for all seven."""
    from htetro_opt.model.robot import SHAPES

    if value is None:
        return None
    if isinstance(value, (list, tuple)) and all(isinstance(v, str) for v in value):
        value = "".join(value)
    if not isinstance(value, str) or not value or any(letter not in SHAPES for letter in value):
        raise ParameterError(f"{name} must be morphology letters of {''.join(SHAPES)} such as 'TZ', got {value!r}")
    return value


def _weights(value, name):
    from htetro_opt.solvers.sequencing._spec import SPEC as SEQUENCING  # the one check of eq. 2's weights

    return SEQUENCING.options["weights"].check(value, name)


OPTIONS = (
    Option("shapes", shape_letters, "allowed morphologies, e.g. TZ or O", metavar="LETTERS",
           default_text="all seven, IOLJZST"),
    Option("shuffle", check_bool, "shuffle the placement order by --seed, for another tiling (default: the fixed "
           "order)", default=False, type=bool),
    seed_option("with --shuffle: its random seed"),
    Option("time_limit", check_time_limit, "give up after this many seconds", default=DEFAULT_TIME_LIMIT, type=float,
           metavar="S"),
    # Budgets of work, the same on every machine (the time limit depends on the machine and its load):
    # with one of them and a time limit that does not run out, a call ends the same way everywhere.
    Option("max_steps", integer(1, none=True), "give up after this many search steps (placements tried; the "
           "same on every machine)", type=int, metavar="N", default_text="none, only the time limit"),
    Option("max_deterministic_time", real(0.0, above=True, none=True), "give up after CP-SAT has spent this much "
           "of its deterministic time (its own unit, about a second, the same on every machine; auto: on its "
           "last stage, CP-SAT region by region, the earlier stages having fixed budgets of their own)",
           type=float, metavar="D", default_text="none, only the time limit"),
    Option("overlap", check_bool, "if the map cannot be tiled, cover it by two overlapping sub-workspaces (the "
           "paper's Fig. 5)", default=False, type=bool),
    Option("weights", _weights, "α, β, λ, γ of eq. 2, for Algorithm 1's choice among a symmetric tile's labellings",
           default=(0.25,) * 4, metavar="A,B,C,D"),
    Option("name", unchecked, "the tileset's name", default="", flag="", study=False),
)

_OPTIONS = ("shapes", "shuffle", "seed", "time_limit", "overlap", "weights", "name")
_BUDGETS = {"auto": ("max_deterministic_time",), "backtracking": ("max_steps",), "cpsat": ("max_deterministic_time",)}
"""The work budget each method takes: the backtracker counts steps, CP-SAT its deterministic time."""
_PAPER = "Le et al. 2018"


def _shuffled(options) -> bool:
    return bool(options.get("shuffle", False))


METHODS = (
    Method("auto", None, "backtracking for a few steps, then a compiled sweep repaired by small exact covers, then "
           "CP-SAT band by band, then region by region", _OPTIONS + _BUDGETS["auto"], seeded=_shuffled, exact=True,
           origin="ours"),
    Method("backtracking", None, "the paper's search", _OPTIONS + _BUDGETS["backtracking"], seeded=_shuffled,
           exact=True, origin="paper",
           paper=_PAPER),
    Method("cpsat", None, "exact cover with OR-Tools CP-SAT", _OPTIONS + _BUDGETS["cpsat"], seeded=_shuffled,
           exact=True, origin="ours"),
)


def _pose(scenario, *, label) -> Problem:
    """A grid scenario's map, the tileset named after it."""
    from htetro_opt.scenarios import Scenario, load_scenario

    loaded = scenario if isinstance(scenario, Scenario) else load_scenario(scenario)
    if not isinstance(loaded, Scenario):
        raise ScenarioError(f"scenario {loaded.name!r} is continuous; tiling needs a grid scenario")
    return Problem(loaded.name, (loaded.workspace,), kwargs={"name": loaded.name}, scenario=loaded)


def _solve(spec: TaskSpec, problem: Problem, method, options: dict):
    return spec.entry_point()(*problem.args, method=method, **{**problem.kwargs, **options})


SPEC = TaskSpec(
    "tiling", package="htetro_opt.solvers.tiling", entry="._tiling:tile_workspace", options=OPTIONS,
    methods=METHODS, default="auto", pose=_pose, solve=_solve,
)
"""The tiling task (see the module docstring). Every method is complete: it tiles the map or proves that
no tiling exists, within its time limit (and its work budget, if given)."""
