"""Speed and quality of Cheng et al. 2020's GA (hTetro-GA), beside pymoo's NSGA-II.

1. Per-generation time: ``minimize(problem, HTetroGA(pop_size=n), ("n_gen", 200), seed=s)`` on the
   24 x 24 maps three_slit and random, n_pop = 50 and 100, beside ``HTetroGA.as_published(n)`` (the
   paper's algorithm without our additions), ``make_algorithm("nsga2", n)`` (pymoo's NSGA-II with the
   same sampling, crossover, mutation, repair and duplicate elimination) and, the baseline of the
   ratio column and of the target, a bare pymoo NSGA-II (its own operators) on pymoo's DTLZ2 with
   four objectives (a trivial vectorised problem), all in one process, seed by seed in turn. CPU (and
   wall) time over the whole run, initial population included, / generations, less the hTetro-GA's
   balanced polish, which runs once when the run ends (not in a generation): its CPU per run is a
   column of its own. hTetro-GA evaluates
   two offspring sets per generation (conservative + non-conservative, up to 2 n_pop new
   individuals), NSGA-II one (n_pop): the evaluated-individuals column says how many.
   Target (issue 15): an hTetro-GA generation at n_pop 100 costs no more CPU than the baseline's.
2. Per-generation split of the same runs, measured by wrapping each part's entry point: the
   simulation (hTetro-GA's one simulation that repairs, shortcuts and scores the offspring, the
   evaluation of the re-planned ones and of the initial population; pymoo's algorithms' repair and
   evaluation), the re-planning step, the other operators (sampling, tournament selection, crossover,
   mutation, removal, rearrangement), duplicate elimination, survival (the non-dominated sort), and
   the rest (pymoo's population bookkeeping, chromosome trimming, the evaluator and termination).
3. Quality: ``plan_ga`` (n_pop = 50) a few seeds per environment of Table 4, with the reach rate,
   the generations, the best time in the final leading front against the exact minimum-time plan, and
   the gap (via :func:`htetro_opt.studies.table4.run_trial`), for each method of ``--methods``.

4. Termination: the default hTetro-GA (n_pop 50) on the first leg of the six Table 4 maps, each run ended
   by today's rule (:class:`~htetro_opt.algorithms.FrontConvergence`, ``"best"``, patience 100) with
   every generation's population recorded, and each candidate rule (``"hypervolume"`` patiences,
   :class:`~htetro_opt.algorithms.termination.HypervolumeWindow` settings) replayed on the record:
   generations, the fastest member's time and the reaching front's hypervolume
   (:func:`~htetro_opt.algorithms.reaching_hypervolume`) where it stops, against today's. Target
   (issue 15): ≥ 2× shorter, no best-time loss, ≤ 1 % hypervolume loss.
5. Diversity (not run by default): ``HTetroGA(reach_share=...)``, the goal-reaching section capped
   at a share of the population, on three_slit, h_shape, random and parallel_dynamic, with and without
   re-planning.
6. Moving obstacles (not run by default): the default hTetro-GA's re-planning step with its
   time-expanded search, with the static-only search (``timed=False``) and without re-planning, on
   parallel_dynamic's leg, n_pop 50, a fixed number of generations (300; quick 100), seeds 0-2, side
   by side in one process: CPU per run and the fastest goal-reaching member's gap to the exact optimum.
7. Routes (not run by default): the route classes among the goal-reaching members of the default
   hTetro-GA's population, generation by generation (400 generations, n_pop 50, seeds 0-4; quick 2),
   with and without ``reach_share=0.75``: on three_slit the slit B2 passes (the rows where it is in
   the wall's columns x = 11, 12), on h_shape the side of the middle block it goes round (B2 left of
   x = 6 or right of x = 17). Reported: the route of the fastest member at the first reaching
   generation and at the end, the routes left at the end, and the generations holding two or more.

8. Balanced pick against the exact optimum of its objective (not run by default; deterministic, a minute):
   on each map of the ga_replan study (htetro_opt/studies/data/ga_replan.toml), leg by leg, the plan
   that maximises the fitness sum f_gr + f_t + f_sm + f_sf exactly
   (:func:`~htetro_opt.solvers.grid_paths.plan_max_fitness_sum`, l_p,max the GA's default per leg,
   each leg from where the previous one's max-sum plan ended) beside the exact minimum time T*
   (:func:`~htetro_opt.solvers.grid_paths.plan_exact`): its sum S*, time, gap to T*, fitnesses and
   CPU. Then the study's committed records (``--records``, default
   benchmarks/results/ga_replan/ga_replan.jsonl, read when the part runs): each run's picked
   (balanced) plan of the hTetro-GA and of the paper's, cut into legs where it first reaches each
   leg's goal, re-scored by the leg's own problem (the run's t0 and l_p,max) and compared with the
   exact maximum at that t0: its shortfall to S*, and how many runs are within 10 % of T* beside
   whether the max-sum chain itself is (when it is not, "balanced within 10 %" is unattainable on
   that map under the paper's objective). Saved as benchmarks/results/ga_replan/balanced_exact.md.

Run:  python benchmarks/bench_ga.py [--quick] [--parts timing,split,termination,diversity,moving,routes,quality,balanced]
                                    [--repeat N] [--jobs N] [--methods htetro-ga,htetro-ga-paper] [--records PATH]

--quick: 1 seed per timing cell, 2 termination and diversity seeds, and quality with 2 seeds and max_gen 300 (full:
3 timing seeds, 5 termination and diversity seeds, 10 quality seeds, max_gen 1000).
"""

