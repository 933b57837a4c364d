"""The pymoo algorithms that run over Cheng et al. 2020's command chromosomes, by name.

The same :class:`~htetro_opt.problems.CommandPathProblem` and operators run under the paper's
hTetro-GA (with our additions, or as published) and under four of pymoo's own algorithms, so that a
study can swap the algorithm and nothing else.
"""

from __future__ import annotations

from math import comb
from typing import Mapping, Sequence

import numpy as np
from pymoo.core.infill import InfillCriterion
from pymoo.core.population import Population

from htetro_opt._validation import check_bool, check_int, check_probability, check_real
from htetro_opt.algorithms.htetro_ga import HTetroGA, trim_reached
from htetro_opt.algorithms.names import GA_ALGORITHMS
from htetro_opt.errors import ParameterError
from htetro_opt.operators.commands import (
    CommandCrossover,
    CommandDuplicateElimination,
    CommandMutation,
    CommandRearrangement,
    CommandRemoval,
    CommandRepair,
    CommandReplan,
    CommandSampling,
    CommandShortcut,
    replan_rows,
)

__all__ = ["ConservativeMating", "ReplanMating", "make_algorithm"]

_PYMOO_REPLAN = (0, 3)  # pymoo's algorithms: the re-planning off unless asked for (W), K when it is on


class ConservativeMating(InfillCriterion):
    """A pymoo algorithm's own mating, plus the hTetro-GA's conservative offspring set.

    Each generation the wrapped mating makes its offspring as usual; then every member of the
    population gets one conservative child, as in the hTetro-GA (Cheng et al. 2020, Fig. 7):
    removal, then rearrangement (:class:`~htetro_opt.operators.CommandRemoval`,
    :class:`~htetro_opt.operators.CommandRearrangement`), then, as the hTetro-GA's default does, the
    shortcut (:class:`~htetro_opt.operators.CommandShortcut`) and the mating's repair. A
    goal-reaching member is first cut to its executed prefix (its genes after the goal never run),
    so that removal keeps the cell where it stops (:func:`~htetro_opt.algorithms.trim_reached`).
    The children, less the duplicates, join the offspring, which then number up to n_offsprings +
    pop_size, as the hTetro-GA's two sets do; every pymoo survival used here cuts pop + off back to
    pop_size. Given to pymoo's algorithms through their ``mating`` so that swapping the algorithm
    compares algorithms, not operator sets.

    Parameters
    ----------
    mating : pymoo Mating
        The algorithm's own (``algorithm.mating`` as pymoo built it).
    """

    def __init__(self, mating) -> None:
        super().__init__(repair=mating.repair, eliminate_duplicates=mating.eliminate_duplicates,
                         n_max_iterations=mating.n_max_iterations)
        self.mating = mating
        self.operators = (CommandRemoval(), CommandRearrangement(), CommandShortcut())

    def do(self, problem, pop, n_offsprings, random_state=None, **kwargs):
        off = self.mating.do(problem, pop, n_offsprings, random_state=random_state, **kwargs)
        if len(pop) == 0 or pop.get("F") is None:
            return off
        parents = Population.new(X=pop.get("X"), reached=pop.get("reached"), executed=pop.get("executed"))
        children = trim_reached(parents)
        for operator in self.operators:
            children = operator.do(problem, children, random_state=random_state)
        children = self.repair.do(problem, children, random_state=random_state)
        children = self.eliminate_duplicates.do(children, pop, off)
        return Population.merge(off, children) if len(children) else off


