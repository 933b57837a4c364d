"""The sequencing task, declared once: :func:`~htetro_opt.solvers.sequencing.sequence_waypoints`'s methods
and options (Le et al. 2018's waypoint TSP, and TSPLIB instances).

:data:`SPEC` is what ``sequence_waypoints``, the command line's ``sequence`` and the study runner's
``sequence`` task read (see :mod:`htetro_opt._spec`). A method is a function
``solve_<name>(instance, *, <its options>) -> (order, info)``; the entry point resolves ``auto``, hands a
closed tour or a fixed end to a method without the ``tours`` capability as an open path, and re-prices
every answer. Importing the spec loads no scipy, numba, OR-Tools or DEAP.
"""

from __future__ import annotations

from dataclasses import replace

from htetro_opt._spec import (Method, Option, Problem, TaskSpec, additions, callback, choice, integer, real,
                              seed_option)
from htetro_opt._validation import check_bool, check_int, check_real, check_time_limit
from htetro_opt.errors import ParameterError
from htetro_opt.solvers.sequencing._budgets import TIME_LIMIT_TEXT
from htetro_opt.solvers.tiling._spec import shape_letters  # a scenario is tiled first: its shapes are the tiler's

__all__ = ["SPEC", "is_tileset", "GA_ADDITIONS", "CANDIDATE_LISTS", "EXACT_AUTO_LIMIT", "EXACT_MAX_SIZE",
           "EXACT_TIME_LIMIT", "FIRST_SOLUTIONS", "ILS_ACCEPT_WORSE", "ILS_ALPHA_AUTO", "ILS_ALPHA_LIMIT",
           "ILS_ALPHA_PAIR_SECONDS", "ILS_ALPHA_TREES", "ILS_KICK_RATE", "ILS_KICK_SPAN", "ILS_LK_DEPTH",
           "ILS_NEIGHBOURS", "ILS_OR3OPT", "check_candidates"]

EXACT_AUTO_LIMIT = 40
"""``auto`` proves the optimum with the exact solver up to this many waypoints (a closed tour counts
one more, the copy of its first waypoint); beyond, see :func:`~htetro_opt.solvers.sequencing.auto_method`."""

EXACT_MAX_SIZE = 40
"""Default largest instance :func:`~htetro_opt.solvers.sequencing.solve_exact` accepts (its ``max_size``)."""

EXACT_TIME_LIMIT = 60.0
"""Default wall-clock budget of :func:`~htetro_opt.solvers.sequencing.solve_exact`, in seconds."""

GA_ADDITIONS = {
    "crossover": "pairs of selected parents are crossed by a linear order crossover (crossover_rate); the paper "
                 "leaves crossover out, as it would revisit waypoints",
    "distinct": "an order already in the population takes no second place when the population is reduced",
    "memetic": "the cheapest share of each generation's children (local_search_rate) is improved by the compiled "
               "2-opt/Or-opt local search of ils",
}
"""Our additions to Le et al. 2018's GA (Algorithm 2), by name: ``ga`` runs them all, ``ga-plain`` (the
paper's) none; each is switched on or off by the ``additions`` option (docs/papers/le2018.md)."""

ILS_NEIGHBOURS = 8
"""Size of each node's neighbour (candidate) list in ``ils``."""

ILS_LK_DEPTH = 0
"""Flips of ``ils``'s LK-style move (0: none, its plain 2-opt moves). Measured on 18 TSPLIB instances of
400-2103 cities (benchmarks/README.md, issue 25): depth 2 (2-opt and sequential 3-opt moves) wins more a
kick (pr1002 at 100 kicks a node: 0.15 % above the optimum against 0.51 %) but costs about twice the time a
kick, and at 10 s its mean gap equals the 2-opt search's (0.385 % both); deeper is slower still. So the
default stays 0, and the runtimes of large instances at their kick budget stay where they were. On the
alpha lists (the default since) depth 3 takes the same 18 at 10 s from 0.339 % to 0.233 %, but it is cut
by the clock from 724 cities on and loses on four of those 13: still off (2026-12-08)."""

