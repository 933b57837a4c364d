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


# --- the hypervolume measure ------------------------------------------------------------------
def dominated_cells(points, k=4):
    """Oracle: the volume of the union of boxes [0, p] in [0, 1]³, by counting the cells of a k-grid
    (exact for coordinates that are multiples of 1 / k)."""
    centres = (np.arange(k) + 0.5) / k
    grid = np.stack(np.meshgrid(centres, centres, centres, indexing="ij"), axis=-1).reshape(-1, 3)
    covered = np.zeros(len(grid), dtype=bool)
    for p in points:
        covered |= (grid <= p).all(axis=1)
    return covered.sum() / k**3


@pytest.mark.parametrize("seed", range(8))
def test_reaching_hypervolume_is_the_dominated_volume_of_the_reaching_members(seed):
    from htetro_opt.algorithms import reaching_hypervolume

    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, 9))
    fitness = rng.integers(-1, 6, size=(n, 3)) / 4  # quarters, some below 0 and above 1 (clipped)
    reached = rng.random(n) < 0.7
    F = -np.column_stack([np.where(reached, 1.0, 0.5), fitness])
    expected = dominated_cells(np.clip(fitness[reached], 0, 1)) if reached.any() else 0.0
    assert reaching_hypervolume(F) == pytest.approx(expected, abs=1e-12)


def test_hypervolume_convergence_counts_a_faster_path_or_a_larger_front():
    term = FrontConvergence(max_gen=100, patience=2, measure="hypervolume")
    assert term.tolerance == 1e-5 and FrontConvergence().tolerance == 1e-9
    front = -np.array([[1.0, 0.5, 0.5, 0.5]])
    term.update(fake_algorithm(front, 1))
    term.update(fake_algorithm(front, 2))
    assert term.stall == 1
    best_sum_up = -np.array([[1.0, 0.5, 0.5, 0.5], [1.0, 0.4, 0.7, 0.7]])  # a new trade-off: the volume grows
    term.update(fake_algorithm(best_sum_up, 3))
    assert term.stall == 0
    inside = -np.array([[1.0, 0.5, 0.5, 0.5], [1.0, 0.4, 0.7, 0.7], [1.0, 0.45, 0.5, 0.5]])  # dominated: no gain
    term.update(fake_algorithm(inside, 4))
    assert term.stall == 1
    faster = -np.array([[1.0, 0.52, 0.1, 0.1]])  # a smaller front, but a faster path
    term.update(fake_algorithm(faster, 5))
    assert term.stall == 0
    term.update(fake_algorithm(faster, 6))
    term.update(fake_algorithm(faster, 7))
    assert term.converged and term.has_terminated()


def test_the_best_measure_counts_what_the_hypervolume_one_ignores():
    # a member's safety rising inside the front restarts "best" but not "hypervolume"
    before = -np.array([[1.0, 0.6, 0.9, 0.3], [1.0, 0.5, 0.5, 0.9]])
    after = -np.array([[1.0, 0.6, 0.9, 0.3], [1.0, 0.5, 0.5, 0.9], [1.0, 0.1, 0.1, 0.95]])  # adds 0.0005
    stalls = {}
    for measure in ("best", "hypervolume"):
        term = FrontConvergence(patience=10, measure=measure, tolerance=1e-3)
        term.update(fake_algorithm(before, 1))
        term.update(fake_algorithm(after, 2))
        stalls[measure] = term.stall
    assert stalls == {"best": 0, "hypervolume": 1}


@pytest.mark.parametrize("measure", ["volume", None, 1])
def test_an_unknown_measure_is_refused(measure):
    with pytest.raises(ParameterError, match="measure"):
        FrontConvergence(measure=measure)