from __future__ import annotations

import argparse
import datetime
import json
import os
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
from htetro_opt.model import SEED000_COMMANDS, Simulator, parse_commands
from htetro_opt.operators.commands import sequences
from htetro_opt.problems import CommandPathProblem
from htetro_opt.scenarios import load_scenario
from htetro_opt.solvers.grid_paths import plan_exact, plan_max_fitness_sum
from htetro_opt.studies.metrics import format_mean_std
from htetro_opt.studies.table4 import ENVIRONMENTS, run_table4, summarise

TIMING_MAPS = ("three_slit", "random")
POP_SIZES = (50, 100)
N_GEN = 200
BASELINE = "nsga2-dtlz2"  # pymoo's NSGA-II on DTLZ2 with 4 objectives: issue 15's yardstick
TIMED = ("htetro-ga", "htetro-ga-paper", "nsga2", BASELINE)
PARTS = ("simulation", "replan", "operators", "duplicates", "survival", "other")


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

    def wrap(self, obj, attr: str, bucket) -> None:
        """Time ``obj.attr`` (a bound method, or a module's function) into ``bucket`` (a name, or a
        function of the call's arguments giving one); restored by :meth:`restore` when it was a
        module attribute."""
        inner = getattr(obj, attr, None)
        if inner is None:
            return

        def timed(*args, **kwargs):
            if self.depth:
                return inner(*args, **kwargs)
            self.depth += 1
            began = time.process_time()  # CPU: the machine is shared, and wall time follows its load
            try:
                return inner(*args, **kwargs)
            finally:
                self.seconds[bucket(*args, **kwargs) if callable(bucket) else bucket] += time.process_time() - began
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


def _baseline_problem():
    from pymoo.problems import get_problem

    return get_problem("dtlz2", n_obj=4)


def run_once(name: str, kind: str, n: int, seed: int, *, split: bool) -> dict:
    """One ``minimize`` run of N_GEN generations; with ``split`` the parts are timed too.

    The parts are found by name: in :mod:`htetro_opt.algorithms.htetro_ga` the functions the
    hTetro-GA calls (``repair_shortcut_evaluate``, ``apply_mutation`` and ``apply_crossover``,
    ``first_keys``) and its survival's ``sort``; the problem's ``simulate`` and ``_evaluate``; for
    pymoo's algorithms each operator's ``do``, the repair's, the duplicate elimination's and the
    survival's. A name that an algorithm does not have is not timed (its time counts as other).
    """
    baseline = kind == BASELINE
    if baseline:
        from pymoo.algorithms.moo.nsga2 import NSGA2

        problem, algorithm = _baseline_problem(), NSGA2(pop_size=n)
    else:
        problem, algorithm = _problem(name), make_algorithm(kind, n)
    clock = _Clock()
    clock.count_evaluations(problem)  # cheap: a few calls per generation
    if split:
        clock.wrap(problem, "_evaluate", "simulation")
        if not baseline:
            clock.wrap(problem, "simulate", "simulation")
        mating = algorithm.mating
        for op in [algorithm.initialization.sampling, mating.selection, mating.crossover, mating.mutation]:
            clock.wrap(op, "do", "operators")
        clock.wrap(algorithm.repair, "do", "simulation")  # pymoo's algorithms repair in their mating loop
        clock.wrap(algorithm.eliminate_duplicates, "do", "duplicates")
        clock.wrap(algorithm.survival, "do", "survival")
        if isinstance(algorithm, HTetroGA):
            replan = algorithm.replan

            def operator_bucket(operator, *args, **kwargs):
                return "replan" if replan is not None and operator is replan else "operators"

            clock.wrap(htetro_ga_module, "repair_shortcut_evaluate", "simulation")
            # the Population-based loop before the array loop (to time an older tree with this script)
            clock.wrap(htetro_ga_module, "repair_and_shortcut", "simulation")
            clock.wrap(htetro_ga_module, "first_occurrences", "duplicates")
            for op in (algorithm.removal, algorithm.rearrangement):
                clock.wrap(op, "do", "operators")
            if replan is not None:
                clock.wrap(replan, "do", "replan")
            clock.wrap(htetro_ga_module, "apply_mutation", operator_bucket)
            clock.wrap(htetro_ga_module, "apply_crossover", "operators")
            clock.wrap(htetro_ga_module, "first_keys", "duplicates")
            clock.wrap(algorithm.survival, "sort", "survival")
    if isinstance(algorithm, HTetroGA):
        # the once-per-run balanced polish, timed apart from the generations (its simulations inside it,
        # the outermost timed call counting alone)
        clock.wrap(algorithm, "_polish", "polish")
    counter = _Counter()
    try:
        began, cpu_began = time.perf_counter(), time.process_time()
        res = minimize(problem, algorithm, ("n_gen", N_GEN), seed=seed, callback=counter, copy_algorithm=False)
        total, cpu = time.perf_counter() - began, time.process_time() - cpu_began
    finally:
        clock.restore()
    gens = counter.generations
    polished = clock.seconds["polish"]
    cpu -= polished
    total -= polished  # the polish is CPU-bound: its wall time is about its CPU time
    F = res.pop.get("F")
    out = {
        "map": "dtlz2" if baseline else name, "algorithm": kind, "n": n, "seed": seed, "generations": gens,
        "ms_per_gen": 1e3 * total / gens,
        "cpu_ms_per_gen": 1e3 * cpu / gens,
        "evaluated_per_gen": res.algorithm.evaluator.n_eval / gens,
        "polish_ms": 1e3 * polished,
        "reached": bool(not baseline and (F[:, 0] == -1.0).any()),
    }
    if split:
        known = sum(clock.seconds[p] for p in PARTS if p != "other")
        out.update({f"{p}_ms": 1e3 * clock.seconds[p] / gens for p in PARTS if p != "other"})
        out["other_ms"] = 1e3 * (cpu - known) / gens
    return out