class ReplanMating(InfillCriterion):
    """A pymoo algorithm's own mating, followed by the hTetro-GA's windowed exact re-planning step.

    Each generation the wrapped mating makes its offspring as usual (the algorithm's selection,
    crossover, mutation, repair, duplicate elimination); then the fastest goal-reaching member of
    the population and ``members`` random reaching ones (:func:`~htetro_opt.operators.commands.replan_rows`)
    are re-planned (:class:`~htetro_opt.operators.commands.CommandReplan`) and those that changed,
    less the duplicates, join the offspring. The offspring then number up to n_offsprings + 1 +
    ``members``; every pymoo survival used here cuts pop + off back to pop_size. This is the step the
    hTetro-GA takes (ours, see :class:`HTetroGA`), given to pymoo's algorithms through their
    ``mating`` so that swapping the algorithm compares algorithms, not operator sets.

    Parameters
    ----------
    mating : pymoo Mating
        The algorithm's own (``algorithm.mating`` as pymoo built it).
    window : int
        W (at least 1).
    members : int
        K.
    """

    def __init__(self, mating, window: int, members: int) -> None:
        super().__init__(repair=mating.repair, eliminate_duplicates=mating.eliminate_duplicates,
                         n_max_iterations=mating.n_max_iterations)
        self.mating = mating
        self.replan = CommandReplan(check_int(window, "replan_window", minimum=1))
        self.members = check_int(members, "replan_members", minimum=0)

    def do(self, problem, pop, n_offsprings, random_state=None, **kwargs):
        off = self.mating.do(problem, pop, n_offsprings, random_state=random_state, **kwargs)
        F = pop.get("F")
        if F is None or len(pop) == 0:
            return off
        rows = replan_rows(F[:, 0] <= -1.0, F[:, 1], self.members, random_state=random_state)  # F = −fitness
        if not len(rows):
            return off
        replanned = self.replan.do(problem, Population.new(X=pop.get("X")[rows]), random_state=random_state)
        replanned = self.eliminate_duplicates.do(replanned, pop, off)
        return Population.merge(off, replanned) if len(replanned) else off


