"""The APF of Nazarahari et al. 2019 (§4.2, Algorithm 1): depths against scipy's BFS, paths feasible
and rising in potential, both sides of a symmetric obstacle, a narrow slit found by halving."""

import numpy as np
import pytest
from scipy.sparse.csgraph import shortest_path

from htetro_opt.model import ContinuousGeometry
from htetro_opt.scenarios import load_scenario
from htetro_opt.solvers.continuous import apf_depths, apf_paths, apf_population, lattice_graph


@pytest.mark.parametrize("name", ["ega07_slits1", "ega02_maze1", "ega12_plankpile", "ega_cross4"])
def test_depths_are_csgraph_bfs(name):
    sc = load_scenario(name)
    nodes, graph = lattice_graph(sc.geometry, 1.0, ends=[sc.starts[0], sc.goals[0]])
    want = shortest_path(graph, unweighted=True, indices=len(nodes) - 1)
    got = apf_depths(graph, len(nodes) - 1)
    assert np.array_equal(np.where(np.isfinite(want), want, -1).astype(int), got)


@pytest.mark.parametrize("name", ["ega01_random1", "ega05_boxpile", "ega08_slits2", "ega10_maze3"])
def test_paths_are_feasible_distinct_and_rise_in_potential(name):
    sc = load_scenario(name)
    start, goal = sc.starts[0], sc.goals[0]
    paths, info = apf_paths(sc.geometry, start, goal, n_paths=10, seed=3)
    assert 1 <= len(paths) <= 10 and len({p.tobytes() for p in paths}) == len(paths)
    nodes, graph = lattice_graph(sc.geometry, info["grid"], ends=[start, goal])
    depth = apf_depths(graph, len(nodes) - 1)
    index = {tuple(p): k for k, p in enumerate(nodes[:-2].tolist())}
    for pbs in paths:
        assert sc.geometry.path_feasible(np.vstack([start, pbs, goal]))
        # every PB is a lattice node, nearer the goal (in hops) than the one before
        depths = [depth[index[tuple(p)]] for p in pbs.tolist()]
        assert all(d >= 0 for d in depths)
        assert depths == sorted(depths, reverse=True) and len(set(depths)) == len(depths)
        assert (not depths) or depths[0] < info["depth"]


def test_a_map_symmetric_about_start_goal_gives_both_sides():
    geo = ContinuousGeometry(10, 10, [[4, 3, 6, 7]])
    paths, _ = apf_paths(geo, [2, 5], [8, 5], n_paths=10, seed=0)
    sides = {float(np.sign(p[:, 1] - 5).sum()) > 0 for p in paths}
    assert sides == {True, False}


def test_a_narrow_slit_is_found_by_halving_the_lattice():
    geo = ContinuousGeometry(10, 10, [[4, 0, 6, 3.25], [4, 3.75, 6, 10]])
    paths, info = apf_paths(geo, [1, 1], [9, 9], n_paths=4, seed=0)
    assert info["grid"] == 0.5 and paths
    for pbs in paths:
        assert geo.path_feasible(np.vstack([[1, 1], pbs, [9, 9]]))
        assert np.any(np.isclose(pbs[:, 1], 3.5))
    closed = ContinuousGeometry(10, 10, [[4, 0, 6, 3.51], [4, 3.6, 6, 10]])  # between two rows of the d/8 lattice
    paths, info = apf_paths(closed, [1, 1], [9, 9], n_paths=4, seed=0)
    assert paths == [] and info["depth"] == -1 and info["grid"] == 0.125


def test_start_on_goal_and_a_lattice_diagonal():
    geo = ContinuousGeometry(10, 10, [[4, 4, 6, 6]])
    paths, _ = apf_paths(geo, [2, 2], [2, 2], seed=0)
    assert len(paths) == 1 and paths[0].shape == (0, 2)
    paths, _ = apf_paths(geo, [1, 1], [3, 3], seed=0)  # the only one-hop-nearer neighbours lie on the diagonal
    assert [p.shape for p in paths] == [(0, 2)]


def test_population_fills_up_with_feasible_moved_copies():
    # a one-cell L-shaped corridor: the APF has a single path, turning at the elbow
    geo = ContinuousGeometry(10, 10, [[0, 0, 10, 1.5], [0, 2.5, 7.5, 10], [8.5, 1.5, 10, 10]])
    start, goal = np.array([1.0, 2.0]), np.array([8.0, 9.0])
    paths, info = apf_population(geo, start, goal, 10, seed=2)
    assert len(paths) == 10 and info["distinct"] == 1
    assert all(geo.path_feasible(np.vstack([start, p, goal])) for p in paths)
    assert len({p.tobytes() for p in paths}) > 1
    assert all(np.hypot(*(p - paths[0]).T).max() <= 0.5 for p in paths)


def test_same_seed_same_paths_and_the_global_rng_untouched():
    sc = load_scenario("ega11_random2")
    np.random.seed(0)
    reference = np.random.random(3)
    np.random.seed(0)
    a, _ = apf_population(sc.geometry, sc.starts[0], sc.goals[0], 12, seed=7)
    b, _ = apf_population(sc.geometry, sc.starts[0], sc.goals[0], 12, seed=np.random.default_rng(7))
    assert len(a) == len(b) == 12 and all(np.array_equal(p, q) for p, q in zip(a, b))
    assert np.array_equal(np.random.random(3), reference)
