"""The waypoint-sequencing instance as a pymoo problem (kept apart: only this needs pymoo)."""

from __future__ import annotations

import numpy as np
from pymoo.core.problem import Problem

from htetro_opt.problems.waypoint_sequencing import SequencingInstance, check_instance

__all__ = ["SequencingProblem"]


class SequencingProblem(Problem):
    """The sequencing instance as a pymoo permutation problem, so pymoo's GAs can run on it.

    With a fixed start the variables are a permutation of the other ``n − 1`` waypoints (use pymoo's
    ``PermutationRandomSampling``, ``OrderCrossover``, ``InversionMutation``); :meth:`order` turns a
    solution into the full order. One objective, the path cost.

    Examples
    --------
    >>> from htetro_opt.scenarios import parse_tileset
    >>> from htetro_opt.problems import SequencingProblem
    >>> inst = SequencingInstance.from_tileset(parse_tileset("1a 1b 1c 1d\\n2a 2b 2c 2d\\n3a 3b 3c 3d"))
    >>> problem = SequencingProblem(inst)
    >>> problem.n_var, problem.evaluate(np.array([[0, 1], [1, 0]]))[:, 0].tolist()
    (2, [2.0, 3.0])
    """

    def __init__(self, instance: SequencingInstance):
        self.instance = check_instance(instance)
        self._free = np.array([i for i in range(instance.n) if i != instance.start], dtype=np.int64)
        super().__init__(n_var=len(self._free), n_obj=1, xl=0, xu=max(len(self._free) - 1, 0), vtype=int)

    def order(self, x) -> np.ndarray:
        """Full waypoint order(s) of solution(s) ``x``."""
        x = np.asarray(x, dtype=np.int64)
        rest = self._free[x]
        if self.instance.start is None:
            return rest
        head = np.full(rest.shape[:-1] + (1,), self.instance.start, dtype=np.int64)
        return np.concatenate([head, rest], axis=-1)

    def _evaluate(self, x, out, *args, **kwargs):
        # Through the instance's legs, so an implicit (matrix-free) instance and a closed tour's
        # return leg are priced as every solver prices them.
        orders = np.atleast_2d(self.order(x))
        total = self.instance.legs(orders[:, :-1], orders[:, 1:]).sum(axis=1)
        if self.instance.closed and orders.shape[1] > 1:
            total = total + self.instance.legs(orders[:, -1], orders[:, 0])
        out["F"] = np.asarray(total, dtype=float).reshape(-1, 1)
