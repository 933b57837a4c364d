"""Do et al. 2021's costs: Fig. 5's search patterns and worked safety numbers, eqs. 9, 10, 12, errors."""

import itertools
import math

import numpy as np
import pytest

from htetro_opt.errors import ParameterError, UnknownShapeError
from htetro_opt.model import (
    N_STATES,
    STATE_NAMES,
    Pose,
    Timing,
    Workspace,
    parse_commands,
    shape_index,
)
from htetro_opt.model.robot import rotate_cells
from htetro_opt.problems.heat_costs import default_t_max, heat_fitness, safety_pattern
from htetro_opt.scenarios import load_scenario
from htetro_opt.solvers import plan_path

O, I = shape_index("O"), shape_index("I")


def open_map(width=12, height=12):
    return np.zeros((height, width), dtype=bool)


def walk(start, tokens):
    """Poses (x, y, state, heading) of translations from ``start`` (hand-rolled, no simulator)."""
    steps = {"x+": (1, 0), "x-": (-1, 0), "y+": (0, 1), "y-": (0, -1)}
    poses = [start]
    for token in tokens:
        x, y, s, h = poses[-1]
        dx, dy = steps[token]
        poses.append((x + dx, y + dy, s, h))
    return np.array(poses), parse_commands(tokens)


def as_set(offsets, weights):
    return {(int(dx), int(dy), int(w)) for (dx, dy), w in zip(offsets, weights)}


# --- Fig. 5's search patterns ------------------------------------------------------------------
def test_o_shape_pattern_has_twenty_cells_eight_of_weight_three():
    offsets, weights = safety_pattern("O", 0)
    assert len(offsets) == len(weights) == 20
    assert sorted(weights.tolist()) == [1] * 12 + [3] * 8
    # B2 at the origin, blocks (0, -1), (0, 0), (1, 0), (1, -1): the edge neighbours weigh 3
    three = {(dx, dy) for dx, dy, w in as_set(offsets, weights) if w == 3}
    assert three == {(-1, 0), (-1, -1), (2, 0), (2, -1), (0, 1), (1, 1), (0, -2), (1, -2)}
    assert not {(0, -1), (0, 0), (1, 0), (1, -1)} & {(dx, dy) for dx, dy, _ in as_set(offsets, weights)}


def test_i_shape_pattern_has_twenty_four_cells():
    offsets, weights = safety_pattern("I", 0)
    assert len(offsets) == 24
    # by hand: columns x = ±1 weigh 1 2 3 3 2 1, x = ±2 four 1s, x = 0 above and below 1 2 2 1
    assert int(weights.sum()) == 2 * 12 + 2 * 4 + 6
    assert as_set(offsets, weights) >= {(1, 0, 3), (1, 1, 3), (0, -2, 2), (0, 4, 1), (-2, 2, 1)}


@pytest.mark.parametrize("state", range(N_STATES))
def test_pattern_turns_with_the_heading(state):
    base_offsets, base_weights = safety_pattern(state, 0)
    for heading in range(1, 4):
        turned = as_set(rotate_cells(base_offsets, heading), base_weights)
        assert turned == as_set(*safety_pattern(STATE_NAMES[state], heading))


def test_pattern_against_a_naive_geometric_count():
    for name in ("L", "T", "S", "h213"):
        for heading in range(4):
            blocks = Pose(0, 0, name, heading).cells().tolist()
            naive = {}
            for dx in range(-5, 6):
                for dy in range(-5, 6):
                    n = sum(math.hypot(dx - bx, dy - by) <= 2 for bx, by in blocks)
                    if n and [dx, dy] not in blocks:
                        naive[(dx, dy, n)] = None
            assert as_set(*safety_pattern(name, heading)) == set(naive)


# --- Fig. 5's worked numbers ---------------------------------------------------------------------
def test_o_shape_worked_example_scores_one_half():
    occ = open_map()
    # O with B2 at (5, 5): blocks (5, 4), (5, 5), (6, 5), (6, 4); two 3-cells west, four 1-cells beyond
    for x, y in [(4, 4), (4, 5), (4, 6), (4, 3), (3, 4), (3, 5)]:
        occ[y, x] = True
    poses, commands = walk((6, 5, O, 0), ["x-"])
    costs = heat_fitness(Workspace(occ), poses, commands)
    assert costs["f_sf"] == pytest.approx(1 - (2 * 3 + 4 * 1) / 20)
    # back east, (4, 4) and (4, 5) are 2 cells from a block (weight 1 each), then out of reach
    poses, commands = walk((6, 5, O, 0), ["x-", "x+", "x+", "x+"])
    assert heat_fitness(Workspace(occ), poses, commands)["f_sf"] == pytest.approx(1 - (0.5 + 2 / 20 + 0 + 0) / 4)


