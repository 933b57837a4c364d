"""htetro-ga-paper is Cheng et al. 2020's hTetro-GA and nothing of ours: spies prove that no addition's code
runs in the paper mode and that each addition, switched on alone, runs (and only it); the paper's defaults,
its two-section sort and the refusal of our options that are not additions."""

from __future__ import annotations

import json

import numpy as np
import pytest
from pymoo.core.population import Population
from pymoo.core.problem import Problem

from htetro_opt.algorithms import GA_ADDITIONS, make_algorithm
from htetro_opt.algorithms import htetro_ga as htetro_ga_module
from htetro_opt.errors import ParameterError
from htetro_opt.model import Pose, Simulator, Workspace, parse_commands
from htetro_opt.model.commands import SEED000_COMMANDS
from htetro_opt.operators import GoalReachabilitySurvival, as_column
from htetro_opt.operators.commands import crossover as crossover_module
from htetro_opt.operators.commands import shortcut as shortcut_module
from htetro_opt.operators.commands import survival as survival_module
from htetro_opt.operators.commands.replan import CommandReachRepair, CommandReplan
from htetro_opt.problems import CommandPathProblem
from htetro_opt.scenarios import load_scenario
from htetro_opt.solvers.grid_paths import plan_ga, plan_path
from htetro_opt.solvers.grid_paths._spec import PAPER_MAX_LENGTH, PAPER_PATIENCE, SPEC


def bordered(width=12, height=12):
    occ = np.zeros((height, width), dtype=bool)
    occ[0, :] = occ[-1, :] = occ[:, 0] = occ[:, -1] = True
    return occ


OPEN = Workspace(bordered())
START, GOAL = Pose(3, 3, "O", 0), Pose(7, 6, "O", 0)
_walled = bordered()
_walled[:, 6] = True  # no way across: no member ever reaches, the reach repair's case
WALLED = Workspace(_walled)
RUN = {"pop_size": 12, "max_gen": 25, "max_length": 20, "seed": 1}


@pytest.fixture
def spies(monkeypatch):
    """Each addition's code, wrapped to count its calls (the original still runs)."""
    calls = {name: 0 for name in GA_ADDITIONS}

    def spy(owner, attribute, addition, *, when=lambda *a, **k: True):
        original = getattr(owner, attribute)

        def wrapper(*args, **kwargs):
            if when(*args, **kwargs):
                calls[addition] += 1
            return original(*args, **kwargs)

        monkeypatch.setattr(owner, attribute, wrapper)

    # repair: the simulation that replaces invalid commands (a generator passed as ``repair``)
    spy(CommandPathProblem, "simulate", "repair", when=lambda *a, **k: k.get("repair") is not None)
    spy(shortcut_module, "loop_cuts", "shortcut")
    spy(survival_module, "reachability_levels", "reach-levels")
    spy(survival_module, "niche_excess", "niching")
    spy(crossover_module, "cap_genes", "gene-cap")
    spy(CommandReplan, "_do", "replanning")
    spy(CommandReachRepair, "_do", "reach-repair")
    spy(htetro_ga_module, "polish_sum", "polish")
    return calls


def _run(workspace, method="htetro-ga-paper", **options):
    return plan_path(workspace, [START, GOAL], method=method, **{**RUN, **options})


def test_the_paper_mode_never_calls_an_addition(spies):
    reached = _run(OPEN)
    assert reached.reached and reached.as_dict()["additions"] == []
    stalled = _run(WALLED, max_gen=40)  # longer than any reach patience below: nothing may fire
    assert not stalled.reached and not stalled.success
    assert spies == dict.fromkeys(GA_ADDITIONS, 0)
    check = Simulator(OPEN, commands=SEED000_COMMANDS).run([reached.commands], START, roadmap=[GOAL])
    assert check.valid[0] and check.reached[0] and check.time[0] == reached.time  # the plan re-validates


@pytest.mark.parametrize("addition", list(GA_ADDITIONS))
def test_each_addition_switched_on_alone_runs_and_no_other(spies, addition):
    parameters = {"reach-repair": {"reach_patience": 2}}.get(addition, {})
    workspace = WALLED if addition == "reach-repair" else OPEN  # the reach repair fires only in a stalled run
    plan = _run(workspace, additions=[addition], **parameters)
    assert plan.as_dict()["additions"] == [addition]
    assert spies[addition] > 0
    assert {name: n for name, n in spies.items() if n} == {addition: spies[addition]}


