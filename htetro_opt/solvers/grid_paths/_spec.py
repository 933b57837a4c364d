"""The grid-path task, declared once: :func:`~htetro_opt.solvers.grid_paths.plan_path`'s methods and options.

:data:`SPEC` is what ``plan_path``, the command line's ``plan`` (on grid scenarios) and the study runner's
``plan`` task read (see :mod:`htetro_opt._spec`). Importing it loads no pymoo, numba or scikit-fem.
"""

from __future__ import annotations

import math

from htetro_opt._spec import (
    Method,
    Option,
    Problem,
    TaskSpec,
    additions,
    at_most,
    bytes_text,
    callback,
    choice,
    duration_text,
    integer,
    real,
    seed_option,
    unchecked,
)
from htetro_opt._validation import check_bool, check_int, check_time_limit
from htetro_opt.algorithms import CONVERGENCE_MEASURES, GA_ADDITIONS, PICKS
from htetro_opt.errors import ParameterError, PlanningError, ScenarioError

__all__ = ["SPEC", "HEAT_ADDITIONS", "HEAT_ELEMENTS", "HEAT_ENGINES", "BAND_SEEDS", "GA_PATIENCE", "PAPER_MAX_LENGTH",
           "PAPER_PATIENCE", "TABLE6_WEIGHTS", "check_bytes"]

HEAT_ADDITIONS = {
    "pinch-split": "the field's bilinear mesh gives a node where two free cells touch only at a corner one copy "
                   "per element, so no heat leaks where no robot passes (the paper's mesh shares the node)",
    "converge": "the reaching waves run until nothing improves (a shortest-path search: the leg's optimum under "
                "the field's rule) instead of stopping when the goal enters the list (§V-B step 4)",
    "surrogate-cost": "the search minimises a sum over commands, eq. 12 with the smoothness and safety terms "
                      "divided by the length of the leg's time-only plan, in place of the paper's tentative cost "
                      "(eqs. 9-12 of the tentative path, over its own length)",
    "exact-pick": "each leg's plan is the best by the exact eqs. 9-12 among the searches for the asked weights "
                  "and for Table 6's four weightings, so that a weighting's plan scores at least as well by its "
                  "own cost as any other row's",
    "relax-fallback": "a leg with no path that never goes down the field takes the unconstrained optimum "
                      "(info relaxed) instead of failing",
    "band": "on maps above 4 million poses the search is restricted to a band around the field's ascent line, "
            "widened until a path is found (options band, band_seed)",
}
"""Our additions to Do et al. 2021's planner (§V), by name: ``heat`` runs them all, ``heat-paper`` (the
paper's) none; each is switched on or off by the ``additions`` option (docs/papers/do2021.md)."""

TABLE6_WEIGHTS = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0), (1.0, 1.0, 1.0))
"""Do et al. 2021's Table-6 weightings (w_t, w_sm, w_sf) of eq. 12: time, smoothness, safety, multi-objective."""

HEAT_ELEMENTS = ("q1", "p0")
"""Elements :func:`~htetro_opt.solvers.grid_paths.solve_heat_field` knows: the bilinear quadrilateral
(the paper's) and DG0 (ours)."""

HEAT_ENGINES = ("dijkstra", "wavefront")
"""The heat planner's searches of a leg: scipy's Dijkstra, or the paper's waves relaxed to convergence
(same optimum)."""

BAND_SEEDS = ("ascent", "grid_distance")
"""Lines the heat planner's band follows: the field's steepest-ascent line, or a shortest cell path
(an ablation)."""

GA_PATIENCE = {"best": 100, "hypervolume": 20}
"""The GAs' patience by convergence measure, when ``patience`` is not given (measured: see plan_ga)."""

PAPER_MAX_LENGTH = 100
"""htetro-ga-paper's l_p,max: Cheng et al. 2020, §V-B3, "l_p,max = 200 is chosen for spiral obstacle
environment, and l_p,max = 100 is selected for other environments" (a study gives the spiral its 200)."""

PAPER_PATIENCE = 10
"""htetro-ga-paper's patience, our reading: the paper stops on "the convergence of the solution" (§IV-A)
without saying when a solution has converged. Its Table 4 ends a run 13–42 generations (means per
row) after the first goal-reaching one, which a patience of more than about 13 generations cannot
give; 10 is the round number below."""


