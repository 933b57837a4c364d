"""``htetro-opt sequence TILESET``: a tileset's waypoints ordered (Le et al. 2018's TSP), or a TSPLIB
instance's nodes, by any method of the sequencing task's spec."""

from __future__ import annotations

from pathlib import Path

from htetro_opt.cli._common import (
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
from htetro_opt.solvers._tasks import SEQUENCING

__all__ = ["add_parser", "run"]

_SPECS = {"sequencing": SEQUENCING}


def add_parser(sub) -> None:
    p = sub.add_parser(
        "sequence",
        help="order a tileset's waypoints (the TSP of Le et al. 2018) or a TSPLIB instance with one method",
        description="Order the waypoints of a labelled tileset as an open path from a start tile, "
        "minimising the eq.-2 cost (weighted displacement of the blocks a-d). TILESET is a labelled "
        "tileset (bundled name or file) or a scenario, which is tiled first (by the tile command's default "
        "method), or a TSPLIB file (.tsp, .atsp), whose nodes are ordered as a closed tour by default, priced "
        "under TSPLIB's rounding.",
    )
    p.add_argument("tileset", metavar="TILESET",
                   help="labelled tileset (bundled name or file), scenario (name or .toml) or TSPLIB file (.tsp)")
    add_method(p, _SPECS)
    add_task_options(p, _SPECS)
    add_outputs(p, plot="a plot of the tileset and the order")


def run(args) -> dict:
    method = check_method(SEQUENCING, args.method)
    options = given_options(args, SEQUENCING, method)
    check_outputs(args, ("plot", "plot"))
    tsplib = args.tileset.lower().endswith((".tsp", ".atsp"))
    if tsplib and args.plot:
        raise ParameterError("--plot does not apply to a TSPLIB file (it has no tiles)")
    shown = console(args)
    problem = SEQUENCING.pose(args.tileset, naming="flag", **{k: v for k, v in options.items()
                                                               if SEQUENCING.options[k].stage == "problem"})
    instance = problem.extras["instance"]
    solving = {k: v for k, v in options.items() if SEQUENCING.options[k].stage == "method"}
    what = "nodes" if tsplib else "waypoints"
    with shown.step(f"sequencing {instance.n} {what} ({method.name})") as progress:
        if method.takes("progress"):
            solving["progress"] = progress
        from htetro_opt.solvers.sequencing import sequence_waypoints

        result = sequence_waypoints(instance, method=method.name, **solving)
    record = result.as_dict()
    ends = {"start": args.opt_start or "1", **({"end": options["end"]} if options.get("end") is not None else {})}
    if tsplib:
        tsp = problem.extras["tsplib"]
        if float(result.cost).is_integer():  # TSPLIB's costs are integers: so is every tour's
            record["cost"] = int(result.cost)
        out = {"tsplib": tsp.name, "type": tsp.type, "edge_weight_type": tsp.edge_weight_type, "waypoints": instance.n,
               "closed": instance.closed, **ends, **record}
        if not args.json:
            print(f"{tsp.name}: {instance.n} nodes, {'closed tour' if instance.closed else 'open path'}, "
                  f"{result.method}, cost {record['cost']} in {result.runtime_s:.3f} s")
            _said_time_limited(result)
            print(" ".join(str(t) for t in result.tiles))
        return out
    tileset = problem.extras["tileset"]
    # a tileset by the name the user gave, never an install path; a scenario tiled by its own name
    name = Path(args.tileset).stem if problem.scenario is tileset else tileset.name
    weights = options.get("weights", SEQUENCING.default_of(method, "weights"))
    out = {"tileset": name, "waypoints": instance.n, **ends, "weights": list(weights),
           **({"closed": True} if instance.closed else {}), **record}
    if args.plot:
        from htetro_opt.viz import plot_tileset

        title = f"{name}: {result.method}, cost {result.cost:.3f} cells"
        late(out, lambda: save_plot(shown, lambda: plot_tileset(tileset, order=result.tiles, title=title), args.plot))
    if not args.json:
        print(f"{name}: {instance.n} waypoints, {result.method}, cost {result.cost:.4f} in {result.runtime_s:.3f} s")
        _said_time_limited(result)
        print(" ".join(str(t) for t in result.tiles))
    return out


def _said_time_limited(result) -> None:
    if result.time_limited:
        print("the time limit stopped the method: the order depends on the machine's speed, not only on the seed")
