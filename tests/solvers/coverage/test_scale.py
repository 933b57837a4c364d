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
from htetro_opt.solvers.coverage import LayerGraph
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