ILS_OR3OPT = False
"""Whether ``ils``'s local search adds the segment exchange (or-3opt) moves. Off: with the local kick it
undoes the kick (0.639 % mean gap on 18 TSPLIB instances of 400-2103 cities at their kick budget, against
0.385 % without); with a global kick (``kick_span`` >= n / 3) 0.232 %, but each kick then costs 2-3 times
as much (benchmarks/README.md, issue 25)."""

ILS_KICK_SPAN = 100
"""Longest segment of a kick's double bridge in ``ils`` (each of its three segments has 1…this many nodes)."""

ILS_ALPHA_TREES = 300
"""Most 1-trees of the subgradient ascent behind ``ils``'s alpha-nearness lists (``candidates="alpha"``). The
lists then cost 0.15-0.25 s at 1000-1600 nodes, and hold 99.9 % (pr1002), 99.2 % (fl1577) and 99.4 % (d1291)
of the edges of fast-tsp's 3 s tours, against 99.5 %, 98.9 % and 97.4 % for the 8 nearest; 1000 trees
change none of the three (benchmarks/README.md, issue 25)."""

ILS_ALPHA_LIMIT = 20_000
"""Most waypoints ``ils`` computes alpha-nearness lists for: they cost O(n²) leg look-ups (three minimum
spanning trees over all the legs, and each node's alpha to every other), 18-22 s at 16 384 TSPLIB coordinates,
so beyond this the nearest lists are the only ones."""

ILS_ALPHA_AUTO = 5_000
"""Up to this many waypoints ``ils``'s default lists (``candidates="auto"``) are the alpha-nearness ones, when
their estimated cost (:data:`ILS_ALPHA_PAIR_SECONDS`) is at most a tenth of the time limit, the nearest
otherwise (a choice fixed by the arguments, so a run stays reproducible). On 18 TSPLIB instances of 400-2103 cities at
their kick budget, two seeds: mean gap to the optimum 0.400 % against 0.656 % with the nearest lists (fl1400
and fl1577, clustered: 0.18 % and 0.35 % against 1.91 % and 3.51 %), better on 9 instances and worse on 9
(benchmarks/README.md, issue 25)."""

ILS_ALPHA_PAIR_SECONDS = 1.5e-7
"""The alpha lists' estimated cost, in seconds a pair of waypoints, for ``candidates="auto"``'s choice (the
time limit's tenth: up to 2582 waypoints at 10 s, 1154 at 2 s): measured 0.15 s at 1002 (1.5e-7 s a pair,
the ascent included), 0.19-0.22 s at 1291-1577 and 20 s at 16 384 TSPLIB coordinates (0.8e-7)."""

ILS_ACCEPT_WORSE = 0.0
"""How far above its best tour, in mean legs, ``ils`` keeps a kick's result (0: only when no costlier).
0.05 and 0.3 gave 0.508 % and 0.580 % mean gap on six TSPLIB instances at 200 000 kicks, against 0.484 %."""

ILS_KICK_RATE = 0.0
"""Kicks ``ils`` plans a second of an explicit ``time_limit`` (0: its :func:`ils_kicks` budget alone).
100 000 alone: 0.369 % mean gap on 18 TSPLIB instances at 10 s against 0.385 %; 50 000 with ``or3opt`` and a
global kick: 0.292 % (benchmarks/README.md, issue 25)."""

FIRST_SOLUTIONS = (
    "AUTOMATIC", "PATH_CHEAPEST_ARC", "PATH_MOST_CONSTRAINED_ARC", "SAVINGS", "PARALLEL_SAVINGS",
    "PARALLEL_CHEAPEST_INSERTION", "SEQUENTIAL_CHEAPEST_INSERTION", "LOCAL_CHEAPEST_INSERTION",
    "LOCAL_CHEAPEST_COST_INSERTION", "GLOBAL_CHEAPEST_ARC", "LOCAL_CHEAPEST_ARC", "FIRST_UNBOUND_MIN_VALUE",
)
"""OR-Tools' first-solution strategies accepted as ``first_solution``. Left out: ``SWEEP`` (needs
waypoint coordinates, the model is invalid without them), and ``CHRISTOFIDES`` and
``BEST_INSERTION``, which with OR-Tools 9.15 end the search early on this model (status
``ROUTING_OPTIMAL`` for a path 9 % above the optimum on 12 waypoints)."""

