"""Coverage measures of Cheng et al. 2019 §V: the command-driven pixel simulation, eq. 4's grid
activity and the plan's metrics.

Oracles: a time-sampled raster of the blocks' squares (translations), the model's swept-cell tables
(every covered pixel lies in a cell the command sweeps), and the footprints of the replayed poses.
"""

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from htetro_opt.errors import ConfigurationError, ParameterError, UnknownCommandError
from htetro_opt.model import (
    FOOTPRINTS,
    SEED004_COMMANDS,
    Pose,
    Simulator,
    Timing,
    Workspace,
    parse_commands,
    sweep_tables,
)
from htetro_opt.model.coverage import grid_activity, simulate_command_coverage
from htetro_opt.scenarios import load_scenario
from htetro_opt.solvers import plan_coverage

TRANSLATE = ("x+", "x-", "y+", "y-")
BLOCK = ("1l", "1r", "2l", "2r", "3l", "3r", "4l", "4r")


def random_valid(ws, start, tokens, n, seed):
    """A random walk of ``n`` commands drawn from ``tokens``, each valid where it is executed."""
    sim = Simulator(ws, commands=SEED004_COMMANDS)
    rng = np.random.default_rng(seed)
    pose, out = sim.encode(start), []
    for _ in range(n):
        options = [t for t in tokens if sim.next[pose, sim.local[parse_commands(t)[0]]] != sim.dead]
        if not options:
            break
        token = options[rng.integers(len(options))]
        out.append(token)
        pose = int(sim.next[pose, sim.local[parse_commands(token)[0]]])
    return out


def sampled_translation_time(ws, start, tokens, p, steps=400):
    """Pixel times of translations by brute force: axis-aligned block squares at many instants."""
    sim = Simulator(ws, commands=SEED004_COMMANDS)
    poses = sim.run([parse_commands(tokens)], start).poses(0)
    xs = (np.arange(ws.width * p) + 0.5) / p - 0.5
    ys = (np.arange(ws.height * p) + 0.5) / p - 0.5
    out = np.zeros((ws.height * p, ws.width * p))
    for (x0, y0, s, h), (x1, y1, _, _) in zip(poses[:-1], poses[1:]):
        a = FOOTPRINTS[s, h] + (x0, y0)
        for u in (np.arange(steps) + 0.5) / steps:
            for cx, cy in a + u * np.array([x1 - x0, y1 - y0]):
                out += np.outer(np.abs(ys - cy) < 0.5, np.abs(xs - cx) < 0.5) / steps
    return out


@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(seed=st.integers(0, 2**16), shape=st.sampled_from(["O", "I", "L", "T"]), p=st.sampled_from([3, 4, 10]))
def test_translations_are_exact(seed, shape, p):
    ws = Workspace(np.zeros((7, 7), dtype=bool))
    start = Pose(3, 3, shape, int(seed % 4))
    tokens = random_valid(ws, start, TRANSLATE, 8, seed)
    result = simulate_command_coverage(ws, start, tokens, pixels_per_cell=p)
    assert result.duration == len(tokens)
    assert result.pixel_time.sum() / p**2 == pytest.approx(4 * result.duration, abs=1e-9)
    if p <= 4:  # the sampled oracle, at a resolution it can afford
        assert np.abs(result.pixel_time - sampled_translation_time(ws, start, tokens, p)).max() < 0.01


