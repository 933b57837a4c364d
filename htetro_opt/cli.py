"""The ``htetro-opt`` command line.

Every command takes a SCENARIO, a bundled name (``htetro-opt scenarios`` lists them) or a path to a
scenario TOML file; ``sequence`` also takes a labelled tileset (a bundled name, ``htetro-opt
scenarios`` lists them too, or a file). Errors print one ``error: …`` line and exit with status 2.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from typing import Sequence

import numpy as np

from htetro_opt import __version__
from htetro_opt._argparse import Parser, UsageError
from htetro_opt.errors import HtetroError, ParameterError, PlanningError, ScenarioError
from htetro_opt.model import Simulator, parse_commands
from htetro_opt.model.commands import DIAGONAL_COMMANDS, SEED000_COMMANDS
from htetro_opt.model.robot import STATE_NAMES
from htetro_opt.problems import FITNESS_NAMES
from htetro_opt.problems import SequencingInstance, check_weights
from htetro_opt.scenarios import (
    Scenario,
    format_tileset,
    list_scenarios,
    list_tilesets,
    load_scenario,
    load_tileset,
    save_tileset,
    scenario_path,
    tileset_path,
)
from htetro_opt.solvers import (
    GA_ALGORITHMS,
    SEQUENCE_SOLVERS,
    TILING_SOLVERS,
    plan_exact,
    plan_ga,
    sequence_waypoints,
    tile_workspace,
)

__all__ = ["main", "main_entry", "build_parser"]

EXIT_ERROR = 2
PLAN_METHODS = {"exact": "dijkstra", "astar": "astar", "nsga2": "ga"}
TILING_TIME_LIMIT = 60.0  # the backtracker can search long on cluttered maps with few allowed shapes


def build_parser() -> argparse.ArgumentParser:
    parser = Parser(prog="htetro-opt", description="Path planning for the hTetro reconfigurable robot.")
    parser.add_argument("--version", action="version", version=f"htetro-opt {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=Parser)

    p = sub.add_parser("scenarios", help="list the bundled scenarios")
    p.add_argument("--json", action="store_true", help="print one JSON object")

    p = sub.add_parser("plan", help="plan a path through a scenario's roadmap")
    p.add_argument("scenario", help="bundled scenario name or path to a scenario TOML file")
    p.add_argument("--method", choices=sorted(PLAN_METHODS), default="exact",
                   help="exact: minimum-time Dijkstra (default); astar: A*, same optimum; "
                        "nsga2: seed 000's multi-objective GA over command chromosomes")
    p.add_argument("--algorithm", choices=GA_ALGORITHMS, default="htetro",
                   help="with --method nsga2: the paper's hTetro-GA (default) or one of pymoo's algorithms")
    p.add_argument("--pop-size", type=int, default=50, help="with --method nsga2: population size n_pop (default 50)")
    p.add_argument("--max-gen", type=int, default=1000,
                   help="with --method nsga2: generations per roadmap leg at most (default 1000)")
    p.add_argument("--patience", type=int, default=100,
                   help="with --method nsga2: stop a leg after this many generations without improvement "
                        "once its goal is reached (default 100)")
    p.add_argument("--max-length", type=int, default=100,
                   help="with --method nsga2: l_p,max, the initial chromosome length (default 100)")
    p.add_argument("--seed", type=int, default=0, help="random seed (the exact methods are deterministic)")
    p.add_argument("--diagonals", action="store_true", help="allow diagonal translations")
    p.add_argument("--clearance", type=float, default=0.0, help="clearance δ in cells around every block")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.add_argument("--plot", metavar="FILE", help="save a PNG of the map and the path")

    p = sub.add_parser(
        "simulate",
        help="execute a command sequence in a scenario",
        description="Execute a command sequence from the scenario's start in the true world (hidden "
        "obstacles included). 'reached' means the whole sequence is valid, passes through the roadmap's "
        "configurations in order and ends on the goal; 'executed' counts the commands run before the "
        "first invalid one.",
    )
    p.add_argument("scenario", help="bundled scenario name or path to a scenario TOML file")
    p.add_argument("--commands", required=True, help='comma- or space-separated tokens, e.g. "x+,x+,sI"')
    p.add_argument("--clearance", type=float, default=0.0, help="clearance δ in cells around every block")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.add_argument("--plot", metavar="FILE", help="save a PNG of the map and the executed path")

    p = sub.add_parser(
        "tile",
        help="tile a scenario's free cells with tetrominoes (seed 003) and label the waypoints",
        description="Tile the free cells of a grid scenario with the robot's tetrominoes and label every "
        "tile's blocks a-d by Algorithm 1 of seed 003. Writes the labelled tileset (to --out, or prints it).",
    )
    p.add_argument("scenario", help="bundled scenario name or path to a scenario TOML file")
    p.add_argument("--shapes", help="allowed morphologies, e.g. TZ or O (default: all seven, IOLJZST)")
    p.add_argument("--solver", choices=TILING_SOLVERS, default="backtracking",
                   help="backtracking: the paper's search (default); cpsat: exact cover with OR-Tools CP-SAT")
    p.add_argument("--overlap", action="store_true",
                   help="if the map cannot be tiled, cover it by two overlapping sub-workspaces (seed 003 Fig. 5)")
    p.add_argument("--seed", type=int, help="shuffle the placement order, for another tiling")
    p.add_argument("--time-limit", type=float, default=TILING_TIME_LIMIT,
                   help=f"give up after this many seconds (default {TILING_TIME_LIMIT:g})")
    p.add_argument("--out", metavar="FILE", help="write the labelled tileset to FILE")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.add_argument("--plot", metavar="FILE", help="save a PNG of the tileset")

    p = sub.add_parser(
        "sequence",
        help="order a tileset's waypoints (seed 003's TSP) with one solver",
        description="Order the waypoints of a labelled tileset as an open path from a start tile, "
        "minimising the eq.-2 cost (weighted displacement of the blocks a-d). TILESET is a labelled "
        "tileset (bundled name or file) or a scenario, which is tiled first.",
    )
    p.add_argument("tileset", help="labelled tileset (bundled name or file) or scenario (name or .toml)")
    p.add_argument("--solver", choices=SEQUENCE_SOLVERS, default="auto",
                   help="auto (default): exact up to 40 waypoints, local search beyond; ga: the paper's GA "
                        "on DEAP with a 2-opt/Or-opt step (ga-plain: without); ortools: routing with "
                        "guided local search; exact: CP-SAT optimum (<= 40 waypoints); local: nearest "
                        "neighbour + 2-opt/Or-opt; zigzag, zigzag2, spiral, spiral2, greedy: the paper's baselines")
    p.add_argument("--start", default="1", help="label of the start tile (default 1), or 'free'")
    p.add_argument("--weights", default="0.25,0.25,0.25,0.25",
                   help="eq. 2's weights α,β,λ,γ of blocks a,b,c,d (default 0.25 each)")
    p.add_argument("--seed", type=int, default=0, help="random seed (deterministic solvers ignore it)")
    p.add_argument("--time-limit", type=float, help="time budget in seconds (exact, ortools, ga, local)")
    p.add_argument("--shapes", help="when TILESET is a scenario: allowed morphologies for the tiling")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.add_argument("--plot", metavar="FILE", help="save a PNG of the tileset and the order")
    return parser


def _grid_scenario(name: str) -> Scenario:
    scenario = load_scenario(name)
    if not isinstance(scenario, Scenario):
        raise ScenarioError(f"scenario {scenario.name!r} is continuous; this command needs a grid scenario")
    return scenario


def _pose_dict(row) -> dict:
    x, y, s, h = (int(v) for v in row)
    return {"x": x, "y": y, "shape": STATE_NAMES[s], "heading": h}


def _check_clearance(value: float) -> float:
    if not 0 <= value < 10:
        raise ParameterError(f"--clearance must be between 0 and 10 cells, got {value:g}")
    return value


def _cmd_scenarios(args) -> dict:
    rows = []
    for name in list_scenarios():
        sc = load_scenario(name)
        if isinstance(sc, Scenario):
            rows.append({"name": name, "size": [sc.workspace.width, sc.workspace.height],
                         "roadmap": len(sc.roadmap), "moving": len(sc.workspace.moving), "source": sc.source})
        else:
            rows.append({"name": name, "size": [sc.width, sc.height], "roadmap": 0, "moving": 0, "source": sc.source})
    tilesets = []
    for name in list_tilesets():
        ts = load_tileset(tileset_path(name))
        tilesets.append({"name": name, "size": [ts.width, ts.height], "tiles": len(ts),
                         "source": "seed 003 (Le et al., Electronics 2018), the paper's labelled tileset"})
    if not args.json:
        width = max((len(r["name"]) for r in rows + tilesets), default=4)
        for r in rows:
            size = "x".join(str(v) for v in r["size"])
            print(f"{r['name']:<{width}}  {size:>9}  {r['source']}")
        if tilesets:
            print("\nlabelled tilesets (for 'sequence'):")
        for r in tilesets:
            size = "x".join(str(v) for v in r["size"])
            print(f"{r['name']:<{width}}  {size:>9}  {r['tiles']} tiles, {r['source']}")
    return {"scenarios": rows, "tilesets": tilesets}


def _cmd_plan(args) -> dict:
    scenario = _grid_scenario(args.scenario)
    clearance = _check_clearance(args.clearance)
    if scenario.goal is None:
        raise PlanningError(f"scenario {scenario.name!r} has no roadmap with a start and a goal to plan for")
    began = time.perf_counter()
    genetic = args.method == "nsga2"
    if genetic:
        if args.diagonals:
            raise ParameterError("--diagonals is not available with --method nsga2 (seed 000 has no diagonal commands)")
        for flag, value, least in (("--pop-size", args.pop_size, 2), ("--max-gen", args.max_gen, 1),
                                   ("--patience", args.patience, 1), ("--max-length", args.max_length, 1)):
            if value < least:
                raise ParameterError(f"{flag} must be at least {least}, got {value}")
        plan = plan_ga(scenario.workspace, scenario.roadmap, algorithm=args.algorithm, pop_size=args.pop_size,
                       max_gen=args.max_gen, patience=args.patience, max_length=args.max_length,
                       seed=args.seed, clearance=clearance)
    else:
        plan = plan_exact(scenario.workspace, scenario.roadmap, diagonals=args.diagonals,
                          clearance=clearance, algorithm=PLAN_METHODS[args.method])
    runtime = time.perf_counter() - began
    out = {
        "scenario": scenario.name,
        "method": args.method,
        "reached": plan.reached,
        "commands": plan.tokens,
        "time": plan.time,
        "objectives": plan.objectives(),
        "runtime_s": round(runtime, 6),
    }
    if genetic:
        out.update(_ga_fields(plan, args))
    if args.plot:
        from htetro_opt.viz import plot_ga_plan, plot_path, save_figure

        method = f"{args.method} ({args.algorithm}, n_pop {args.pop_size}, seed {args.seed})" if genetic else args.method
        status = "reached" if plan.reached else f"goal NOT reached (leg {plan.failed_leg + 1} {'not solved' if genetic else 'has no path'})"
        title = f"{scenario.name}: {method}, time {plan.time:g}, {len(plan.tokens)} commands, {status}"
        if genetic:
            figure = plot_ga_plan(scenario.workspace, plan, roadmap=scenario.roadmap, hidden=scenario.hidden, title=title)
        else:
            figure = plot_path(scenario.workspace, plan.poses, roadmap=scenario.roadmap, hidden=scenario.hidden, title=title)
        save_figure(figure, args.plot)
    if not args.json:
        legs = len(scenario.roadmap) - 1
        failure = "was not solved" if genetic else "has no path"
        status = "reached" if plan.reached else f"NOT reached: leg {plan.failed_leg + 1} of {legs} {failure}"
        print(f"{scenario.name}: {status} ({args.method}, {runtime:.3f} s); time {plan.time:g}, "
              f"{len(plan.tokens)} commands")
        if genetic:
            fitness = ", ".join(f"{k} {v:.3f}" for k, v in out["fitness"].items())
            print(f"generations {out['generations']}, goal first reached in generation {out['reach_generation']}; "
                  f"multi-objective solution: {fitness}; leading front: {len(out['front'])} members")
        if plan.tokens:
            print(" ".join(plan.tokens))
    return out


def _ga_fields(plan, args) -> dict:
    """The GA's extra JSON fields: the last leg's front, and every leg's record."""
    legs = [
        {
            "start": leg.start.as_dict(),
            "goal": leg.goal.as_dict(),
            "reached": leg.reached,
            "reach_generation": leg.reach_generation,
            "generations": leg.generations,
            "converged": leg.converged,
            "runtime_s": round(leg.runtime_s, 6),
            "selected": {name: member.as_dict() for name, member in leg.selected.items()},
            "front": [member.as_dict() for member in leg.front],
        }
        for leg in plan.legs
    ]
    fitness = np.mean([leg.selected["multi_objective"].fitness for leg in plan.legs], axis=0)
    return {
        "algorithm": args.algorithm,
        "pop_size": args.pop_size,
        "seed": args.seed,
        "reach_generation": plan.reach_generation,
        "generations": sum(leg.generations for leg in plan.legs),
        "fitness": {name: float(v) for name, v in zip(FITNESS_NAMES, fitness)},
        "front": legs[-1]["front"],
        "legs": legs,
    }


