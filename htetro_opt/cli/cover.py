"""``htetro-opt cover SCENARIO``: commands that cover every cell the robot can cover (Cheng et al. 2019),
by any method of the coverage task's spec."""

from __future__ import annotations

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
from htetro_opt.solvers._tasks import COVERAGE

__all__ = ["add_parser", "run"]

_SPECS = {"coverage": COVERAGE}


def add_parser(sub) -> None:
    p = sub.add_parser(
        "cover",
        help="plan complete coverage of a scenario (Cheng et al. 2019)",
        description="Plan commands (Cheng et al. 2019's 13) that cover every free cell the robot can cover in the "
        "allowed morphology layers: stripes of rows cut into regions, each searched for its cheapest covering walk, "
        "joined by one auxiliary DAG; or a baseline (a one-layer boustrophedon, tiling + TSP). Cells no allowed pose "
        "covers are reported.",
    )
    p.add_argument("scenario", help="bundled scenario name or path to a scenario TOML file")
    add_method(p, _SPECS)
    add_task_options(p, _SPECS)
    add_outputs(p, plot="a plot of the map, the stripes, the regions and the plan (the paper's Figs. 14a, 15a)")
    p.add_argument("--coverage-plot", metavar="FILE",
                   help="save the pixel coverage times and their histogram (the paper's Figs. 14b-c, 15b-c)")


def run(args) -> dict:
    method = check_method(COVERAGE, args.method)
    options = given_options(args, COVERAGE, method)
    check_outputs(args, ("plot", "plot"), ("coverage_plot", "coverage plot"))
    if args.coverage_plot:
        from htetro_opt.viz import figure_format

        figure_format(args.coverage_plot)
    shown = console(args)
    with shown.step(f"covering ({method.name})"):
        problem, plan = COVERAGE.solve(args.scenario, method=method.name, naming="flag", **options)
    workspace = problem.scenario.workspace
    out = {"scenario": problem.name, **plan.as_dict()}
    title = f"{problem.name}: {method.name}"
    if args.plot:
        from htetro_opt.viz import plot_cover

        late(out, lambda: save_plot(shown, lambda: plot_cover(workspace, plan, title=title), args.plot))
    if args.coverage_plot:
        from htetro_opt.viz import plot_cover_heat

        late(out, lambda: save_plot(shown, lambda: plot_cover_heat(plan, title=title), args.coverage_plot))
    if not args.json:
        state = "complete" if plan.complete else f"incomplete ({len(plan.uncoverable)} free cells uncoverable)"
        if not plan.success:  # the paper's algorithm left cells or ran out of nodes: said, not rescued
            state = f"not successful: {plan.message}"
        # only the region-searching methods (stripes) have region searches to count
        searches = (f"{plan.regions_optimal} of {plan.regions} region searches optimal, " if plan.regions else "")
        print(f"{problem.name}: {method.name} with {','.join(plan.layers)}: {plan.action_cost} commands, {state}, "
              f"average coverage time {plan.average_coverage_time:.3f}, {searches}{plan.runtime_s:.3f} s")
        if plan.time_limited:
            print("the time limit cut the region searches short: the plan depends on the machine's speed")
        print(",".join(plan.tokens))
    return out