def make_algorithm(
    name: str = "htetro-ga",
    pop_size: int = 50,
    *,
    sampling_weights: Mapping[str, float] | None = None,
    crossover_rate: float = 0.5,
    replan_window: int | None = None,
    replan_members: int | None = None,
    reach_share: float | None = None,
    conservative: bool | None = None,
    include: Sequence = (),
    reach_patience: int | None = None,
    polish_window: int | None = None,
    additions=None,
):
    """A pymoo algorithm over command chromosomes.

    Parameters
    ----------
    name : {"htetro-ga", "htetro-ga-paper", "nsga2", "nsga3", "smsemoa", "agemoea"}
        ``"htetro-ga"`` is :class:`HTetroGA` with our eight additions (:data:`GA_ADDITIONS`),
        ``"htetro-ga-paper"``
        :meth:`HTetroGA.as_published`; the others are pymoo's algorithms with the command sampling,
        single-point crossover (rate ``crossover_rate``), mutation, duplicate elimination and the
        repair (NSGA-III with Das–Dennis reference directions, about ``pop_size`` of them).
    pop_size : int
    sampling_weights : mapping of token to float, optional
        λ_mc of Algorithm 1.
    crossover_rate : float
    replan_window, replan_members : int, optional
        The hTetro-GA's windowed exact re-planning (:class:`HTetroGA`); None: the algorithm's
        default (W = 40 and 3 members for ``"htetro-ga"``, off for ``"htetro-ga-paper"``). pymoo's
        algorithms take the same step through their mating (:class:`ReplanMating`), off by default
        (their defaults stay pymoo's); with a window and no ``replan_members``, K = 3.
    reach_share : float, optional
        The hTetro-GA's cap on the goal-reaching section of its sort (:class:`HTetroGA`, ours); None: the
        default, 1 (no cap). ``"htetro-ga-paper"`` and pymoo's algorithms refuse a share other than 1
        (the paper's sort has no such cap; pymoo's algorithms have no such sort).
    conservative : bool, optional
        pymoo's algorithms only: add the hTetro-GA's conservative offspring set (removal,
        rearrangement, shortcut) to their mating (:class:`ConservativeMating`); None: off (their
        defaults stay pymoo's). The hTetro-GA always makes that set: a value is refused there.
    include : sequence of int arrays
        Chromosomes put into the initial population (:class:`CommandSampling`'s ``include``).
    reach_patience : int, optional
        The hTetro-GA's reach repair (:class:`HTetroGA`): after this many generations without a
        reaching member and without a rise of the best f_gr, the member nearest to the goal gets the
        minimum-time path to it. None: the default (100 for ``"htetro-ga"``, off for
        ``"htetro-ga-paper"``); 0 turns it off. pymoo's algorithms have no such step: a value other
        than 0 is refused there.
    additions : collection of str, optional
        The hTetro-GA's additions of ours switched on, exactly (:data:`GA_ADDITIONS`' names; a window or
        patience given for one that is off is ignored): None, the name's (``"htetro-ga"`` all,
        ``"htetro-ga-paper"`` none, a keyword given switching one back on).
    polish_window : int, optional
        The hTetro-GA's balanced polish when a run ends (:class:`HTetroGA`,
        :func:`~htetro_opt.operators.commands.polish_sum`): W, the window of the largest-sum member's
        path re-planned for the largest fitness sum. None: the default (40 for ``"htetro-ga"``, off for
        ``"htetro-ga-paper"``); 0 turns it off. pymoo's algorithms have no such step: a value other
        than 0 is refused there.

    Raises
    ------
    ParameterError
        If the name is unknown, ``pop_size`` is below 2, ``crossover_rate`` is not a probability, a
        sampling weight is negative, ``replan_window`` or ``replan_members`` is negative,
        ``reach_share`` is not in (0, 1] or below 1 for one of pymoo's, ``reach_patience`` or
        ``polish_window`` is negative or positive for one of pymoo's, ``conservative`` is not a bool
        or is given for the hTetro-GA, or ``"agemoea"`` is asked for
        without numba installed (pymoo's AGE-MOEA needs it: the ``agemoea`` extra).

    Examples
    --------
    >>> type(make_algorithm("nsga2", 20)).__name__, make_algorithm("htetro-ga-paper", 20).shortcut
    ('NSGA2', False)
    """
    if name not in GA_ALGORITHMS:
        raise ParameterError(f"unknown algorithm {name!r}: expected one of {', '.join(GA_ALGORITHMS)}")
    pop_size = check_int(pop_size, "pop_size", minimum=2)
    crossover_rate = check_probability(crossover_rate, "crossover_rate")
    sampling = CommandSampling(sampling_weights, include=include)
    replan = {key: check_int(value, key, minimum=0) for key, value in
              (("replan_window", replan_window), ("replan_members", replan_members)) if value is not None}
    if reach_share is not None:
        replan["reach_share"] = check_real(reach_share, "reach_share", minimum=0.0, maximum=1.0, include_minimum=False)
    if reach_patience is not None:
        replan["reach_patience"] = check_int(reach_patience, "reach_patience", minimum=0)
    if polish_window is not None:
        replan["polish_window"] = check_int(polish_window, "polish_window", minimum=0)
    if conservative is not None:
        conservative = check_bool(conservative, "conservative")
        if name in ("htetro-ga", "htetro-ga-paper"):
            raise ParameterError(f"conservative applies to pymoo's algorithms (nsga2, nsga3, smsemoa, agemoea), not to "
                                 f"{name!r}, which always makes the conservative offspring set")
    if name == "htetro-ga-paper" and replan.get("reach_share", 1.0) < 1.0:
        raise ParameterError("reach_share caps the goal-reaching section of the sort, which the paper's sort does not "
                             "(§IV-C: every member that reaches goes first): htetro-ga-paper refuses it, htetro-ga "
                             "takes it")
    if additions is not None and name in ("htetro-ga", "htetro-ga-paper"):  # exactly these, whatever the name's
        return HTetroGA.with_additions(additions, pop_size, sampling=sampling, crossover_rate=crossover_rate,
                                       **replan)
    if additions is not None and tuple(additions):
        raise ParameterError(f"additions apply to the hTetro-GA (htetro-ga, htetro-ga-paper), not to {name!r}")
    if name == "htetro-ga":
        return HTetroGA(pop_size=pop_size, sampling=sampling, crossover_rate=crossover_rate, **replan)
    if name == "htetro-ga-paper":
        return HTetroGA.as_published(pop_size=pop_size, sampling=sampling, crossover_rate=crossover_rate, **replan)
    if replan.pop("reach_patience", 0):
        raise ParameterError(f"reach_patience applies to the hTetro-GA (htetro-ga, htetro-ga-paper), not to {name!r}")
    if replan.pop("polish_window", 0):
        raise ParameterError(f"polish_window applies to the hTetro-GA (htetro-ga, htetro-ga-paper), not to {name!r}")
    if replan.get("reach_share", 1.0) < 1.0:
        raise ParameterError(f"reach_share applies to the hTetro-GA (htetro-ga, htetro-ga-paper), not to {name!r}")
    operators = dict(
        sampling=sampling,
        crossover=CommandCrossover(prob=crossover_rate, length_cap=2),  # the hTetro-GA's gene cap, as before
        mutation=CommandMutation(),
        eliminate_duplicates=CommandDuplicateElimination(),
        repair=CommandRepair(),
    )
    algorithm = _pymoo_algorithm(name, pop_size, operators)
    if conservative:
        algorithm.mating = ConservativeMating(algorithm.mating)
    window = replan.get("replan_window", _PYMOO_REPLAN[0])
    if window:
        algorithm.mating = ReplanMating(algorithm.mating, window, replan.get("replan_members", _PYMOO_REPLAN[1]))
    return algorithm


