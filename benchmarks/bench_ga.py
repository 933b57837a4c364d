"""Speed and quality of Cheng et al. 2020's GA (hTetro-GA), with pymoo's NSGA-II on the same operators beside it.

1. Per-generation time: ``minimize(problem, HTetroGA(pop_size=n), ("n_gen", 200), seed=s)`` on the
   24 x 24 maps three_slit and random, n_pop = 50 and 100, beside ``HTetroGA.as_published(n)`` (the
   paper's algorithm without the library's repair, shortcut and niching) and ``make_algorithm("nsga2",
   n)`` (pymoo's NSGA-II with the same sampling, crossover, mutation, repair and duplicate
   elimination), the baseline of the ratio column. Wall (and CPU) time over the whole run, initial
   population included, / generations. hTetro-GA evaluates two offspring sets per generation
   (conservative + non-conservative, up to 2 n_pop new individuals), NSGA-II one (n_pop): the
   evaluated-individuals column says how many.
2. Per-generation split of the same runs, measured by wrapping each part's entry point: the problem's
   ``_evaluate`` (the batch simulation and the four fitnesses), the repair (it simulates every new
   chromosome too; with hTetro-GA's one ``repair_and_shortcut`` call per generation, the shortcut too), the other
   operators (sampling, tournament selection, crossover, mutation, removal, rearrangement, shortcut), duplicate elimination, survival (the non-dominated sort), and the
   rest (pymoo's population bookkeeping, chromosome trimming, the evaluator and termination).
3. Quality: ``plan_ga`` (n_pop = 50) a few seeds per environment of Table 4, with the reach rate,
   the generations, the best time in the final leading front against the exact minimum-time plan, and
   the gap (via :func:`htetro_opt.studies.table4.run_trial`), for each method of ``--methods``.

Run:  python benchmarks/bench_ga.py [--quick] [--parts timing,split,quality] [--repeat N] [--jobs N]
                                    [--methods htetro-ga,htetro-ga-paper]

--quick: 1 seed per timing cell, and quality with 2 seeds and max_gen 300 (full: 3 timing seeds,
10 quality seeds, max_gen 1000).
"""

from __future__ import annotations

import argparse
import platform
import statistics
import sys
import time
import types
from collections import defaultdict

import numpy as np
import pymoo
from pymoo.core.callback import Callback
from pymoo.optimize import minimize

from htetro_opt.algorithms import HTetroGA, make_algorithm
from htetro_opt.algorithms import htetro_ga as htetro_ga_module
from htetro_opt.model import SEED000_COMMANDS, Simulator
from htetro_opt.problems import CommandPathProblem
from htetro_opt.scenarios import load_scenario
from htetro_opt.studies.metrics import format_mean_std
from htetro_opt.studies.table4 import ENVIRONMENTS, run_table4, summarise

TIMING_MAPS = ("three_slit", "random")
POP_SIZES = (50, 100)
N_GEN = 200
TARGET_MS = 20.0  # the target per generation at n_pop = 100
TIMED = ("htetro-ga", "htetro-ga-paper", "nsga2")
PARTS = ("evaluation", "repair", "operators", "duplicates", "survival", "other")


class _Counter(Callback):
    def __init__(self) -> None:
        super().__init__()
        self.generations = 0

    def notify(self, algorithm) -> None:
        self.generations += 1


def _problem(name: str) -> CommandPathProblem:
    scenario = load_scenario(name)
    sim = Simulator(scenario.workspace, commands=SEED000_COMMANDS)
    return CommandPathProblem(sim, scenario.start, scenario.goal, max_length=100)


class _Clock:
    """Per-part timers of one run. Only the outermost timed call counts, so an operator's ``do``
    calling its own ``_do``, or a part calling another, is not counted twice."""

    def __init__(self) -> None:
        self.seconds: dict[str, float] = defaultdict(float)
        self.evaluated = 0
        self.depth = 0
        self.patched: list[tuple[object, str, object]] = []

    def wrap(self, obj, attr: str, bucket: str) -> None:
        """Time ``obj.attr`` (a bound method, or a module's function) into ``bucket``; restored by
        :meth:`restore` when it was a module attribute."""
        inner = getattr(obj, attr, None)
        if inner is None:
            return

        def timed(*args, **kwargs):
            if self.depth:
                return inner(*args, **kwargs)
            self.depth += 1
            began = time.perf_counter()
            try:
                return inner(*args, **kwargs)
            finally:
                self.seconds[bucket] += time.perf_counter() - began
                self.depth -= 1

        if isinstance(obj, types.ModuleType):
            self.patched.append((obj, attr, inner))
        setattr(obj, attr, timed)

    def count_evaluations(self, problem) -> None:
        inner = problem._evaluate

        def counted(X, *args, **kwargs):
            self.evaluated += len(X)
            return inner(X, *args, **kwargs)

        problem._evaluate = counted

    def restore(self) -> None:
        for obj, attr, inner in reversed(self.patched):
            setattr(obj, attr, inner)
        self.patched.clear()