CANDIDATE_LISTS = ("auto", "nearest", "alpha")
"""The neighbour (candidate) lists of ``ils`` and fast-tsp, the ``candidates`` option: ``nearest``, each node's
cheapest legs; ``alpha``, alpha-nearness (Helsgaun 2000, LKH); ``auto``, the method's own choice (``ils``:
alpha up to :data:`ILS_ALPHA_AUTO` waypoints within a tenth of the time limit; fast-tsp: its own, see
:func:`~htetro_opt.solvers.sequencing.solve_fast_tsp`)."""

check_candidates = choice(CANDIDATE_LISTS)
"""The check of a ``candidates`` value: the option's, and ``ils``'s and fast-tsp's when called directly."""


def _label(value, name):
    """A tile or node label (a positive integer, or its text), or ``"free"``."""
    if value in (None, "free"):
        return value
    if isinstance(value, str) and value.strip().isdigit():  # the command line's "--start 1"
        value = int(value)
    try:
        return check_int(value, name, minimum=1)
    except ParameterError:
        raise ParameterError(f"{name} must be a tile label (a positive integer) or 'free', got {value!r}") from None


def _end(value, name):
    if value == "free":
        raise ParameterError(f"{name} must be a tile label (a positive integer): an open path's end is free "
                             "unless given")
    return _label(value, name)


def _weights(value, name):
    """Eq. 2's four weights: numbers in [0, 1e6] (huge ones overflow the costs) with a positive sum; the command
    line's text "a,b,c,d" too."""
    from htetro_opt.problems.waypoint_sequencing import check_weights  # light: numpy only

    text = value
    if isinstance(value, str):
        try:
            value = [float(v) for v in value.split(",")]
        except ValueError:
            raise ParameterError(f"{name} must be four comma-separated numbers a,b,c,d, got {text!r}") from None
    if isinstance(value, (str, bytes)) or not hasattr(value, "__len__") or len(value) != 4:
        raise ParameterError(f"{name} must be four numbers a,b,c,d, got {text!r}")
    try:
        values = [check_real(v, f"{name}[{i}]", minimum=0.0, maximum=1e6) for i, v in enumerate(value)]
        return tuple(float(v) for v in check_weights(values))
    except ParameterError:
        raise ParameterError(f"{name} must be four numbers in [0, 1e6] with a positive sum, got {text!r}") from None