@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(seed=st.integers(0, 2**16))
def test_turning_commands_keep_the_sum_and_stay_in_their_swept_cells(seed):
    ws = Workspace(np.random.default_rng(seed).random((9, 9)) < 0.08)
    free = np.argwhere(~ws.occupancy)
    sim = Simulator(ws, commands=SEED004_COMMANDS)
    starts = [Pose(int(x), int(y), "I", h) for y, x in free for h in range(4)]
    starts = [s for s in starts if not sim.pose_conflicts(sim.encode(s))]
    if not starts:
        return
    start = starts[seed % len(starts)]
    tokens = random_valid(ws, start, TRANSLATE + BLOCK, 12, seed)
    if not tokens:
        return
    result = simulate_command_coverage(ws, start, tokens)
    assert result.pixel_time.sum() / 100 == pytest.approx(4 * result.duration, rel=0.01)
    # covered pixels lie inside cells the commands sweep (the model's swept-cell tables)
    tables = sweep_tables()
    poses = sim.run([parse_commands(tokens)], start).poses(0)
    swept = np.zeros(ws.occupancy.shape, dtype=bool)
    for (x, y, s, h), c in zip(poses[:-1], parse_commands(tokens)):
        cells = tables.cells(s, h, c) + (x, y)
        swept[cells[:, 1], cells[:, 0]] = True
    assert not (result.cell_time[~swept] > 0).any()
    assert not (result.cell_time[ws.occupancy] > 0).any()


def test_plan_metrics_and_activity():
    sc = load_scenario("coverage_16x16")
    plan = plan_coverage(sc.workspace, "O,vI,hI")
    result = plan.coverage
    assert result is plan.coverage  # computed once
    assert result.duration == plan.time == plan.action_cost
    assert result.pixel_time.sum() / 100 == pytest.approx(4 * plan.time, rel=0.01)
    free = ~sc.workspace.occupancy
    assert plan.average_coverage_time == pytest.approx(result.cell_time[free].mean())
    expected = 100 * (result.cell_time[plan.coverable] >= 1.5).sum() / plan.coverable.sum()
    assert plan.recovered_pct == pytest.approx(expected) and 0 < plan.recovered_pct < 100
    assert plan.coverable_pct == 100.0 and plan.coverage_pct == 100.0
    moves = sum(t in TRANSLATE for t in plan.tokens)
    assert plan.path_length == moves and plan.switches > 0
    # eq. 4: the union of the visited footprints, -1 on obstacles; every covered cell has time
    union = np.zeros(free.shape, dtype=bool)
    for x, y, s, h in plan.poses:
        cells = FOOTPRINTS[s, h] + (x, y)
        union[cells[:, 1], cells[:, 0]] = True
    activity = plan.activity
    assert (activity == np.where(sc.workspace.occupancy, -1, np.where(union, 1, 0))).all()
    assert (result.cell_time[activity == 1] > 0).all()
    half = grid_activity(sc.workspace, plan.poses[: len(plan.poses) // 2])
    assert ((half == 1) <= (activity == 1)).all() and (half == 0).any()
    # the result works with the seed-003 measures
    assert result.heat.max() == 255 and 0 <= result.recovered(150, denominator="free") <= 100


def test_timing_and_bad_input():
    ws = Workspace(np.zeros((6, 6), dtype=bool))
    start = Pose(2, 2, "I", 0)
    slow = simulate_command_coverage(ws, start, "3r,3r,x+", timing=Timing(block=2.0))
    assert slow.duration == 5.0 and slow.pixel_time.sum() / 100 == pytest.approx(20.0, rel=0.01)
    ids = simulate_command_coverage(ws, start, parse_commands("3r,3r,x+"))
    assert ids.duration == 3.0
    assert simulate_command_coverage(ws, start, []).duration == 0.0
    with pytest.raises(ConfigurationError, match="command 3 of 3"):
        simulate_command_coverage(ws, start, "x-,x-,x-")  # the third takes the I off the map
    with pytest.raises(ConfigurationError, match="start"):
        simulate_command_coverage(ws, Pose(0, 0, "I", 0), "x+")
    with pytest.raises(UnknownCommandError):
        simulate_command_coverage(ws, start, "jump")
    for options in ({"dt": 0}, {"pixels_per_cell": 0}, {"pixels_per_cell": 5000}):
        with pytest.raises(ParameterError):
            simulate_command_coverage(ws, start, "x+", **options)
    with pytest.raises(ParameterError, match="poses"):
        grid_activity(ws, np.zeros((2, 3), dtype=int))
    with pytest.raises(ParameterError, match="off the map"):
        grid_activity(ws, [Pose(0, 0, "I", 0)])
