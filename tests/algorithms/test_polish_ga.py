"""The hTetro-GA's balanced polish: when the run ends the largest-sum member is polished (to the leg's
exact maximum for a short path) and joins the population by the GA's own sort, the generations before
are untouched, the paper's variant has it off, and the option reaches the algorithm from make_algorithm,
plan_ga, the study runner and the CLI, bad values refused by name."""

import numpy as np
import pytest
from pymoo.core.callback import Callback
from pymoo.optimize import minimize

from htetro_opt.algorithms import HTetroGA, make_algorithm, select_solutions
from htetro_opt.cli import main
from htetro_opt.errors import ParameterError
from htetro_opt.model import Pose, Workspace
from htetro_opt.operators import sequences
from htetro_opt.problems import CommandPathProblem
from htetro_opt.scenarios import load_scenario
from htetro_opt.solvers.grid_paths import plan_ga, plan_max_fitness_sum, plan_path
from htetro_opt.studies.runner import Study, StudyError, run_trial

TOLERANCE = 1e-9


def _walled():
    """A 14 × 10 room with a wall from the bottom to y = 5 at x = 7, the goal behind it."""
    occupancy = np.zeros((10, 14), dtype=bool)
    occupancy[0, :] = occupancy[-1, :] = occupancy[:, 0] = occupancy[:, -1] = True
    occupancy[1:6, 7] = True
    return Workspace(occupancy)


WALLED = _walled()
START, GOAL = Pose(2, 2, "O", 0), Pose(11, 2, "O", 0)
MAX_LENGTH = 40


@pytest.fixture(scope="module")
def problem():
    return CommandPathProblem(WALLED, START, GOAL, max_length=MAX_LENGTH)


class _Trajectory(Callback):
    """The population's objectives after every generation (the callback runs before the end of the run)."""

    def __init__(self) -> None:
        super().__init__()
        self.F = []

    def notify(self, algorithm) -> None:
        self.F.append(algorithm.pop.get("F").copy())


def _run(problem, polish_window, seed):
    trajectory = _Trajectory()
    res = minimize(problem, HTetroGA(pop_size=12, polish_window=polish_window), ("n_gen", 25), seed=seed,
                   callback=trajectory)
    return res, trajectory


def _best_sum(res) -> float:
    F = res.pop.get("F")
    return float(-F[select_solutions(F)["multi_objective"]].sum())


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_the_polished_pick_is_the_exact_maximum_and_the_run_before_it_unchanged(problem, seed):
    plain, plain_trajectory = _run(problem, 0, seed)
    polished, polished_trajectory = _run(problem, 40, seed)
    assert len(plain_trajectory.F) == len(polished_trajectory.F) == 25
    assert all(np.array_equal(a, b) for a, b in zip(plain_trajectory.F, polished_trajectory.F))
    assert _best_sum(polished) > _best_sum(plain)  # these seeds' picks fall short of the maximum
    # the pick's path has at most W commands: the polish re-plans it whole, to the leg's largest sum
    best = plan_max_fitness_sum(WALLED, START, GOAL, max_length=MAX_LENGTH).info["fitness_sum"]
    assert _best_sum(polished) == pytest.approx(best, abs=TOLERANCE)
    assert len(polished.pop) == len(plain.pop) == 12
    # the population is consistent: the polished member is a leading-front member of res.opt, and the
    # other members are those of the plain run less the ones the sort dropped for it
    F = polished.pop.get("F")
    row = select_solutions(F)["multi_objective"]
    assert polished.pop[row].get("rank") == 0 and any(np.array_equal(F[row], f) for f in polished.opt.get("F"))
    plain_X = {tuple(x) for x in sequences(plain.pop.get("X"))}
    assert sum(tuple(x) not in plain_X for x in sequences(polished.pop.get("X"))) <= 1


def test_the_polish_is_reproducible(problem):
    a, _ = _run(problem, 40, 3)
    b, _ = _run(problem, 40, 3)
    assert [x.tolist() for x in sequences(a.pop.get("X"))] == [x.tolist() for x in sequences(b.pop.get("X"))]


def test_defaults_and_the_paper_variant():
    assert HTetroGA().polish_window == 40
    assert HTetroGA.as_published().polish_window == 0
    assert HTetroGA.as_published(polish_window=12).polish_window == 12
    assert make_algorithm("htetro-ga").polish_window == 40
    assert make_algorithm("htetro-ga-paper").polish_window == 0
    assert make_algorithm("htetro-ga", polish_window=7).polish_window == 7
    assert make_algorithm("htetro-ga-paper", polish_window=7).polish_window == 7
    make_algorithm("nsga2", polish_window=0)  # off is what pymoo's algorithms do anyway


@pytest.mark.parametrize("value", [-1, 2.5, "40", True])
def test_bad_windows_are_refused_by_name(value):
    with pytest.raises(ParameterError, match="polish_window"):
        HTetroGA(polish_window=value)
    with pytest.raises(ParameterError, match="polish_window"):
        make_algorithm("htetro-ga", polish_window=value)
    with pytest.raises(ParameterError, match="polish_window"):
        plan_ga(WALLED, [START, GOAL], polish_window=value)


@pytest.mark.parametrize("name", ["nsga2", "smsemoa"])
def test_pymoos_algorithms_refuse_a_window(name):
    with pytest.raises(ParameterError, match=rf"polish_window applies to the hTetro-GA .* not to '{name}'"):
        make_algorithm(name, polish_window=5)
    with pytest.raises(ParameterError, match="polish_window applies to the hTetro-GA"):
        plan_ga(WALLED, [START, GOAL], algorithm=name, polish_window=5)


