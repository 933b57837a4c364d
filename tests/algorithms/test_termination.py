"""FrontConvergence and HypervolumeWindow: when they stop, the cap, and what a run reports."""

from types import SimpleNamespace

import numpy as np
import pytest
from pymoo.core.population import Population
from pymoo.optimize import minimize

from htetro_opt.algorithms import ConvergenceRecorder, FrontConvergence, HTetroGA
from htetro_opt.algorithms.termination import HypervolumeWindow
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


def one_member(f_t, f_sm, f_sf, f_gr=1.0):
    """A population of one individual, as pymoo's F = −fitness; its reaching HV is f_t·f_sm·f_sf."""
    return -np.array([[f_gr, f_t, f_sm, f_sf]])


def stop_generation(term, populations):
    """The first generation (1-based) after which ``term`` has terminated, or None."""
    for gen, F in enumerate(populations, start=1):
        term.update(fake_algorithm(F, gen))
        if term.has_terminated():
            return gen
    return None


def test_hypervolume_window_stops_once_the_front_has_not_moved_for_a_window():
    # reached from generation 3 on; the front then stands still: the window of 4 needs 5 reaching
    # generations (the newest against the one 4 before), so the run stops at generation 3 + 4
    populations = [one_member(0.5, 0.5, 0.5, f_gr=0.5)] * 2 + [one_member(0.5, 0.5, 0.5)] * 20
    term = HypervolumeWindow(max_gen=100, window=4)
    assert stop_generation(term, populations) == 7
    assert term.converged


def test_hypervolume_window_keeps_going_while_the_front_moves():
    # the safety of the one member rises by 1 % a generation: 4 % over the window, far above 1e-3
    populations = [one_member(0.5, 0.5, 0.5 * 1.01 ** gen) for gen in range(30)]
    term = HypervolumeWindow(max_gen=30, window=4, tolerance=1e-3)
    assert stop_generation(term, populations) == 30
    assert not term.converged  # stopped by the cap


def test_hypervolume_window_a_creeping_front_within_tolerance_stops():
    # 0.01 % a generation is 0.04 % over the window: below a tolerance of 1e-3, above one of 1e-4
    populations = [one_member(0.5, 0.5, 0.5 * 1.0001 ** gen) for gen in range(30)]
    assert stop_generation(HypervolumeWindow(max_gen=30, window=4, tolerance=1e-3), populations) == 5
    assert stop_generation(HypervolumeWindow(max_gen=30, window=4, tolerance=1e-4), populations) == 30


def test_hypervolume_window_a_faster_path_always_counts():
    # the best time rises by 1e-6 a generation while the other two fall so that the hypervolume
    # does not rise at all: any faster path is movement, whatever the tolerance
    populations = [one_member(0.5 + 1e-6 * gen, 0.5, 0.5 * 0.5 / (0.5 + 1e-6 * gen)) for gen in range(20)]
    term = HypervolumeWindow(max_gen=20, window=4, tolerance=0.5)
    assert stop_generation(term, populations) == 20 and not term.converged


def test_hypervolume_window_a_step_restarts_the_wait_and_a_drop_is_no_step():
    # still for 6 generations, one 10 % step at generation 7, then still; a generation whose front
    # shrinks (crowding swapping members) neither moves it nor resets the best-so-far
    hv = [0.5] * 6 + [0.55] * 3 + [0.4] + [0.55] * 10
    populations = [one_member(0.5, 0.5, v) for v in hv]
    assert stop_generation(HypervolumeWindow(max_gen=100, window=4), populations[:6]) == 5
    assert stop_generation(HypervolumeWindow(max_gen=100, window=4), populations[4:]) == 7  # gens 5..11
    assert stop_generation(HypervolumeWindow(max_gen=100, window=8), populations) == 15  # step at 7, + 8


def test_hypervolume_window_waits_for_the_goal():
    term = HypervolumeWindow(max_gen=6, window=1)
    unreached = [one_member(1.0, 1.0, 1.0, f_gr=0.5)] * 6
    assert stop_generation(term, unreached) == 6 and not term.converged
    algorithm = fake_algorithm(unreached[0], 6)
    term.update(algorithm)
    assert algorithm.data["converged"] is False


@pytest.mark.parametrize("options", [dict(max_gen=0), dict(max_gen=2.5), dict(window=0), dict(window=-3),
                                     dict(window=1.0), dict(window=True), dict(window=None),
                                     dict(tolerance=-1e-3), dict(tolerance=float("nan")),
                                     dict(tolerance=float("inf")), dict(tolerance="0.1")])
def test_hypervolume_window_parameters(options):
    with pytest.raises(ParameterError, match=next(iter(options))):
        HypervolumeWindow(**options)


def test_hypervolume_window_runs_are_deterministic_and_report_convergence(small_problem):
    runs = [minimize(small_problem, HTetroGA(pop_size=12), HypervolumeWindow(max_gen=300, window=5), seed=4)
            for _ in range(2)]
    assert all(res.data["converged"] is True for res in runs)
    assert runs[0].algorithm.n_gen == runs[1].algorithm.n_gen < 300
    np.testing.assert_array_equal(runs[0].pop.get("F"), runs[1].pop.get("F"))