def timing(repeat: int, *, split: bool) -> list[dict]:
    """Every timed cell, seed by seed in turn (so that a change of the machine's load during the run
    touches every algorithm alike); the median over the seeds."""
    for name in TIMING_MAPS:
        problem = _problem(name)  # compile the sweep tables once before timing
        problem.simulate([np.zeros(1, dtype=np.int64)] * 2, repair=np.random.default_rng(0))  # load the compiled loop
    runs: dict[tuple, list[dict]] = defaultdict(list)
    for seed in range(repeat):
        for n in POP_SIZES:
            for name in TIMING_MAPS:
                for kind in TIMED:
                    if kind == BASELINE and name != TIMING_MAPS[0]:
                        continue  # the baseline has no map: once per n_pop and seed
                    r = run_once(name, kind, n, seed, split=split)
                    runs[(r["map"], kind, n)].append(r)
                    print(f"  seed {seed} {r['map']} {kind} n={n}: {r['ms_per_gen']:.1f} ms/gen wall, "
                          f"{r['cpu_ms_per_gen']:.1f} CPU", file=sys.stderr, flush=True)
    rows = []
    for (name, kind, n), cell in runs.items():
        row = {"map": name, "algorithm": kind, "n": n, "runs": len(cell)}
        for key in cell[0]:
            if key.endswith("_ms") or key in ("ms_per_gen", "cpu_ms_per_gen", "evaluated_per_gen", "polish_ms"):
                row[key] = statistics.median(r[key] for r in cell)
        row["reached"] = sum(r["reached"] for r in cell)
        rows.append(row)
    return rows


def print_timing(rows: list[dict]) -> None:
    print(f"## Per-generation time ({N_GEN} generations, median of {rows[0]['runs']} seeds)\n")
    print("| map | n_pop | algorithm | ms/gen CPU | ms/gen wall | evaluated/gen | CPU µs per evaluated individual "
          f"| CPU / {BASELINE} | polish ms per run |")
    print("|---|---:|---|---:|---:|---:|---:|---:|---:|")
    by = {(r["map"], r["algorithm"], r["n"]): r for r in rows}
    for n in POP_SIZES:
        base = by[("dtlz2", BASELINE, n)]
        for name in TIMING_MAPS + ("dtlz2",):
            for kind in TIMED:
                if (name, kind, n) not in by:
                    continue
                r = by[(name, kind, n)]
                print(f"| {name} | {n} | {kind} | {r['cpu_ms_per_gen']:.1f} | {r['ms_per_gen']:.1f} "
                      f"| {r['evaluated_per_gen']:.0f} | {1e3 * r['cpu_ms_per_gen'] / r['evaluated_per_gen']:.0f} "
                      f"| {r['cpu_ms_per_gen'] / base['cpu_ms_per_gen']:.2f}× | {r['polish_ms']:.0f} |")
    base = by[("dtlz2", BASELINE, 100)]["cpu_ms_per_gen"]
    for kind in ("htetro-ga", "htetro-ga-paper"):
        worst = max(by[(m, kind, 100)]["cpu_ms_per_gen"] for m in TIMING_MAPS)
        print(f"\nTarget (issue 15): {kind} at n_pop = 100 costs no more CPU per generation than {BASELINE} "
              f"({base:.1f} ms): {'met' if worst <= base else 'NOT met'} (worst map {worst:.1f} ms, {worst / base:.2f}×).")
    print()


def print_split(rows: list[dict]) -> None:
    print(f"## Per-generation split ({N_GEN} generations, median of {rows[0]['runs']} seeds, ms of CPU per generation)\n")
    print("| map | algorithm | n_pop | total | simulation | re-planning | other operators | duplicate elimination "
          "| survival | other |")
    print("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|")
    for r in rows:
        total = r["cpu_ms_per_gen"]
        cells = [f"{r[p + '_ms']:.2f} ({100 * r[p + '_ms'] / total:.0f} %)" for p in PARTS]
        print(f"| {r['map']} | {r['algorithm']} | {r['n']} | {total:.2f} | " + " | ".join(cells) + " |")
    print()


TERMINATION_MAPS = ("three_slit", "h_shape", "random", "parallel_dynamic")  # also the diversity part's
REPLAY_MAPS = ENVIRONMENTS  # the termination part's: the six seed-000 maps of Table 4
TERMINATION_MAX_LENGTH = {"spiral": 200}  # l_p,max as plan_ga picks it: the paper's 200 on the spiral, else 100


def termination_rules() -> dict:
    """The terminations replayed on the recorded runs, by label (fresh objects on each call)."""
    from htetro_opt.algorithms import FrontConvergence
    from htetro_opt.algorithms.termination import HypervolumeWindow

    rules = {"best, patience 100 (today)": lambda: FrontConvergence()}
    for patience in (20, 30, 40, 60):
        rules[f"hypervolume, patience {patience}"] = lambda p=patience: FrontConvergence(patience=p, measure="hypervolume")
    for window, tolerance in ((40, 1e-3), (60, 1e-3), (100, 5e-3), (100, 1e-3), (150, 5e-3)):
        rules[f"HV window {window}, tol {tolerance:g}"] = lambda w=window, t=tolerance: HypervolumeWindow(window=w, tolerance=t)
    return rules