OPTIONS = (
    # how a tileset, a scenario or a TSPLIB file is posed as an instance
    Option("start", _label, "label of the start tile or TSPLIB node, or 'free'", default=1, stage="problem",
           reference=True),
    Option("end", _end, "open paths: label of the tile or TSPLIB node the order ends at", stage="problem",
           reference=True, default_text="free"),
    Option("closed", check_bool, "a closed tour, back to the start (--open: an open path)", type=bool,
           flag="--closed", off_flag="--open", stage="problem", reference=True,
           default_text="closed for TSPLIB files, open for tilesets"),
    Option("weights", _weights, "tilesets: eq. 2's weights α,β,λ,γ of blocks a,b,c,d", default=(0.25,) * 4,
           metavar="A,B,C,D", stage="problem", reference=True),
    Option("shapes", shape_letters, "when TILESET is a scenario: allowed morphologies for its tiling (by tile's "
           "default method)", stage="problem", reference=True, default_text="all seven"),
    # the methods' own
    seed_option(),
    Option("time_limit", check_time_limit, "time budget in seconds", type=float, metavar="S",
           default_text=f"sized to the instance: {TIME_LIMIT_TEXT}"),
    Option("progress", callback, "progress(done, total, note) from the methods that report", flag="",
           study=False),
    Option("restarts", integer(0), "kicks of the iterated local search", default=0, type=int, metavar="N"),
    Option("max_starts", integer(1), "nearest-neighbour starts tried", default=32, flag=""),
    Option("kicks", integer(0, none=True), "kicks of the iterated local search (0: local search only)", flag="",
           default_text="sized to the instance (ils_kicks)"),
    Option("neighbours", integer(1), "size of each node's candidate list", default=ILS_NEIGHBOURS, flag=""),
    Option("lk_depth", integer(0), "flips of ils's Lin-Kernighan-style move (0: its 2-opt moves; 2: 2-opt and "
           "sequential 3-opt, stronger a kick, slower)", default=ILS_LK_DEPTH, type=int, metavar="N"),
    Option("or3opt", check_bool, "ils: add the segment-exchange (or-3opt) moves to the local search",
           default=ILS_OR3OPT, type=bool, flag="--or3opt", off_flag="--no-or3opt"),
    Option("kick_rate", real(0.0), "ils: kicks planned a second of an explicit time limit (0: the kicks sized to "
           "the instance only)", default=ILS_KICK_RATE, type=float, metavar="K"),
    Option("accept_worse", real(0.0), "ils: keep a kick's result up to this many mean legs above the best tour",
           default=ILS_ACCEPT_WORSE, flag=""),
    Option("kick_span", integer(1), "ils: longest segment of a kick's double bridge", default=ILS_KICK_SPAN,
           flag=""),
    Option("pop_size", integer(2), "population size", default=60, flag=""),
    Option("max_gen", integer(0), "generations at most", default=2000, flag=""),
    Option("patience", integer(1, none=True), "generations without improvement before stopping", default=200,
           flag=""),
    Option("additions", additions(GA_ADDITIONS), "the GA's additions of ours switched on: all, none, or some of "
           f"{', '.join(GA_ADDITIONS)} (docs/papers/le2018.md)", metavar="NAMES"),
    Option("crossover_rate", real(0.0, 1.0), "order-crossover rate (the crossover addition)", default=0.8, flag=""),
    Option("mutation_rate", real(0.0, 1.0), "share of the children mutated by the paper's swap", default=0.2,
           flag=""),
    Option("tournament_size", integer(1), "tournament size", default=3, flag=""),
    Option("elite", integer(0, none=True), "the e best parents kept, the other places to the best children", flag="",
           default_text="none: parents and children compete for every place"),
    Option("local_search_rate", real(0.0, 1.0), "share of offspring improved by 2-opt/Or-opt (the memetic addition)",
           default=0.25, flag=""),
    Option("iterations", integer(1), "random restarts of the greedy search", default=10_000, flag=""),
    Option("scale", real(0.0, above=True, none=True),
           "multiplier turning costs into OR-Tools' integers", flag="", default_text="from the largest cost"),
    Option("solution_limit", integer(1, none=True), "OR-Tools: stop after this many solutions of its local "
           "search, so that the order is the same on every machine", type=int, metavar="N",
           default_text="none, only the time limit"),
    Option("first_solution", choice(FIRST_SOLUTIONS), "OR-Tools' first-solution strategy",
           default="PATH_CHEAPEST_ARC", flag="", choices=FIRST_SOLUTIONS),
    Option("max_size", integer(1), "largest instance the exact solver accepts", default=EXACT_MAX_SIZE, flag=""),
    Option("threads", integer(1), "fast-tsp's threads", default=1, flag=""),
    Option("candidates", check_candidates, "neighbour lists: nearest (the cheapest legs), alpha "
           "(alpha-nearness, Helsgaun 2000) or auto, the method's own (ils: alpha up to "
           f"{ILS_ALPHA_AUTO} waypoints when they fit a tenth of the time limit, nearest otherwise)", default="auto",
           choices=CANDIDATE_LISTS),
    Option("runs", integer(1), "LKH's independent runs, the best kept", default=1, type=int, metavar="N"),
)

_PAPER = "Le et al. 2018"
_GA = ("seed", "time_limit", "progress", "additions", "pop_size", "max_gen", "patience", "crossover_rate",
       "mutation_rate", "tournament_size", "elite", "local_search_rate")
_PARAMETERS = {"crossover": "crossover_rate", "memetic": "local_search_rate"}  # addition -> the option it uses
_PATTERN = dict(capabilities={"asymmetric", "geometry"}, origin="baseline", paper=_PAPER, family=("pattern",))

