"""The vectorised simulator against a plain per-command reference, and its invariants."""

import os
import re
import sys
import time
import tracemalloc

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from htetro_opt.errors import (
    ConfigurationError,
    ParameterError,
    PlanningError,
    UnknownCommandError,
)
from htetro_opt.model import (
    COMMANDS,
    SEED004_COMMANDS,
    STATE_NAMES,
    MovingObstacle,
    Pose,
    Simulator,
    Timing,
    Workspace,
    command_id,
    parse_commands,
    shape_index,
    simulate,
    sweep_tables,
    transitions_at,
)

ALL_TOKENS = [c.token for c in COMMANDS]


def reference_run(workspace, tokens, start, *, roadmap=(), clearance=0.0, timing=Timing()):
    """Execute one sequence command by command from the swept-cell table: the obvious algorithm."""
    tables = sweep_tables(clearance)
    x, y, s, h = start.x, start.y, shape_index(start.shape), start.heading
    goals = [(p.x, p.y, shape_index(p.shape), p.heading) for p in roadmap]
    progress, total = 0, 0.0
    for t, token in enumerate(tokens):
        c = command_id(token)
        if not tables.legal[s, c]:
            return False, t, (x, y, s, h), total, progress
        occ = workspace.occupancy | workspace.moving_during(t) if workspace.moving else workspace.occupancy
        for ox, oy in tables.cells(s, h, c):
            cx, cy = x + ox, y + oy
            if not (0 <= cx < workspace.width and 0 <= cy < workspace.height) or occ[cy, cx]:
                return False, t, (x, y, s, h), total, progress
        x, y = x + tables.shift[c][0], y + tables.shift[c][1]
        s, h = tables.next_state[s, c], tables.next_heading[s, h, c]
        total += timing.duration(token)
        if progress < len(goals) and (x, y, s, h) == goals[progress]:
            progress += 1
    return True, -1, (x, y, s, h), total, progress


def random_map(rng, w, h, density):
    occ = rng.random((h, w)) < density
    occ[:, :4] = False  # keep a free strip for the start (and its clearance)
    return occ


@pytest.mark.parametrize("clearance", [0.0, 0.3])
def test_batch_matches_reference_on_random_sequences(clearance):
    rng = np.random.default_rng(7)
    ws = Workspace(random_map(rng, 14, 12, 0.12))
    start = Pose(1, 5, "I", 0)
    sim = Simulator(ws, commands=ALL_TOKENS, clearance=clearance)
    tokens = [list(rng.choice(ALL_TOKENS, size=rng.integers(0, 40))) for _ in range(300)]
    result = sim.run([parse_commands(t) for t in tokens], start)
    for i, seq in enumerate(tokens):
        valid, first, final, total, _ = reference_run(ws, seq, start, clearance=clearance)
        assert result.valid[i] == valid
        assert result.first_invalid[i] == first
        assert tuple(result.final[i]) == final
        assert result.time[i] == pytest.approx(total)
        assert result.executed[i] == (first if first >= 0 else len(seq))
        assert result.prefix(i).tolist() == parse_commands(seq[: result.executed[i]]).tolist()
    assert 0 < result.valid.sum() < len(tokens)  # the sample exercises both outcomes


def test_moving_obstacles_match_reference():
    rng = np.random.default_rng(3)
    occ = np.zeros((10, 10), dtype=bool)
    moving = (
        MovingObstacle(np.array([[5, 2], [5, 3]]), np.array([[0, 0], [0, 5]])),
        MovingObstacle(np.array([[2, 8]]), np.array([[6, 0]]), mode="loop", speed=2),
    )
    ws = Workspace(occ, moving=moving)
    start = Pose(1, 1, "O", 0)
    sim = Simulator(ws)
    tokens = [list(rng.choice(["x+", "x-", "y+", "y-", "r+", "sI", "sO"], size=30)) for _ in range(300)]
    result = sim.run([parse_commands(t) for t in tokens], start)
    blocked_by_moving = 0
    static = Simulator(ws.without_moving()).run([parse_commands(t) for t in tokens], start)
    for i, seq in enumerate(tokens):
        valid, first, final, total, _ = reference_run(ws, seq, start)
        assert (result.valid[i], result.first_invalid[i], tuple(result.final[i])) == (valid, first, final)
        blocked_by_moving += int(static.executed[i] > result.executed[i])
    assert blocked_by_moving > 0


