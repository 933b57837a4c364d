"""The study runner's overhead per trial, executor by executor, side by side.

Trials that do nothing (the runner's cost alone) and trials that sleep 0.1 s (the cost of running
real work through it) go through :func:`~htetro_opt.studies.runner.run_study` with each executor:
``serial``, ``processes`` (a local pool) and ``dask`` (a local cluster of worker processes), each
twice: with a results file (one line per trial, flushed and ``fsync``-ed) and without. Every run is
timed at two sizes; the difference divided by the extra trials is the **marginal overhead per
trial** (start-up cost excluded), the time of the smaller run minus its trials' work and their
overhead the **fixed start-up cost** (a pool or cluster started and stopped); each the fastest of
``--repeat`` runs. For the sleeping trials the overhead is the wall-clock time beyond the ideal
``trials × 0.1 s / workers``, per trial. Every executor's records must equal the serial ones
(runtime fields aside). Target: ≤ 5 ms per trial for ``processes``.

Run:  python benchmarks/bench_studies.py [--quick] [--workers N] [--repeat N]
"""

from __future__ import annotations

import argparse
import os
import platform
import tempfile
import time

from htetro_opt.studies.runner import RUNTIME_FIELDS, Study, Trial, run_study

SLEEP = 0.1


def noop_trial(task, scenario, method, parameters, seed, *, label=None, metrics=()):
    """A trial that does nothing: its record is its inputs."""
    return {**Trial(task, scenario, method, parameters, seed, label or method, tuple(metrics)).head(),
            "runtime_s": 0.0, "error": None}


def sleep_trial(task, scenario, method, parameters, seed, *, label=None, metrics=()):
    """A trial that waits 0.1 s (a stand-in for work that releases the CPU)."""
    time.sleep(SLEEP)
    return noop_trial(task, scenario, method, parameters, seed, label=label, metrics=metrics)


def _study(trials: int) -> Study:
    # a seeded method, so that every seed is a trial of its own; the trial functions ignore it
    return Study(name="bench", task="plan", scenarios=["three_slit"], seeds=trials,
                 methods=[{"method": "htetro-ga"}])


def _content(records) -> list[dict]:
    return sorted(({k: v for k, v in r.items() if k not in RUNTIME_FIELDS} for r in records), key=lambda r: r["key"])


def _timed(trials: int, function, executor: str, workers: int | None, with_file: bool, repeat: int):
    """The shortest wall-clock time of ``repeat`` runs (the machine is shared), and the records."""
    best = float("inf")
    for _ in range(repeat):
        with tempfile.TemporaryDirectory() as folder:
            began = time.perf_counter()
            run = run_study(_study(trials), executor=executor, workers=workers, trial=function,
                            out=folder if with_file else None)
            best = min(best, time.perf_counter() - began)
    return best, run.records


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true", help="fewer trials")
    parser.add_argument("--workers", type=int, default=2, help="processes / Dask workers (default 2)")
    parser.add_argument("--repeat", type=int, default=2, help="runs of each size, the fastest kept (default 2)")
    args = parser.parse_args()
    _timed(10, noop_trial, "serial", None, True, 1)  # imports and first-use costs out of the way
    sizes = {noop_trial: (100, 300) if args.quick else (200, 1000), sleep_trial: (20, 40) if args.quick else (40, 100)}
    executors = [("serial", None), ("processes", args.workers), ("dask", args.workers)]
    print(f"Python {platform.python_version()}, {os.cpu_count()} CPUs, {args.workers} workers\n")
    print("| trials | executor | results file | runs (trials) | fixed start-up | overhead per trial |")
    print("|---|---|---|---|---:|---:|")
    for function, (small, large) in sizes.items():
        work = 0.0 if function is noop_trial else SLEEP
        reference = None
        for executor, workers in executors:
            for with_file in (False, True):
                if function is sleep_trial and executor == "serial" and not with_file:
                    continue  # the serial runs of sleeping trials only wait: one is enough
                parallel = workers or 1
                times = {}
                for n in (small, large):
                    times[n], records = _timed(n, function, executor, workers, with_file, args.repeat)
                    content = _content(records)
                    if n == large:
                        reference = reference or content
                        assert content == reference, f"{executor} records differ from the serial ones"
                ideal = {n: n * work / parallel for n in times}
                per_trial = ((times[large] - ideal[large]) - (times[small] - ideal[small])) / (large - small)
                fixed = times[small] - ideal[small] - small * per_trial
                name = "no-op" if function is noop_trial else f"{SLEEP:g} s sleep"
                print(f"| {name} | {executor}{'' if workers is None else f' ({workers})'} | "
                      f"{'yes (fsync)' if with_file else 'no'} | {small}, {large} | {fixed:.2f} s | "
                      f"{1e3 * per_trial:.2f} ms |", flush=True)


if __name__ == "__main__":
    main()