def _cmd_simulate(args) -> dict:
    scenario = _grid_scenario(args.scenario)
    clearance = _check_clearance(args.clearance)
    if scenario.start is None:
        raise PlanningError(f"scenario {scenario.name!r} has no start configuration to simulate from")
    sequence = parse_commands(args.commands)
    used = sorted(set(SEED000_COMMANDS) | set(DIAGONAL_COMMANDS) | {t for t in args.commands.replace(",", " ").split()})
    world = scenario.true_workspace()
    sim = Simulator(world, commands=used, clearance=clearance)
    result = sim.run([sequence], scenario.start, roadmap=scenario.roadmap[1:])
    first_invalid = int(result.first_invalid[0])
    out = {
        "scenario": scenario.name,
        "valid": bool(result.valid[0]),
        "reached": bool(result.valid[0] and result.reached[0]),
        "executed": int(result.executed[0]),
        "first_invalid": None if first_invalid < 0 else first_invalid,
        "final": _pose_dict(result.final[0]),
        "time": float(result.time[0]),
    }
    if args.plot:
        from htetro_opt.viz import plot_path, save_figure

        state = "valid" if out["valid"] else f"invalid at command {first_invalid + 1}"
        title = f"{scenario.name}: {out['executed']} of {len(sequence)} commands executed ({state})"
        save_figure(plot_path(world, result.poses(0), roadmap=scenario.roadmap,
                              hidden=scenario.hidden, title=title), args.plot)
    if not args.json:
        f = out["final"]
        print(f"{'valid' if out['valid'] else 'INVALID at command ' + str(first_invalid + 1)}; "
              f"executed {out['executed']} of {len(sequence)}; reached: {out['reached']}; "
              f"final ({f['x']}, {f['y']}) {f['shape']} heading {f['heading']}; time {out['time']:g}")
    return out


