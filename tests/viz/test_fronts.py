"""plot_fronts, plot_parallel, plot_convergence: what is drawn equals the fronts and histories given."""

import subprocess
import sys

import numpy as np
import pytest

from htetro_opt.errors import ParameterError
from htetro_opt.model import Pose, Workspace
from htetro_opt.problems import FITNESS_NAMES
from htetro_opt.solvers.grid_paths import plan_path
from htetro_opt.viz import plot_convergence, plot_fronts, plot_parallel

OPEN = Workspace(np.zeros((8, 8), dtype=bool))
ROADMAP = [Pose(1, 1, "O", 0), Pose(3, 3, "O", 0), Pose(5, 2, "O", 0)]


@pytest.fixture(scope="module")
def ga_plan():
    """A real two-leg GA plan (half a second)."""
    plan = plan_path(OPEN, ROADMAP, method="htetro-ga", pop_size=10, max_gen=30, max_length=8, seed=1)
    assert len(plan.legs) == 2 and all(len(leg.front) for leg in plan.legs)
    return plan


def random_front(n, seed):
    rng = np.random.default_rng(seed)
    return np.column_stack([np.ones(n), rng.uniform(-0.5, 1.0, n), rng.random(n), rng.random(n)])


def member_fitness(leg):
    """The oracle of a leg's front: its members' fitnesses, read one by one."""
    return np.array([[float(v) for v in member.fitness] for member in leg.front])


def legend_labels(fig) -> list[str]:
    legends = [ax.get_legend() for ax in fig.axes if ax.get_legend() is not None] + list(fig.legends)
    assert len(legends) == 1
    return [t.get_text() for t in legends[0].get_texts()]


@pytest.mark.parametrize("objectives", [("f_t", "f_sm", "f_sf"), ("f_sf", "f_gr"), tuple(FITNESS_NAMES)])
def test_scatter_panels_plot_the_fronts_columns(ga_plan, objectives):
    fronts = {"nsga2-like": random_front(12, 0), "htetro-ga": ga_plan, "first leg": ga_plan.legs[0]}
    expected = [fronts["nsga2-like"], member_fitness(ga_plan.legs[-1]), member_fitness(ga_plan.legs[0])]
    fig = plot_fronts(fronts, objectives=objectives, title="three fronts")
    k = len(objectives)
    assert len(fig.axes) == k * k
    column = {name: FITNESS_NAMES.index(name) for name in objectives}
    for i, y_name in enumerate(objectives):
        for j, x_name in enumerate(objectives[:i]):
            ax = fig.axes[i * k + j]
            drawn = [np.asarray(c.get_offsets()) for c in ax.collections]
            assert len(drawn) == len(expected)
            for points, front in zip(drawn, expected):
                assert np.array_equal(points, front[:, [column[x_name], column[y_name]]])
    assert legend_labels(fig) == ["nsga2-like", "htetro-ga", "first leg"]
    bottom = [fig.axes[(k - 1) * k + j].get_xlabel() for j in range(k)]
    assert [label.split("\n")[0] for label in bottom] == [f"{name} (higher is better)" for name in objectives]
    left = [fig.axes[i * k].get_ylabel() for i in range(1, k)]
    assert [label.split("\n")[0] for label in left] == [f"{n} (higher is better)" for n in objectives[1:]]
    if "f_t" in objectives:  # f_t = 1 − t/t_max goes negative for a path slower than t_max: its axis says so
        assert "< 0 slower" in bottom[objectives.index("f_t")]
    assert fig._suptitle.get_text() == "three fronts"


def test_diagonal_histograms_count_every_member():
    fronts = [random_front(7, 1), random_front(4, 2)]
    fig = plot_fronts(fronts)
    for d in range(3):
        ax = fig.axes[d * 3 + d]
        assert ax.get_title() == ("f_t", "f_sm", "f_sf")[d]
        heights = [patch.get_path().vertices[:, 1].max() for patch in ax.patches]  # one step outline per front
        assert len(ax.patches) == 2 and max(heights) >= 1
    for i, j in [(0, 1), (0, 2), (1, 2)]:  # above the diagonal: blank
        assert not fig.axes[i * 3 + j].axison and not fig.axes[i * 3 + j].collections