METHODS = (
    # auto runs exact, ils or ortools (auto_method): it takes their options and hands each the ones it takes
    Method("auto", None, f"exact up to {EXACT_AUTO_LIMIT} waypoints, ils beyond (ortools for asymmetric costs)",
           ("seed", "time_limit", "progress", "max_size", "kicks", "neighbours", "lk_depth", "or3opt",
            "kick_rate", "accept_worse", "kick_span", "candidates", "scale",
            "first_solution",
            "solution_limit"),
           seeded=True, capabilities={"asymmetric", "tours", "implicit"}, revision=2),  # 2: ils's alpha lists
    Method("exact", "._exact:solve_exact", f"the CP-SAT optimum with a proof (<= {EXACT_MAX_SIZE} waypoints)",
           ("time_limit", "max_size"), exact=True, origin="reference", capabilities={"asymmetric"}),
    Method("ortools", "._ortools:solve_ortools", "OR-Tools routing with guided local search (the paper's baseline)",
           ("time_limit", "progress", "scale", "first_solution", "solution_limit"), origin="baseline", paper=_PAPER,
           capabilities={"asymmetric", "progress", "timed"}),
    Method("local", "._local:solve_local", "nearest neighbour + 2-opt/Or-opt, iterated with --restarts",
           ("seed", "time_limit", "progress", "restarts", "max_starts"),
           seeded=lambda options: options.get("restarts", 0) > 0, capabilities={"progress"}),
    Method("ils", "._ils:solve_ils", "the compiled, seeded iterated local search (2-opt, Or-opt, double-bridge "
           "kicks)", ("seed", "time_limit", "kicks", "neighbours", "lk_depth", "or3opt", "kick_rate",
           "accept_worse", "kick_span", "candidates"), seeded=True,
           capabilities={"tours", "implicit"}, revision=2),  # 2: the alpha-nearness lists by default
    Method("ga", "._ga:solve_ga", "the paper's GA on DEAP with our additions (order crossover, distinct "
           "survivors, a 2-opt/Or-opt step)", _GA, defaults={"additions": tuple(GA_ADDITIONS), "patience": 50},
           seeded=True, origin="ours", paper=_PAPER, family=("ga",), capabilities={"progress"}),
    # Algorithm 2 as published: no crossover ("not included ... due to a similar waypoint re-visiting
    # issue"), so every child is its parent with two random waypoints swapped
    Method("ga-plain", "._ga:solve_ga", "the paper's GA on DEAP, as published (swap mutation, no crossover)", _GA,
           defaults={"additions": (), "mutation_rate": 1.0}, seeded=True, origin="paper", paper=_PAPER,
           family=("ga",), capabilities={"progress"}),
    Method("zigzag", "._baselines:solve_zigzag", "the paper's zigzag, one row", presets={"rows": 1}, **_PATTERN),
    Method("zigzag2", "._baselines:solve_zigzag", "the paper's zigzag, two rows", presets={"rows": 2}, **_PATTERN),
    Method("spiral", "._baselines:solve_spiral", "the paper's spiral, one row", presets={"rows": 1}, **_PATTERN),
    Method("spiral2", "._baselines:solve_spiral", "the paper's spiral, two rows", presets={"rows": 2}, **_PATTERN),
    Method("greedy", "._baselines:solve_greedy", "the paper's greedy search", ("seed", "time_limit", "progress",
           "iterations"), seeded=True, origin="baseline", paper=_PAPER, capabilities={"asymmetric", "progress"}),
    Method("fast-tsp", "._backends:solve_fast_tsp", "the fast-tsp package (optional, MIT; time-based, unseeded)",
           ("time_limit", "threads", "candidates"), origin="external", requires="fast-tsp",
           capabilities={"tours", "timed"}),
    Method("lkh", "._backends:solve_lkh", "LKH-3 through the elkai package (optional; non-commercial use only)",
           ("runs",), origin="external", requires="lkh", capabilities={"asymmetric", "tours"}),
)


