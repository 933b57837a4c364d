"""``htetro-opt simulate SCENARIO --commands …``: a command sequence executed from the scenario's start in
the true world (hidden obstacles included)."""

from __future__ import annotations

import sys
from pathlib import Path

from htetro_opt.cli._common import add_outputs, check_outputs, console, grid_scenario, late, save_gif, save_plot
from htetro_opt.errors import ParameterError, PlanningError
from htetro_opt.solvers._tasks import GRID_PATHS

__all__ = ["add_parser", "run"]

_CLEARANCE = GRID_PATHS.options["clearance"]  # the simulator's clearance: the plan task's option, checked alike


def add_parser(sub) -> None:
    p = sub.add_parser(
        "simulate",
        help="execute a command sequence in a scenario",
        description="Execute a command sequence from the scenario's start in the true world (hidden "
        "obstacles included). 'reached' means the whole sequence is valid, passes through the roadmap's "
        "configurations in order and ends on the goal; 'executed' counts the commands run before the "
        "first invalid one.",
    )
    p.add_argument("scenario", help="bundled scenario name or path to a scenario TOML file")
    p.add_argument("--commands", required=True,
                   help='comma- or space-separated tokens, e.g. "x+,x+,sI"; @FILE reads them from a file, - from stdin')
    p.add_argument(_CLEARANCE.flag, type=float, default=_CLEARANCE.default, metavar=_CLEARANCE.metavar,
                   help=f"{_CLEARANCE.help} (default {_CLEARANCE.default:g})")
    add_outputs(p, plot="a plot of the map and the executed path",
                gif="an animated GIF of the executed commands, step by step")


def run(args) -> dict:
    from htetro_opt.model import Simulator, parse_commands
    from htetro_opt.model.commands import DIAGONAL_COMMANDS, SEED000_COMMANDS
    from htetro_opt.model.robot import STATE_NAMES

    scenario = grid_scenario(args.scenario)
    clearance = _CLEARANCE.check(args.clearance, _CLEARANCE.flag)
    check_outputs(args, ("plot", "plot"), ("gif", "animation"))
    if scenario.start is None:
        raise PlanningError(f"scenario {scenario.name!r} has no start configuration to simulate from")
    text = _commands_text(args.commands)
    sequence = parse_commands(text)
    used = sorted(set(SEED000_COMMANDS) | set(DIAGONAL_COMMANDS) | {t for t in text.replace(",", " ").split()})
    world = scenario.true_workspace()
    sim = Simulator(world, commands=used, clearance=clearance)
    result = sim.run([sequence], scenario.start, roadmap=scenario.roadmap[1:])
    first_invalid = int(result.first_invalid[0])
    x, y, s, h = (int(v) for v in result.final[0])
    out = {
        "scenario": scenario.name,
        "valid": bool(result.valid[0]),
        "reached": bool(result.valid[0] and result.reached[0]),
        "executed": int(result.executed[0]),
        "first_invalid": None if first_invalid < 0 else first_invalid,
        "final": {"x": x, "y": y, "shape": STATE_NAMES[s], "heading": h},
        "time": float(result.time[0]),
    }
    shown = console(args)
    if args.plot:
        from htetro_opt.viz import plot_path

        state = "valid" if out["valid"] else f"invalid at command index {first_invalid} (0-based)"
        title = f"{scenario.name}: {out['executed']} of {len(sequence)} commands executed ({state})"
        late(out, lambda: save_plot(shown, lambda: plot_path(
            world, result.poses(0), roadmap=scenario.roadmap, hidden=scenario.hidden, title=title), args.plot))
    if args.gif:  # the executed prefix: an invalid command is where the run stopped
        title = f"{scenario.name}: {out['executed']} of {len(sequence)} commands executed"
        late(out, lambda: save_gif(shown, world, result.prefix(0), scenario.start, roadmap=scenario.roadmap,
                                   hidden=scenario.hidden, title=title, path=args.gif))
    if not args.json:
        f = out["final"]
        print(f"{'valid' if out['valid'] else f'INVALID at command index {first_invalid} (0-based)'}; "
              f"executed {out['executed']} of {len(sequence)}; reached: {out['reached']}; "
              f"final ({f['x']}, {f['y']}) {f['shape']} heading {f['heading']}; time {out['time']:g} s")
    return out


def _commands_text(argument: str) -> str:
    """``--commands``: the tokens themselves, ``@FILE`` for a file of them, or ``-`` for stdin
    (a long sequence does not fit on a command line)."""
    if argument == "-":
        return sys.stdin.read()
    if argument.startswith("@"):
        path = Path(argument[1:])
        try:
            return path.read_text(encoding="utf-8-sig")
        except (OSError, UnicodeDecodeError) as err:
            raise ParameterError(f"--commands {argument}: cannot read {str(path)!r}: "
                                 f"{getattr(err, 'strerror', None) or err}") from err
    return argument