MAX_POPULATION = 100_000
"""The largest ``pop_size`` of the GAs: each member holds a chromosome of a hundred and more commands and its
simulation, about 10 kB (1 GB at this size)."""

MAX_GENERATIONS = 1_000_000
"""The largest ``max_gen`` of the GAs: a generation takes about a millisecond or more (17 minutes a leg at this
size), so a larger one is a mistake rather than a plan."""


def _population(value: int) -> str:
    return f"would hold that many chromosomes and their simulations, about {bytes_text(value * 10_000)}"


def _generations(value: int) -> str:
    return f"generations would take {duration_text(value * 1e-3)} or more a leg at a millisecond each"


_UNITS = {"": 1, "b": 1, "kb": 10**3, "mb": 10**6, "gb": 10**9, "tb": 10**12,
          "kib": 2**10, "mib": 2**20, "gib": 2**30, "tib": 2**40}


def check_bytes(value, name):
    """A memory size in bytes: a positive integer, or a text such as ``"8GiB"``, ``"512 MiB"``, ``"2.5GB"``,
    ``"1000000"``; None passes (the default budget).

    Examples
    --------
    >>> check_bytes("8GiB", "memory_budget"), check_bytes("1.5 kB", "memory_budget"), check_bytes(None, "m")
    (8589934592, 1500, None)
    """
    import re

    if value is None:
        return None
    if isinstance(value, str):
        match = re.fullmatch(r"\s*([0-9]*\.?[0-9]+(?:[eE][+-]?[0-9]+)?)\s*([A-Za-z]*)\s*", value)
        unit = match and match[2].lower()
        if not match or unit not in _UNITS:
            raise ParameterError(f"{name} must be a size in bytes such as 8GiB, 512MiB, 2GB or 1000000, got {value!r}")
        value = float(match[1]) * _UNITS[unit]
        if not value.is_integer():
            value = math.floor(value)
        value = int(value)
    value = check_int(value, name, minimum=1)
    return value


def _heat_weights(value, name):
    from htetro_opt.problems.heat_costs import check_heat_weights

    return check_heat_weights(value, name)


_ANY_ADDITION = additions({**GA_ADDITIONS, **HEAT_ADDITIONS})


def _additions(value, name):
    """Names of either planner's additions, ``"all"`` kept as such: the method's own set is known only in
    :func:`_relations`, which resolves it."""
    if isinstance(value, str) and value == "all":
        return "all"
    return _ANY_ADDITION(value, name)


def _band(value, name):
    if value in ("auto", "full"):
        return value
    if isinstance(value, str) and value.strip().isdigit():  # the command line's "--band 8"
        value = int(value)
    try:
        return check_int(value, name, minimum=1)
    except ParameterError:
        raise ParameterError(f"{name} must be auto, full or a radius in cells (an integer >= 1), "
                             f"got {value!r}") from None