class _Populations(Callback):
    """Each generation's objectives: every termination only reads them, so a rule's stop is
    replayed exactly on the longer run (the search does not depend on the termination)."""

    def __init__(self) -> None:
        super().__init__()
        self.F: list[np.ndarray] = []

    def notify(self, algorithm) -> None:
        self.F.append(np.array(algorithm.pop.get("F"), dtype=float))


def _replay(rule, populations: list[np.ndarray]) -> int:
    """The generation (1-based) at which ``rule`` stops the recorded run, or its length if never."""
    from pymoo.core.population import Population

    for gen, F in enumerate(populations, start=1):
        state = types.SimpleNamespace(pop=Population.new("F", F), n_gen=gen, data={})
        rule.update(state)
        if rule.has_terminated():
            return gen
    return len(populations)


def termination(seeds: int) -> list[dict]:
    """The default hTetro-GA (n_pop 50, max_gen 1000) on each map's first leg under today's termination
    (``FrontConvergence()``), every generation's population recorded; each rule of
    :func:`termination_rules` replayed on the record: where it stops, the fastest reaching member's
    time and the reaching front's hypervolume there."""
    from htetro_opt.algorithms import FrontConvergence, reaching_hypervolume
    from htetro_opt.operators.commands.survival import reaches_goal

    records = []
    for seed in range(seeds):
        for name in REPLAY_MAPS:
            scenario = load_scenario(name)
            sim = Simulator(scenario.workspace, commands=SEED000_COMMANDS)
            problem = CommandPathProblem(sim, scenario.roadmap[0], scenario.roadmap[1],
                                         max_length=TERMINATION_MAX_LENGTH.get(name, 100))
            recorder = _Populations()
            began = time.process_time()
            minimize(problem, make_algorithm("htetro-ga", 50), FrontConvergence(), seed=seed, callback=recorder)
            cpu = time.process_time() - began
            populations = recorder.F
            for label, make in termination_rules().items():
                stop = _replay(make(), populations)
                F = populations[stop - 1]
                reached = reaches_goal(F)
                records.append({"map": name, "seed": seed, "rule": label, "generations": stop,
                                "best_time": float((-F[reached, 1]).max()) if reached.any() else -np.inf,
                                "hv": reaching_hypervolume(F), "cpu_s": cpu * stop / len(populations)})
            # the replay of today's rule must end where the run ended: the record is the run
            assert records[-len(termination_rules())]["generations"] == len(populations)
            hv = np.array([reaching_hypervolume(F) for F in populations])
            # not a rule: the first generation within 1 % of the run's final hypervolume (knows the future)
            bound = int(np.argmax(hv >= 0.99 * hv[-1])) + 1
            F = populations[bound - 1]
            records.append({"map": name, "seed": seed, "rule": "bound: first within 1 % of final HV",
                            "generations": bound, "best_time": float((-F[reaches_goal(F), 1]).max()),
                            "hv": float(hv[bound - 1]),
                            "cpu_s": cpu * bound / len(populations)})
            print(f"  {name} seed {seed}: {len(populations)} generations, {cpu:.1f} s, HV {hv[-1]:.4f}",
                  file=sys.stderr, flush=True)
    return records


def print_termination(records: list[dict], seeds: int) -> None:
    print(f"## Termination: rules replayed on the default hTetro-GA's runs, {len(REPLAY_MAPS)} maps x {seeds} "
          "seeds (first leg, n_pop 50)\n")
    print("Each run ends by today's rule; every rule is replayed on its recorded populations (exact: the "
          "termination does not steer the search). Against today's: generations, fastest time, HV.\n")
    print("| rule | generations | shorter | best time: worse runs | HV loss mean | HV loss max | runs > 1 % |")
    print("|---|---:|---:|---:|---:|---:|---:|")
    by = {(r["map"], r["seed"], r["rule"]): r for r in records}
    today = "best, patience 100 (today)"
    for label in dict.fromkeys(r["rule"] for r in records):
        pairs = [(by[(m, s, today)], by[(m, s, label)]) for m in REPLAY_MAPS for s in range(seeds)]
        g0, g1 = sum(a["generations"] for a, _ in pairs), sum(b["generations"] for _, b in pairs)
        worse = sum(b["best_time"] < a["best_time"] - 1e-9 for a, b in pairs)  # f_t: higher is faster
        losses = np.array([max(0.0, (a["hv"] - b["hv"]) / a["hv"]) for a, b in pairs if a["hv"] > 0])
        print(f"| {label} | {g0} → {g1} | {g0 / g1:.2f}× | {worse} of {len(pairs)} | {100 * losses.mean():.2f} % "
              f"| {100 * losses.max():.2f} % | {int((losses > 0.01).sum())} |")
    print()


