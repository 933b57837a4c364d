"""Repair (ours, optional): replace each command that would be invalid by a random valid one."""

from __future__ import annotations

from pymoo.core.repair import Repair

from htetro_opt.operators.commands._chromosome import as_column, sequences
from htetro_opt.operators.commands.shortcut import repair_and_shortcut

__all__ = ["CommandRepair"]


class CommandRepair(Repair):
    """Simulate each chromosome from the problem's start and replace every command that would be
    invalid where it is executed by one drawn uniformly from the commands valid there.

    Under MODEL.md §5 a child stops at its first invalid command, so the paper's operators can only
    lengthen a path by a mutation that hits that one gene: along the spiral's 112-command corridor
    that takes thousands of generations. Repaired chromosomes are executed whole, every gene counts,
    and the child-termination rule is untouched (a repaired chromosome has no invalid command unless
    no command at all is valid somewhere). This is the "knowledge-based" repair of Hu and Yang's GA,
    which the paper cites; it is not part of the paper's hTetro-GA.

    The problem must provide ``simulator``, ``start_id``, ``goal`` and ``t0``
    (:class:`~htetro_opt.problems.CommandPathProblem` does).
    """

    def _do(self, problem, X, random_state=None, **kwargs):
        return as_column(repair_and_shortcut(problem, sequences(X), repair=random_state))
