"""Start-up (issue 25, item 6): a whole `htetro-opt plan` process against `python -c "import numpy, scipy"`.

Each command runs as a new process, the two in turn (A B A B ...) after one warm-up run each, so a
drift of the machine's speed hits both; the figures are the process's own CPU time (user + system, from
the kernel's accounting of the finished child) and its wall time, and the ratio A/B pair by pair, with the
median, the minimum and the maximum. The load average is printed before and after: quote it beside the
figures. The warm-up run also fills the caches (numba's, the swept-cell tables'), so the counted runs are
the "second process" of the issue.

Run:  python benchmarks/bench_startup.py [--runs N] [--scenario NAME] [--json]
"""

from __future__ import annotations

import argparse
import os
import resource
import shutil
import statistics
import subprocess
import sys
import time

BASELINE = [sys.executable, "-c", "import numpy, scipy"]


def plan_command(scenario: str, json: bool) -> list[str]:
    exe = shutil.which("htetro-opt") or None
    head = [exe] if exe else [sys.executable, "-m", "htetro_opt.cli"]
    return head + ["plan", scenario] + (["--json"] if json else [])


def run_once(command: list[str]) -> tuple[float, float]:
    """CPU seconds (user + system) and wall seconds of one process running ``command``."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    began = time.perf_counter()
    subprocess.run(command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=True)
    wall = time.perf_counter() - began
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime), wall


def spread(values) -> str:
    return f"{statistics.median(values):.3f} (min {min(values):.3f}, max {max(values):.3f})"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=9, help="counted runs of each command (default 9)")
    parser.add_argument("--scenario", default="three_slit", help="the scenario planned (default three_slit, 24 x 24)")
    parser.add_argument("--json", action="store_true", help="plan with --json (the whole result printed)")
    args = parser.parse_args()
    plan = plan_command(args.scenario, args.json)
    print(f"load average before: {' '.join(f'{v:.2f}' for v in os.getloadavg())}")
    print(f"A: {' '.join(plan[-3 if args.json else -2:])} (htetro-opt)\nB: {' '.join(BASELINE[1:])}")
    run_once(plan), run_once(BASELINE)  # warm-up: the caches filled, the files in the page cache
    a, b = [], []
    for _ in range(args.runs):
        a.append(run_once(plan))
        b.append(run_once(BASELINE))
    for k, what in ((0, "cpu s"), (1, "wall s")):
        print(f"A {what:7s} {spread([r[k] for r in a])}")
        print(f"B {what:7s} {spread([r[k] for r in b])}")
        print(f"A/B {what:5s} {spread([x[k] / y[k] for x, y in zip(a, b)])}")
    print(f"load average after: {' '.join(f'{v:.2f}' for v in os.getloadavg())}")


if __name__ == "__main__":
    main()