def test_the_paper_mode_on_the_command_line_has_no_additions_and_revalidates(capsys):
    from htetro_opt.cli import main

    assert main(["plan", "three_slit", "--method", "htetro-ga-paper", "--json", "--quiet"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["method"] == "htetro-ga-paper" and out["additions"] == [] and out["reached"]
    scenario = load_scenario("three_slit")
    commands = parse_commands(",".join(out["commands"]))
    check = Simulator(scenario.workspace, commands=SEED000_COMMANDS).run([commands], scenario.start,
                                                                          roadmap=[scenario.goal])
    assert check.valid[0] and check.reached[0] and check.time[0] == out["time"]
    assert main(["plan", "three_slit", "--method", "htetro-ga", "--max-gen", "3", "--pop-size", "8", "--json",
                 "--quiet"]) == 0
    assert json.loads(capsys.readouterr().out)["additions"] == list(GA_ADDITIONS)


def test_the_paper_modes_defaults_are_the_papers():
    # l_p,max = 100 (§V-B3); patience our reading of "convergence of the solution" (Table 4); no additions
    assert SPEC.default_of("htetro-ga-paper", "max_length") == PAPER_MAX_LENGTH == 100
    assert SPEC.default_of("htetro-ga-paper", "patience") == PAPER_PATIENCE == 10
    assert SPEC.default_of("htetro-ga-paper", "additions") == ()
    # the library's plan_ga uses the same: the defaults give the run of the explicit values, and not that of others
    roadmap = [START, Pose(8, 8, "O", 0)]
    default = plan_ga(OPEN, roadmap, algorithm="htetro-ga-paper", pop_size=10, max_gen=60, seed=4)
    explicit = plan_ga(OPEN, roadmap, algorithm="htetro-ga-paper", pop_size=10, max_gen=60, seed=4,
                       patience=10, max_length=100)
    assert default.commands.tolist() == explicit.commands.tolist()
    assert default.legs[0].generations == explicit.legs[0].generations
    member = default.legs[0].selected["multi_objective"]
    assert member.fitness[1] == pytest.approx(1 - member.time / 100)  # f_t's t_max = l_p,max × 1 s = 100 s
    longer = plan_ga(OPEN, roadmap, algorithm="htetro-ga-paper", pop_size=10, max_gen=60, seed=4, patience=40)
    assert longer.legs[0].generations > default.legs[0].generations  # the patience bites


@pytest.mark.parametrize("call", [
    lambda: plan_path(OPEN, [START, GOAL], method="htetro-ga-paper", seed_exact=True),
    lambda: plan_path(OPEN, [START, GOAL], method="htetro-ga-paper", reach_share=0.5),
    lambda: plan_ga(OPEN, [START, GOAL], algorithm="htetro-ga-paper", seed_exact=True),
    lambda: plan_ga(OPEN, [START, GOAL], algorithm="htetro-ga-paper", reach_share=0.5),
    lambda: make_algorithm("htetro-ga-paper", 10, reach_share=0.5),
    lambda: make_algorithm("htetro-ga-paper", 10, reach_share=0.5, additions=["niching"]),
])
def test_the_paper_mode_refuses_our_options_that_are_not_additions(call):
    with pytest.raises(ParameterError, match="seed_exact|reach_share|seed-exact|reach-share"):
        call()


def test_the_papers_sort_has_two_sections_and_the_reach_levels_more():
    # no member reaches; A2 is dominated by A (same f_gr); B has a lower f_gr but better f_t, f_sm, f_sf.
    # The paper (§IV-C steps 3-4): one section for all of them, fronts {A, B}, {A2}: A and B survive.
    # Reach levels (ours): f_gr first, A and A2 survive.
    f = np.array([[0.5, 0.2, 0.2, 0.2], [0.5, 0.1, 0.1, 0.1], [0.25, 0.9, 0.9, 0.9]])  # A, A2, B
    pop = Population.new("X", as_column([[i] for i in range(3)]), "F", -f)
    pop.set("idx", np.arange(3), "end", np.array([1, 2, 3]))
    problem = Problem(n_var=1, n_obj=4)

    def kept(levels):
        survival = GoalReachabilitySurvival(levels=levels)
        return sorted(survival.do(problem, pop, n_survive=2, random_state=np.random.default_rng(0)).get("idx").tolist())

    assert kept(False) == [0, 2] and kept(True) == [0, 1]
    assert not make_algorithm("htetro-ga-paper", 10).survival.levels and make_algorithm("htetro-ga", 10).survival.levels


def test_the_papers_crossover_has_no_gene_cap():
    paper, ours = make_algorithm("htetro-ga-paper", 10), make_algorithm("htetro-ga", 10)
    problem = CommandPathProblem(OPEN, START, GOAL, max_length=3)
    assert paper.mating.crossover.limit(problem) is None and ours.mating.crossover.limit(problem) == 6