def test_i_shape_worked_example_scores_fourteen_over_twenty_four():
    occ = open_map()
    # I with B2 at (5, 5): blocks (5, 4) … (5, 7); the column east (weights 1 2 3 3 2 1) and two 1-cells
    occ[3:9, 6] = True
    occ[4:6, 7] = True
    poses, commands = walk((4, 5, I, 0), ["x+"])
    costs = heat_fitness(Workspace(occ), poses, commands)
    assert costs["f_sf"] == pytest.approx(1 - 14 / 24)


def test_off_map_cells_count_as_obstacles():
    occ = open_map()
    # O with B2 at (0, 1): blocks (0, 0), (0, 1), (1, 1), (1, 0) in the corner
    poses, commands = walk((1, 1, O, 0), ["x-"])
    offsets, weights = safety_pattern("O")
    off = sum(int(w) for (dx, dy), w in zip(offsets, weights) if dx < 0 or dy + 1 < 0)
    assert off > 0
    assert heat_fitness(Workspace(occ), poses, commands)["f_sf"] == pytest.approx(1 - off / 20)


def test_safety_against_a_naive_loop_on_random_maps():
    rng = np.random.default_rng(3)
    for _ in range(5):
        occ = rng.random((10, 9)) < 0.3
        n = 6
        poses = np.column_stack([rng.integers(-1, 10, n), rng.integers(-1, 11, n),
                                 rng.integers(0, N_STATES, n), rng.integers(0, 4, n)])
        commands = rng.integers(0, 4, n - 1)
        penalties = []
        for x, y, s, h in poses[1:]:
            blocks = Pose(0, 0, STATE_NAMES[s], h).cells().tolist()
            total = size = 0
            for dx in range(-5, 6):
                for dy in range(-5, 6):
                    weight = sum(math.hypot(dx - bx, dy - by) <= 2 for bx, by in blocks)
                    if weight == 0 or [dx, dy] in blocks:
                        continue
                    cx, cy = x + dx, y + dy
                    size += 1
                    total += weight * (not (0 <= cx < 9 and 0 <= cy < 10) or bool(occ[cy, cx]))
            penalties.append(total / size)
        got = heat_fitness(Workspace(occ), poses, commands)["f_sf"]
        assert got == pytest.approx(1 - np.mean(penalties))


# --- eqs. 9, 10, 12 ---------------------------------------------------------------------------
def test_default_t_max_on_24_by_24():
    ws = Workspace(open_map(24, 24))
    assert default_t_max(ws) == pytest.approx(132 * Timing().translation)
    assert default_t_max(ws, Timing(translation=0.3)) == pytest.approx(39.6)
    assert default_t_max(Workspace(open_map(10, 7))) == pytest.approx(4 * 8 / 2)


def test_time_cost_uses_the_commands_durations():
    ws = Workspace(open_map(24, 24))
    poses = np.array([(5, 5, O, 0), (6, 5, O, 0), (6, 5, O, 1)])
    costs = heat_fitness(ws, poses, parse_commands("x+ r+"), timing=Timing(translation=0.5, rotation=4.0))
    assert costs["f_t"] == pytest.approx(1 - (0.5 + 4.0) / (0.5 * 132))
    assert heat_fitness(ws, poses, parse_commands("x+ r+"), t_max=2.0)["f_t"] == pytest.approx(1 - 3.0 / 2.0)


@pytest.mark.parametrize("k", [1, 2, 5])
def test_equal_commands_are_perfectly_smooth(k):
    poses, commands = walk((3, 3, O, 0), ["x+"] * k)
    assert heat_fitness(Workspace(open_map()), poses, commands)["f_sm"] == 1.0