def test_roadmap_progress_and_stop_at_goal():
    ws = Workspace(np.zeros((8, 8), dtype=bool))
    start, mid, goal = Pose(1, 1, "O", 0), Pose(3, 1, "O", 0), Pose(3, 3, "O", 0)
    seqs = [
        parse_commands("x+,x+,y+,y+"),  # through mid, ends on goal
        parse_commands("y+,y+,x+,x+"),  # ends on goal but skips mid
        parse_commands("x+,x+,y+,y+,x+"),  # passes goal, moves on
        parse_commands("x+,x+,y+"),  # stops short
    ]
    r = Simulator(ws).run(seqs, start, roadmap=[mid, goal])
    assert r.reached.tolist() == [True, False, False, False]
    assert r.progress.tolist() == [3, 1, 3, 2]
    r = Simulator(ws).run(seqs, start, roadmap=[mid, goal], stop_at_goal=True)
    assert r.reached.tolist() == [True, False, True, False]
    assert r.executed.tolist() == [4, 4, 4, 3]
    assert r.poses(2)[-1].tolist() == [3, 3, shape_index("O"), 0]


def test_poses_and_time_of_a_known_sequence():
    ws = Workspace(np.zeros((8, 8), dtype=bool))
    r = simulate(ws, [parse_commands("sI,x+,r+,y+")], Pose(3, 3, "O", 0))
    assert r.poses(0).tolist() == [[3, 3, 1, 0], [3, 3, 0, 0], [4, 3, 0, 0], [4, 3, 0, 1], [4, 4, 0, 1]]
    assert r.time[0] == 3.0 + 1.0 + 2.0 + 1.0
    assert r.final_pose(0) == Pose(4, 4, "I", 1)


def test_empty_sequences_and_empty_batch():
    ws = Workspace(np.zeros((5, 5), dtype=bool))
    r = simulate(ws, [np.array([], dtype=int)] * 2, Pose(1, 1, "O", 0))
    assert r.valid.all() and (r.executed == 0).all() and (r.time == 0).all()
    assert len(simulate(ws, [], Pose(1, 1, "O", 0))) == 0


def test_errors():
    ws = Workspace(np.zeros((5, 5), dtype=bool))
    sim = Simulator(ws)
    with pytest.raises(ConfigurationError, match="start"):
        sim.run([parse_commands("x+")], Pose(4, 4, "O", 0))  # a block outside the map
    with pytest.raises(UnknownCommandError, match="x\\+y\\+"):
        sim.run([parse_commands("x+y+")], Pose(1, 1, "O", 0))  # diagonals not enabled
    with pytest.raises(UnknownCommandError, match="'jump' at position 2"):
        parse_commands("x+, jump")


def test_a_pose_colliding_with_many_cells_says_how_many_and_shows_five():
    sim = Simulator(Workspace(np.ones((12, 12), dtype=bool)), clearance=3.0)
    with pytest.raises(ConfigurationError) as info:
        sim.check_pose(Pose(5, 5, "O", 0), what="start")
    message = str(info.value)
    n = len(sim.pose_conflicts(sim.encode(Pose(5, 5, "O", 0))))
    assert n > 40 and f"{n} cells" in message and f"and {n - 5} more" in message
    assert message.count("), (") == 4 and len(message) < 200