def _pose(source, *, label, start, end, closed, weights, shapes) -> Problem:
    """A labelled tileset, a grid scenario (tiled first, by ``tile``'s default method) or a TSPLIB file as a
    :class:`~htetro_opt.problems.SequencingInstance`: tilesets open paths, TSPLIB files closed tours."""
    from htetro_opt.problems import SequencingInstance

    kind, loaded = _source(source)
    if kind == "tsplib":
        untiled = (("weights", tuple(weights) != SPEC.options["weights"].default), ("shapes", shapes is not None))
        for name, given in untiled:
            if given:
                raise ParameterError(f"{label(name)} does not apply to a TSPLIB file (it has no tiles)")
        closed = True if closed is None else closed
        if closed and end is not None:
            raise ParameterError(f"{label('end')} applies to open paths: a TSPLIB file is a closed tour unless "
                                 "asked for an open path (--open on the command line, closed=False in a call or a "
                                 "study)")
        nodes = range(1, loaded.dimension + 1)
        instance = SequencingInstance.from_tsplib(loaded, closed=closed,  # coordinates stay implicit
                                                  start=_index(start, nodes, label("start"), "node"),
                                                  end=_index(end, nodes, label("end"), "node"))
        return Problem(loaded.name, (instance,), scenario=loaded, extras={"instance": instance, "tsplib": loaded})
    if kind == "tileset":
        if shapes is not None:
            raise ParameterError(f"{label('shapes')} applies only to a scenario to tile, not to a labelled tileset")
        tileset = loaded
    else:
        from htetro_opt.solvers.tiling import tile_workspace

        tileset = tile_workspace(loaded.workspace, shapes=shapes, name=loaded.name).tileset
    if start != "free":
        _index(start, tileset.ids, label("start"), "tile")  # from_tileset takes the label itself
    instance = SequencingInstance.from_tileset(tileset, start=None if start == "free" else start, weights=weights)
    if closed or end is not None:
        instance = replace(instance, closed=bool(closed), end=_index(end, instance.ids, label("end"), "tile"))
    return Problem(tileset.name, (instance,), scenario=loaded, extras={"instance": instance, "tileset": tileset})


def _index(tile, ids, name: str, what: str):
    """The index of tile (node) ``tile`` among ``ids``; None for None or "free"."""
    if tile is None or tile == "free":
        return None
    ids = list(ids)
    if tile not in ids:
        raise ParameterError(f"{name} {tile}: there is no {what} {tile}")
    return ids.index(tile)


def is_tileset(name: str) -> bool:
    """``sequence``'s rule for a name: a ``.toml`` file or a bundled scenario is a scenario to tile first; a
    TSPLIB file (.tsp, .atsp) is an instance of its own; any other name a labelled tileset (bundled or a file)."""
    from htetro_opt.scenarios import list_scenarios, list_tilesets

    if name.lower().endswith((".tsp", ".atsp", ".toml")):
        return False
    return name in list_tilesets() or name not in list_scenarios()


def _source(source):
    """(kind, loaded): a TSPLIB file (.tsp, .atsp), a labelled tileset (a bundled name or any other file) or a
    grid scenario (a bundled scenario name, a .toml file or a loaded Scenario)."""
    from htetro_opt.scenarios import Scenario, Tileset, load_scenario, load_tileset, scenario_path, tileset_path

    if isinstance(source, Tileset):
        return "tileset", source
    if isinstance(source, Scenario):
        return "scenario", source
    if not isinstance(source, str):
        raise ParameterError(f"a sequencing source must be a tileset, a scenario or a file name, got {source!r}")
    if source.lower().endswith((".tsp", ".atsp")):
        from htetro_opt.scenarios.tsplib import load_tsplib

        return "tsplib", load_tsplib(source)
    if not is_tileset(source):
        scenario_path(source)  # a clear error for a missing file
        from htetro_opt.errors import ScenarioError

        loaded = load_scenario(source)
        if not isinstance(loaded, Scenario):
            raise ScenarioError(f"scenario {loaded.name!r} is continuous; sequencing tiles a grid scenario")
        return "scenario", loaded
    return "tileset", load_tileset(tileset_path(source))


def _relations(method: Method, given: dict, label) -> None:
    """A rate given for an addition that is off is refused (it would change nothing)."""
    if not method.takes("additions"):
        return
    on = given.get("additions", method.defaults.get("additions", ()))
    for addition, option in _PARAMETERS.items():
        if option in given and addition not in on:
            raise ParameterError(f"{label(option)} sets the {addition} addition, which is off in {method.name}: "
                                 f"switch it on with {label('additions')} (e.g. {addition})")


SPEC = TaskSpec(
    "sequencing", package="htetro_opt.solvers.sequencing", entry="._dispatch:sequence_waypoints", options=OPTIONS,
    methods=METHODS, default="auto", exact="exact",
    families={"ga": "the GA methods", "pattern": "the pattern baselines"},
    common=tuple(option.name for option in OPTIONS if option.stage == "problem"), relations=_relations, pose=_pose,
)
"""The sequencing task (see the module docstring)."""