OPTIONS = (
    Option("clearance", real(0.0), "clearance δ in cells around every block", default=0.0, type=float, metavar="δ",
           reference=True),
    Option("diagonals", check_bool, "allow diagonal translations", default=False, type=bool, reference=True),
    Option("commands", unchecked, "the command tokens the simulator compiles (default: the method's set)",
           flag="", study=False),
    Option("timing", unchecked, "a Timing of the commands' durations", flag="", study=False),
    Option("t0", integer(0), "commands executed before the plan starts (the clock of moving obstacles)", default=0,
           flag="", study=False),
    Option("memory_budget", check_bytes, "most memory the exact search may take, in bytes or as 8GiB, 512MiB, 2GB; "
           "a map that needs more is refused before anything is allocated, saying how much it needs",
           metavar="BYTES", default_text="the smaller of 4 GiB and half the physical memory"),
    # the GAs over command chromosomes (Cheng et al. 2020; pymoo's algorithms on the same problem)
    Option("pop_size", at_most(integer(2), MAX_POPULATION, _population), "population size n_pop", default=50,
           type=int, metavar="N"),
    Option("max_gen", at_most(integer(1), MAX_GENERATIONS, _generations), "generations per roadmap leg at most",
           default=1000, type=int, metavar="N"),
    Option("patience", integer(1, none=True), "stop a leg after this many generations without improvement once "
           "its goal is reached", type=int, metavar="N",
           default_text=", ".join(f"{n} with --converge {m}" for m, n in GA_PATIENCE.items())),
    Option("convergence", choice(CONVERGENCE_MEASURES), "what counts as an improvement for --patience: best, a "
           "rise of the goal-reaching members' best f_t, f_sm, f_sf or fitness sum; hypervolume, of the best f_t "
           "or of their front's hypervolume (half the generations, a slightly smaller front)", default="best",
           flag="--converge", choices=CONVERGENCE_MEASURES),
    Option("max_length", integer(1, none=True), "l_p,max, the initial chromosome length", type=int, metavar="L",
           default_text="per leg, the least multiple of 100 whose time is at least 1.5 times the leg's exact "
           "minimum time, as the paper's 100 and 200 on its maps (ours)"),
    seed_option(),
    Option("additions", _additions, "the additions of ours switched on: all, none, or some of the hTetro-GA's "
           f"{', '.join(GA_ADDITIONS)} (docs/papers/cheng2020.md) or of the heat planner's "
           f"{', '.join(HEAT_ADDITIONS)} (docs/papers/do2021.md)", metavar="NAMES"),
    Option("replan_window", integer(0), "windowed exact re-planning (ours): each generation a window of up to W "
           "executed commands of the fastest and of --replan-members random goal-reaching members is replaced by "
           "the minimum-time path between its ends; 0 off", default=40, type=int, metavar="W"),
    Option("replan_members", integer(0), "random goal-reaching members re-planned each generation besides the "
           "fastest", default=3, type=int, metavar="K"),
    Option("reach_share", real(0.0, 1.0, above=True), "cap on the goal-reaching section of the hTetro-GA's sort, a "
           "share in (0, 1] of n_pop (ours, not in htetro-ga-paper; 1: no cap)", default=1.0, type=float, metavar="S"),
    Option("reach_patience", integer(0), "reach repair (ours): when no member has reached the goal and the best "
           "goal reachability has not risen for N generations, the member nearest to the goal gets the "
           "minimum-time path to it; 0 off", default=100, type=int, metavar="N"),
    Option("polish_window", integer(0), "balanced polish (ours): when each leg's run ends, the largest-sum "
           "leading-front member has windows of up to W commands re-planned exactly for the largest fitness sum; "
           "0 off", default=40, type=int, metavar="W"),
    Option("conservative", check_bool, "add the hTetro-GA's conservative offspring set (removal, rearrangement, "
           "shortcut of every member) to the algorithm's mating, so that a swap compares algorithms, not operator "
           "sets", default=False, type=bool),
    Option("seed_exact", check_bool, "put each leg's exact minimum-time plan into its initial population (ours, "
           "not in htetro-ga-paper); the JSON then reports the gaps to the exact optimum", default=False, type=bool),
    Option("pick", choice(tuple(PICKS)), "the solution each leg returns: balanced, the largest sum of the four "
           "fitnesses (the paper's multi-objective solution), or the best f_t, f_sm or f_sf", default="balanced",
           choices=tuple(PICKS)),
    Option("sampling_weights", unchecked, "λ_mc of Algorithm 1 (token → weight)", flag="", study=False),
    Option("verbose", check_bool, "print pymoo's per-generation log", default=False, flag="", study=False),
    Option("hv_reference", unchecked, "record each leg's hypervolume by generation against this point",
           flag="", study=False),
    Option("progress", callback, "progress(done, total, note) after every generation", flag="", study=False),
    Option("time_limit", check_time_limit, "seconds for the whole roadmap, past which each leg stops at its next "
           "generation (the plan then depends on the machine's speed)", type=float, metavar="S", default_text="none"),
    # Do et al. 2021's heat-conduction planner
    Option("weights", _heat_weights, "weights of time, smoothness and safety (eq. 12)", default=(1.0, 0.0, 0.0),
           metavar="WT,WSM,WSF"),
    Option("t_max", real(0.0, above=True, none=True), "t_max of f_t in seconds", type=float, metavar="S",
           default_text="half an O-shape boustrophedon of the empty map"),
    Option("element", choice(HEAT_ELEMENTS), "the field's element, bilinear q1 (the paper's) or cell-centred p0",
           default="q1", choices=HEAT_ELEMENTS),
    Option("monotone", check_bool, "drop the rule that translations never go down the temperature field",
           default=True, type=bool, flag="", off_flag="--no-monotone"),
    Option("band", _band, "search the whole pose graph (full), or a band of R cells around the field's ascent "
           "line, widened until a path is found (auto: full up to 4 million poses, else R 8)", default="auto",
           metavar="auto|full|R"),
    Option("band_seed", choice(BAND_SEEDS), "where the band is centred: the field's ascent line or a "
           "grid-distance path", default="ascent", flag="", choices=BAND_SEEDS),
    Option("engine", choice(HEAT_ENGINES), "the pose-graph search", default="dijkstra", flag="", choices=HEAT_ENGINES),
    Option("field_options", unchecked, "options of solve_heat_field", flag="", study=False),
    Option("keep_fields", check_bool, "keep the legs' temperature fields in the plan's info (for plots)",
           default=False, flag="", study=False),
    Option("sensor_range", real(0.0, above=True, none=True), "run in the true world (hidden obstacles), sensing "
           "cells within R cells of the blocks and replanning when the plan meets a new obstacle (Do et al. "
           "2021: 6)", type=float, metavar="R", stage="problem", default_text="off: plan on the known map"),
)

