"""plot_continuous, plot_apf_potential, plot_continuous_front: what is drawn is the plans' paths and
PBs, the obstacles (and C-obstacles), the closest approach; bad inputs raise typed errors."""

import numpy as np
import pytest

from htetro_opt.errors import ParameterError
from htetro_opt.scenarios import load_scenario
from htetro_opt.solvers.continuous import plan_continuous
from htetro_opt.viz import plot_apf_potential, plot_continuous, plot_continuous_front, save_figure


def by_gid(ax, gid):
    return [a for a in ax.get_children() if a.get_gid() == gid]


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
