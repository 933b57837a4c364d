"""Coverage at scale (issue 25, items 3 and 5): the layer graph without the simulator's whole table, the
replay without it, the DAG solved sweep by sweep, and time limits that cut every phase.

Oracles: the full :class:`~htetro_opt.model.Simulator` (its table, its run), a plain breadth-first
search over that table, and the whole DAG's Dijkstra.
"""

from collections import deque

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from htetro_opt.model import SEED004_COMMANDS, Simulator, Workspace
from htetro_opt.model.commands import command_id
from htetro_opt.scenarios import load_scenario
from htetro_opt.solvers import plan_coverage
from htetro_opt.solvers.coverage import LayerGraph, _stripes
from htetro_opt.solvers.coverage._layers import SWITCH_COMMANDS, MOVES

LAYERS = ["O,vI,hI", "O", "vI,hI", "L@1,T@2,S@0,vI"]


def scattered(n: int, seed: int, w: int | None = None) -> np.ndarray:
    """benchmarks/bench_cover.py's maps: n² / 40 blocks of 1-3 x 1-3 cells at seeded places."""
    rng = np.random.default_rng(seed)
    w = n if w is None else w
    occ = np.zeros((n, w), dtype=bool)
    for _ in range(n * w // 40):
        x, y = rng.integers(0, w), rng.integers(0, n)
        occ[y:y + rng.integers(1, 4), x:x + rng.integers(1, 4)] = True
    return occ


@settings(max_examples=15, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(seed=st.integers(0, 2**16), w=st.integers(5, 14), h=st.integers(5, 14), density=st.sampled_from([0.0, 0.1, 0.2]),
       clearance=st.sampled_from([0.0, 0.3]), layers=st.sampled_from(LAYERS))
def test_the_layer_graph_is_the_simulators_table(seed, w, h, density, clearance, layers):
    ws = Workspace(np.random.default_rng(seed).random((h, w)) < density)
    lg = LayerGraph(ws, layers, clearance=clearance)
    sim = Simulator(ws, commands=SEED004_COMMANDS, clearance=clearance)
    col = {t: int(sim.local[command_id(t)]) for t in ("stop",) + MOVES + SWITCH_COMMANDS}
    for a, layer in enumerate(lg.layers):
        ids = (layer.state * 4 + layer.heading) * w * h + np.arange(w * h)
        valid = sim.next[ids, col["stop"]] != sim.dead
        assert np.array_equal(lg.valid[a].ravel(), valid)
        for d, t in enumerate(MOVES):
            assert np.array_equal(lg.move[a, d].ravel(), valid & (sim.next[ids, col[t]] != sim.dead))
    for cell in range(0, w * h, 3):  # the fewest block commands and their tokens: a plain BFS over the table
        x, y = cell % w, cell // w
        for a, la in enumerate(lg.layers):
            start = (la.state * 4 + la.heading) * w * h + cell
            parent = {start: None} if lg.valid[a, y, x] else {}
            queue = deque(parent)
            while queue:
                p = queue.popleft()
                for t in SWITCH_COMMANDS:
                    q = int(sim.next[p, col[t]])
                    if q != sim.dead and q not in parent:
                        parent[q] = (p, t)
                        queue.append(q)
            for b, lb in enumerate(lg.layers):
                goal = (lb.state * 4 + lb.heading) * w * h + cell
                want = -1
                if goal in parent and lg.valid[b, y, x]:
                    tokens, at = [], goal
                    while parent[at] is not None:
                        at, t = parent[at]
                        tokens.append(t)
                    want = len(tokens)
                    if a != b:
                        assert lg.switch_tokens((x, y), a, b) == tokens[::-1]
                assert lg.switch_cost[a, b, y, x] == want


def test_the_layer_graph_compiles_no_simulator():
    lg = LayerGraph(Workspace(scattered(24, 0)), "O,vI,hI")
    assert "sim" not in vars(lg)  # the cached property: built only when asked for
    assert lg.sim.n_poses == 23 * 4 * 24 * 24 and "sim" in vars(lg)


# --- the plan: re-validated by the full simulator, every coverable cell covered ------------------------------------
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_plans_replay_in_the_full_simulator_and_cover_every_coverable_cell(seed):
    ws = Workspace(scattered(12, seed, w=14))
    plan = plan_coverage(ws, "O,vI,hI")
    run = Simulator(ws, commands=SEED004_COMMANDS).run([plan.commands], plan.start)  # the independent oracle
    assert run.valid[0] and float(run.time[0]) == plan.time
    assert np.array_equal(run.poses(0), plan.poses)
    assert plan.success and not (plan.coverable & ~plan.covered).any()


# --- the DAG: built sweep by sweep, the same search as the whole DAG -------------------------------------------------
def _whole_dag(monkeypatch):
    """Make _Planner.dag build every sweep before the search (the whole DAG, as before it was built lazily)."""
    dag = _stripes._Planner.dag

    def whole(self, chain, **kw):
        g = dag(self, chain, **kw)
        self.build_all(g)
        g.expand = None
        return g

    monkeypatch.setattr(_stripes._Planner, "dag", whole)


@pytest.mark.parametrize("case", [("coverage_16x16", "O,vI,hI", {}), ("coverage_16x7", "O,hI", {"stripes": "2,3,2"}),
                                  ("coverage_16x7", "O,hI", {"stripes": "2,3,2", "ends": "both"}),
                                  ("scattered", "O,vI,hI", {})])
def test_the_dag_built_sweep_by_sweep_gives_the_whole_dags_plan(monkeypatch, case):
    name, layers, options = case
    ws = Workspace(scattered(14, 5, w=16)) if name == "scattered" else load_scenario(name).workspace
    lazy = plan_coverage(ws, layers, **options)
    with monkeypatch.context() as m:
        _whole_dag(m)
        whole = plan_coverage(ws, layers, **options)
    assert lazy.tokens == whole.tokens and lazy.info["dag_path"] == whole.info["dag_path"]
    assert (lazy.info["dag_nodes"], lazy.info["dag_edges"]) == (whole.info["dag_nodes"], whole.info["dag_edges"])


def test_a_stopped_dag_search_returns_the_cheapest_path_to_its_furthest_node():
    import networkx as nx

    rng = np.random.default_rng(3)
    g, ref = _stripes._Dag(), nx.DiGraph()
    for layer in range(40):  # a layered DAG: progress is the layer
        for i in range(4):
            for j in range(4):
                if rng.random() < 0.7:
                    w = int(rng.integers(0, 5))
                    g.add_edge((layer, i), (layer + 1, j), kind="fixed", cost=w)
                    ref.add_edge((layer, i), (layer + 1, j), weight=w)
    for i in range(4):
        g.add_edge("S", (0, i), kind="fixed", cost=0)
        ref.add_edge("S", (0, i), weight=0)
    calls = []

    def stop():  # a budget of checks, not a clock: the search stops at its second check (64 nodes settled)
        calls.append(1)
        return len(calls) >= 2

    assert g.number_of_nodes() > 100

    weight = lambda u, v, e: e["cost"]  # noqa: E731
    found = g.shortest_path("S", "nowhere", weight, stop=stop, progress=lambda n: -1 if n == "S" else n[0])
    assert g.stopped and found is not None
    d, path = found
    assert path[0] == "S" and all(ref.has_edge(u, v) for u, v in zip(path[:-1], path[1:]))
    assert d == nx.shortest_path_length(ref, "S", path[-1], weight="weight")  # the cheapest way there
    unstopped = g.shortest_path("S", path[-1], weight)
    assert not g.stopped and unstopped[0] == d