def test_an_intermediate_state_without_block_commands_names_the_paper_and_the_commands():
    sim = Simulator(Workspace(np.zeros((6, 6), dtype=bool)))
    with pytest.raises(ConfigurationError) as info:
        sim.run([[0]], Pose(2, 2, "h112", 0))
    message = str(info.value)
    assert "Cheng et al. 2019's block commands" in message and "3r" in message and "seed" not in message


# --- memory budget ---------------------------------------------------------------------------------

SIMULATE = sys.modules["htetro_opt.model.simulate"]  # the module (htetro_opt.model.simulate is the function)


def test_a_huge_map_is_refused_at_once_naming_the_memory(monkeypatch):
    monkeypatch.setattr(Simulator, "_transition_table", lambda self: pytest.fail("allocated before the check"))
    huge = Workspace(np.zeros((5000, 5000), dtype=bool))
    began = time.process_time()  # "at once" in CPU time, which a busy machine does not stretch
    with pytest.raises(PlanningError) as info:
        Simulator(huge)
    assert time.process_time() - began < 2.0
    message = str(info.value)
    assert "5000 x 5000 map" in message and "GiB of memory, more than the budget of" in message
    assert re.search(r"fit a map of at most [\d,]+ cells \(e\.g\. \d+ x \d+\)", message), message


def test_the_budget_is_the_constant_or_half_the_physical_memory():
    budget = SIMULATE.memory_budget()
    assert 0 < budget <= SIMULATE.MEMORY_BUDGET
    if hasattr(os, "sysconf") and "SC_PHYS_PAGES" in os.sysconf_names:
        assert budget <= os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE") // 2


@pytest.mark.parametrize("commands", [None, ["x+", "x-", "y+", "y-", "3l", "3r"]], ids=["default", "blocks"])
def test_the_map_the_message_says_fits_does_fit_and_one_cell_more_does_not(monkeypatch, commands):
    monkeypatch.setattr(SIMULATE, "MEMORY_BUDGET", 2 * 2**20)  # 2 MiB
    with pytest.raises(PlanningError) as info:
        Simulator(Workspace(np.zeros((40, 40), dtype=bool)), commands=commands)
    fits = int(re.search(r"at most ([\d,]+) cells", str(info.value))[1].replace(",", ""))
    assert 100 < fits < 1600 and "2.0 MiB" in str(info.value)
    Simulator(Workspace(np.zeros((1, fits), dtype=bool)), commands=commands)
    with pytest.raises(PlanningError):
        Simulator(Workspace(np.zeros((1, fits + 1), dtype=bool)), commands=commands)


@pytest.mark.parametrize("commands", [None, ["x+", "x-", "y+", "y-", "3l", "3r"]], ids=["default", "blocks"])
def test_the_estimate_bounds_the_memory_compiling_and_running_takes(commands):
    """tracemalloc's peak (numpy reports its arrays to it) against the bytes the budget check counts,
    with the repair's table of valid commands (the most a run adds)."""
    ws = Workspace(np.zeros((60, 60), dtype=bool))
    # sweep tables cached, imports done, and the compiled step loop loaded (numba compiles it on the first
    # run, and its compiler's allocations would count in the peak when this test runs first in a process)
    warm = Simulator(Workspace(np.zeros((8, 8), dtype=bool)), commands=commands)
    warm.run([parse_commands("x-,x-")], Pose(2, 2, "O", 0), repair=np.random.default_rng(0))
    tracemalloc.start()
    try:
        sim = Simulator(ws, commands=commands)
        run = sim.run([parse_commands("x-,x-,x-,x-")], Pose(2, 2, "O", 0), repair=np.random.default_rng(0))
        assert run.valid[0] and run.sequence(0).tolist() != parse_commands("x-,x-,x-,x-").tolist()  # repaired
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    estimate = SIMULATE.compile_bytes(sim.n_poses, sim.n_commands)
    assert peak <= estimate <= 1.4 * peak


# --- property tests ----------------------------------------------------------------------------