def _comp_by_cv_then_random(pop, P, random_state=None, **kwargs):
    """pymoo's NSGA-III tournament (``comp_by_cv_then_random``) with the algorithm's generator passed
    on: pymoo 0.6.2's draws the winner of two equally infeasible individuals from fresh entropy (its
    ``compare`` is called without ``random_state``), so a constrained problem (the path bases') gave
    another front at every run of the same seed."""
    from pymoo.operators.selection.tournament import compare

    S = np.full(P.shape[0], -1, dtype=int)
    for i, (a, b) in enumerate(P[:, :2]):
        if pop[a].CV > 0.0 or pop[b].CV > 0.0:  # the less infeasible, or a random one of two equal
            S[i] = compare(a, pop[a].CV, b, pop[b].CV, method="smaller_is_better", return_random_if_equal=True,
                           random_state=random_state)
        else:  # both feasible: a random one, as pymoo's
            S[i] = random_state.choice([a, b])
    return S[:, None]


def _pymoo_algorithm(name: str, pop_size: int, operators: dict, *, n_objectives: int = 4):
    """pymoo's ``name`` (nsga2, nsga3, smsemoa, agemoea) over the given operators; NSGA-III's Das–Dennis
    directions are the most, for ``n_objectives``, that ``pop_size`` holds (at least one partition)."""
    if name == "nsga2":
        from pymoo.algorithms.moo.nsga2 import NSGA2

        return NSGA2(pop_size=pop_size, **operators)
    if name == "nsga3":
        from pymoo.algorithms.moo.nsga3 import NSGA3
        from pymoo.util.ref_dirs import get_reference_directions

        partitions = 1
        while _n_directions(n_objectives, partitions + 1) <= pop_size:
            partitions += 1
        from pymoo.operators.selection.tournament import TournamentSelection

        ref_dirs = get_reference_directions("das-dennis", n_objectives, n_partitions=partitions)
        operators = {"selection": TournamentSelection(func_comp=_comp_by_cv_then_random), **operators}
        return NSGA3(ref_dirs=ref_dirs, pop_size=pop_size, **operators)
    if name == "smsemoa":
        from pymoo.algorithms.moo.sms import SMSEMOA

        return SMSEMOA(pop_size=pop_size, **operators)
    try:
        from pymoo.algorithms.moo.age import AGEMOEA
    except Exception as err:  # pymoo's AGE-MOEA module turns a missing numba into a bare Exception
        raise ParameterError(
            f"algorithm 'agemoea' needs numba, which pymoo's AGE-MOEA imports: pip install 'htetro-opt[agemoea]' ({err})"
        ) from err
    return AGEMOEA(pop_size=pop_size, **operators)


def _n_directions(n_obj: int, partitions: int) -> int:
    return comb(partitions + n_obj - 1, n_obj - 1)