def test_plan_ga_passes_the_window():
    options = dict(pop_size=12, max_gen=15, max_length=MAX_LENGTH, seed=1)
    plain = plan_ga(WALLED, [START, GOAL], polish_window=0, **options)
    polished = plan_ga(WALLED, [START, GOAL], **options)
    assert plain.reached and polished.reached
    sums = [float(plan.legs[0].selected["multi_objective"].fitness.sum()) for plan in (plain, polished)]
    best = plan_max_fitness_sum(WALLED, START, GOAL, max_length=MAX_LENGTH).info["fitness_sum"]
    assert sums[1] == pytest.approx(best, abs=TOLERANCE) and sums[0] <= sums[1] + TOLERANCE
    assert polished.legs[0].generations == plain.legs[0].generations
    assert plan_ga(WALLED, [START, GOAL], **options).tokens == polished.tokens  # the same seed, the same plan


def _study(**entry):
    return Study(name="x", task="plan", scenarios=["h_shape"], methods=[entry])


@pytest.mark.parametrize("method", ["nsga2", "dijkstra", "heat"])
def test_the_runner_takes_the_window_for_the_htetro_ga_only(method):
    assert _study(method="htetro-ga", polish_window=12).methods[0].options == {"polish_window": 12}
    paper = _study(method="htetro-ga-paper", polish_window=12, additions=["polish"])  # the paper plus one of ours
    assert paper.methods[0].options == {"additions": ["polish"], "polish_window": 12}
    with pytest.raises(StudyError, match=r"methods\[0\]: polish_window sets the polish addition, which is off"):
        _study(method="htetro-ga-paper", polish_window=12)  # as published: no polish, whatever the window
    with pytest.raises(StudyError, match=r"methods\[0\]: polish_window"):
        _study(method="htetro-ga", polish_window=-1)
    with pytest.raises(StudyError, match=rf"methods\[0\]: polish_window applies to the .* not to {method}"):
        _study(method=method, polish_window=5)


def test_the_runner_passes_the_window_to_the_planner():
    options = {"pop_size": 12, "max_gen": 30, "patience": 10}
    grid = load_scenario("h_shape")
    for window in (0, 40):
        record = run_trial("plan", "h_shape", "htetro-ga", {**options, "polish_window": window}, 0)
        plan = plan_path(grid.workspace, grid.roadmap, method="htetro-ga", seed=0, polish_window=window, **options)
        assert record["polish_window"] == window and record["commands"] == ",".join(plan.tokens)


def _cli(capsys, argv):
    code = main(argv)
    out, err = capsys.readouterr()
    return code, out, err


def test_the_cli_passes_the_window(capsys, monkeypatch):
    import htetro_opt.solvers.grid_paths._dispatch as dispatch

    given = {}
    real = dispatch.plan_path

    def spy(workspace, roadmap, **options):
        given.update(options)
        return real(workspace, roadmap, **{**options, "pop_size": 4, "max_gen": 2})

    monkeypatch.setattr(dispatch, "plan_path", spy)
    code, _, err = _cli(capsys, ["plan", "h_shape", "--method", "htetro-ga", "--polish-window", "12", "--json"])
    assert code == 0, err
    assert given["polish_window"] == 12
    given.clear()
    assert _cli(capsys, ["plan", "h_shape", "--method", "htetro-ga-paper", "--json"])[0] == 0
    assert "polish_window" not in given  # the algorithm's default


@pytest.mark.parametrize("argv, words", [
    (["--method", "htetro-ga", "--polish-window", "-1"], ["--polish-window"]),
    (["--method", "nsga2", "--polish-window", "5"], ["--polish-window", "nsga2"]),
    (["--method", "dijkstra", "--polish-window", "5"], ["--polish-window"]),
])
def test_the_cli_refuses_bad_windows_in_one_line(capsys, argv, words):
    code, out, err = _cli(capsys, ["plan", "h_shape", *argv])
    assert code == 2 and out == ""
    lines = err.splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: ") and "Traceback" not in err
    for word in words:
        assert word in lines[0], (word, lines[0])


def test_a_crowded_leading_front_makes_room_for_the_polished_member(problem):
    """When the leading front outnumbers the population, the crowding cut could drop the polished
    member (here the cut is made to): it then replaces the most crowded survivor."""
    res = minimize(problem, HTetroGA(pop_size=12, polish_window=0), ("n_gen", 25), seed=0)
    algorithm = res.algorithm
    before = {tuple(x) for x in sequences(algorithm.pop.get("X"))}
    sort = algorithm.survival.sort

    def cut_the_newcomer(F, end, n_survive, *, random_state):
        if len(F) <= n_survive:
            return sort(F, end, n_survive, random_state=random_state)
        rows = np.arange(n_survive)  # the members, not the polished one appended last
        return rows, np.zeros(n_survive, dtype=np.int64), np.arange(n_survive, dtype=float)

    algorithm.survival.sort = cut_the_newcomer
    algorithm.polish_window = 40
    algorithm._polish()
    after = [tuple(x) for x in sequences(algorithm.pop.get("X"))]
    assert len(after) == 12 and len(set(after) - before) == 1 and len(before - set(after)) == 1
    F = algorithm.pop.get("F")
    best = plan_max_fitness_sum(WALLED, START, GOAL, max_length=MAX_LENGTH).info["fitness_sum"]
    assert float(-F[select_solutions(F)["multi_objective"]].sum()) == pytest.approx(best, abs=TOLERANCE)
    assert len(algorithm.opt) == int((algorithm.pop.get("rank") == 0).sum())