def turn_token(token, quarter_turns):
    """The token that does in a map turned by 90°·k what ``token`` does in the original."""
    cmd = COMMANDS[command_id(token)]
    if cmd.kind not in ("translation", "diagonal"):
        return token
    dx, dy = cmd.shift
    for _ in range(quarter_turns % 4):
        dx, dy = -dy, dx
    parts = ("x+" if dx > 0 else "x-" if dx < 0 else "") + ("y+" if dy > 0 else "y-" if dy < 0 else "")
    return parts


@settings(max_examples=60, deadline=None)
@given(
    seed=st.integers(0, 10_000),
    tokens=st.lists(st.sampled_from(ALL_TOKENS), min_size=0, max_size=25),
    quarter_turns=st.integers(1, 3),
)
def test_turning_the_whole_world_turns_the_outcome(seed, tokens, quarter_turns):
    """Simulation commutes with turning the map, the start heading and every translation."""
    rng = np.random.default_rng(seed)
    n = 11
    occ = rng.random((n, n)) < 0.1
    centre = (5, 5)
    occ[3:8, 3:8] = False
    start = Pose(5, 5, STATE_NAMES[rng.integers(0, 7)], int(rng.integers(0, 4)))

    def turn_cell(x, y, k):
        for _ in range(k % 4):  # about the map's centre cell
            x, y = centre[0] - (y - centre[1]), centre[1] + (x - centre[0])
        return x, y

    turned_occ = np.zeros_like(occ)
    for y in range(n):
        for x in range(n):
            tx, ty = turn_cell(x, y, quarter_turns)
            turned_occ[ty, tx] = occ[y, x]
    a = Simulator(Workspace(occ), commands=ALL_TOKENS)
    b = Simulator(Workspace(turned_occ), commands=ALL_TOKENS)
    try:
        ra = a.run([parse_commands(tokens)], start)
    except ConfigurationError:
        return  # start collides: nothing to compare
    turned_start = Pose(5, 5, start.shape, (start.heading + quarter_turns) % 4)
    rb = b.run([parse_commands([turn_token(t, quarter_turns) for t in tokens])], turned_start)
    assert ra.valid[0] == rb.valid[0] and ra.executed[0] == rb.executed[0]
    x, y, s, h = ra.final[0]
    assert tuple(rb.final[0]) == (*turn_cell(x, y, quarter_turns), s, (h + quarter_turns) % 4)
    assert ra.time[0] == rb.time[0]


@settings(max_examples=60, deadline=None)
@given(shape=st.sampled_from(STATE_NAMES[:7]), heading=st.integers(0, 3),
       target=st.sampled_from(STATE_NAMES[:7]), turns=st.integers(0, 4))
def test_rotation_and_shapeshift_invariants(shape, heading, target, turns):
    """r+ then r− and sX then back are identities; four r+ are a full turn; B2's cell never moves."""
    ws = Workspace(np.zeros((13, 13), dtype=bool))
    start = Pose(6, 6, shape, heading)
    seqs = [
        parse_commands(["r+", "r-"]),
        parse_commands(["r+"] * 4),
        parse_commands(["s" + target, "s" + shape]),
        parse_commands(["r+"] * turns + ["s" + target] + ["r-"] * turns),
    ]
    sim = Simulator(ws)
    r = sim.run(seqs, start)
    assert r.valid.all()
    for i in range(3):
        assert tuple(r.final[i]) == (6, 6, shape_index(shape), heading)
    assert tuple(r.final[3]) == (6, 6, shape_index(target), heading)
    assert (r.trace[:, 0] == sim.encode(start)).all()  # every trace begins at the start pose
    for i in range(len(seqs)):
        assert (r.poses(i)[:, :2] == (6, 6)).all()


