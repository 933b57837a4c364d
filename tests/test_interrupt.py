"""Ctrl-C and SIGTERM (htetro_opt._interrupt): the native solvers stopped at once, the compiled loops' flag,
the command line's one line and exit status at any moment, a study's workers ending with it.

No test here asserts how long anything took: a signal is sent some time into a run (or once the run has
reached a state read from /proc), and what is asserted is the exit status, the one line, what is left
on disk and which processes are left, each waited for with a generous timeout.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest

from htetro_opt._interrupt import kernel_flag, on_signal

EXE = Path(sys.executable).parent / "htetro-opt"
LINUX = sys.platform.startswith("linux")


def test_a_signal_in_the_block_calls_stop_and_is_delivered_after_it():
    stopped = threading.Event()
    with pytest.raises(KeyboardInterrupt):
        with on_signal(stopped.set) as interrupted:
            os.kill(os.getpid(), signal.SIGINT)
            assert stopped.wait(2.0)  # the helper thread called stop() while the block still ran
            assert interrupted.is_set()
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler  # handlers restored


def test_without_a_signal_nothing_happens_and_handlers_are_restored():
    before = {s: signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM)}
    with on_signal(lambda: pytest.fail("stop called without a signal")) as interrupted:
        time.sleep(0.05)
    assert not interrupted.is_set()
    assert {s: signal.getsignal(s) for s in before} == before
    assert signal.set_wakeup_fd(-1) == -1  # no wakeup fd left behind


def test_an_ignored_signal_stays_ignored():
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        with on_signal() as interrupted:
            os.kill(os.getpid(), signal.SIGINT)
            time.sleep(0.2)
        assert not interrupted.is_set()
    finally:
        signal.signal(signal.SIGINT, previous)


@pytest.fixture(scope="module")
def free_160(tmp_path_factory) -> str:
    """A free 160 x 160 map: CP-SAT builds its model in ~2.5 s and then solves for ~6 s."""
    path = tmp_path_factory.mktemp("maps") / "free160.toml"
    rows = "\n".join(["." * 160] * 160)
    path.write_text(f'name = "free160"\nsource = "test"\ngrid = """\n{rows}\n"""\n')
    return str(path)


@pytest.mark.parametrize("argv,signum,code,word", [
    # OR-Tools' guided local search would run its whole 20 s budget
    (["sequence", "tiling_64x64", "--method", "ortools", "--time-limit", "20"], signal.SIGINT, 130, "interrupted"),
    (["tile", "{free_160}", "--method", "cpsat", "--time-limit", "60"], signal.SIGTERM, 143, "terminated"),
    (["tile", "{free_160}", "--method", "cpsat", "--time-limit", "60"], signal.SIGINT, 130, "interrupted"),
])
def test_native_solvers_stop_at_a_signal(argv, signum, code, word, free_160):
    argv = [a.replace("{free_160}", free_160) for a in argv]
    proc = _start(argv)
    time.sleep(3.5)  # into the solve (OR-Tools' guided local search would run its whole 20 s budget)
    returncode, err = _signal(proc, signum)
    assert returncode == code, err
    assert err.strip() == word


# --- helpers: processes read from /proc, never timed ----------------------------------------------------
def _start(argv, **kwargs) -> subprocess.Popen:
    return subprocess.Popen([str(EXE), *argv], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, **kwargs)


def _signal(proc: subprocess.Popen, signum) -> tuple[int, str]:
    assert proc.poll() is None, "the command ended before the signal: pick a longer run"
    proc.send_signal(signum)
    _, err = proc.communicate(timeout=60)
    return proc.returncode, err


def _status(pid: int) -> dict[str, str]:
    try:
        text = Path(f"/proc/{pid}/status").read_text()
    except OSError:  # gone
        return {}
    return dict(line.split(":\t", 1) for line in text.splitlines() if ":\t" in line)


def _mask_has(pid: int, field: str, signum) -> bool:
    value = _status(pid).get(field)
    return value is not None and bool(int(value, 16) >> (int(signum) - 1) & 1)


def _running(pid: int) -> bool:
    """Whether ``pid`` is a live process (a zombie, dead but not yet reaped by its new parent, is not)."""
    state = _status(pid).get("State", "")
    return bool(state) and not state.startswith(("Z", "X"))


def _main_thread_asleep(pid: int) -> bool:
    """Whether the main thread of ``pid`` is in a sleep system call: its ``wchan``, or where the kernel hides
    that, its system call's number (clock_nanosleep: 230 on x86-64, 115 on arm64)."""
    try:
        if "nanosleep" in Path(f"/proc/{pid}/wchan").read_text():
            return True
        return Path(f"/proc/{pid}/syscall").read_text().split()[0] in {"230", "115"}
    except (OSError, IndexError):
        return False