def _time_limit(value: float | None) -> float | None:
    if value is not None and not value > 0:
        raise ParameterError(f"--time-limit must be positive, got {value:g}")
    return value


def _tileset_of_scenario(name: str, *, shapes, solver="backtracking", seed=None, time_limit=None, overlap=False):
    scenario = _grid_scenario(name)
    return tile_workspace(scenario.workspace, shapes=shapes, solver=solver, seed=seed, time_limit=time_limit,
                          overlap=overlap, name=scenario.name)


def _cmd_tile(args) -> dict:
    time_limit = _time_limit(args.time_limit)
    shapes = list(args.shapes) if args.shapes else None
    began = time.perf_counter()
    tileset = _tileset_of_scenario(args.scenario, shapes=shapes, solver=args.solver, seed=args.seed,
                                   time_limit=time_limit, overlap=args.overlap)
    runtime = time.perf_counter() - began
    if args.out:
        save_tileset(tileset, args.out)
    counts = {shape: tileset.shapes.count(shape) for shape in sorted(set(tileset.shapes))}
    out = {"scenario": tileset.name, "solver": args.solver, "tiles": len(tileset), "shapes": counts,
           "overlapping": tileset.overlapping, "runtime_s": round(runtime, 6), "out": args.out}
    if args.plot:
        from htetro_opt.viz import plot_tileset, save_figure

        save_figure(plot_tileset(tileset, title=f"{tileset.name}: {len(tileset)} tiles ({args.solver})"), args.plot)
    if args.json:
        if not args.out:
            out["tileset"] = format_tileset(tileset)
    elif args.out:
        print(f"{tileset.name}: {len(tileset)} tiles in {runtime:.3f} s "
              f"({', '.join(f'{k} {v}' for k, v in counts.items())}); written to {args.out}")
    else:
        print(format_tileset(tileset))
    return out