@settings(max_examples=40, deadline=None)
@given(tokens=st.lists(st.sampled_from(["x+", "x-", "y+", "y-", "x+y+", "x-y-", "x+y-", "x-y+"]), max_size=30))
def test_translations_keep_shape_and_heading_and_add_up(tokens):
    ws = Workspace(np.zeros((70, 70), dtype=bool))
    r = Simulator(ws, diagonals=True).run([parse_commands(tokens)], Pose(35, 35, "T", 2))
    # the displacement read off the tokens' text, not off the command table the simulator uses
    dx = sum(t.count("x+") - t.count("x-") for t in tokens)
    dy = sum(t.count("y+") - t.count("y-") for t in tokens)
    assert r.valid[0]
    assert tuple(r.final[0]) == (35 + dx, 35 + dy, shape_index("T"), 2)
    diagonals = sum(len(t) == 4 for t in tokens)
    assert r.time[0] == pytest.approx(len(tokens) - diagonals + diagonals * 2 ** 0.5)


def test_repair_changes_only_what_dies():
    # One loop serves plain and repairing runs: with nothing to repair, a repairing run is the plain run.
    rng = np.random.default_rng(5)
    ws = Workspace(random_map(rng, 14, 12, 0.12))
    sim = Simulator(ws)
    start = Pose(1, 5, "O", 0)
    seqs = [parse_commands(list(rng.choice(["x+", "x-", "y+", "y-", "r+", "sI", "sO"], size=int(rng.integers(0, 30)))))
            for _ in range(200)]
    plain = sim.run(seqs, start)
    valid = [s for s, ok in zip(seqs, plain.valid) if ok]
    assert 10 < len(valid) < len(seqs)
    a, b = sim.run(valid, start), sim.run(valid, start, repair=np.random.default_rng(0))
    assert np.array_equal(a.keys, b.keys) and np.array_equal(a.local, b.local)
    assert np.array_equal(a.time, b.time) and np.array_equal(a.executed, b.executed)
    repaired = sim.run(seqs, start, repair=np.random.default_rng(0))
    assert repaired.valid.sum() > plain.valid.sum()
    for i in np.flatnonzero(plain.valid):  # valid sequences come through unchanged
        assert np.array_equal(repaired.sequence(i), seqs[i])
    for i in np.flatnonzero(~plain.valid):  # the others keep their prefix up to the first invalid command
        k = plain.first_invalid[i]
        assert np.array_equal(repaired.sequence(i)[:k], seqs[i][:k]) and repaired.sequence(i)[k] != seqs[i][k]


def test_array_holding_objects_compare_by_identity_and_hash():
    a, b = Workspace(np.zeros((3, 3), dtype=bool)), Workspace(np.zeros((3, 3), dtype=bool))
    assert a == a and a != b
    assert len({a, b, MovingObstacle(np.array([[0, 0]]), np.array([[1, 0]]))}) == 3


# --- transitions_at: the simulator's rows at some cells, without the whole table ----------------------

SEED004 = list(SEED004_COMMANDS)


def simulator_rows(sim, cells):
    """The simulator's next poses of every (state, heading, command) at ``cells``, ``dead`` as −1."""
    ws = sim.workspace
    states, headings = np.meshgrid(np.arange(sim.n_states), np.arange(4), indexing="ij")
    rows = np.empty((len(cells), sim.n_states, 4, sim.n_commands), dtype=np.int64)
    for i, (x, y) in enumerate(cells):
        ids = ((states * 4 + headings) * ws.height + y) * ws.width + x
        rows[i] = sim.next[ids, : sim.n_commands]
    rows[rows == sim.dead] = -1
    return rows


