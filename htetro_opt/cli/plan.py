"""``htetro-opt plan SCENARIO``: a path through a grid scenario's roadmap (the grid-path task) or through a
continuous scenario (the continuous task), by any method of the task's spec."""

from __future__ import annotations

import numpy as np

from htetro_opt.cli._common import (
    add_method,
    add_outputs,
    add_task_options,
    check_method,
    check_outputs,
    console,
    given_options,
    late,
    save_gif,
    save_plot,
)
from htetro_opt.solvers._tasks import CONTINUOUS, GRID_PATHS

__all__ = ["add_parser", "run"]

_SPECS = {"grid scenarios": GRID_PATHS, "continuous scenarios": CONTINUOUS}


def _seconds(time: float) -> str:
    """A plan's time for a title: 33, 45.9 (diagonal moves make times like 45.8855 s)."""
    return f"{time:.1f}".rstrip("0").rstrip(".")


def add_parser(sub) -> None:
    p = sub.add_parser("plan", help="plan a path through a scenario's roadmap",
                       description="Plan the robot's commands through a grid scenario's roadmap (start, "
                       "configurations, goal), or every robot's path through a continuous scenario (Nazarahari "
                       "et al. 2019), with one method; every plan is re-validated in the simulator.")
    p.add_argument("scenario", help="bundled scenario name or path to a scenario TOML file")
    add_method(p, _SPECS)
    add_task_options(p, _SPECS)
    add_outputs(p, plot="a plot of the map and the path", gif="an animated GIF of the plan, step by step (grid)")


def run(args) -> dict:
    from htetro_opt.scenarios import Scenario, load_scenario

    scenario = load_scenario(args.scenario)
    grid = isinstance(scenario, Scenario)
    spec, other = (GRID_PATHS, "continuous scenarios") if grid else (CONTINUOUS, "grid scenarios")
    kind = "grid" if grid else "continuous"
    method = check_method(spec, args.method, what=f" ({scenario.name!r} is a {kind} scenario)")
    if not grid and args.gif:
        raise _only("--gif", "grid scenarios")
    options = given_options(args, spec, method, others={other: _SPECS[other]})
    check_outputs(args, ("plot", "plot"), ("gif", "animation"))
    shown = console(args)
    if "heat" in method.family and args.plot:
        options["keep_fields"] = True  # the plot draws the legs' fields
    # a GA reports its generations out of max_gen
    total = options.get("max_gen", spec.default_of(method, "max_gen")) if method.takes("progress") else None
    with shown.step(f"planning ({method.name})", total, "generations" if total else "") as progress:
        if method.takes("progress"):
            options["progress"] = progress
        problem, plan = spec.solve(scenario, method=method.name, **options)
    out = {"scenario": problem.name, **plan.as_dict()}
    return _grid(args, problem, plan, out, shown) if grid else _continuous(args, problem, plan, out, shown)


def _only(flag: str, where: str):
    from htetro_opt.errors import ParameterError

    return ParameterError(f"{flag} applies to {where} only")


def _grid(args, problem, plan, out: dict, shown) -> dict:
    scenario = problem.scenario
    genetic = bool(plan.legs)
    if plan.reached:
        status = f"time {_seconds(plan.time)} s, {len(plan.tokens)} commands, reached"
    else:
        status = (f"goal NOT reached (leg {plan.failed_leg + 1} {'not solved' if genetic else 'has no path'}; "
                  f"{len(plan.tokens)} commands of the legs before it)")
    title = f"{scenario.name}: {plan.method}, {status}"  # the figure and the animation say the same
    if args.plot:
        from htetro_opt.viz import plot_ga_plan, plot_path

        if genetic:
            def figure():
                return plot_ga_plan(scenario.workspace, plan, roadmap=scenario.roadmap, hidden=scenario.hidden,
                                    title=title)
        elif plan.info.get("fields"):
            from htetro_opt.viz import plot_heat_plan

            def figure():
                return plot_heat_plan(scenario.workspace, plan, plan.info["fields"], replans=plan.info.get("replans"),
                                      roadmap=scenario.roadmap, hidden=scenario.hidden, title=title)
        else:
            def figure():
                return plot_path(scenario.workspace, plan.poses, roadmap=scenario.roadmap, hidden=scenario.hidden,
                                 title=title)
        late(out, lambda: save_plot(shown, figure, args.plot))
    if args.gif:
        late(out, lambda: save_gif(shown, scenario.workspace, plan.commands, scenario.roadmap[0],
                                   roadmap=scenario.roadmap, hidden=scenario.hidden, title=title, path=args.gif))
    if not args.json:
        legs = len(scenario.roadmap) - 1
        failure = "was not solved" if genetic else "has no path"
        status = "reached" if plan.reached else f"NOT reached: leg {plan.failed_leg + 1} of {legs} {failure}"
        print(f"{scenario.name}: {status} ({plan.method}, {plan.runtime_s:.3f} s); time {plan.time:g} s, "
              f"{len(plan.tokens)} commands")
        if genetic:
            fitness = ", ".join(f"{k} {v:.3f}" for k, v in out["fitness"].items())
            first = out["reach_generation"]
            pick = out["pick"]
            print(f"generations {out['generations']}, goal first reached "
                  f"{'in generation ' + str(first) if first is not None else 'in no generation'}; "
                  f"{'multi-objective' if pick == 'balanced' else pick} solution: {fitness}; "
                  f"leading front: {len(out['front'])} members")
            if "gap" in out:
                print(f"gap to the exact optimum ({out['gap']['exact']:g} s): {pick} {out['gap']['picked']:.1%}, "
                      f"fastest {out['gap']['fastest']:.1%}")
        if plan.time_limited:
            print("the time limit cut the run short: the plan depends on the machine's speed, not only on the seed")
        if plan.tokens:
            print(" ".join(plan.tokens))
    return out


def _continuous(args, problem, plan, out: dict, shown) -> dict:
    scenario = problem.scenario
    if "front" in out["info"]:  # pymoo's NSGA-II: its front beside the plan, not among its extras
        out["front"] = out["info"].pop("front")
    if args.plot:
        from htetro_opt.viz import plot_continuous

        status = "reached" if plan.reached else "NOT reached"
        title = f"{scenario.name}: {plan.method}, length {plan.length:.2f}, {status}"
        late(out, lambda: save_plot(shown, lambda: plot_continuous(scenario, plan, title=title), args.plot))
    if not args.json:
        status = "reached" if plan.reached else "NOT reached: " + ", ".join(
            f"robot {k}" for k, ok in enumerate(plan.robots_reached) if not ok)
        closest = "" if plan.min_robot_distance is None else (
            f"; closest approach {plan.min_robot_distance:.3f} (d_s {plan.safety_distance:g}, "
            f"{len(plan.conflicts)} conflict(s))")
        print(f"{scenario.name}: {status} ({plan.method}, {plan.runtime_s:.3f} s); length {plan.length:.3f}, "
              f"smoothness {np.nansum(plan.smoothness_deg):.1f} deg{closest}")
    return out