def diversity(seeds: int, windows=(40, 0), shares=(1.0, 0.75)) -> list[dict]:
    """The reaching share (``HTetroGA(reach_share=...)``): one leg per map (n_pop 50, l_p,max 100,
    ``FrontConvergence()``), the fastest and the balanced member of the final population against the
    exact optimum, with and without re-planning."""
    from pymoo.optimize import minimize as run

    from htetro_opt.algorithms import FrontConvergence, select_solutions

    records = []
    for name in TERMINATION_MAPS:
        problem = _problem(name)
        exact = plan_exact(problem.simulator, [problem.start, problem.goal]).time
        for seed in range(seeds):
            leg_seed = int(np.random.SeedSequence(seed).generate_state(1)[0])  # as plan_ga's first leg
            for window in windows:
                for share in shares:
                    began = time.process_time()
                    res = run(problem, HTetroGA(50, replan_window=window, reach_share=share), FrontConvergence(),
                              seed=leg_seed)
                    F, times = res.pop.get("F"), res.pop.get("time")
                    reached = res.pop.get("reached").astype(bool)
                    records.append({"map": name, "seed": seed, "W": window, "share": share, "exact": exact,
                                    "fastest": float(times[reached].min()) if reached.any() else float("nan"),
                                    "balanced": float(times[select_solutions(F)["multi_objective"]]),
                                    "generations": res.algorithm.n_gen, "cpu_s": time.process_time() - began})
                    print(f"  {name} seed {seed} W={window} share={share}: fastest {records[-1]['fastest']:g} "
                          f"(exact {exact:g})", file=sys.stderr, flush=True)
    return records


def print_diversity(records: list[dict], seeds: int) -> None:
    print(f"## Reaching share: {len(TERMINATION_MAPS)} maps x {seeds} seeds, n_pop 50, gap to the exact optimum\n")
    print("| map | W | reach share | fastest gap % mean / max | > 3 % | balanced gap % mean / max | generations | CPU s |")
    print("|---|---:|---:|---|---:|---|---:|---:|")
    cells = defaultdict(list)
    for r in records:
        cells[(r["map"], r["W"], r["share"])].append(r)
    for (name, window, share), cell in cells.items():
        fastest = np.array([100 * (r["fastest"] - r["exact"]) / r["exact"] for r in cell])
        balanced = np.array([100 * (r["balanced"] - r["exact"]) / r["exact"] for r in cell])
        print(f"| {name} | {window} | {share:g} | {np.nanmean(fastest):.1f} / {np.nanmax(fastest):.1f} "
              f"| {int((fastest > 3).sum())} of {len(cell)} | {np.nanmean(balanced):.1f} / {np.nanmax(balanced):.1f} "
              f"| {np.mean([r['generations'] for r in cell]):.0f} | {np.mean([r['cpu_s'] for r in cell]):.1f} |")
    print()


MOVING_VARIANTS = ("time-expanded", "static-only", "off")


def moving(generations: int, seeds: int = 3) -> list[dict]:
    """Part 6: the re-planning step's searches on parallel_dynamic, side by side, seed by seed."""
    scenario = load_scenario("parallel_dynamic")
    sim = Simulator(scenario.workspace, commands=SEED000_COMMANDS)
    exact = plan_exact(sim, scenario.roadmap[:2]).time
    records = []
    for seed in range(seeds):
        for variant in MOVING_VARIANTS:
            problem = CommandPathProblem(sim, scenario.start, scenario.roadmap[1], max_length=100)
            algorithm = HTetroGA(50, replan_window=0 if variant == "off" else 40)
            if variant == "static-only":
                algorithm.replan.timed = False
            began = time.process_time()
            res = minimize(problem, algorithm, ("n_gen", generations), seed=seed)
            cpu = time.process_time() - began
            times, reached = res.pop.get("time"), res.pop.get("reached").astype(bool)
            records.append({"seed": seed, "variant": variant, "exact": exact, "cpu_s": cpu,
                            "fastest": float(times[reached].min()) if reached.any() else float("nan")})
            print(f"  parallel_dynamic seed {seed} {variant}: fastest {records[-1]['fastest']:g} (exact {exact:g}), "
                  f"{cpu:.1f} s", file=sys.stderr, flush=True)
    return records


def print_moving(records: list[dict], generations: int) -> None:
    print(f"## Re-planning on parallel_dynamic: n_pop 50, {generations} generations, CPU per run\n")
    print("| re-planning | fastest gap % per seed | CPU s mean | CPU ratio to no re-planning |")
    print("|---|---|---:|---:|")
    cpu = {v: np.mean([r["cpu_s"] for r in records if r["variant"] == v]) for v in MOVING_VARIANTS}
    for v in MOVING_VARIANTS:
        gaps = [100 * (r["fastest"] - r["exact"]) / r["exact"] for r in records if r["variant"] == v]
        print(f"| {v} | {', '.join(f'{g:.1f}' for g in gaps)} | {cpu[v]:.1f} | {cpu[v] / cpu['off']:.2f} |")
    print()


def route_class(name: str, poses: np.ndarray) -> str:
    """Part 7's route of a path (its poses, (x, y, state, heading) rows)."""
    x, y = poses[:, 0], poses[:, 1]
    if name == "three_slit":
        return "slit y=" + "+".join(str(v) for v in sorted(set(y[(x == 11) | (x == 12)].tolist())))
    return "+".join(side for side, hit in (("left", (x < 6).any()), ("right", (x > 17).any())) if hit) or "none"


class _Routes(Callback):
    """Each generation's routes of the goal-reaching members, with each route's fastest time."""

    def __init__(self, problem, name):
        super().__init__()
        self.problem, self.name, self.log = problem, name, []

    def notify(self, algorithm):
        result = self.problem.simulate(sequences(algorithm.pop.get("X")))
        routes = {}
        for i in np.flatnonzero(result.reached):
            route = route_class(self.name, result.poses(i))
            routes[route] = min(routes.get(route, np.inf), float(result.time[i]))
        self.log.append(routes)