@pytest.mark.parametrize(
    ("size", "density", "clearance", "options"),
    [
        ((9, 7), 0.1, 0.0, {}),
        ((12, 10), 0.2, 0.3, {"diagonals": True}),
        ((15, 6), 0.05, 0.5, {"commands": SEED004}),
        ((11, 13), 0.15, 0.3, {"commands": SEED004 + ["x+y+", "x-y-", "sI", "sT"]}),
        ((20, 17), 0.3, 0.0, {"commands": ALL_TOKENS}),
        ((6, 1), 0.0, 0.5, {}),  # one row: every footprint at heading 0 leaves the map
    ],
)
def test_transitions_at_rows_are_the_simulators_rows(size, density, clearance, options):
    rng = np.random.default_rng(sum(size) + int(10 * clearance))
    width, height = size
    ws = Workspace(rng.random((height, width)) < density)
    sim = Simulator(ws, clearance=clearance, **options)
    cells = np.column_stack([rng.integers(0, width, 40), rng.integers(0, height, 40)])  # repeats included
    rows = transitions_at(ws, cells, clearance=clearance, **options)
    assert rows.shape == (40, sim.n_states, 4, sim.n_commands) and rows.dtype == np.int64
    assert np.array_equal(rows, simulator_rows(sim, cells))
    if height > 1:
        assert (rows >= 0).any() and (rows == -1).any()  # both outcomes are compared


def test_transitions_at_every_cell_is_the_simulators_whole_table():
    ws = Workspace(random_map(np.random.default_rng(2), 10, 8, 0.2))
    sim = Simulator(ws, commands=SEED004, clearance=0.3)
    cells = np.argwhere(np.ones((8, 10), dtype=bool))[:, ::-1]
    rows = transitions_at(ws, cells, commands=SEED004, clearance=0.3)
    table = sim.next[: sim.n_poses, : sim.n_commands].astype(np.int64)
    table[table == sim.dead] = -1
    expected = table.reshape(sim.n_states, 4, 8, 10, sim.n_commands).transpose(2, 3, 0, 1, 4).reshape(rows.shape)
    assert np.array_equal(rows, expected)
    assert rows.shape[1] == 23


def test_transitions_at_by_hand_from_the_model_geometry():
    """MODEL.md §2's footprints and numbering on a 5 x 4 map, read off by hand."""
    occ = np.zeros((4, 5), dtype=bool)
    occ[1, 4] = True  # cell (4, 1)
    ws = Workspace(occ)
    W, H, o = 5, 4, shape_index("O")
    own = ((o * 4 + 0) * H + 1) * W + 2  # O at (2, 1), heading 0: blocks (2, 0), (2, 1), (3, 1), (3, 0)
    rows = transitions_at(ws, [(2, 1), (1, 1)], commands=["x+", "x-", "y+", "y-", "r+"])
    assert rows[0, o, 0].tolist() == [
        -1,  # x+ puts B3 on the obstacle (4, 1)
        own - 1,  # x-: one cell left
        own + W,  # y+: one row up
        -1,  # y-: B1 and B4 would leave the map below
        -1,  # r+: the turning blocks sweep cells below the map
    ]
    assert rows[1, o, 0, 0] == own  # from (1, 1), x+ lands on (2, 1)
    corner = transitions_at(ws, [(3, 3)], commands=["x+", "x-", "y+", "y-"])[0, o, 0]  # blocks (3..4, 2..3)
    # x+ and y+ leave the map, x- lands on (2, 3), y- puts B4 on the obstacle (4, 1)
    assert corner.tolist() == [-1, own + 2 * W, -1, -1]
    # In an empty 7 x 7 map, the centre is far enough from every edge for a turn and a shapeshift.
    big = transitions_at(Workspace(np.zeros((7, 7), dtype=bool)), [(3, 3), (0, 0)], commands=["r+", "sI"])
    centre = ((o * 4 + 0) * 7 + 3) * 7 + 3
    assert big[0, o, 0].tolist() == [centre + 7 * 7, ((0 * 4 + 0) * 7 + 3) * 7 + 3]  # heading + 1; state I
    assert (big[1, o] == -1).all()  # B1 of the O at (0, 0) is at (0, -1) at every heading but one
    assert (big[1] == -1).all()  # no shape turns or changes shape in the corner


