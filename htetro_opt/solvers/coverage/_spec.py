"""The coverage task, declared once: :func:`~htetro_opt.solvers.coverage.plan_coverage`'s methods and
options (Cheng et al. 2019).

:data:`SPEC` is what ``plan_coverage``, the command line's ``cover`` and the study runner's ``cover``
task read (see :mod:`htetro_opt._spec`). Importing it loads no networkx or scipy.
"""

from __future__ import annotations

from htetro_opt._spec import (Method, Option, Problem, TaskSpec, additions, at_most, bytes_text, choice, integer,
                              real)
from htetro_opt._validation import check_bool, check_int, check_time_limit
from htetro_opt.errors import ParameterError, ScenarioError

__all__ = ["SPEC", "DEFAULT_LAYERS", "ENDS", "MOPUP_ORDERS", "STARTS", "STRIPES_ADDITIONS"]

STRIPES_ADDITIONS = {
    "fixed-regions": "a sweep is cut into regions every region_columns columns, on two grids offset by half a region "
                     "(the DAG takes the cheaper), each region searched in a window of 3 columns beyond its own; the "
                     "paper cuts a stripe only at its forced poses and searches each region in the whole stripe",
    "best-first": "a region is searched best-first (A*) over (vertex, covered cells), vertices revisited, with a "
                  "consistent bound that proves the optimum; the paper's Alg. 5 is a depth-first search over simple "
                  "paths that inserts a pose as a cut when no simple path covers the region",
    "greedy-fallback": "a region search that spends its node budget (or runs past the time limit) takes its best "
                       "walk so far, or the greedy walk (past the time limit only one chain of each sweep is priced, "
                       "each region by its greedy walk, no region searched); the paper's "
                       "search has no budget, so without it the region fails and the result lists it",
    "split-sweeps": "a stripe a wall splits into pieces is also planned piece by piece, the pieces joined by transit "
                    "legs, and the cheaper plan kept; the paper widens it until one piece covers it (Alg. 5 l. 14)",
    "sweep-order": "the order and directions of the sweeps are improved by moving or reversing one at a time while "
                   "the whole plan's cost drops; the paper sweeps the stripes as a boustrophedon",
    "shortest-joins": "consecutive stripes are joined by shortest paths in the workspace graph; the paper joins them "
                      "by its cut-edges, translations in one layer through both bands (Def. 9)",
    "mopup": "the cells the stripes leave uncovered are visited afterwards by a walk (in the mopup option's order); "
             "the paper has no such walk, so without it they are left uncovered and listed",
}
"""Our additions to Cheng et al. 2019's Alg. 5, by name: ``stripes`` runs them all, ``stripes-paper`` none; each
is switched on or off singly by the ``additions`` option (docs/papers/cheng2019.md). ``ends="both"`` (both
directions and folded sweeps) is a further option of ours, of ``stripes`` only and off by default (about four
times the work); ``memo`` is none: it gives the same plan."""

_PARAMETERS = {"region_columns": "fixed-regions", "mopup": "mopup"}  # option -> the addition it sets

DEFAULT_LAYERS = ("O", "vI", "hI")
"""The paper's best morphology set (Table 2: {O, vI, hI} with 4-row stripes)."""

ENDS = ("sweep", "both")
"""Where a stripe's sweep may be left: at its far end (the paper's cut-edges), or at either end."""

MOPUP_ORDERS = ("sequenced", "nearest")
"""How the cells the sweeps or lanes left are visited: 2-opt/Or-opt over exact leg costs, or nearest first."""

STARTS = ("scenario", "auto")
"""Where a scenario's plan starts: its roadmap's first pose (and ends at its last), or the bottom-left pose
of the first layer (a free end)."""


def _start(value, name):
    if value not in STARTS:
        raise ParameterError(f"{name} must be 'scenario' (the roadmap's first and last poses) or 'auto' (the "
                             f"bottom-left pose of the first layer, a free end), got {value!r}")
    return value


def _layers(value, name):
    """A morphology set: ``"O,vI"`` or ``["O", "vI"]`` (any form of ``parse_layers``), as its layers' names
    joined by commas."""
    from htetro_opt.errors import UnknownShapeError
    from htetro_opt.solvers.coverage._layers import parse_layers

    if not isinstance(value, (str, list, tuple)):
        raise ParameterError(f"{name} must be morphology layers such as 'O,vI,hI' or ['O', 'hI'], got {value!r}")
    try:
        return ",".join(layer.name for layer in parse_layers(value))
    except UnknownShapeError as err:
        raise ParameterError(f"{name}: {err.args[0]}") from None


def _stripes(value, name):
    """Stripe widths: a width (an int, or ``"4"``) or widths bottom up (``[2, 3, 2]`` or ``"2,3,2"``), each
    a positive integer; whether they fit a map is the planner's check, against the map's height."""
    if isinstance(value, str):  # the command line's "--stripes 2,3,2"
        parts = [p.strip() for p in value.split(",")]
        if not all(p.isdigit() for p in parts):
            raise ParameterError(f"{name} must be a width or comma-separated widths such as '2,3,2', got {value!r}")
        value = int(parts[0]) if len(parts) == 1 else [int(p) for p in parts]
    if isinstance(value, (list, tuple)):
        if not value:
            raise ParameterError(f"{name} must name at least one width, got {value!r}")
        return [check_int(v, f"{name}[{i}]", minimum=1) for i, v in enumerate(value)]
    try:
        return check_int(value, name, minimum=1)
    except ParameterError:
        raise ParameterError(f"{name} must be a width (an integer >= 1) or a list of widths bottom up, "
                             f"got {value!r}") from None