def test_default_labels_and_explicit_ones(ga_plan):
    assert legend_labels(plot_fronts([random_front(3, 0), ga_plan])) == ["front 1", "htetro-ga"]
    assert legend_labels(plot_fronts(random_front(3, 0))) == ["front 1"]
    assert legend_labels(plot_fronts([random_front(3, 0), ga_plan.legs[0].front], labels=["x", "y"])) == ["x", "y"]
    # a list of fitness rows is one front, not one front per row
    fig = plot_fronts([[1, 0.1, 0.2, 0.3], [1, 0.4, 0.5, 0.6]], labels=["only"])
    assert np.array_equal(fig.axes[3].collections[0].get_offsets(), [[0.1, 0.2], [0.4, 0.5]])


def test_parallel_coordinates_scale_each_axis_over_all_fronts(ga_plan):
    fronts = [random_front(9, 3), ga_plan, random_front(5, 4) - 0.3]
    values = [fronts[0], member_fitness(ga_plan.legs[-1]), fronts[2]]
    objectives = ("f_sf", "f_t", "f_sm")
    cols = [FITNESS_NAMES.index(o) for o in objectives]
    low = np.min([v[:, cols].min(axis=0) for v in values], axis=0)
    high = np.max([v[:, cols].max(axis=0) for v in values], axis=0)
    fig = plot_parallel(fronts, labels=["a", "b", "c"], objectives=objectives)
    ax = fig.axes[0]
    assert len(ax.collections) == 3
    for collection, front in zip(ax.collections, values):
        segments = collection.get_segments()
        assert len(segments) == len(front)  # one polyline per member
        for polyline, member in zip(segments, front):
            assert np.array_equal(polyline[:, 0], [0, 1, 2])
            assert np.allclose(polyline[:, 1], (member[cols] - low) / (high - low))
    texts = {t.get_gid(): t.get_text() for t in ax.texts}
    for name, lo, hi in zip(objectives, low, high):
        assert float(texts[f"min {name}"]) == pytest.approx(lo, rel=1e-2, abs=1e-3)
        assert float(texts[f"max {name}"]) == pytest.approx(hi, rel=1e-2, abs=1e-3)
    assert [t.get_text() for t in ax.get_xticklabels()] == list(objectives)
    assert legend_labels(fig) == ["a", "b", "c"]


def test_parallel_coordinates_put_a_constant_objective_in_the_middle():
    front = random_front(6, 5)  # f_gr is 1 everywhere
    fig = plot_parallel(front, objectives=("f_gr", "f_t"))
    segments = np.array(fig.axes[0].collections[0].get_segments())
    assert np.array_equal(segments[:, 0, 1], np.full(6, 0.5))
    texts = {t.get_gid(): t.get_text() for t in fig.axes[0].texts}
    assert texts["min f_gr"] == texts["max f_gr"] == "1"


def test_convergence_lines_are_the_history_columns(ga_plan):
    history = np.vstack([leg.history for leg in ga_plan.legs])
    first = len(ga_plan.legs[0].history)
    fig = plot_convergence(ga_plan, title="two legs")
    ax = fig.axes[0]
    lines = {line.get_gid(): line for line in ax.lines}
    for i, name in enumerate(FITNESS_NAMES):
        x, y = np.asarray(lines[name].get_xdata(), float), np.asarray(lines[name].get_ydata(), float)
        kept = ~np.isnan(y)
        assert np.array_equal(y[kept], history[:, i])
        assert np.array_equal(x[kept], np.arange(1, len(history) + 1))
        assert np.isnan(y[first])  # the legs are not joined
    separators = [line for line in ax.lines if line.get_gid() == "leg separator"]
    assert len(separators) == 1 and separators[0].get_xdata()[0] == first + 0.5
    assert legend_labels(fig)[:4] == list(FITNESS_NAMES)
    assert ax.get_xlabel().startswith("generation") and ax.get_title() == "two legs"


def test_convergence_of_one_leg_or_an_array_has_no_separator(ga_plan):
    history = np.asarray(ga_plan.legs[1].history)
    for given in (ga_plan.legs[1], history, history.tolist()):
        ax = plot_convergence(given).axes[0]
        assert not [line for line in ax.lines if line.get_gid() == "leg separator"]
        lines = {line.get_gid(): line for line in ax.lines}
        assert np.array_equal(lines["f_sf"].get_ydata(), history[:, 3])
        assert ax.get_xlabel() == "generation"