def test_transitions_at_ignores_moving_obstacles():
    occ = np.zeros((8, 8), dtype=bool)
    moving = (MovingObstacle(np.array([[4, 2], [4, 3]]), np.array([[0, 0], [0, 4]])),)
    ws = Workspace(occ, moving=moving)
    cells = np.argwhere(np.ones((8, 8), dtype=bool))[:, ::-1]
    assert np.array_equal(transitions_at(ws, cells), transitions_at(ws.without_moving(), cells))


def test_transitions_at_memory_grows_with_the_cells_not_the_map():
    """The same 100 cells take the same memory on a 150 x 150 and a 2000 x 2000 map (4 MB of occupancy):
    no copy of the map, no table over it."""
    cells = np.column_stack([np.arange(100), np.arange(100) * 7 % 150])

    def peak_on(side):
        ws = Workspace(np.zeros((side, side), dtype=bool))
        transitions_at(ws, cells[:1])  # sweep tables cached
        tracemalloc.start()
        try:
            rows = transitions_at(ws, cells)
            return tracemalloc.get_traced_memory()[1], rows, ws
        finally:
            tracemalloc.stop()

    small, _, _ = peak_on(150)
    big, rows, ws = peak_on(2000)
    assert rows.shape == (100, 7, 4, 13) and (rows >= 0).any()
    assert rows.nbytes < big <= small + 2**14 and big < ws.occupancy.nbytes / 2


def test_transitions_at_empty_cells():
    ws = Workspace(np.zeros((5, 5), dtype=bool))
    assert transitions_at(ws, []).shape == (0, 7, 4, 13)
    assert transitions_at(ws, np.empty((0, 2), dtype=int), diagonals=True).shape == (0, 7, 4, 17)


@pytest.mark.parametrize(
    ("cells", "message"),
    [
        ([(5, 0)], r"inside the 5 x 4 map; outside it: cell \(5, 0\) \(the first at cells\[0\]\)"),
        ([(0, 0), (-1, 2), (0, 4)], r"outside it: 2 cells \(-1, 2\), \(0, 4\) \(the first at cells\[1\]\)"),
        (np.array([[0, 0], [2**63 + 5, 1]], dtype=np.uint64), r"outside it: cell \(9223372036854775813, 1\)"),
        ([1, 2], r"an \(n, 2\) array of \(x, y\) cells \(one cell is \[\(x, y\)\]\), got shape \(2,\)"),
        ([(0, 0, 0)], r"an \(n, 2\) array of \(x, y\) cells, got shape \(1, 3\)"),
        (np.zeros((2, 2, 2), dtype=int), r"got shape \(2, 2, 2\)"),
        ("ab", r"got shape \(\)"),
        (None, r"got shape \(\)"),
        ([(0, 0), (1,)], r"an \(n, 2\) array of \(x, y\) cells, got \[\(0, 0\), \(1,\)\]"),
        ([(0.0, 1.0)], "must hold integer .* got an array of float64"),
        ([(0.5, 1)], "must hold integer .* got an array of float64"),
        ([(True, False)], "must hold integer .* got an array of bool"),
    ],
)
def test_transitions_at_refuses_bad_cells(cells, message):
    with pytest.raises(ParameterError, match=message):
        transitions_at(Workspace(np.zeros((4, 5), dtype=bool)), cells)


def test_transitions_at_refuses_bad_options():
    ws = Workspace(np.zeros((4, 4), dtype=bool))
    with pytest.raises(ParameterError, match="workspace must be a Workspace"):
        transitions_at(np.zeros((4, 4), dtype=bool), [(1, 1)])
    with pytest.raises(ParameterError, match="clearance"):
        transitions_at(ws, [(1, 1)], clearance=-0.1)
    with pytest.raises(ParameterError, match="diagonals"):
        transitions_at(ws, [(1, 1)], diagonals=1)
    with pytest.raises(UnknownCommandError, match="jump"):
        transitions_at(ws, [(1, 1)], commands=["x+", "jump"])