OPTIONS = (
    Option("shapes", _layers, "morphology layers: O, vI, hI or SHAPE@H, comma-separated",
           default=",".join(DEFAULT_LAYERS), stage="problem", metavar="LAYERS"),
    Option("start", _start, "scenario: the roadmap's first pose as start and last as goal (auto when the "
           "scenario has none); auto: the bottom-left pose of the first layer, a free end", default="scenario",
           stage="problem", choices=STARTS),
    Option("clearance", real(0.0), "clearance δ in cells around every block",
           default=0.0, type=float, metavar="δ"),
    Option("stripes", _stripes, "stripe width W (H // W bands, the last taking the remainder) or widths bottom up, "
           "e.g. 2,3,2", default=4, metavar="W|W1,W2,..."),
    Option("region_columns", integer(1), "columns of a region", default=4, type=int,
           metavar="N"),
    Option("budget", at_most(integer(1), 10_000_000, lambda v: f"search nodes a region may hold in memory, about "
                             f"{bytes_text(v * 200)}"), "search nodes per region search; past them the region takes "
           "its greedy walk (greedy-fallback) or fails (reported)", default=20_000, type=int, metavar="N"),
    Option("ends", choice(ENDS), "leave a stripe at its sweep's far end (sweep) or at either end (both: every "
           "stripe swept either way, or out and back; never costlier)", default="sweep", choices=ENDS),
    Option("mopup", choice(MOPUP_ORDERS), "how the cells the sweeps left are visited (the mopup addition): re-ordered "
           "by 2-opt and Or-opt over exact leg costs (sequenced), or nearest first", default="sequenced",
           choices=MOPUP_ORDERS),
    Option("additions", additions(STRIPES_ADDITIONS), "the stripes' additions of ours switched on: all, none, or "
           f"some of {', '.join(STRIPES_ADDITIONS)} (docs/papers/cheng2019.md)", metavar="NAMES"),
    Option("memo", check_bool, "memoise region searches by their content (False gives the same plan, slower)",
           default=True, flag="", study=False),
    Option("time_limit", check_time_limit, "seconds; near them the remaining regions take their greedy walk "
           "(greedy-fallback) or fail, and at them the DAG's search and the mop-up stop, leaving a partial plan "
           "(info.time_limit_cut says what was cut)", type=float, metavar="S", default_text="none"),
)

_PAPER = "Cheng et al. 2019"
_STRIPES = ("stripes", "region_columns", "budget", "mopup", "memo", "time_limit", "additions")

METHODS = (
    Method("stripes", "._stripes:plan_stripes", "the paper's stripes, regions and auxiliary DAG, with our "
           "readings and additions", (*_STRIPES, "ends"), defaults={"additions": tuple(STRIPES_ADDITIONS)},
           origin="ours", paper=_PAPER, family=("stripes",), revision=2),
    # Alg. 5 as published: cuts at forced poses, a depth-first search over simple paths with insertions, cut-edges
    # between stripes, no mop-up; a region search past its node budget fails (the paper's search has none)
    Method("stripes-paper", "._stripes:plan_stripes", "its Alg. 5 as published (simple paths, cuts at forced poses, "
           "no mop-up)", _STRIPES, defaults={"additions": ()}, origin="paper", paper=_PAPER, family=("stripes",),
           revision=2),
    Method("boustrophedon", "._baselines:boustrophedon_path", "lanes in the first layer (a baseline)",
           ("mopup",), origin="baseline", paper=_PAPER),
    Method("tiling-tsp", "._baselines:tiling_tsp_tokens", "tile with the shapes, order the tiles, drive through "
           "them (a baseline)", ("time_limit",), origin="baseline", paper=_PAPER),
)


def _pose(scenario, *, label, shapes, start) -> Problem:
    """A grid scenario's map and the morphology layers; with ``start="scenario"`` its roadmap's first and
    last poses as the plan's start and goal (a free start and end when it has none)."""
    from htetro_opt.scenarios import Scenario, load_scenario

    loaded = scenario if isinstance(scenario, Scenario) else load_scenario(scenario)
    if not isinstance(loaded, Scenario):
        raise ScenarioError(f"scenario {loaded.name!r} is continuous; coverage needs a grid scenario")
    ends = {}
    if start == "scenario" and loaded.roadmap:
        ends = {"start": loaded.start, "goal": loaded.goal}
    return Problem(loaded.name, (loaded.workspace, shapes), kwargs=ends, scenario=loaded)


def _relations(method: Method, given: dict, label) -> None:
    """An option given for an addition that is off is refused (it would change nothing)."""
    if not method.takes("additions"):
        return
    on = given.get("additions", method.defaults.get("additions", ()))
    for option, addition in _PARAMETERS.items():
        if option in given and addition not in on:
            raise ParameterError(f"{label(option)} sets the {addition} addition, which is off in {method.name}: "
                                 f"switch it on with {label('additions')} (e.g. {addition})")


SPEC = TaskSpec(
    "coverage", package="htetro_opt.solvers.coverage", entry="._dispatch:plan_coverage", options=OPTIONS,
    methods=METHODS, default="stripes", families={"stripes": "the stripes methods"},
    common=("shapes", "start", "clearance"), relations=_relations, pose=_pose,
)
"""The coverage task (see the module docstring). It has no exact method: a study measures a plan
against its lower bound on the action cost instead."""
