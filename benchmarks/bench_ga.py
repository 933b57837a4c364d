"""Speed and quality of Cheng et al. 2020's GA (hTetro-GA), beside pymoo's NSGA-II.

1. Per-generation time: ``minimize(problem, HTetroGA(pop_size=n), ("n_gen", 200), seed=s)`` on the
   24 x 24 maps three_slit and random, n_pop = 50 and 100, beside ``HTetroGA.as_published(n)`` (the
   paper's algorithm without our additions), ``make_algorithm("nsga2", n)`` (pymoo's NSGA-II with the
   same sampling, crossover, mutation, repair and duplicate elimination) and, the baseline of the
   ratio column and of the target, a bare pymoo NSGA-II (its own operators) on pymoo's DTLZ2 with
   four objectives (a trivial vectorised problem), all in one process, seed by seed in turn. CPU (and
   wall) time over the whole run, initial population included, / generations. hTetro-GA evaluates
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

Run:  python benchmarks/bench_ga.py [--quick] [--parts timing,split,termination,diversity,moving,routes,quality] [--repeat N]
                                    [--jobs N] [--methods htetro-ga,htetro-ga-paper]

--quick: 1 seed per timing cell, 2 termination and diversity seeds, and quality with 2 seeds and max_gen 300 (full:
3 timing seeds, 5 termination and diversity seeds, 10 quality seeds, max_gen 1000).
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
from htetro_opt.operators.commands import sequences
from htetro_opt.problems import CommandPathProblem
from htetro_opt.scenarios import load_scenario
from htetro_opt.solvers.grid_paths import plan_exact
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
    counter = _Counter()
    try:
        began, cpu_began = time.perf_counter(), time.process_time()
        res = minimize(problem, algorithm, ("n_gen", N_GEN), seed=seed, callback=counter, copy_algorithm=False)
        total, cpu = time.perf_counter() - began, time.process_time() - cpu_began
    finally:
        clock.restore()
    gens = counter.generations
    F = res.pop.get("F")
    out = {
        "map": "dtlz2" if baseline else name, "algorithm": kind, "n": n, "seed": seed, "generations": gens,
        "ms_per_gen": 1e3 * total / gens,
        "cpu_ms_per_gen": 1e3 * cpu / gens,
        "evaluated_per_gen": res.algorithm.evaluator.n_eval / gens,
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
            if key.endswith("_ms") or key in ("ms_per_gen", "cpu_ms_per_gen", "evaluated_per_gen"):
                row[key] = statistics.median(r[key] for r in cell)
        row["reached"] = sum(r["reached"] for r in cell)
        rows.append(row)
    return rows


def print_timing(rows: list[dict]) -> None:
    print(f"## Per-generation time ({N_GEN} generations, median of {rows[0]['runs']} seeds)\n")
    print("| map | n_pop | algorithm | ms/gen CPU | ms/gen wall | evaluated/gen | CPU µs per evaluated individual "
          f"| CPU / {BASELINE} |")
    print("|---|---:|---|---:|---:|---:|---:|---:|")
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
                      f"| {r['cpu_ms_per_gen'] / base['cpu_ms_per_gen']:.2f}× |")
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


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer seeds and a smaller quality budget")
    parser.add_argument("--parts", default="timing,split,termination,quality",
                        help="comma-separated: timing, split, termination, diversity, moving, routes, quality")
    parser.add_argument("--repeat", type=int, help="seeds per timing cell (default 3, quick 1)")
    parser.add_argument("--jobs", type=int, default=1, help="processes for the quality runs (default 1)")
    parser.add_argument("--methods", default="htetro-ga,htetro-ga-paper",
                        help="comma-separated methods for the quality runs (default htetro-ga,htetro-ga-paper)")
    args = parser.parse_args()
    parts = {p.strip() for p in args.parts.split(",") if p.strip()}
    unknown = parts - {"timing", "split", "termination", "diversity", "moving", "routes", "quality"}
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


if __name__ == "__main__":
    main()
