"""One entry point for complete coverage planning, whatever the method."""

from __future__ import annotations

import time as _time
from typing import Callable

from htetro_opt._validation import check_real
from htetro_opt.errors import ParameterError, PlanningError
from htetro_opt.model.workspace import Workspace, check_workspace
from htetro_opt.solvers.coverage._baselines import boustrophedon_path, tiling_tsp_tokens
from htetro_opt.solvers.coverage._layers import LayerGraph, parse_layers
from htetro_opt.solvers.coverage._result import CoveragePlan, check_end, coverability, finish_coverage
from htetro_opt.solvers.coverage._spec import DEFAULT_LAYERS, SPEC
from htetro_opt.solvers.coverage._stripes import mop_up, plan_stripes, shortest_path, stripe_widths

__all__ = ["plan_coverage", "auto_start"]

_BUILT_IN = ("stripes", "stripes-paper", "boustrophedon", "tiling-tsp")  # planned below; a registered one is called


def auto_start(lg: LayerGraph, widths=None):
    """The bottom-left valid vertex (least x, then least y) of the first listed layer that has one,
    preferring one inside the first stripe (rows below ``widths[0]``).

    Raises
    ------
    PlanningError
        If no layer of S has a valid pose anywhere on the map.
    """
    low, high = lg.rows
    for layer in range(lg.n_layers):
        valid = lg.valid[layer]
        if not valid.any():
            continue
        ys, xs = (a for a in valid.nonzero())
        nodes = [lg.node(layer, int(x), int(y)) for x, y in zip(xs, ys)]
        inside = [v for v in nodes if widths is None or high[v] < widths[0]]
        return min(inside or nodes, key=lambda v: (lg.decode(v)[1], lg.decode(v)[2]))
    names = ", ".join(layer.name for layer in lg.layers)
    raise PlanningError(f"no pose of the morphology set ({names}) fits anywhere on the map")


