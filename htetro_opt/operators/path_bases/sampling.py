"""The initial population of path bases: Nazarahari et al. 2019's APF paths (§4.2)."""

from __future__ import annotations

import numpy as np
from pymoo.core.sampling import Sampling

from htetro_opt._validation import check_bool
from htetro_opt.errors import PlanningError

__all__ = ["PathBasesSampling", "initial_paths"]


def initial_paths(geometry, start, goal, n: int, *, grid: float, finer: bool, seed,
                  refine: bool = True) -> list[np.ndarray]:
    """``n`` APF paths of one robot: all on the lattice of spacing ``grid`` (the paper), or, with
    ``finer`` (ours), the even-numbered ones there and the odd-numbered ones on the lattice of
    spacing ``grid`` / 2, which passes gaps narrower than ``grid`` (the paper's d = 1 lattice misses
    the shortest way between ``ega12_plankpile``'s planks). With ``refine`` (ours) a lattice that does
    not join the start to the goal is halved up to three times; without it (the paper) the goal is then
    unreachable. Empty when the goal is unreachable."""
    from htetro_opt.model._apf import REFINEMENTS, apf_population  # shapely loads when paths are drawn

    refinements = REFINEMENTS if refine else 0
    coarse, _ = apf_population(geometry, start, goal, n - n // 2 if finer else n, grid=grid, seed=seed,
                               refinements=refinements)
    if not finer or not coarse or n < 2:
        return coarse
    fine, _ = apf_population(geometry, start, goal, n // 2, grid=grid / 2, seed=seed, refinements=refinements)
    out = []
    for i in range(len(coarse)):
        out.append(coarse[i])
        if i < len(fine):
            out.append(fine[i])
    return out


class PathBasesSampling(Sampling):
    """Each robot's APF paths (:func:`initial_paths` on the problem's lattice step, ties broken by
    pymoo's ``random_state``), the i-th individual holding every robot's i-th path.

    Parameters
    ----------
    initial : sequence of K lists of (n, 2) arrays, optional
        Paths already found per robot (as the planner's reachability check finds them), used
        instead of running the APF again; cycled when fewer than the population.
    finer : bool
        Half the paths from the lattice of half the step (ours; see :func:`initial_paths`).
    refine : bool
        A lattice that does not join the start to the goal halved up to three times (ours; see
        :func:`initial_paths`).

    Raises
    ------
    PlanningError
        (In ``do``) when a robot's goal cannot be reached from its start.
    """

    def __init__(self, initial=None, *, finer: bool = False, refine: bool = True) -> None:
        super().__init__()
        self.initial = None if initial is None else [list(paths) for paths in initial]
        self.finer = check_bool(finer, "finer")
        self.refine = check_bool(refine, "refine")

    def _do(self, problem, n_samples, *args, random_state=None, **kwargs):
        pools = []
        for k in range(problem.n_robots):
            if self.initial is not None:
                pool = self.initial[k]
            else:
                pool = initial_paths(problem.geometry, problem.starts[k], problem.goals[k], n_samples,
                                     grid=problem.step, finer=self.finer, seed=random_state, refine=self.refine)
            if not pool:
                raise PlanningError(f"robot {k} cannot reach its goal {problem.goals[k].tolist()} from its start "
                                    f"{problem.starts[k].tolist()}")
            pools.append(pool)
        X = np.empty((n_samples, 1), dtype=object)
        for i in range(n_samples):
            X[i, 0] = problem.join([pool[i % len(pool)].copy() for pool in pools])
        return X
