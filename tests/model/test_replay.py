"""model.simulate.replay: one sequence run without the Simulator's table, against Simulator.run itself."""

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from htetro_opt.errors import ConfigurationError, UnknownCommandError
from htetro_opt.model import SEED004_COMMANDS, Pose, Simulator, Workspace, parse_commands
from htetro_opt.model.commands import command_id
from htetro_opt.model.simulate import replay


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(seed=st.integers(0, 2**16), w=st.integers(4, 12), h=st.integers(4, 12),
       density=st.sampled_from([0.0, 0.1, 0.25]), clearance=st.sampled_from([0.0, 0.2]),
       seed004=st.booleans(), walk=st.booleans())
def test_replay_is_the_simulators_run(seed, w, h, density, clearance, seed004, walk):
    rng = np.random.default_rng(seed)
    ws = Workspace(rng.random((h, w)) < density)
    commands = SEED004_COMMANDS if seed004 else None
    sim = Simulator(ws, commands=commands, clearance=clearance)
    fits = np.flatnonzero(sim.next[:-1, sim.local[command_id("stop")]] != sim.dead)
    if not len(fits):
        return
    start = int(rng.choice(fits))
    if walk:  # mostly valid: each command drawn among those valid where the robot is, then one at random
        pose, seq = start, []
        for _ in range(int(rng.integers(1, 60))):
            ok = np.flatnonzero(sim.next[pose, : sim.n_commands] != sim.dead)
            c = int(rng.choice(ok)) if len(ok) and rng.random() < 0.95 else int(rng.integers(sim.n_commands))
            seq.append(int(sim.command_ids[c]))
            pose = int(sim.next[pose, c])
            if pose == sim.dead:
                break
        seq = np.array(seq, dtype=np.int64)
    else:
        seq = rng.choice(sim.command_ids, size=int(rng.integers(0, 30)))
    run = sim.run([seq], start)
    got = replay(ws, seq, start, commands=commands, clearance=clearance)
    assert got.valid == bool(run.valid[0])
    assert got.first_invalid == int(run.first_invalid[0]) and got.executed == int(run.executed[0])
    assert np.array_equal(got.poses, run.poses(0))
    assert got.final_id == int(run.trace[0, run.executed[0]])
    assert got.time == float(run.time[0])


def test_replay_checks_its_start_and_commands():
    ws = Workspace(np.zeros((5, 5), dtype=bool))
    with pytest.raises(ConfigurationError, match="start"):
        replay(ws, [], Pose(4, 4, "O", 0))
    with pytest.raises(UnknownCommandError, match="1l"):
        replay(ws, parse_commands("x+,1l"), Pose(1, 1, "O", 0))  # not in the default set
    assert replay(ws, parse_commands("x+,1l"), Pose(1, 1, "O", 0), commands=SEED004_COMMANDS).executed >= 1