def routes(seeds: int, generations: int = 400) -> list[dict]:
    """Part 7, seed by seed."""
    records = []
    for name in ("three_slit", "h_shape"):
        scenario = load_scenario(name)
        sim = Simulator(scenario.workspace, commands=SEED000_COMMANDS)
        for share in (1.0, 0.75):
            for seed in range(seeds):
                problem = CommandPathProblem(sim, scenario.start, scenario.roadmap[1], max_length=100)
                log = _Routes(problem, name)
                minimize(problem, HTetroGA(50, reach_share=share), ("n_gen", generations), seed=seed, callback=log)
                reaching = [r for r in log.log if r]
                first, last = reaching[0], log.log[-1]
                records.append({"map": name, "share": share, "seed": seed,
                                "first": min(first, key=first.get), "first_time": min(first.values()),
                                "last": min(last, key=last.get), "last_time": min(last.values()),
                                "routes": dict(sorted(last.items(), key=lambda kv: kv[1])),
                                "multi": sum(len(r) >= 2 for r in reaching), "reaching": len(reaching)})
                print(f"  {name} share {share} seed {seed}: {records[-1]}", file=sys.stderr, flush=True)
    return records


def print_routes(records: list[dict]) -> None:
    print("## Route classes of the goal-reaching members: n_pop 50, 400 generations\n")
    print("| map | reach share | seed | fastest at first reach | fastest at the end | routes at the end (fastest time) "
          "| generations with >= 2 routes / with a reaching member |")
    print("|---|---:|---:|---|---|---|---|")
    for r in records:
        left = ", ".join(f"{k} ({v:g})" for k, v in r["routes"].items())
        print(f"| {r['map']} | {r['share']:g} | {r['seed']} | {r['first']} ({r['first_time']:g}) "
              f"| {r['last']} ({r['last_time']:g}) | {left} | {r['multi']} / {r['reaching']} |")
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


BALANCED_MAPS = ("random", "spiral", "h_shape", "three_slit", "perpendicular_dynamic", "parallel_dynamic", "maze",
                 "zigzag")  # the ga_replan study's scenarios, in its order
BALANCED_METHODS = ("htetro-ga", "htetro-ga-paper")
GA_REPLAN_RECORDS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "results", "ga_replan", "ga_replan.jsonl")
WITHIN = 0.10  # issue 15's target for the balanced pick's gap


def _leg_cuts(sim: Simulator, commands: np.ndarray, roadmap) -> list[int] | None:
    """Where each leg of a chained plan ends: the first arrival on the leg's goal after the previous
    leg's end, as each leg's GA stopped its children (None if some goal is never reached)."""
    trace = sim.run([commands], roadmap[0]).trace[0]
    cuts, end = [], 0
    for goal in roadmap[1:]:
        hits = np.flatnonzero(trace[end + 1 :] == sim.encode(goal))
        if not len(hits):
            return None
        end = end + 1 + int(hits[0])
        cuts.append(end)
    return cuts


class _Oracle:
    """The exact max-sum plan of a leg at a start time, cached by the phase of the moving obstacles
    (the plan and the GA's default l_p,max depend on t0 only through it), with its CPU seconds."""

    def __init__(self, sim: Simulator, roadmap) -> None:
        self.sim, self.roadmap = sim, roadmap
        self.period = sim.workspace.period if sim.workspace.moving else 1
        self.cache: dict[tuple[int, int], tuple] = {}

    def __call__(self, leg: int, t0: int):
        key = (leg, t0 % self.period)
        if key not in self.cache:
            began = time.process_time()
            plan = plan_max_fitness_sum(self.sim, self.roadmap[leg], self.roadmap[leg + 1], t0=t0)
            self.cache[key] = (plan, time.process_time() - began)
        return self.cache[key]


def _leg_sum(sim: Simulator, start, goal, commands: np.ndarray, t0: int, max_length: int) -> float:
    """A leg's fitness sum as its GA scored it: the leg's problem at the run's t0 and l_p,max."""
    problem = CommandPathProblem(sim, start, goal, max_length=max_length, t0=t0)
    result = problem.simulate([commands])
    return float(problem.fitness(result)[0].sum())


CERTIFICATE_SCALES = (0.95, 0.9, 0.8, 0.7, 0.6, 0.5)  # t_max' / t_max tried by _within_bound


def _within_bound(sim: Simulator, start, goal, max_length: int, budget: float) -> tuple[float, int]:
    """An upper bound on the largest fitness sum among a leg's goal-reaching sequences of time at most
    ``budget``, and the l_p,max' that gives it (a Lagrangian certificate).

    With t_max' = l_p,max' x t_translation < t_max and μ = t_max / t_max' − 1, a sequence of time T
    sums, under t_max', its sum under t_max minus μ T / t_max; so every sequence with T <= budget sums
    at most S*(t_max') + μ budget / t_max under t_max, S*(t_max') being the exact maximum at t_max'."""
    best = (np.inf, max_length)
    t_max = max_length * sim.timing.translation
    for scale in CERTIFICATE_SCALES:
        shorter = max(1, round(scale * max_length))
        relaxed = plan_max_fitness_sum(sim, start, goal, max_length=shorter).info["fitness_sum"]
        bound = relaxed + (max_length / shorter - 1) * budget / t_max
        best = min(best, (bound, shorter))
    return best