def plan_coverage(workspace: Workspace, layers=DEFAULT_LAYERS, *, method: str | Callable = SPEC.default, start=None,
                  goal=None, **options) -> CoveragePlan:
    """Plan commands that cover every cell the robot can cover, with one method (Cheng et al. 2019).

    Parameters
    ----------
    workspace : Workspace
    layers : str or sequence of str
        The morphology set S (:func:`~htetro_opt.solvers.coverage.parse_layers`): ``O``, ``vI``,
        ``hI`` or ``SHAPE@H``; the paper's best, O, vI, hI, by default. ``"boustrophedon"`` uses
        the first only.
    method : str or callable, keyword-only
        A method of the task's spec (:data:`~htetro_opt.solvers.coverage.SPEC`, which lists every
        method with its options and defaults):

        - ``"stripes"`` (default): stripes of rows, each cut into regions of ``region_columns``
          columns, every region searched for its cheapest covering walk, and one auxiliary DAG
          (Dijkstra) picking the ports and layers between them (see
          ``htetro_opt.solvers.coverage._stripes`` for our reading of the paper);
        - ``"stripes-paper"``: the paper's Alg. 5 as written, none of our additions: regions cut only
          at forced poses (the only pose of the stripe covering some cell), a depth-first search over
          simple paths (no vertex twice, §IV-D), on failure a pose covering an uncovered cell inserted
          as a cut, stripes joined by cut-edges, no mop-up. The paper's search has no node budget: a
          region search that spends ``budget`` fails (listed in ``failed_regions``), and cells the
          stripes leave are left uncovered (``missed``); either makes ``success`` false;
        - ``"boustrophedon"``: lanes as tall as the first layer's footprint, swept alternately;
        - ``"tiling-tsp"``: tile the free cells with the layers' shapes (any heading), order the
          tiles as a TSP and drive through their poses by minimum-command legs.

        Or a callable ``method(layer_graph, start_pose, goal_pose)`` returning command tokens (or
        ids) from the start (so is a method registered in the spec); its answer is re-validated like
        the others'.
    start : Pose or (x, y, shape, heading), optional, keyword-only
        The start; by default the bottom-left pose of the first layer in the first stripe.
    goal : Pose, optional, keyword-only
        Where the plan must end; by default anywhere (a free end).
    **options
        The method's options, each checked and defaulted by the spec before any work:
    stripes : int, str or sequence of int, keyword-only
        Stripe widths bottom up (:func:`~htetro_opt.solvers.coverage.stripe_widths`): an int w is
        ⌊H / w⌋ bands of w rows, the last taking the remainder. Default 4 (the paper's N_str,2).
    region_columns : int, keyword-only
        Columns of a region (default 4).
    budget : int, keyword-only
        Search nodes per region search (default 20 000); past them the region takes its greedy walk
        (``greedy-fallback``) or fails and is listed in ``failed_regions``.
    additions : collection of str, keyword-only
        Stripe methods: our additions switched on, names of
        :data:`~htetro_opt.solvers.coverage.STRIPES_ADDITIONS` (``"all"``, ``"none"`` or ``"a,b"`` too):
        all for ``"stripes"``, none for ``"stripes-paper"``; the plan's ``additions`` lists them.
    clearance : float, keyword-only
        δ in cells (MODEL.md §4).
    time_limit : float, optional, keyword-only
        Seconds; past them the remaining regions take their greedy walk, or fail without
        ``greedy-fallback`` (``time_limited``). None: no limit.
    memo : bool, keyword-only
        Memoise region searches by their content (True); False gives the same plan, slower.
    ends : {"sweep", "both"}, keyword-only
        ``"stripes"`` only: where a stripe's sweep may be left. ``"sweep"`` (default, the paper's
        cut-edges): at its far end, each sweep in the direction the stripes' order gives it.
        ``"both"``: the start end too; every sweep is in the DAG in both directions, and (default
        variant) also folded, out for the lower half of its rows and back for the upper half, so
        that the O in 4-row bands may finish where it began. For one order of the sweeps its DAG
        is a superset of ``"sweep"``'s, and the plan keeps the cheaper of the two plans with their
        mop-ups: it never costs more. About four times the work.
    mopup : {"sequenced", "nearest"}, keyword-only
        How the cells the sweeps or lanes left are visited (stripe methods: with the ``mopup``
        addition): nearest first, or ``"sequenced"`` (default): those same vertices re-ordered by
        2-opt and Or-opt over the exact leg costs, kept only when cheaper.

    Returns
    -------
    CoveragePlan
        Re-validated in the simulator. Cells no pose of S covers, or that the start cannot reach, are
        reported in ``uncoverable``, not searched for; a plan is ``complete`` when every free cell is covered,
        ``success`` when every coverable cell is and no region search failed (``missed``, ``failed_regions``).

    Raises
    ------
    UnknownShapeError
        If a layer is not one of the accepted forms.
    ParameterError
        On an unknown method, ``ends`` or ``mopup``, stripe widths that are not positive or do not
        sum to the height, ``region_columns`` or ``budget`` below 1, or a time limit that is not positive.
    ConfigurationError
        If the start or goal collides, lies off the map or is in a layer outside S.
    PlanningError
        If no pose of S fits anywhere on the map.
    TilingError
        ``"tiling-tsp"`` only: if the layers' shapes cannot tile the free cells.

    Examples
    --------
    >>> import numpy as np
    >>> ws = Workspace(np.zeros((4, 8), dtype=bool))  # 32 free cells: at least (32 - 4) / 2 = 14 O moves
    >>> plan = plan_coverage(ws, "O", stripes=4)
    >>> plan.complete, plan.action_cost, plan.regions == plan.regions_optimal
    (True, 14, True)
    >>> plan_coverage(ws, "vI").tokens  # the vertical I sweeps 4 new cells a command
    ['x+', 'x+', 'x+', 'x+', 'x+', 'x+', 'x+']
    >>> plan_coverage(ws, "O", method="boustrophedon").action_cost
    14
    """
    began = _time.perf_counter()
    check_workspace(workspace)
    if callable(method):  # a user's walk: the map's clearance is its only option
        name = getattr(method, "__name__", type(method).__name__)
        unknown = sorted(set(options) - {"clearance"})
        if unknown:
            raise ParameterError(f"a callable method takes no option {', '.join(map(repr, unknown))}: "
                                 "its only option is clearance")
        options = {"clearance": check_real(options.get("clearance", 0.0), "clearance", minimum=0.0)}
    else:
        chosen = SPEC.method(method)
        name, options = chosen.name, SPEC.check(chosen, options, stage="method")
        if chosen.name not in _BUILT_IN:  # a method registered in the spec is called as a user's walk is
            method = chosen.load(SPEC.package)
    clearance = options["clearance"]
    parsed = parse_layers(layers)
    if method == "boustrophedon":
        parsed = parsed[:1]
    # the auto start prefers the first stripe; a method without stripes that of the default width where it fits,
    # so that every method starts from the same pose
    default = SPEC.options["stripes"].default
    widths = stripe_widths(options["stripes"], workspace.height) if "stripes" in options else \
        stripe_widths(default, workspace.height) if default <= workspace.height else None
    time_limit = options.get("time_limit")
    lg = LayerGraph(workspace, parsed, clearance=clearance)
    start_node = auto_start(lg, widths) if start is None else check_end(lg, start, "start")
    goal_node = None if goal is None else check_end(lg, goal, "goal")
    cov = coverability(lg, start_node)
    if goal_node is not None and not cov.reachable[goal_node]:
        raise PlanningError(f"the goal {tuple(lg.pose(goal_node))} cannot be reached from the start in this "
                            "morphology set")
    if callable(method):
        tokens = method(lg, lg.pose(start_node), None if goal_node is None else lg.pose(goal_node))
        if isinstance(tokens, str):
            tokens = [t for t in tokens.replace(",", " ").split()]
        return finish_coverage(lg, list(tokens), start_node, method=name, goal_node=goal_node, coverable=cov,
                               began=began, stripes=())
    extras: dict = {}
    if method == "tiling-tsp":
        tokens, info = tiling_tsp_tokens(lg, start_node, goal_node, time_limit=time_limit)
        return finish_coverage(lg, tokens, start_node, method=name, goal_node=goal_node, coverable=cov, began=began,
                               stripes=(), info=info)
    if method in ("stripes", "stripes-paper"):
        deadline = None if time_limit is None else began + time_limit
        on = options["additions"]
        ends = options.get("ends", "sweep")  # stripes-paper's sweeps leave at their far end (the paper's cut-edges)
        outcome = plan_stripes(lg, cov, start_node, goal_node, widths, region_columns=options["region_columns"],
                               budget=options["budget"], deadline=deadline, memo=options["memo"], additions=on,
                               ends=ends, mopup=options["mopup"])
        path = outcome.path
        extras = {"stripes_detail": tuple(outcome.stripes), "regions": outcome.regions,
                  "regions_optimal": outcome.regions_optimal, "memo_hits": outcome.memo_hits,
                  "nodes": outcome.nodes, "dag_cost": outcome.dag_cost, "time_limited": outcome.time_limited,
                  "info": {**outcome.info, "additions": list(on)}, "ends": ends,
                  "failed_regions": tuple(outcome.failed.values())}
        used_stripes = widths
        mopup = "mopup" in on  # without it, what the stripes leave stays uncovered and the plan says so
    else:
        path = boustrophedon_path(lg, start_node, cov.reachable)
        extras = {"info": {}}
        used_stripes = ()
        mopup = True
    lanes = len(path) - 1
    # the mop-up within the time limit, less a twentieth of it for the commands and the replay (what it cuts is
    # said in time_limit_cut: cells left uncovered, the sequencing skipped)
    mop_deadline = None if time_limit is None else began + 0.95 * time_limit
    mop_cut: dict = {}
    added = mop_up(lg, path, cov.coverable, cov.reachable, order=options["mopup"], goal=goal_node,
                   deadline=mop_deadline, cut=mop_cut) if mopup else []
    if mop_cut:
        extras["time_limited"] = True
        extras["info"]["time_limit_cut"] = {**extras["info"].get("time_limit_cut", {}), **mop_cut}
    mopup_path = [path[-1]] + added
    tail = []
    if goal_node is not None and mopup_path[-1] != goal_node:
        _, tail = shortest_path(lg, mopup_path[-1], goal_node)
    tokens_main = lg.commands_of(path)
    tokens_mop = lg.commands_of(mopup_path)
    tokens_tail = lg.commands_of(tail) if tail else []
    if method == "boustrophedon":
        extras["info"] = {"lane_vertices": lanes}
    plan = finish_coverage(lg, tokens_main + tokens_mop + tokens_tail, start_node, method=name, stripes=used_stripes,
                           goal_node=goal_node, coverable=cov, began=began, mopup_commands=len(tokens_mop),
                           transit_commands=len(tokens_tail), **extras)
    cut = plan.info.get("time_limit_cut")
    if cut is not None:  # what the cut left, from the replay (a switch's intermediate poses cover cells too)
        cut["cells_left"] = len(plan.missed)
    return plan
