"""plot_continuous, plot_apf_potential, plot_continuous_front: what is drawn is the plans' paths and
PBs, the obstacles (and C-obstacles), the closest approach; bad inputs raise typed errors."""

import numpy as np
import pytest

from PIL import Image

from htetro_opt.errors import ParameterError
from htetro_opt.scenarios import load_scenario, parse_scenario
from htetro_opt.solvers.continuous import SPEC, plan_continuous
from htetro_opt.viz import plot_apf_potential, plot_continuous, plot_continuous_front, save_figure

SMALL = {"prm": {"seed": 0}, "rrt": {"seed": 0, "time_limit": 0.2}, "pso": {"seed": 0, "pop_size": 6, "max_gen": 3},
         "ega": {"seed": 0, "pop_size": 6, "max_gen": 3}, "ega-paper": {"seed": 0, "pop_size": 6, "max_gen": 3},
         "nsga2": {"seed": 0, "pop_size": 6, "max_gen": 3}}
"""Options that keep every method's plan of a small map short (the graph searches take none)."""


def by_gid(ax, gid):
    return [a for a in ax.get_children() if a.get_gid() == gid]


def assert_png(path):
    assert path.stat().st_size > 0
    with Image.open(path) as image:
        assert image.format == "PNG"
        image.verify()


def assert_paths_drawn(ax, plan, p=0):
    for k, path in enumerate(plan.paths):
        lines = by_gid(ax, f"path-{p}-{k}")
        if len(path):
            assert len(lines) == 1 and np.array_equal(np.column_stack(lines[0].get_data()), path)
        else:
            assert not lines  # a robot that did not reach its goal has no line


@pytest.mark.parametrize("method, name", [(m, "ega07_slits1") for m in SPEC.methods]
                         + [("ega", "ega_cross4"), ("pso", "ega_cross4")])
def test_every_method_s_plan_is_drawn_and_saved(method, name, tmp_path):
    sc = load_scenario(name)
    plan = plan_continuous(sc, method=method, **SMALL.get(method, {}))
    ax = plot_continuous(sc, plan, title=method).axes[0]
    assert ax.get_xlabel() == "x (map units)" and ax.get_ylabel() == "y (map units)"
    assert_paths_drawn(ax, plan)
    if method == "pso":  # its info gives the PBs' count: the PBs drawn are the path's interior vertices
        for k, path in enumerate(plan.paths):
            pbs = by_gid(ax, f"pbs-0-{k}")
            assert len(pbs) == (len(path) > 2)
            if pbs:
                assert np.array_equal(np.column_stack(pbs[0].get_data()), path[1:-1])
    assert_png(save_figure(ax.figure, tmp_path / f"{method}.png"))


def test_plans_with_a_robot_short_of_its_goal_are_drawn_and_say_so(tmp_path):
    walled = {"name": "walled", "width": 10, "height": 10,  # a goal at (7.5, 8) inside a closed box
              "obstacles": [[6, 6, 9, 7], [6, 9, 9, 10], [6, 6, 7, 10], [8, 6, 9, 10]]}
    boxed, free = {"start": [1, 5], "goal": [7.5, 8]}, {"start": [1, 1], "goal": [9, 2]}
    first_boxed = parse_scenario({**walled, "robots": [boxed, free]})
    alone = parse_scenario({**walled, "robots": [boxed]})
    for method in SPEC.methods:
        plan = plan_continuous(first_boxed, method=method, **SMALL.get(method, {}))
        assert plan.robots_reached == (False, True), method
        ax = plot_continuous(first_boxed, plan).axes[0]
        assert_paths_drawn(ax, plan)
        labels = ax.get_legend_handles_labels()[1]
        assert labels[2].startswith(f"{method}: ") and labels[2].endswith(" (robot 0 not reached)"), labels
        assert_png(save_figure(ax.figure, tmp_path / f"{method}.png"))
    plan = plan_continuous(alone, method="pso", **SMALL["pso"])
    ax = plot_continuous(alone, plan).axes[0]
    assert not plan.reached and "pso: goal not reached" in ax.get_legend_handles_labels()[1]


def test_paths_and_path_bases_are_the_plans(tmp_path):
    sc = load_scenario("ega07_slits1")
    plans = [plan_continuous(sc), plan_continuous(sc, method="ega", seed=0, max_gen=4)]
    fig = plot_continuous(sc, plans)
    ax = fig.axes[0]
    for p, plan in enumerate(plans):
        (line,) = by_gid(ax, f"path-{p}-0")
        assert np.array_equal(np.column_stack(line.get_data()), plan.paths[0])
    (pbs,) = by_gid(ax, "pbs-1-0")
    assert np.array_equal(np.column_stack(pbs.get_data()), np.array(plans[1].info["path_bases"][0]))
    (obstacles,) = by_gid(ax, "obstacles")
    assert len(obstacles.get_paths()) == len(sc.obstacles) and not by_gid(ax, "c-obstacles")  # r = 0
    assert save_figure(fig, tmp_path / "slits.png").stat().st_size > 0


def test_several_robots_show_their_closest_approach():
    sc = load_scenario("ega_cross4")
    plan = plan_continuous(sc)
    ax = plot_continuous(sc, plan).axes[0]
    discs = by_gid(ax, "closest-0")
    assert len(discs) == 2 and by_gid(ax, "c-obstacles")
    gap = np.hypot(*np.subtract(discs[0].center, discs[1].center))
    assert gap == pytest.approx(plan.min_robot_distance, abs=1e-9)


def test_apf_potential_and_front():
    sc = load_scenario("ega04_corridor1")
    ax = plot_apf_potential(sc, seed=0).axes[0]
    (dots,) = by_gid(ax, "potential")
    assert dots.get_array().max() == 0  # the goal: zero hops
    plan = plan_continuous(sc, method="nsga2", seed=1, max_gen=5)
    (front,) = by_gid(plot_continuous_front(plan).axes[0], "front")
    assert len(front.get_offsets()) == len(plan.info["front"])
    with pytest.raises(ParameterError, match="no front"):
        plot_continuous_front(plan_continuous(sc))
    with pytest.raises(ParameterError, match="ContinuousPlan"):
        plot_continuous(sc, ["exact"])
    with pytest.raises(ParameterError, match="grid scenario"):
        plot_continuous(load_scenario("three_slit"))


def test_one_plan_of_several_robots_has_a_legend_entry_a_robot_and_visible_ends():
    sc = load_scenario("ega_cross4")  # the four robots swap corners: each start is another's goal
    plan = plan_continuous(sc)
    ax = plot_continuous(sc, plan).axes[0]
    labels = ax.get_legend_handles_labels()[1]
    assert [f"robot {k}: {length:.2f}" for k, length in enumerate(plan.lengths)] == [
        label for label in labels if label.startswith("robot ")]
    assert f"exact: total {plan.length:.2f}" in labels
    (starts,), (goals,) = by_gid(ax, "starts"), by_gid(ax, "goals")
    assert starts.get_zorder() > goals.get_zorder()  # the dots over the stars
    assert not goals.get_facecolors().size or (goals.get_facecolors()[:, 3] == 0).all()  # hollow stars
    widths = [by_gid(ax, f"path-0-{k}")[0].get_linewidth() for k in range(sc.n_robots)]
    assert widths == sorted(widths, reverse=True) and len(set(widths)) == sc.n_robots  # coincident paths show