def balanced(records_path: str) -> dict:
    """Part 8: per map, the chained exact max-sum plan beside T*, and the study's runs against it."""
    with open(records_path) as handle:
        records = [json.loads(line) for line in handle if line.strip()]
    stamp = datetime.datetime.fromtimestamp(os.path.getmtime(records_path), datetime.UTC)
    maps = []
    for name in BALANCED_MAPS:
        scenario = load_scenario(name)
        roadmap = list(scenario.roadmap)
        sim = Simulator(scenario.workspace, commands=SEED000_COMMANDS)
        reference = plan_exact(sim, roadmap).time
        oracle = _Oracle(sim, roadmap)
        legs, t0 = [], 0
        for leg in range(len(roadmap) - 1):  # the max-sum chain: each leg from where the previous one ended
            plan, cpu = oracle(leg, t0)
            exact = plan_exact(sim, roadmap[leg : leg + 2], t0=t0)
            legs.append({"leg": leg, "t0": t0, "plan": plan, "cpu_s": cpu,
                         "fastest_sum": _leg_sum(sim, roadmap[leg], roadmap[leg + 1], exact.commands, t0,
                                                 plan.info["max_length"])})
            t0 += len(plan.commands)
        chain_time = sum(leg["plan"].time for leg in legs)
        certificate = None
        if len(legs) == 1 and chain_time > (1 + WITHIN) * reference:  # is every max-sum plan slower? prove it
            certificate = _within_bound(sim, roadmap[0], roadmap[1], legs[0]["plan"].info["max_length"],
                                        (1 + WITHIN) * reference)
        runs = {}
        for method in BALANCED_METHODS:
            trials = [r for r in records if r.get("kind") == "trial" and r["scenario"] == name and r["method"] == method]
            rows = []
            for trial in trials:
                row = {"seed": trial["seed"], "reached": bool(trial["reached"]), "shortfalls": [], "sums": []}
                if row["reached"]:
                    commands = np.asarray(parse_commands(trial["commands"]), dtype=np.int64)
                    row["time"] = float(sim.run([commands], roadmap[0]).time[0])
                    cuts = _leg_cuts(sim, commands, roadmap)
                    for leg, (lo, hi) in enumerate(zip([0] + cuts[:-1], cuts)):
                        optimum = oracle(leg, lo)[0].info  # its max_length is the GA's default at this t0
                        picked = _leg_sum(sim, roadmap[leg], roadmap[leg + 1], commands[lo:hi], lo,
                                          optimum["max_length"])
                        row["sums"].append(picked)
                        row["shortfalls"].append(optimum["fitness_sum"] - picked)
                rows.append(row)
            runs[method] = rows
        maps.append({"name": name, "reference": reference, "legs": legs, "chain_time": chain_time, "runs": runs,
                     "certificate": certificate,
                     "oracle_cpu_s": sum(cpu for _, cpu in oracle.cache.values()), "oracles": len(oracle.cache)})
        print(f"  {name}: T* {reference:g}, max-sum chain {chain_time:g} ({len(oracle.cache)} exact max-sum "
              "plans)", file=sys.stderr, flush=True)
    return {"maps": maps, "records": records_path, "mtime": stamp, "n_records": len(records)}