def _is_scenario(name: str) -> bool:
    if name.endswith(".toml"):
        return True
    if name in list_tilesets():
        return False
    return name in list_scenarios()


def _cmd_sequence(args) -> dict:
    time_limit = _time_limit(args.time_limit)
    try:
        weights = check_weights([float(v) for v in args.weights.split(",")])
    except ValueError as err:
        raise ParameterError(f"--weights must be four comma-separated numbers a,b,c,d, got {args.weights!r}") from err
    if args.start == "free":
        start = None
    else:
        try:
            start = int(args.start)
        except ValueError as err:
            raise ParameterError(f"--start must be a tile label or 'free', got {args.start!r}") from err
    if _is_scenario(args.tileset):
        scenario_path(args.tileset)  # a clear error for a missing file
        tileset = _tileset_of_scenario(args.tileset, shapes=list(args.shapes) if args.shapes else None,
                                       time_limit=TILING_TIME_LIMIT)
    else:
        if args.shapes:
            raise ParameterError("--shapes applies only when TILESET is a scenario to tile")
        tileset = load_tileset(tileset_path(args.tileset))
    instance = SequencingInstance.from_tileset(tileset, start=start, weights=weights)
    result = sequence_waypoints(instance, args.solver, seed=args.seed, time_limit=time_limit)
    out = {"tileset": tileset.name, "waypoints": instance.n, "start": args.start, "weights": weights.tolist(),
           **result.as_dict()}
    if args.plot:
        from htetro_opt.viz import plot_tileset, save_figure

        title = f"{tileset.name}: {result.solver}, cost {result.cost:.3f}"
        save_figure(plot_tileset(tileset, order=result.tiles, title=title), args.plot)
    if not args.json:
        print(f"{tileset.name}: {instance.n} waypoints, {result.solver}, cost {result.cost:.4f} "
              f"in {result.runtime_s:.3f} s")
        print(" ".join(str(t) for t in result.tiles))
    return out


_COMMANDS = {"scenarios": _cmd_scenarios, "plan": _cmd_plan, "simulate": _cmd_simulate,
             "tile": _cmd_tile, "sequence": _cmd_sequence}


def main(argv: Sequence[str] | None = None) -> int:
    """Run the CLI; returns the exit status (0 success, 2 error)."""
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
        out = _COMMANDS[args.command](args)
    except (UsageError, HtetroError) as err:
        print("error: " + " ".join(str(err).split()), file=sys.stderr)
        return EXIT_ERROR
    except SystemExit as done:  # --help and --version
        return int(done.code or 0)
    if getattr(args, "json", False):
        print(json.dumps(out))
    return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())


def main_entry() -> None:
    """Console-script entry point."""
    try:
        code = main()
        sys.stdout.flush()
    except BrokenPipeError:  # output piped into e.g. `head`, which closed it: not an error of ours
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        code = 1
    sys.exit(code)
