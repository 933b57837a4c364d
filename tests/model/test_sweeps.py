"""Swept-cell tables against the reference sizes of shared/MODEL.md §4."""

import numpy as np
import pytest

from htetro_opt.errors import ParameterError

from htetro_opt.model.commands import COMMANDS, command_id
from htetro_opt.model.robot import FOOTPRINTS, N_STATES, SHAPES, rotate_cells, shape_index
from htetro_opt.model.sweeps import motion_samples, swept_cells, sweep_tables

ROTATION_SWEEPS = {"I": 16, "O": 12, "L": 15, "J": 16, "Z": 13, "S": 16, "T": 15}
SHAPESHIFT_SWEEPS = {  # rows: from, columns: to (I, O, L, J, Z, S, T)
    "I": [4, 16, 10, 14, 16, 16, 19],
    "O": [16, 4, 18, 19, 27, 12, 11],
    "L": [10, 18, 4, 8, 10, 10, 17],
    "J": [14, 19, 8, 4, 10, 10, 11],
    "Z": [16, 27, 10, 10, 4, 18, 17],
    "S": [16, 12, 10, 10, 18, 4, 9],
    "T": [19, 11, 17, 11, 17, 9, 4],
}


@pytest.fixture(scope="module")
def tables():
    return sweep_tables()


def as_set(cells):
    return {tuple(c) for c in np.asarray(cells).tolist()}


@pytest.mark.parametrize("shape", SHAPES)
@pytest.mark.parametrize("token", ["r+", "r-"])
def test_rotation_sweep_sizes(tables, shape, token):
    assert tables.counts[shape_index(shape), 0, command_id(token)] == ROTATION_SWEEPS[shape]


@pytest.mark.parametrize("source", SHAPES)
def test_shapeshift_sweep_sizes(tables, source):
    got = [int(tables.counts[shape_index(source), 0, command_id("s" + t)]) for t in SHAPES]
    assert got == SHAPESHIFT_SWEEPS[source]


def test_every_sweep_contains_start_and_end_footprints(tables):
    for s in range(N_STATES):
        for h in range(4):
            for c in range(len(COMMANDS)):
                if not tables.legal[s, c]:
                    continue
                cells = as_set(tables.cells(s, h, c))
                end = FOOTPRINTS[tables.next_state[s, c], tables.next_heading[s, h, c]] + tables.shift[c]
                assert as_set(FOOTPRINTS[s, h]) <= cells
                assert as_set(end) <= cells


def test_axis_translation_sweeps_exactly_start_and_end(tables):
    for s in range(7):
        for h in range(4):
            for token in ("x+", "x-", "y+", "y-"):
                c = command_id(token)
                expected = as_set(FOOTPRINTS[s, h]) | as_set(FOOTPRINTS[s, h] + tables.shift[c])
                assert as_set(tables.cells(s, h, c)) == expected


def test_diagonal_sweeps_add_the_two_side_cells_of_every_block(tables):
    c = command_id("x+y+")
    for s in range(7):
        start = FOOTPRINTS[s, 0]
        expected = set()
        for dx, dy in ((0, 0), (1, 1), (1, 0), (0, 1)):
            expected |= as_set(start + (dx, dy))
        assert as_set(tables.cells(s, 0, c)) == expected


def test_body_frame_sweeps_turn_with_the_heading(tables):
    for token in ["r+", "r-", "sO", "sT", "3r", "1l", "stop"]:
        c = command_id(token)
        for s in range(N_STATES):
            if tables.legal[s, c]:
                base = tables.cells(s, 0, c)
                for h in range(1, 4):
                    assert as_set(tables.cells(s, h, c)) == as_set(rotate_cells(base, h))


def test_stop_sweeps_the_footprint(tables):
    c = command_id("stop")
    for s in range(N_STATES):
        for h in range(4):
            assert as_set(tables.cells(s, h, c)) == as_set(FOOTPRINTS[s, h])


def test_sweeps_do_not_change_with_finer_sampling(monkeypatch):
    # The largest motions (180° shapeshifts, I's rotation) sampled 8 times finer give the same cells.
    from htetro_opt.model import sweeps as module

    cases = [("O", "sZ"), ("I", "sT"), ("I", "r+"), ("Z", "sO"), ("O", "sI")]
    coarse = [as_set(swept_cells(*motion_samples(shape_index(a), COMMANDS[command_id(t)])))
              for a, t in cases]
    monkeypatch.setattr(module, "_MAX_TURN_PER_SAMPLE", module._MAX_TURN_PER_SAMPLE / 8)
    fine = [as_set(swept_cells(*motion_samples(shape_index(a), COMMANDS[command_id(t)])))
            for a, t in cases]
    assert coarse == fine


def test_clearance_grows_every_sweep():
    plain, padded = sweep_tables(0.0), sweep_tables(0.4)
    for s in range(7):
        for c in range(len(COMMANDS)):
            if plain.legal[s, c]:
                assert as_set(plain.cells(s, 0, c)) < as_set(padded.cells(s, 0, c))


def test_seed_004_block_commands(tables):
    i, o = shape_index("I"), shape_index("O")
    three_r = command_id("3r")
    middle = tables.next_state[i, three_r]
    assert middle >= 7  # an intermediate state
    assert tables.next_state[middle, three_r] == o  # two 3r take I to O (seed 004 §IV)
    assert not tables.legal[o, three_r]  # θH2 would leave [π/2, 3π/2]
    assert tables.next_state[i, command_id("2r")] == i
    assert tables.next_heading[i, 0, command_id("2r")] == 3


def test_bad_clearance_is_rejected():
    with pytest.raises(ParameterError, match="clearance"):
        sweep_tables(-0.1)
