"""The leading front, the paper's four output solutions, and their per-generation record."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from pymoo.optimize import minimize

from htetro_opt.algorithms import SELECTIONS, ConvergenceRecorder, HTetroGA, leading_front, select_solutions
from htetro_opt.errors import PlanningError
from htetro_opt.model import Pose, Workspace
from htetro_opt.problems import CommandPathProblem


def test_leading_front():
    F = -np.array([
        [1.0, 0.5, 0.5, 0.5],  # 0: reaches, dominated by 1
        [1.0, 0.6, 0.5, 0.5],  # 1
        [1.0, 0.4, 0.9, 0.5],  # 2
        [0.5, 0.9, 0.9, 0.9],  # 3: dominates everyone on the last three, but does not reach
    ])
    assert leading_front(F).tolist() == [1, 2]
    unreached = -np.array([[0.5, 0.5, 0.5, 0.5], [0.5, 0.9, 0.9, 0.9], [0.2, 1.0, 0.1, 0.1], [0.2, 0.1, 0.1, 0.1]])
    assert leading_front(unreached).tolist() == [1, 2]  # nobody reaches: the plain non-dominated front
    assert len(leading_front(np.empty((0, 4)))) == 0


def test_select_solutions_examples():
    F = -np.array([
        [1.0, 0.5, 0.5, 0.5],  # 0: dominated by 1, ties it on f_t and comes first
        [1.0, 0.5, 0.6, 0.6],  # 1
        [1.0, 0.7, 0.1, 0.2],  # 2: fastest
        [1.0, 0.3, 0.9, 0.3],  # 3: smoothest
        [1.0, 0.2, 0.2, 0.95],  # 4: safest
        [0.5, 1.0, 1.0, 1.0],  # 5: best at everything but f_gr
    ])
    chosen = select_solutions(F)
    assert set(chosen) == set(SELECTIONS)
    assert chosen == {"multi_objective": 1, "time": 2, "smoothness": 3, "safety": 4}
    # ties: the shorter time wins, then the lower index
    F = -np.array([[1.0, 0.5, 0.9, 0.3], [1.0, 0.6, 0.9, 0.1], [1.0, 0.6, 0.9, 0.1]])
    assert select_solutions(F) == {"multi_objective": 0, "time": 1, "smoothness": 1, "safety": 0}
    with pytest.raises(PlanningError):
        select_solutions(np.empty((0, 4)))


def dominates(a, b):
    return (a <= b).all() and (a < b).any()


@settings(max_examples=80, deadline=None)
@given(st.data(), st.integers(1, 15))
def test_select_solutions_picks_from_the_leading_front(data, n):
    values = st.sampled_from([0.0, 0.25, 0.5, 0.75, 1.0])
    fit = np.array(data.draw(st.lists(st.lists(values, min_size=3, max_size=3), min_size=n, max_size=n)))
    f_gr = np.array(data.draw(st.lists(st.sampled_from([1.0, 0.5, 0.2]), min_size=n, max_size=n)))
    F = -np.column_stack([f_gr, fit])
    pool = np.flatnonzero(f_gr == 1.0) if (f_gr == 1.0).any() else np.arange(n)
    front = [i for i in pool if not any(dominates(F[j], F[i]) for j in pool)]
    assert sorted(leading_front(F).tolist()) == front
    chosen = select_solutions(F)
    for name, score in (("multi_objective", -F.sum(axis=1)), ("time", -F[:, 1]), ("smoothness", -F[:, 2]),
                        ("safety", -F[:, 3])):
        i = chosen[name]
        assert i in front
        assert score[i] == max(score[j] for j in front)


def test_convergence_recorder_logs_each_generation():
    problem = CommandPathProblem(Workspace(np.zeros((10, 10), dtype=bool)), Pose(3, 3, "O", 0), Pose(5, 4, "O", 0),
                                 max_length=10)
    recorder = ConvergenceRecorder()
    res = minimize(problem, HTetroGA(pop_size=10), ("n_gen", 6), seed=2, callback=recorder)
    history = np.array(recorder.history)
    assert history.shape == (6, 4)  # one row of (f_gr, f_t, f_sm, f_sf) per generation
    F = res.pop.get("F")
    assert history[-1].tolist() == (-F[select_solutions(F)["multi_objective"]]).tolist()
    first = int(np.argmax(history[:, 0] == 1.0)) + 1  # generations count from 1
    assert history[:, 0].max() == 1.0 and recorder.reach_generation == first
    assert recorder.reach_time_s > 0
