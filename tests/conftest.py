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


def _cpu_seconds(pid: int) -> float:
    """CPU time (user + system, all threads) a running process has used, from /proc."""
    import os

    with open(f"/proc/{pid}/stat") as stat:
        fields = stat.read().rsplit(")", 1)[1].split()  # after the command name, which may hold spaces
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")  # utime, stime


def signal_after_cpu(argv, signum, cpu: float):
    """Run the CLI, send it ``signum`` once it has spent ``cpu`` seconds of CPU time on its work, and
    return (exit code, stdout, stderr, CPU seconds it spent after the signal).

    Measured in CPU time, not on the clock: how far a run has got, and how much work it does after the
    signal before it stops, are the same on a busy machine, where wall-clock time stretches with the
    load. The CPU time after the signal is the child's total (from its resource usage once reaped)
    minus what it had used when the signal was sent.
    """
    import resource
    import subprocess
    import sys
    import time
    from pathlib import Path

    exe = Path(sys.executable).parent / "htetro-opt"
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    proc = subprocess.Popen([str(exe), *argv], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        while True:
            assert proc.poll() is None, "the command ended before the signal: pick a longer run"
            used = _cpu_seconds(proc.pid)
            if used >= cpu:
                break
            time.sleep(0.02)  # a pause between two looks, not a measure
        proc.send_signal(signum)
        out, err = proc.communicate(timeout=600)  # a guard against a hang only
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    total = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return proc.returncode, out, err, total - used


@pytest.fixture
def signal_cli():
    """:func:`signal_after_cpu`: a CLI run signalled after some CPU time of its own."""
    return signal_after_cpu