def _children(pid: int) -> list[int]:
    """The processes whose parent is ``pid`` (from /proc: no psutil)."""
    out = []
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit() and _status(int(entry.name)).get("PPid", "").strip() == str(pid):
            out.append(int(entry.name))
    return out


def _wait_for(condition, what: str, timeout: float = 30.0):
    """Poll ``condition()`` until it is true (returned) or ``timeout`` seconds pass (a failure naming ``what``)."""
    deadline = time.monotonic() + timeout
    while True:
        value = condition()
        if value:
            return value
        if time.monotonic() > deadline:
            pytest.fail(f"timed out waiting for {what}")
        time.sleep(0.05)


def _handling_installed(proc: subprocess.Popen) -> bool:
    """The command's own signal handling is in (the console script's first act): SIGTERM is caught."""
    assert proc.poll() is None, proc.communicate()
    return _mask_has(proc.pid, "SigCgt", signal.SIGTERM)


GA = ["plan", "three_slit", "--method", "htetro-ga", "--max-gen", "100000", "--patience", "100000"]


# --- the compiled loops' flag ---------------------------------------------------------------------------
def _ils_case(n=300, seed=4):
    from htetro_opt.problems.waypoint_sequencing import SequencingInstance
    from htetro_opt.solvers.sequencing import _ils

    xy = np.random.default_rng(seed).uniform(0, 100, (n, 2))
    instance = SequencingInstance.from_matrix(np.hypot(*(xy[:, None] - xy[None]).transpose(2, 0, 1)), start=0)
    cm, m, dummy, top = _ils._cost_model(instance)
    return _ils, cm, _ils._neighbour_lists(cm, 8), 1e-9 * max(1.0, top), m


def test_the_flag_is_clear_outside_the_command_line():
    with pytest.raises(KeyboardInterrupt):
        with on_signal():
            os.kill(os.getpid(), signal.SIGINT)
    assert kernel_flag().tolist() == [0]  # a library caller's later searches are not stopped


def test_a_set_flag_stops_the_ils_kernel_and_a_clear_one_changes_nothing():
    ils, cm, nbr, eps, m = _ils_case()
    start = np.arange(m, dtype=np.int64)
    free = start.copy()
    for depth in (0, 2):  # the 2-opt moves and the LK-style move (lk_depth, here with or3opt) alike
        halted = start.copy()
        halt = np.ones(1, np.uint8)
        assert ils._ils(cm, nbr, halted, 500, ils.ILS_KICK_SPAN, np.uint64(7), eps, halt, depth, depth == 2,
                        0.0) == (0, 0)
        assert halted.tolist() == start.tolist()  # not one move: the flag is read before the first
    done, _ = ils._ils(cm, nbr, free, 500, ils.ILS_KICK_SPAN, np.uint64(7), eps, np.zeros(1, np.uint8), 0,
                       False, 0.0)
    assert done == 500 and ils._tour_cost(cm, free) < ils._tour_cost(cm, start)
    stuck = start.copy()
    assert ils._descend(cm, nbr, ils._neighbour_costs(cm, nbr), stuck, True, np.arange(1, 4), True, eps,
                        1 << 40, np.ones(1, np.uint8)) == 0
    assert stuck.tolist() == start.tolist()


