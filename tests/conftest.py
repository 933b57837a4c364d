"""Shared test helpers: an obviously-correct, slow, per-command model of validity."""

import pytest

from htetro_opt.model import Timing, sweep_tables
from htetro_opt.model.commands import COMMANDS


def naive_successors(workspace, pose, t, tokens, *, clearance=0.0, timing=Timing()):
    """(token, next pose, duration) of every valid command from ``pose`` = (x, y, state, heading) at time t."""
    tables = sweep_tables(clearance)
    x, y, s, h = pose
    occ = workspace.occupancy | workspace.moving_during(t) if workspace.moving else workspace.occupancy
    out = []
    for token in tokens:
        c = next(i for i, cmd in enumerate(COMMANDS) if cmd.token == token)
        if not tables.legal[s, c]:
            continue
        ok = True
        for ox, oy in tables.cells(s, h, c):
            cx, cy = x + ox, y + oy
            if not (0 <= cx < workspace.width and 0 <= cy < workspace.height) or occ[cy, cx]:
                ok = False
                break
        if ok:
            nxt = (x + int(tables.shift[c][0]), y + int(tables.shift[c][1]),
                   int(tables.next_state[s, c]), int(tables.next_heading[s, h, c]))
            out.append((token, nxt, timing.duration(token)))
    return out


@pytest.fixture
def successors():
    return naive_successors


def pytest_collection_modifyitems(config, items):
    """The notebooks first. They are the run's longest items (5-17 s each, collected last), and
    pytest-xdist's work stealing evens out the two workers' ends only with short items left: a notebook
    at the end kept the other worker idle for its whole run."""
    items.sort(key=lambda item: not item.nodeid.startswith("notebooks/"))