@pytest.mark.parametrize("k", [2, 3, 6])
def test_alternating_commands(k):
    poses, commands = walk((3, 3, O, 0), ["x+", "x-"] * (k // 2) + ["x+"] * (k % 2))
    assert heat_fitness(Workspace(open_map()), poses, commands)["f_sm"] == pytest.approx(1 - (k - 1) / k)


def test_weights_time_alone_and_scale_invariance():
    occ = open_map()
    occ[2, 6] = True
    poses, commands = walk((3, 3, O, 0), ["x+", "x+", "y+", "x+"])
    ws = Workspace(occ)
    alone = heat_fitness(ws, poses, commands, weights=(1, 0, 0))
    assert alone["f"] == alone["f_t"]
    mixed = heat_fitness(ws, poses, commands, weights=(1, 2, 3))
    assert mixed["f_sf"] < 1.0 and mixed["f_sm"] < 1.0
    assert mixed["f"] == pytest.approx((mixed["f_t"] + 2 * mixed["f_sm"] + 3 * mixed["f_sf"]) / 6)
    assert heat_fitness(ws, poses, commands, weights=(10, 20, 30))["f"] == pytest.approx(mixed["f"])


def test_empty_path_scores_one():
    costs = heat_fitness(Workspace(open_map()), [(5, 5, O, 0)], [], weights=(1, 1, 1))
    assert costs == {"f_t": 1.0, "f_sm": 1.0, "f_sf": 1.0, "f": 1.0}


def test_a_real_plan_on_three_slit():
    scenario = load_scenario("three_slit")
    ws = scenario.workspace
    plan = plan_path(ws, scenario.roadmap)
    assert plan.reached and len(plan.commands) > 0
    t_max = Timing().translation * math.ceil(ws.height / 2) * (ws.width - 2) / 2
    costs = heat_fitness(ws, plan.poses, plan.commands, weights=(1, 1, 1))
    assert costs["f_t"] == pytest.approx(1 - plan.time / t_max)
    tokens = plan.tokens
    changes = sum(a != b for a, b in itertools.pairwise(tokens))
    assert costs["f_sm"] == pytest.approx(1 - changes / len(tokens))
    assert costs["f_sf"] <= 1.0


# --- errors -----------------------------------------------------------------------------------
@pytest.mark.parametrize("weights, word", [
    ((0, 0, 0), "all be zero"), ((1, -1, 0), "weights[1]"), ((1, float("nan"), 0), "weights[1]"),
    ((1, 1), "three numbers"), ("abc", "three numbers"), ((True, 1, 1), "weights[0]"), (None, "three numbers"),
])
def test_bad_weights(weights, word):
    poses, commands = walk((3, 3, O, 0), ["x+"])
    with pytest.raises(ParameterError, match=word.replace("[", r"\[")):
        heat_fitness(Workspace(open_map()), poses, commands, weights=weights)


@pytest.mark.parametrize("t_max", [0, -1.0, float("inf"), float("nan"), "1", True])
def test_bad_t_max(t_max):
    poses, commands = walk((3, 3, O, 0), ["x+"])
    with pytest.raises(ParameterError, match="t_max"):
        heat_fitness(Workspace(open_map()), poses, commands, t_max=t_max)


def test_bad_paths_and_arguments():
    ws = Workspace(open_map())
    poses, commands = walk((3, 3, O, 0), ["x+", "x+"])
    with pytest.raises(ParameterError, match="commands must hold one command"):
        heat_fitness(ws, poses, commands[:1])
    with pytest.raises(ParameterError, match=r"commands\[1\]"):
        heat_fitness(ws, poses, [0, 999])
    with pytest.raises(ParameterError, match="commands must be"):
        heat_fitness(ws, poses, ["x+", "x+"])
    with pytest.raises(ParameterError, match="shape"):
        heat_fitness(ws, poses[:, :3], commands)
    with pytest.raises(ParameterError, match="poses must be"):
        heat_fitness(ws, [[1.5, 2, 0, 0]], [])
    with pytest.raises(ParameterError, match="poses row 1"):
        heat_fitness(ws, [(3, 3, O, 0), (4, 3, N_STATES, 0)], [0])
    with pytest.raises(ParameterError, match="poses row 0"):
        heat_fitness(ws, [(3, 3, O, 4)], [])
    with pytest.raises(ParameterError, match="timing"):
        heat_fitness(ws, poses, commands, timing={"translation": 1})
    with pytest.raises(ParameterError, match="workspace"):
        heat_fitness(open_map(), poses, commands)


def test_bad_patterns_and_t_max_maps():
    with pytest.raises(UnknownShapeError):
        safety_pattern("Q")
    with pytest.raises(ParameterError, match="state"):
        safety_pattern(N_STATES)
    with pytest.raises(ParameterError, match="heading"):
        safety_pattern("O", 4)
    with pytest.raises(ParameterError, match="give t_max"):
        default_t_max(Workspace(open_map(2, 5)))
    with pytest.raises(ParameterError, match="timing"):
        default_t_max(Workspace(open_map()), 0.3)