_SIMULATOR = ("clearance", "commands", "timing")
_GA = (*_SIMULATOR, "pop_size", "max_gen", "patience", "convergence", "max_length", "seed", "replan_window",
       "replan_members", "seed_exact", "pick", "sampling_weights", "verbose", "hv_reference", "progress", "time_limit")
_HTETRO_GA = (*_GA, "additions", "reach_share", "reach_patience", "polish_window")
# The paper mode refuses our two options that are not additions (an exact plan in the initial population, a cap
# on the goal-reaching section): both change the paper's algorithm, and neither is on in htetro-ga by default.
_HTETRO_GA_PAPER = tuple(name for name in _HTETRO_GA if name not in ("seed_exact", "reach_share"))
_PYMOO = (*_GA, "conservative")
_GA_KIND = dict(seeded=True, family=("ga",), capabilities={"progress"}, problem={"diagonals": False},
                paper="Cheng et al. 2020")
_OURS = {"additions": tuple(GA_ADDITIONS)}
# The paper's: none of ours (their parameters keep their defaults, for a switch back on), the paper's l_p,max
# (§V-B3: 100, 200 on its spiral map) and our reading of its "convergence of the solution" (see PAPER_PATIENCE).
_OFF = {"additions": (), "patience": PAPER_PATIENCE, "max_length": PAPER_MAX_LENGTH}
_PARAMETERS = {"replanning": "replan_window", "reach-repair": "reach_patience", "polish": "polish_window"}
_HEAT_PARAMETERS = {"band": "band", "converge": "engine"}  # a band radius; engine: the converged search's
_HEAT = (*_SIMULATOR, "weights", "t_max", "additions", "keep_fields")


def _relations(method: Method, given: dict, label) -> None:
    """``additions`` as the method's own names (``all``: every one of them, another planner's refused); a
    window, patience or band given (and not 0) sets an addition: refused when that addition is off."""
    if not method.takes("additions"):
        return
    heat = "heat" in method.family
    own = HEAT_ADDITIONS if heat else GA_ADDITIONS
    if "additions" in given:
        names = given["additions"]
        if names == "all":
            names = tuple(own)
        foreign = [n for n in names if n not in own]
        if foreign:
            raise ParameterError(f"{label('additions')}: {', '.join(foreign)} {'is' if len(foreign) == 1 else 'are'} "
                                 f"not an addition of {method.name}: its additions are {', '.join(own)}")
        given["additions"] = tuple(n for n in own if n in names)
    on = given.get("additions", method.defaults.get("additions", ()))
    for addition, option in (_HEAT_PARAMETERS if heat else _PARAMETERS).items():
        value = given.get(option)
        sets = option == "engine" and value is not None or option == "band" and isinstance(value, int) \
            or option not in ("engine", "band") and bool(value)
        if sets and addition not in on:
            raise ParameterError(f"{label(option)} sets the {addition} addition, which is off in {method.name}: "
                                 f"switch it on with {label('additions')} (e.g. {addition})")


def _exact(name: str, summary: str) -> Method:
    return Method(name, "._exact:plan_exact", summary, (*_SIMULATOR, "diagonals", "t0", "memory_budget"),
                  presets={"method": name},
                  exact=True, origin="reference", family=("exact",))


def _pymoo(name: str, label: str) -> Method:
    return Method(name, "._ga:plan_ga", f"pymoo's {label} on the hTetro-GA's problem and operators", _PYMOO,
                  defaults={"replan_window": 0}, presets={"algorithm": name}, origin="library",
                  **{**_GA_KIND, "family": ("ga", "pymoo")})


