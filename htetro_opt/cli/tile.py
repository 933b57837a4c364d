"""``htetro-opt tile SCENARIO``: the free cells tiled with the robot's tetrominoes, each tile's blocks
labelled a–d by Algorithm 1 of Le et al. 2018 (the tiling task)."""

from __future__ import annotations

import os

from htetro_opt.cli._common import (
    LateOutputError,
    add_method,
    add_outputs,
    add_task_options,
    check_method,
    check_outputs,
    console,
    given_options,
    late,
    save_plot,
)
from htetro_opt.errors import ParameterError
from htetro_opt.solvers._tasks import TILING

__all__ = ["add_parser", "run"]

_SPECS = {"tiling": TILING}


def add_parser(sub) -> None:
    p = sub.add_parser(
        "tile",
        help="tile a scenario's free cells with tetrominoes (Le et al. 2018) and label the waypoints",
        description="Tile the free cells of a grid scenario with the robot's tetrominoes and label every "
        "tile's blocks a-d by Algorithm 1 of Le et al. 2018. Writes the labelled tileset (to --out, or prints it).",
    )
    p.add_argument("scenario", help="bundled scenario name or path to a scenario TOML file")
    add_method(p, _SPECS)
    add_task_options(p, _SPECS)
    p.add_argument("--out", metavar="FILE", help="write the labelled tileset to FILE")
    add_outputs(p, plot="a plot of the tileset")


def run(args) -> dict:
    from htetro_opt.scenarios import format_tileset, save_tileset

    method = check_method(TILING, args.method)
    options = given_options(args, TILING, method)
    if "seed" in options and not options.get("shuffle"):
        raise ParameterError("--seed applies only with --shuffle (without it the tiling is the same every time)")
    check_outputs(args, ("out", "tileset"), ("plot", "plot"))
    shown = console(args)
    with shown.step(f"tiling ({method.name})"):
        problem, result = TILING.solve(args.scenario, method=method.name, **options)
    tileset = result.tileset
    out = {"scenario": problem.name, **result.as_dict(), "out": args.out}
    if args.plot:  # before the tileset file: a failed plot leaves no tileset written either
        from htetro_opt.viz import plot_tileset

        title = f"{tileset.name}: {len(tileset)} tiles ({method.name})"
        late(out, lambda: save_plot(shown, lambda: plot_tileset(tileset, title=title), args.plot))
    if args.out:
        try:
            late(out, lambda: save_tileset(tileset, args.out))
        except LateOutputError:
            if args.plot:  # a failed command leaves no output behind
                os.unlink(args.plot)
            raise
    if args.json:
        if not args.out:
            out["tileset"] = format_tileset(tileset)
    elif args.out:
        print(f"{tileset.name}: {result.message} in {result.runtime_s:.3f} s; written to {args.out}")
    else:
        print(format_tileset(tileset))
    return out