def print_balanced(report: dict) -> None:
    today = datetime.date.today().isoformat()
    where = os.path.relpath(report["records"], os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    print(f"## The balanced pick against the exact maximum of its fitness sum ({today})\n")
    print(f"Produced by `python benchmarks/bench_ga.py --parts balanced` on {today}; the runs are the study records "
          f"`{where}` as they were when the part ran ({report['n_records']} records, modified "
          f"{report['mtime']:%Y-%m-%d %H:%M:%S} UTC). The exact max-sum plan is "
          "`plan_max_fitness_sum` (the largest f_gr + f_t + f_sm + f_sf over every goal-reaching command sequence, "
          "under the GA's own problem: child termination at the first arrival, t_max = l_p,max x 1 s with the GA's "
          "default l_p,max per leg), chained leg by leg; T* is `plan_exact`'s minimum time (per leg at that leg's "
          "start time; for the roadmap, the study's reference).\n")
    print("### Per leg: the exact max-sum plan\n")
    print("| map | leg | t0 | l_p,max | T* (s) | S* | time (s) | gap to T* | f_t | f_sm | f_sf | commands "
          "| sum of the fastest plan | lengths searched | CPU s |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for m in report["maps"]:
        for leg in m["legs"]:
            plan, info = leg["plan"], leg["plan"].info
            print(f"| {m['name']} | {leg['leg'] + 1} | {leg['t0']} | {info['max_length']} | {info['exact_time']:g} "
                  f"| {info['fitness_sum']:.4f} | {plan.time:g} | {100 * (plan.time / info['exact_time'] - 1):.1f} % "
                  f"| {info['f_t']:.3f} | {info['f_sm']:.3f} | {info['f_sf']:.3f} | {info['n_commands']} "
                  f"| {leg['fastest_sum']:.4f} | {info['lengths_searched']} | {leg['cpu_s']:.1f} |")
    print()
    print("### Per map: the study's balanced picks against it\n")
    print("Shortfall = S* at the leg's start time minus the picked leg's sum (each leg of each reaching run; "
          "never negative if the optimum is right). \"Within 10 %\": the picked plan's time at most 1.1 T* "
          "(the study's gap). \"Attainable\": whether the max-sum chain itself is within 10 % of T*. Where it is "
          "not, \"sum within 10 % at most\" is a Lagrangian upper bound on the largest sum of any plan of time "
          "<= 1.1 T* (S* at a shorter t_max' = l_p,max' x 1 s plus (t_max / t_max' - 1) x 1.1 T* / t_max, the "
          "least over l_p,max' = 0.5 to 0.95 l_p,max, the best l_p,max' in brackets): below S*, it proves that every "
          "plan of the largest sum is more than 10 % slower than T*, ties included, so a GA whose balanced pick is "
          "the exact optimum of its objective misses the target there.\n")
    print("| map | T* (s) | max-sum chain time (s) | its gap | attainable | sum within 10 % at most | method "
          "| runs reaching | within 10 % | picked sum mean | shortfall mean / max | picked gap mean / max |")
    print("|---|---:|---:|---:|:---:|---:|---|---:|---:|---:|---:|---:|")
    for m in report["maps"]:
        chain_gap = m["chain_time"] / m["reference"] - 1
        if m["certificate"] is None:
            bound = "–"
        else:
            value, shorter = m["certificate"]
            optimum = m["legs"][0]["plan"].info["fitness_sum"]
            bound = f"{value:.4f} ({shorter}; S* − {optimum - value:.4f})"
        for method, rows in m["runs"].items():
            reaching = [r for r in rows if r["reached"]]
            gaps = [r["time"] / m["reference"] - 1 for r in reaching]
            sums = [sum(r["sums"]) / len(r["sums"]) for r in reaching]
            shortfalls = [s for r in reaching for s in r["shortfalls"]]
            within = sum(g <= WITHIN + 1e-12 for g in gaps)
            cells = ("– | – | –" if not reaching else
                     f"{np.mean(sums):.4f} | {np.mean(shortfalls):.4f} / {np.max(shortfalls):.4f} "
                     f"| {100 * np.mean(gaps):.1f} % / {100 * np.max(gaps):.1f} %")
            print(f"| {m['name']} | {m['reference']:g} | {m['chain_time']:g} | {100 * chain_gap:.1f} % "
                  f"| {'yes' if chain_gap <= WITHIN + 1e-12 else '**no**'} | {bound} | {method} "
                  f"| {len(reaching)}/{len(rows)} "
                  f"| {within}/{len(rows)} | {cells} |")
    print()
    print("### The runs above 10 %\n")
    print("Each reaching run whose picked plan is more than 10 % slower than T*, with its fitness sum's shortfall to "
          "the exact maximum (summed over its legs).\n")
    print("| map | method | seed | time (s) | gap | picked sum | shortfall | max-sum chain within 10 % |")
    print("|---|---|---:|---:|---:|---:|---:|:---:|")
    for m in report["maps"]:
        attainable = m["chain_time"] <= (1 + WITHIN) * m["reference"] + 1e-9
        for method, rows in m["runs"].items():
            for r in rows:
                if r["reached"] and r["time"] > (1 + WITHIN) * m["reference"] + 1e-9:
                    print(f"| {m['name']} | {method} | {r['seed']} | {r['time']:g} "
                          f"| {100 * (r['time'] / m['reference'] - 1):.1f} % | {sum(r['sums']):.4f} "
                          f"| {sum(r['shortfalls']):.4f} | {'yes' if attainable else 'no'} |")
    print()
    total = sum(m["oracle_cpu_s"] for m in report["maps"])
    count = sum(m["oracles"] for m in report["maps"])
    print(f"{count} exact max-sum plans (one per leg and start-time phase met), {total:.1f} CPU s in all. Picked sums "
          "are means over a run's legs (one leg but on perpendicular_dynamic, three).\n")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer seeds and a smaller quality budget")
    parser.add_argument("--parts", default="timing,split,termination,quality",
                        help="comma-separated: timing, split, termination, diversity, moving, routes, quality, balanced")
    parser.add_argument("--repeat", type=int, help="seeds per timing cell (default 3, quick 1)")
    parser.add_argument("--jobs", type=int, default=1, help="processes for the quality runs (default 1)")
    parser.add_argument("--methods", default="htetro-ga,htetro-ga-paper",
                        help="comma-separated methods for the quality runs (default htetro-ga,htetro-ga-paper)")
    parser.add_argument("--records", default=GA_REPLAN_RECORDS,
                        help="the ga_replan study's records for the balanced part (default: the committed ones)")
    args = parser.parse_args()
    parts = {p.strip() for p in args.parts.split(",") if p.strip()}
    unknown = parts - {"timing", "split", "termination", "diversity", "moving", "routes", "quality", "balanced"}
    if unknown:
        parser.error(f"unknown parts: {', '.join(sorted(unknown))}")
    repeat = args.repeat or (1 if args.quick else 3)
    print(f"Python {platform.python_version()}, numpy {np.__version__}, pymoo {pymoo.__version__}, "
          f"{platform.machine()}, mode {'quick' if args.quick else 'full'}\n")
    if "timing" in parts:
        print_timing(timing(repeat, split=False))
    if "split" in parts:
        print_split(timing(repeat, split=True))
    if "termination" in parts:
        seeds = 2 if args.quick else 5
        print_termination(termination(seeds), seeds)
    if "diversity" in parts:
        seeds = 2 if args.quick else 5
        print_diversity(diversity(seeds), seeds)
    if "moving" in parts:
        generations = 100 if args.quick else 300
        print_moving(moving(generations), generations)
    if "routes" in parts:
        print_routes(routes(2 if args.quick else 5))
    if "quality" in parts:
        seeds, max_gen = (2, 300) if args.quick else (10, 1000)
        methods = [m.strip() for m in args.methods.split(",") if m.strip()]
        print_quality(quality(seeds, max_gen, args.jobs, methods), seeds, max_gen)
    if "balanced" in parts:
        print_balanced(balanced(args.records))


if __name__ == "__main__":
    main()
