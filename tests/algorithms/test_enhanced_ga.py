"""Nazarahari et al. 2019's enhanced GA as a pymoo algorithm: the paper's offspring counts, the
feasibility-first elitist survival, our switches, and pymoo's multi-objective algorithms over the
same path bases."""

import numpy as np
import pytest
from pymoo.optimize import minimize
from pymoo.util.nds.non_dominated_sorting import NonDominatedSorting

from htetro_opt.algorithms import EGA_ADDITIONS, PATH_ALGORITHMS, EnhancedGA, make_path_algorithm
from htetro_opt.errors import ParameterError
from htetro_opt.problems import PathBasesProblem
from htetro_opt.scenarios import load_scenario


def test_offspring_counts_follow_the_yarpiz_ga():
    ga = EnhancedGA(10)
    assert (ga.n_children, ga.n_mutants) == (4, 2)  # 2⌊0.35·10/2 + ½⌋, ⌊0.15·10 + ½⌋
    assert (EnhancedGA(50).n_children, EnhancedGA(50).n_mutants) == (18, 8)
    paper = EnhancedGA.as_published(10)
    assert paper.additions == () and (paper.delete_children, paper.refine, paper.finer_apf, paper.dedup) == (
        False, False, False, False)
    assert ga.additions == tuple(EGA_ADDITIONS) and (ga.delete_children, ga.refine, ga.finer_apf, ga.dedup) == (
        True, True, True, True)
    assert EnhancedGA.as_published(10, additions=["taut-refinement"]).refine
    assert make_path_algorithm("ega").initialization.sampling.finer
    assert not make_path_algorithm("ega-paper").initialization.sampling.finer


@pytest.mark.parametrize("factory", [EnhancedGA, EnhancedGA.as_published])
def test_survivors_are_sorted_feasible_first_and_the_best_never_worsens(factory):
    problem = PathBasesProblem(load_scenario("ega05_boxpile"))
    res = minimize(problem, factory(10), ("n_gen", 12), seed=3)
    history = np.array(res.algorithm.history)
    assert len(history) == 12 and np.all(np.diff(history) <= 1e-9)
    F, G = res.algorithm.pop.get("F", "G")
    assert len(F) == 10 and np.all(G[:, 0] == 0)  # APF paths are feasible: so are the elitist survivors
    assert np.all(np.diff(F[:, 0]) >= 0)
    assert res.opt[0].F[0] == pytest.approx(history[-1])


def test_the_roulette_and_operators_draw_only_from_pymoo():
    problem = PathBasesProblem(load_scenario("ega08_slits2"))
    np.random.seed(0)
    reference = np.random.random(3)
    np.random.seed(0)
    runs = [minimize(problem, EnhancedGA(8), ("n_gen", 6), seed=5).algorithm for _ in range(2)]
    assert len(runs[0].history) == 6 and runs[0].history == runs[1].history
    assert all(np.array_equal(a.X[0], b.X[0]) for a, b in zip(runs[0].pop, runs[1].pop))
    assert np.array_equal(np.random.random(3), reference)


def test_bad_settings_raise_typed_errors():
    with pytest.raises(ParameterError, match="pop_size"):
        EnhancedGA(1)
    with pytest.raises(ParameterError, match="crossover_share"):
        EnhancedGA(10, crossover_share=1.5)
    with pytest.raises(ParameterError, match="unknown addition 'refine'"):
        EnhancedGA(10, additions=["refine"])
    problem = PathBasesProblem(load_scenario("ega04_corridor1"), objectives="separate")
    with pytest.raises(ParameterError, match="one objective"):
        minimize(problem, EnhancedGA(10), ("n_gen", 2), seed=0)
    with pytest.raises(ParameterError, match="unknown algorithm"):
        make_path_algorithm("moead")


@pytest.mark.parametrize("name", ["nsga2", "nsga3", "smsemoa"])
def test_pymoo_algorithms_run_over_path_bases(name):
    sc = load_scenario("ega04_corridor1")
    problem = PathBasesProblem(sc, objectives="separate", safety="min")
    res = minimize(problem, make_path_algorithm(name, 10), ("n_gen", 8), seed=1)
    F, G = res.algorithm.pop.get("F", "G")
    assert F.shape == (10, 3) and np.all(G[:, 0] == 0)
    front = NonDominatedSorting().do(F, only_non_dominated_front=True)
    assert len(front) >= 2
    for x in res.algorithm.pop.get("X")[:, 0]:
        assert sc.geometry.path_feasible(problem.polyline(x))
    assert set(PATH_ALGORITHMS) >= {"ega", "ega-paper", name}


@pytest.mark.parametrize("name", ["nsga2", "nsga3", "smsemoa"])
def test_pymoo_algorithms_over_path_bases_are_reproducible(name):
    """The same seed gives the same population: pymoo 0.6.2's NSGA-III tournament drew the winner of two
    equally infeasible path-bases individuals from fresh entropy (8 fronts in 12 runs of seed 1 here)."""
    sc = load_scenario("ega04_corridor1")
    problem = PathBasesProblem(sc, objectives="separate", safety="min")
    runs = [minimize(problem, make_path_algorithm(name, 10), ("n_gen", 8), seed=1).algorithm.pop.get("F")
            for _ in range(3)]
    assert all(np.array_equal(runs[0], F) for F in runs[1:])