def run_once(name: str, kind: str, n: int, seed: int, *, split: bool) -> dict:
    """One ``minimize`` run of N_GEN generations; with ``split`` the parts are timed too.

    The parts are found by name: each operator's ``do`` (every algorithm, hTetro-GA included, calls
    its operators through it), the survival's ``do``, the duplicate elimination's ``do``, and in
    :mod:`htetro_opt.algorithms.htetro_ga` the ``first_occurrences`` helper and the
    ``repair_and_shortcut`` function that HTetroGA calls once per generation (counted as repair).
    """
    problem = _problem(name)
    algorithm = make_algorithm(kind, n)
    clock = _Clock()
    clock.count_evaluations(problem)  # cheap: a few calls per generation
    if split:
        clock.wrap(problem, "_evaluate", "evaluation")
        mating = algorithm.mating
        operators = [algorithm.initialization.sampling, mating.selection, mating.crossover, mating.mutation]
        if isinstance(algorithm, HTetroGA):
            operators += [algorithm.removal, algorithm.rearrangement]
        for op in operators:
            clock.wrap(op, "do", "operators")
        clock.wrap(algorithm.repair, "do", "repair")  # shared with mating/initialisation
        clock.wrap(htetro_ga_module, "repair_and_shortcut", "repair")  # HTetroGA's one repair + shortcut step
        clock.wrap(algorithm.eliminate_duplicates, "do", "duplicates")
        clock.wrap(htetro_ga_module, "first_occurrences", "duplicates")
        clock.wrap(algorithm.survival, "do", "survival")
    counter = _Counter()
    try:
        began, cpu_began = time.perf_counter(), time.process_time()
        res = minimize(problem, algorithm, ("n_gen", N_GEN), seed=seed, callback=counter, copy_algorithm=False)
        total, cpu = time.perf_counter() - began, time.process_time() - cpu_began
    finally:
        clock.restore()
    gens = counter.generations
    out = {
        "map": name, "algorithm": kind, "n": n, "seed": seed, "generations": gens,
        "ms_per_gen": 1e3 * total / gens,
        "cpu_ms_per_gen": 1e3 * cpu / gens,
        "evaluated_per_gen": clock.evaluated / gens,
        "reached": bool((res.pop.get("F")[:, 0] == -1.0).any()),
    }
    if split:
        known = sum(clock.seconds[p] for p in PARTS if p != "other")
        out.update({f"{p}_ms": 1e3 * clock.seconds[p] / gens for p in PARTS if p != "other"})
        out["other_ms"] = 1e3 * (total - known) / gens
    return out


def timing(repeat: int, *, split: bool) -> list[dict]:
    rows = []
    for name in TIMING_MAPS:
        _problem(name)  # compile the sweep tables once before timing
        for n in POP_SIZES:
            for kind in TIMED:
                runs = [run_once(name, kind, n, seed, split=split) for seed in range(repeat)]
                row = {"map": name, "algorithm": kind, "n": n, "runs": len(runs)}
                for key in runs[0]:
                    if key.endswith("_ms") or key in ("ms_per_gen", "cpu_ms_per_gen", "evaluated_per_gen"):
                        row[key] = statistics.median(r[key] for r in runs)
                row["reached"] = sum(r["reached"] for r in runs)
                rows.append(row)
                print(f"  {name} {kind} n={n}: {row['ms_per_gen']:.1f} ms/gen wall, {row['cpu_ms_per_gen']:.1f} CPU",
                      file=sys.stderr, flush=True)
    return rows


def print_timing(rows: list[dict]) -> None:
    print(f"## Per-generation time ({N_GEN} generations, median of {rows[0]['runs']} seeds)\n")
    print("| map | n_pop | algorithm | ms/gen wall | ms/gen CPU | evaluated/gen | CPU µs per evaluated individual "
          "| CPU / NSGA-II |")
    print("|---|---:|---|---:|---:|---:|---:|---:|")
    by = {(r["map"], r["algorithm"], r["n"]): r for r in rows}
    for name in TIMING_MAPS:
        for n in POP_SIZES:
            base = by[(name, "nsga2", n)]["cpu_ms_per_gen"]
            for kind in TIMED:
                r = by[(name, kind, n)]
                print(f"| {name} | {n} | {kind} | {r['ms_per_gen']:.1f} | {r['cpu_ms_per_gen']:.1f} "
                      f"| {r['evaluated_per_gen']:.0f} | {1e3 * r['cpu_ms_per_gen'] / r['evaluated_per_gen']:.0f} "
                      f"| {r['cpu_ms_per_gen'] / base:.2f}× |")
    worst = max(by[(m, "htetro-ga", 100)]["ms_per_gen"] for m in TIMING_MAPS)
    worst_cpu = max(by[(m, "htetro-ga", 100)]["cpu_ms_per_gen"] for m in TIMING_MAPS)
    print(f"\nTarget < {TARGET_MS:g} ms per generation of HTetroGA at n_pop = 100: "
          f"{'met' if worst < TARGET_MS else 'NOT met'} on wall time (worst {worst:.1f} ms), "
          f"{'met' if worst_cpu < TARGET_MS else 'NOT met'} on CPU time (worst {worst_cpu:.1f} ms).\n")


