"""FrontConvergence: counting generations without improvement, the cap, and what a run reports."""

from types import SimpleNamespace

import numpy as np
import pytest
from pymoo.core.population import Population
from pymoo.optimize import minimize

from htetro_opt.algorithms import ConvergenceRecorder, FrontConvergence, HTetroGA
from htetro_opt.errors import ParameterError
from htetro_opt.model import Pose, Workspace
from htetro_opt.problems import CommandPathProblem


def fake_algorithm(F, n_gen):
    return SimpleNamespace(pop=Population.new("F", np.asarray(F, dtype=float)), n_gen=n_gen, data={})


@pytest.fixture(scope="module")
def small_problem():
    occ = np.zeros((10, 10), dtype=bool)
    occ[0, :] = occ[-1, :] = occ[:, 0] = occ[:, -1] = True
    return CommandPathProblem(Workspace(occ), Pose(3, 3, "O", 0), Pose(6, 5, "O", 0), max_length=12)


def test_front_convergence_counts_generations_without_improvement():
    term = FrontConvergence(max_gen=100, patience=3)
    reached = -np.array([[1.0, 0.5, 0.5, 0.5], [0.5, 0.9, 0.9, 0.9]])
    assert term.update(fake_algorithm(reached, 1)) == pytest.approx(0.01)
    assert term.update(fake_algorithm(reached, 2)) == pytest.approx(1 / 3)
    assert term.update(fake_algorithm(reached, 3)) == pytest.approx(2 / 3)
    better_safety = -np.array([[1.0, 0.5, 0.5, 0.6]])
    assert term.update(fake_algorithm(better_safety, 4)) == pytest.approx(0.04)  # improved: the count restarts
    assert not term.has_terminated()
    worse = -np.array([[1.0, 0.4, 0.4, 0.4]])
    for gen, expected in ((5, 1 / 3), (6, 2 / 3)):
        algorithm = fake_algorithm(worse, gen)
        assert term.update(algorithm) == pytest.approx(expected)
        assert not term.converged and algorithm.data["converged"] is False
    algorithm = fake_algorithm(better_safety, 7)
    assert term.update(algorithm) == 1.0  # matching the best is no improvement
    assert term.converged and term.has_terminated() and algorithm.data["converged"] is True


def test_front_convergence_waits_for_the_goal_and_stops_at_max_gen():
    term = FrontConvergence(max_gen=5, patience=1)
    unreached = -np.array([[0.5, 1.0, 1.0, 1.0]])
    for gen in range(1, 5):
        assert term.update(fake_algorithm(unreached, gen)) == pytest.approx(gen / 5)
    assert not term.has_terminated()
    algorithm = fake_algorithm(unreached, 5)
    assert term.update(algorithm) == 1.0
    assert term.has_terminated() and not term.converged and algorithm.data["converged"] is False


@pytest.mark.parametrize("options", [dict(max_gen=0), dict(max_gen=-5), dict(max_gen=2.5), dict(max_gen=True),
                                     dict(patience=0), dict(patience=1.0), dict(patience=None),
                                     dict(tolerance=-1e-3), dict(tolerance=float("nan"))])
def test_front_convergence_parameters(options):
    with pytest.raises(ParameterError):
        FrontConvergence(**options)


def test_a_run_reports_convergence_on_its_result(small_problem):
    # minimize works on a copy of the termination: the result, not the object passed in, tells
    term = FrontConvergence(max_gen=300, patience=5)
    recorder = ConvergenceRecorder()
    res = minimize(small_problem, HTetroGA(pop_size=12), term, seed=0, callback=recorder)
    assert res.data["converged"] is True
    assert term.converged is False  # the caller's object was never run
    generations = len(recorder.history)
    assert generations < 100 and recorder.reach_generation is not None
    assert recorder.reach_generation + 5 <= generations  # at least `patience` generations after reaching
    assert (res.pop.get("F")[:, 0] == -1.0).any()


def test_a_capped_run_reports_no_convergence(small_problem):
    res = minimize(small_problem, HTetroGA(pop_size=12), FrontConvergence(max_gen=2, patience=50), seed=0)
    assert res.data["converged"] is False