METHODS = (
    _exact("dijkstra", "the minimum-time plan over (x, y, shape, heading), time-expanded for moving obstacles"),
    _exact("astar", "the same optimum by A* on the point robot's distance field (the default: it expands a "
           "fraction of dijkstra's poses, 1 in 1,800 on malaga_building)"),
    Method("htetro-ga", "._ga:plan_ga", "Cheng et al. 2020's multi-objective GA over command chromosomes, with our "
           "additions", _HTETRO_GA, defaults=_OURS, presets={"algorithm": "htetro-ga"}, origin="ours",
           **{**_GA_KIND, "family": ("ga", "htetro-ga")}),
    Method("htetro-ga-paper", "._ga:plan_ga", "the same GA as published", _HTETRO_GA_PAPER, defaults=_OFF,
           presets={"algorithm": "htetro-ga-paper"}, origin="paper", **{**_GA_KIND, "family": ("ga", "htetro-ga")}),
    _pymoo("nsga2", "NSGA-II"),
    _pymoo("nsga3", "NSGA-III"),
    _pymoo("smsemoa", "SMS-EMOA"),
    _pymoo("agemoea", "AGE-MOEA"),
    Method("heat", "._heat:plan_heat", "Do et al. 2021's search up a heat-conduction field with our additions "
           "(diagonals included, static maps)", (*_HEAT, "element", "monotone", "band", "band_seed", "engine",
                                                 "field_options", "sensor_range"),
           defaults={"additions": tuple(HEAT_ADDITIONS)}, presets={"method": "heat"}, origin="ours",
           paper="Do et al. 2021", family=("heat",), problem={"diagonals": True}, revision=2),
    Method("heat-paper", "._heat:plan_heat", "the same planner as published: the paper's mesh, reaching rule, stop "
           "rule and tentative cost", (*_HEAT, "sensor_range"), defaults={"additions": ()},
           presets={"method": "heat-paper"},
           origin="paper", paper="Do et al. 2021", family=("heat",), problem={"diagonals": True}),
)


def _pose(scenario, *, label, sensor_range) -> Problem:
    """A grid scenario's map and roadmap (a bundled name, a file or a loaded Scenario)."""
    from htetro_opt.scenarios import Scenario, load_scenario

    loaded = scenario if isinstance(scenario, Scenario) else load_scenario(scenario)
    if not isinstance(loaded, Scenario):
        raise ScenarioError(f"scenario {loaded.name!r} is continuous; this task needs a grid scenario")
    if loaded.goal is None:
        raise PlanningError(f"scenario {loaded.name!r} has no roadmap with a start and a goal to plan for")
    return Problem(loaded.name, (loaded.workspace, loaded.roadmap), scenario=loaded,
                   extras={"sensor_range": sensor_range})


def _solve(spec: TaskSpec, problem: Problem, method, options: dict):
    """``plan_path``, or with a sensor range the heat planner's run in the true world (as a plan)."""
    sensor_range = problem.extras.get("sensor_range")
    if sensor_range is None:
        return spec.entry_point()(*problem.args, method=method, **options)
    from htetro_opt.solvers.grid_paths._replan import replan_heat

    # the options given only: replan_heat treats a given band apart (it hands plan_heat the map, not its simulator)
    chosen = method if isinstance(method, Method) else spec.method(method)
    options = spec.check(chosen, options, stage="method", fill=False)
    return replan_heat(problem.scenario, sensor_range=sensor_range, **chosen.presets, **options).as_plan()


SPEC = TaskSpec(
    "grid-path planning", package="htetro_opt.solvers.grid_paths", entry="._dispatch:plan_path", options=OPTIONS,
    # A* is the default and the exact reference: the same optimum as Dijkstra's (tests/solvers/grid_paths check
    # both against the explicit pose graph), at 2.4 s on a 1.7 M-cell map where Dijkstra takes 127 s
    # (benchmarks/README.md, "Exact planner without the explicit graph (issue 25)")
    methods=METHODS, default="astar", exact="astar", aliases={"exact": "astar"},
    families={"exact": "the exact methods", "ga": "the GA methods", "htetro-ga": "the hTetro-GA methods",
              "pymoo": "pymoo's algorithms", "heat": "the heat planner"},
    common=_SIMULATOR, relations=_relations, pose=_pose, solve=_solve,
)
"""The grid-path task (see the module docstring)."""