def print_split(rows: list[dict]) -> None:
    print(f"## Per-generation split ({N_GEN} generations, median of {rows[0]['runs']} seeds, ms per generation)\n")
    print("| map | algorithm | n_pop | total | evaluation | repair (+ shortcut) | other operators | duplicate elimination "
          "| survival | other |")
    print("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|")
    for r in rows:
        total = r["ms_per_gen"]
        cells = [f"{r[p + '_ms']:.2f} ({100 * r[p + '_ms'] / total:.0f} %)" for p in PARTS]
        print(f"| {r['map']} | {r['algorithm']} | {r['n']} | {total:.2f} | " + " | ".join(cells) + " |")
    print()


def quality(seeds: int, max_gen: int, jobs: int, methods: list[str]) -> list[dict]:
    def report(done, total, note):
        print(f"  [{done}/{total}] {note}", file=sys.stderr, flush=True)

    records = []
    for method in methods:
        run = run_table4(ENVIRONMENTS, [50], range(seeds), max_gen=max_gen, method=method,
                         executor="serial" if jobs == 1 else "processes", workers=None if jobs == 1 else jobs,
                         progress=report)
        records += run.records
    return records


def print_quality(records: list[dict], seeds: int, max_gen: int) -> None:
    print(f"## Quality: plan_ga, n_pop = 50, {seeds} seeds per environment, max_gen {max_gen}, patience 100\n")
    print("| environment | method | reached | reach gen | terminate gen | run time (s) | exact optimum "
          "| best GA time | gap mean | gap max | output plan time |")
    print("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|")

    def gap(v):
        return "–" if v is None else f"{100 * v:.1f} %"

    for row in summarise(records):
        lo, hi = row["exact_time_min"], row["exact_time_max"]
        exact = "–" if lo is None else (f"{lo:g}" if lo == hi else f"{lo:g}–{hi:g}")
        print(f"| {row['scenario']} | {row['method']} | {row['reached']}/{row['runs']} "
              f"| {format_mean_std(row['reach_generation_mean'], row['reach_generation_std'], digits=1)} "
              f"| {format_mean_std(row['terminate_generation_mean'], row['terminate_generation_std'], digits=1)} "
              f"| {format_mean_std(row['terminate_time_s_mean'], row['terminate_time_s_std'], digits=1)} "
              f"| {exact} | {format_mean_std(row['best_time_mean'], row['best_time_std'], digits=1)} "
              f"| {gap(row['best_gap_mean'])} | {gap(row['best_gap_max'])} "
              f"| {'–' if row['time_mean'] is None else format(row['time_mean'], '.1f')} |")
    print()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer seeds and a smaller quality budget")
    parser.add_argument("--parts", default="timing,split,quality", help="comma-separated: timing, split, quality")
    parser.add_argument("--repeat", type=int, help="seeds per timing cell (default 3, quick 1)")
    parser.add_argument("--jobs", type=int, default=1, help="processes for the quality runs (default 1)")
    parser.add_argument("--methods", default="htetro-ga,htetro-ga-paper",
                        help="comma-separated methods for the quality runs (default htetro-ga,htetro-ga-paper)")
    args = parser.parse_args()
    parts = {p.strip() for p in args.parts.split(",") if p.strip()}
    unknown = parts - {"timing", "split", "quality"}
    if unknown:
        parser.error(f"unknown parts: {', '.join(sorted(unknown))}")
    repeat = args.repeat or (1 if args.quick else 3)
    print(f"Python {platform.python_version()}, numpy {np.__version__}, pymoo {pymoo.__version__}, "
          f"{platform.machine()}, mode {'quick' if args.quick else 'full'}\n")
    if "timing" in parts:
        print_timing(timing(repeat, split=False))
    if "split" in parts:
        print_split(timing(repeat, split=True))
    if "quality" in parts:
        seeds, max_gen = (2, 300) if args.quick else (10, 1000)
        methods = [m.strip() for m in args.methods.split(",") if m.strip()]
        print_quality(quality(seeds, max_gen, args.jobs, methods), seeds, max_gen)


if __name__ == "__main__":
    main()
