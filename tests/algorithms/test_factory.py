"""make_algorithm: every name runs the same problem and operators under its pymoo algorithm."""

import sys

import numpy as np
import pytest
from pymoo.optimize import minimize

from htetro_opt.algorithms import GA_ALGORITHMS, HTetroGA, make_algorithm
from htetro_opt.errors import ParameterError
from htetro_opt.model import Pose, Workspace
from htetro_opt.operators import CommandRepair, as_column, sequences
from htetro_opt.problems import CommandPathProblem


@pytest.fixture(scope="module")
def small_problem():
    occ = np.zeros((10, 10), dtype=bool)
    occ[0, :] = occ[-1, :] = occ[:, 0] = occ[:, -1] = True
    return CommandPathProblem(Workspace(occ), Pose(3, 3, "O", 0), Pose(6, 5, "O", 0), max_length=12)


@pytest.mark.parametrize("name", GA_ALGORITHMS)
def test_every_algorithm_runs(small_problem, name):
    pop_size = 6 if name == "agemoea" else 12
    res = minimize(small_problem, make_algorithm(name, pop_size), ("n_gen", 3), seed=1)
    assert res.F.ndim == 2 and res.F.shape[1] == 4 and len(res.F) >= 1
    F = res.pop.get("F")
    assert len(res.pop) == pop_size
    X = sequences(res.pop.get("X"))
    assert all(np.isin(x, small_problem.command_ids).all() for x in X)
    assert np.array_equal(small_problem.evaluate(as_column(X)), F)  # the stored objectives are current


def test_names_give_their_algorithms():
    from pymoo.algorithms.moo.nsga2 import NSGA2
    from pymoo.algorithms.moo.nsga3 import NSGA3
    from pymoo.algorithms.moo.sms import SMSEMOA

    assert type(make_algorithm("htetro-ga", 10)) is HTetroGA
    assert make_algorithm("htetro-ga-paper", 10).shortcut is False
    assert type(make_algorithm("nsga2", 10)) is NSGA2
    assert type(make_algorithm("nsga3", 10)) is NSGA3
    assert type(make_algorithm("smsemoa", 10)) is SMSEMOA


def test_pymoo_algorithms_get_the_repair():
    for name in ("nsga2", "nsga3", "smsemoa", "agemoea"):
        assert isinstance(make_algorithm(name, 12).repair, CommandRepair)


@pytest.mark.parametrize("name, pop_size, options, word", [
    ("nsga4", 10, {}, "'nsga4'"),
    ("htetro", 10, {}, "'htetro'"),  # the old name is refused, not mapped
    ("nsga2", 1, {}, "pop_size"),
    ("nsga2", 10, {"sampling_weights": {"x+": -1.0}}, "sampling weight of 'x\\+'"),
    ("nsga2", 10, {"crossover_rate": 1.5}, "crossover_rate"),  # named as the caller knows it
    ("htetro-ga", 10, {"crossover_rate": -0.5}, "crossover_rate"),
])
def test_make_algorithm_parameters(name, pop_size, options, word):
    with pytest.raises(ParameterError, match=word):
        make_algorithm(name, pop_size, **options)


def test_agemoea_without_numba_is_a_clear_error(monkeypatch):
    monkeypatch.delitem(sys.modules, "pymoo.algorithms.moo.age", raising=False)
    monkeypatch.setitem(sys.modules, "numba", None)  # makes `import numba` fail
    with pytest.raises(ParameterError, match="numba"):
        make_algorithm("agemoea", 12)
