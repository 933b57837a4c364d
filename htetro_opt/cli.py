"""The ``htetro-opt`` command line.

Every command takes a SCENARIO, a bundled name (``htetro-opt scenarios`` lists them) or a path to a
scenario TOML file. Errors print one ``error: …`` line and exit with status 2.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from typing import Sequence

import numpy as np

from htetro_opt import __version__
from htetro_opt.errors import HtetroError, ParameterError, PlanningError, ScenarioError
from htetro_opt.model import Simulator, parse_commands
from htetro_opt.model.commands import DIAGONAL_COMMANDS, SEED000_COMMANDS
from htetro_opt.model.robot import STATE_NAMES
from htetro_opt.problems import FITNESS_NAMES
from htetro_opt.scenarios import Scenario, list_scenarios, load_scenario
from htetro_opt.solvers import GA_ALGORITHMS, plan_exact, plan_ga

__all__ = ["main", "main_entry", "build_parser"]

EXIT_ERROR = 2
PLAN_METHODS = {"exact": "dijkstra", "astar": "astar", "nsga2": "ga"}


class _Parser(argparse.ArgumentParser):
    def error(self, message: str):  # one line, exit 2 (argparse prints usage too)
        raise _UsageError(message)


class _UsageError(Exception):
    """A command-line usage error, reported like every other error: one line, exit status 2."""


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="htetro-opt", description="Path planning for the hTetro reconfigurable robot.")
    parser.add_argument("--version", action="version", version=f"htetro-opt {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)

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
    if not args.json:
        width = max((len(r["name"]) for r in rows), default=4)
        for r in rows:
            size = "x".join(str(v) for v in r["size"])
            print(f"{r['name']:<{width}}  {size:>9}  {r['source']}")
    return {"scenarios": rows}


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


_COMMANDS = {"scenarios": _cmd_scenarios, "plan": _cmd_plan, "simulate": _cmd_simulate}


def main(argv: Sequence[str] | None = None) -> int:
    """Run the CLI; returns the exit status (0 success, 2 error)."""
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
        out = _COMMANDS[args.command](args)
    except (_UsageError, HtetroError) as err:
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
    sys.exit(main())