def test_a_set_flag_stops_the_tiling_sweep_before_its_next_tile():
    from htetro_opt.solvers.tiling._common import _PAD
    from htetro_opt.solvers.tiling._sweep import sweep

    w = 40  # a free 40 x 40 grid, padded as the portfolio pads it, tiled by O tetrominoes
    stride = w + 2 * _PAD
    grid = np.ones((w + 2 * _PAD, stride), dtype=np.uint8)
    grid[_PAD:-_PAD, _PAD:-_PAD] = 0
    square = np.array([[0, 1, stride, stride + 1]], dtype=np.int64)
    args = (square, stride, 16, _PAD * stride, (_PAD + w) * stride)
    filled = grid.ravel().copy()
    anchors, _, at = sweep(filled, *args, np.ones(1, np.uint8))
    assert len(anchors) == 0 and at >= 0 and filled.tolist() == grid.ravel().tolist()
    anchors, _, at = sweep(grid.ravel().copy(), *args, np.zeros(1, np.uint8))
    assert len(anchors) == (w // 2) ** 2 and at == -1


# --- the command line: one line, 130 / 143, at any moment -----------------------------------------------
@pytest.mark.parametrize("after", [0.5, 1.5])
def test_ctrl_c_into_a_ga_run_prints_one_line_and_exits_130(after, tmp_path):
    proc = _start([*GA, "--plot", str(tmp_path / "never.png")], cwd=tmp_path)
    _wait_for(lambda: _handling_installed(proc), "the command's signal handling")
    time.sleep(after)  # 0.5 s: still importing the solvers (or compiling), 1.5 s: into the run, on most machines
    code, err = _signal(proc, signal.SIGINT)
    assert code == 130, err
    assert err.splitlines() == ["interrupted"] and "Traceback" not in err
    assert list(tmp_path.iterdir()) == []  # no plot, no temporary file


@pytest.mark.parametrize("after", [0.5, 1.5])
def test_sigterm_into_a_ga_run_prints_one_line_and_exits_143(after, tmp_path):
    proc = _start(GA, cwd=tmp_path)
    _wait_for(lambda: _handling_installed(proc), "the command's signal handling")
    time.sleep(after)
    code, err = _signal(proc, signal.SIGTERM)
    assert code == 143, err
    assert err.splitlines() == ["terminated"]


def test_sigterm_at_the_first_moment_of_our_code_still_gives_the_line(tmp_path):
    proc = _start(GA, cwd=tmp_path)
    _wait_for(lambda: _handling_installed(proc), "the command's signal handling")
    code, err = _signal(proc, signal.SIGTERM)  # at once: the command line is still being imported
    assert code == 143, err
    assert err.splitlines() == ["terminated"]


@pytest.mark.skipif(not LINUX, reason="signal masks read from /proc")
def test_a_main_thread_stuck_in_c_is_ended_by_the_helper_thread(tmp_path):
    """The fallback: the main thread never gets back to Python (here: SIGINT and SIGTERM blocked in it, asleep in
    C); the helper thread prints the line, removes the registered temporary file and exits with the status."""
    partial = tmp_path / ".out.tmp"
    code = (
        "import signal, sys, time\n"
        "from htetro_opt._interrupt import install, removed_on_exit\n"
        "install()\n"
        "open(sys.argv[1], 'w').write('half')\n"
        "with removed_on_exit(sys.argv[1]):\n"
        "    signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT, signal.SIGTERM})\n"
        "    print('ready', flush=True)\n"
        "    time.sleep(120)\n")
    proc = subprocess.Popen([sys.executable, "-c", code, str(partial)], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    assert proc.stdout.readline() == "ready\n"
    # only once the main thread sleeps (else it would run the handler at its next bytecode, the usual path)
    _wait_for(lambda: _main_thread_asleep(proc.pid), "the main thread to sleep")
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 143 and err.splitlines() == ["terminated"], err
    assert not partial.exists()


@pytest.mark.parametrize("signum, code, word", [(signal.SIGINT, 130, "interrupted"), (signal.SIGTERM, 143, "terminated")])
def test_a_signal_inside_an_llvm_callback_still_ends_with_the_one_line(signum, code, word):
    """A signal whose handler runs inside llvmlite's ctypes callback (numba's object cache, while a kernel
    is compiled or loaded): ctypes would swallow the exception with a traceback and the code would go on;
    the process ends there with the line and the status. The callback's module is named like llvmlite's."""
    script = (
        "import ctypes, os, signal, sys\n"
        "from htetro_opt._interrupt import install\n"
        "install()\n"
        "scope = {'__name__': 'llvmlite.binding.executionengine', 'os': os}\n"
        "exec('def notify():\\n    os.kill(os.getpid(), %d)\\n    for _ in range(1000): pass\\n', scope)\n"
        "ctypes.CFUNCTYPE(None)(scope['notify'])()\n"
        "print('went on after the signal', flush=True)\n" % int(signum))
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120)
    assert done.returncode == code and done.stderr.splitlines() == [word], done.stderr
    assert done.stdout == ""


# --- a study's workers ------------------------------------------------------------------------------------
STUDY = """name = "{name}"
task = "plan"
scenarios = ["three_slit"]
seeds = {seeds}
metrics = []
[[methods]]
method = "htetro-ga"
pop_size = {pop}
max_gen = {gen}
patience = {gen}
"""


def _study_file(tmp_path, name, *, seeds=4, pop=50, gen=100000) -> Path:
    path = tmp_path / f"{name}.toml"
    path.write_text(STUDY.format(name=name, seeds=seeds, pop=pop, gen=gen))
    return path


def _workers_ready(pid: int, count: int) -> list[int] | None:
    """``pid``'s worker processes once ``count`` of them have run their initializer (SIGINT ignored)."""
    workers = [c for c in _children(pid) if _mask_has(c, "SigIgn", signal.SIGINT)]
    return workers if len(workers) >= count else None


@pytest.mark.skipif(not LINUX, reason="processes read from /proc")
def test_a_sigkilled_study_leaves_no_worker_behind(tmp_path):
    study = _study_file(tmp_path, "killed")
    proc = _start(["study", str(study), "--executor", "processes", "--workers", "2", "--out", str(tmp_path / "out")])
    try:
        workers = _wait_for(lambda: proc.poll() is None and _workers_ready(proc.pid, 2), "the study's two workers")
        assert all(_running(w) for w in workers)
        proc.kill()  # SIGKILL: nothing of the study process runs after it
        proc.communicate(timeout=30)
        _wait_for(lambda: not any(_running(w) for w in workers), "the workers to end with their parent")
    finally:
        if proc.poll() is None:
            proc.kill()
    assert not any(_running(w) for w in workers)


@pytest.mark.skipif(not LINUX, reason="processes read from /proc")
@pytest.mark.parametrize("signum,code,word", [(signal.SIGINT, 130, "interrupted"), (signal.SIGTERM, 143, "terminated")])
def test_a_signalled_study_ends_its_workers_and_resumes_exactly(signum, code, word, tmp_path):
    from htetro_opt.studies.runner import read_records, run_study

    study = _study_file(tmp_path, "cut", seeds=4, pop=8, gen=40)
    out = tmp_path / "out"
    results = out / "cut.jsonl"
    proc = _start(["study", str(study), "--executor", "processes", "--workers", "2", "--out", str(out)])
    workers = _wait_for(lambda: proc.poll() is None and _workers_ready(proc.pid, 2), "the study's two workers")
    # once some trials are recorded and others are still running
    _wait_for(lambda: results.exists() and results.read_bytes().count(b"\n") >= 1, "a first record")
    returncode, err = _signal(proc, signum)
    if returncode == 0:
        pytest.skip("the study finished before the signal")
    assert returncode == code and err.splitlines()[-1:] == [word] and "Traceback" not in err
    _wait_for(lambda: not any(_running(w) for w in workers), "the workers to end with the study")
    data = results.read_bytes()
    assert data == b"" or data.endswith(b"\n")  # complete records only
    kept = read_records(results)
    assert 1 <= len(kept) < 4
    assert not (out / "cut.csv").exists()  # the summary is written only at the end
    resumed = run_study(study, out=out, executor="serial", resume=True)
    assert resumed.resumed == len(kept)
    fresh = run_study(study, executor="serial")

    def content(records):
        return [{k: v for k, v in r.items() if k not in ("runtime_s", "fingerprint")} for r in records]

    assert content(resumed.records) == content(fresh.records)
    assert len(read_records(results)) == 4