def test_a_negative_f_t_is_labelled_and_has_its_zero_line():
    ax = plot_convergence([[0.1, -0.4, 0.5, 0.9], [0.2, -0.1, 0.6, 0.9]]).axes[0]  # slower than t_max
    assert ax.get_ylabel().startswith("fitness (higher is better)") and "< 0 slower" in ax.get_ylabel()
    assert [line.get_ydata()[0] for line in ax.lines if line.get_gid() == "zero"] == [0.0]
    ax = plot_convergence([[0.1, 0.4, 0.5, 0.9]]).axes[0]
    assert not [line for line in ax.lines if line.get_gid() == "zero"]


@pytest.fixture(scope="module")
def exact_plan():
    return plan_path(OPEN, ROADMAP[:2], method="dijkstra")


@pytest.mark.parametrize("call, argument", [
    (lambda: plot_fronts(np.zeros((3, 3))), "fronts"),
    (lambda: plot_fronts(np.zeros(4)), "fronts"),
    (lambda: plot_fronts([np.zeros((2, 4)), np.zeros((2, 5))]), r"fronts\[1\]"),
    (lambda: plot_fronts({"ga": np.zeros((2, 4)), "bad": "x"}), r"fronts\['bad'\]"),
    (lambda: plot_fronts(np.full((2, 4), np.nan)), "fronts"),
    (lambda: plot_fronts("front"), "fronts"),
    (lambda: plot_fronts([]), "fronts"),
    (lambda: plot_fronts(np.zeros((0, 4))), "fronts"),
    (lambda: plot_fronts(np.zeros((2, 4)), objectives=("f_t", "speed")), "objectives.*'speed'"),
    (lambda: plot_fronts(np.zeros((2, 4)), objectives="f_t"), "objectives"),
    (lambda: plot_fronts(np.zeros((2, 4)), objectives=("f_t",)), "objectives"),
    (lambda: plot_fronts(np.zeros((2, 4)), objectives=("f_t", "f_t")), "objectives"),
    (lambda: plot_fronts([np.zeros((2, 4))] * 2, labels=["one"]), "labels"),
    (lambda: plot_fronts(np.zeros((2, 4)), labels="one"), "labels"),
    (lambda: plot_parallel(np.zeros((2, 4)), labels=["a", "b"]), "labels"),
    (lambda: plot_parallel(np.zeros((2, 2))), "fronts"),
    (lambda: plot_parallel(np.zeros((2, 4)), objectives=("f_x", "f_t")), "objectives"),
    (lambda: plot_convergence(np.zeros((5, 3))), "history_or_plan"),
    (lambda: plot_convergence(np.zeros((0, 4))), "history_or_plan"),
    (lambda: plot_convergence([object()]), r"history_or_plan\[0\]"),
    (lambda: plot_convergence({"f_t": [1.0]}), "history_or_plan"),
])
def test_bad_inputs_name_the_argument(call, argument):
    with pytest.raises(ParameterError, match=argument):
        call()


def test_a_plan_without_ga_legs_is_refused(exact_plan):
    for call, argument in [(plot_fronts, "fronts"), (plot_parallel, "fronts"), (plot_convergence, "history_or_plan")]:
        with pytest.raises(ParameterError, match=f"{argument} is a 'dijkstra' plan without GA legs"):
            call(exact_plan)


def test_plotting_arrays_imports_neither_matplotlib_early_nor_pymoo():
    code = ("import sys, htetro_opt.viz.fronts as f; before = 'matplotlib' in sys.modules; "
            "import matplotlib; matplotlib.use('Agg'); "
            "row = [[1, .1, .2, .3]]; f.plot_fronts(row); f.plot_parallel(row); f.plot_convergence(row); "
            "print(before, 'pymoo' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.split() == ["False", "False"]


def test_importing_viz_does_not_import_matplotlib():
    code = "import sys, htetro_opt.viz; print('matplotlib' in sys.modules, hasattr(htetro_opt.viz, 'plot_fronts'))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.split() == ["False", "True"]
