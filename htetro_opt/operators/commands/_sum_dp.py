"""The fixed-length dynamic programme over (pose, last command) layers that maximises Cheng et al. 2020's fitness sum.

Shared by the exact maximiser of a leg's fitness sum
(:func:`~htetro_opt.solvers.grid_paths.plan_max_fitness_sum`, whose module docstring proves the
method) and the hTetro-GA's balanced polish (:mod:`.polish`), which solves the same programme over a
window of a path. It lives among the operators because imports flow one way (model ← problems ←
operators ← algorithms ← solvers): an operator may not import a solver.

For a path of exactly L commands that first reaches the goal at its last one, the fitness sum is
``4 − bracket`` with a bracket that is a sum of per-command costs: ``dur(c) / t_max`` for each
command, ``1 / (L − 1)`` for each change between neighbouring commands and ``D(p) / (L λ_sp)`` for
the danger of each pose after a command. :func:`min_bracket` finds the least such cost over the
sequences of exactly ``length`` commands from one pose to another, the commands' validity checked at
the moving obstacles' clock, with optional boundary commands before and after (a window inside a
longer path pays for changing from the command before it and into the command after it).
"""

from __future__ import annotations

import numpy as np

from htetro_opt._jit import lazy_jit
from htetro_opt.model.simulate import Simulator

__all__ = ["backward_steps", "first_arrivals", "min_bracket", "reverse_graph", "usable_table"]


@lazy_jit  # compiled on first use: importing the operators does not import numba
def first_arrivals(target, usable, phase0, start, goal, arrivals):
    """``arrivals[l]`` = whether some valid sequence of exactly l commands first reaches ``goal`` at
    its l-th command (``arrivals[0]`` stays False): a forward reachability pass over the layers, the
    goal never expanded (a child stops there)."""
    n_poses, n_commands = target.shape
    period = usable.shape[0]
    here = np.zeros(n_poses, dtype=np.bool_)
    after = np.zeros(n_poses, dtype=np.bool_)
    here[start] = True
    for k in range(1, len(arrivals)):
        phase = (phase0 + k - 1) % period
        after[:] = False
        any_live = False
        for p in range(n_poses):
            if not here[p]:
                continue
            for c in range(n_commands):
                if usable[phase, p, c]:
                    q = target[p, c]
                    if q == goal:
                        arrivals[k] = True
                    else:
                        after[q] = True
                        any_live = True
        here, after = after, here
        if not any_live:
            break


@lazy_jit
def min_bracket(target, usable, phase0, durations, danger, start, start_command, end, end_command, goal, length,
                w_time, w_change, w_danger, steps_to_end, value, scratch, active, touched, stamp, parents,
                keep_parents):
    """The least bracket over the valid sequences of exactly ``length`` commands from pose ``start``
    (its first command executed at a clock of phase ``phase0``) to pose ``end``, and the last command
    of the best (``inf`` and −1 when there is none).

    Each command c costs ``w_time * durations[c] + w_danger * danger[q]`` (q the pose after it) plus
    ``w_change`` when it differs from the command before it. The command before the first is
    ``start_command`` (−1: none, the first command pays no change) and the command after the last is
    ``end_command`` (−1: none; otherwise the last command pays ``w_change`` when it differs). The
    pose ``goal`` is forbidden except as the last pose when ``end == goal`` (a child stops at its
    first arrival). ``steps_to_end[q]`` is a lower bound on the commands from pose q to ``end``: a
    pose that cannot reach ``end`` in the layers left is not expanded (all zeros: no pruning).

    ``value``/``scratch`` (poses × commands, float) hold V of the current and the next layer; they
    must be all ``inf`` on entry and are left so (only the rows of the poses a layer touches are
    reset, not the whole tables: on a 128 × 128 map a table is 48 MB and a layer touches a few
    thousand poses). ``active``/``touched`` (poses, int) hold the poses of finite V in them,
    ``stamp`` (poses, int) marks a pose as touched in a layer. With ``keep_parents``, ``parents[k − 1, p′, c′]`` is
    ``p * n_commands + c`` of the best predecessor of (p′, c′) in layer k (−1 in layer 1), written
    wherever V is, so that ``parents`` need not be initialised: a walk back from a finite V reads
    only entries this call wrote.
    For the inner minimum over the previous command, see the exact maximiser's module docstring:
    per pose, keeping its own command or changing from the pose's best is all that needs comparing.
    """
    n_commands = target.shape[1]
    period = usable.shape[0]
    inf = np.inf
    stamp[:] = 0
    n_active = 1
    active[0] = start
    for k in range(1, length + 1):
        phase = (phase0 + k - 1) % period
        last = k == length
        left = length - k  # commands still to come after layer k
        n_touched = 0
        for i in range(n_active):
            p = active[i]
            if k == 1:
                best_here, best_command = 0.0, start_command
            else:
                best_here, best_command = inf, -1
                for c in range(n_commands):
                    if value[p, c] < best_here:
                        best_here, best_command = value[p, c], c
                if best_here == inf:
                    continue
            switched = best_here + w_change
            for c in range(n_commands):
                if not usable[phase, p, c]:
                    continue
                q = target[p, c]
                if last:
                    if q != end:
                        continue
                elif q == goal or steps_to_end[q] > left:  # a child stops on the goal; q cannot reach end in time
                    continue
                if k == 1:
                    previous = -1
                    base = 0.0 if start_command < 0 or c == start_command else w_change
                elif value[p, c] <= switched:  # keeping the command beats the best change (inf never does)
                    base, previous = value[p, c], c
                else:
                    base, previous = switched, best_command
                candidate = base + w_time * durations[c] + w_danger * danger[q]
                if candidate < scratch[q, c]:
                    scratch[q, c] = candidate
                    if keep_parents:
                        parents[k - 1, q, c] = -1 if previous < 0 or k == 1 else p * n_commands + previous
                    if stamp[q] != k:
                        stamp[q] = k
                        touched[n_touched] = q
                        n_touched += 1
        for i in range(n_active):  # V of layer k − 1 is spent: its rows back to inf for layer k + 1
            value[active[i], :] = inf
        if n_touched == 0:
            return inf, -1
        value, scratch = scratch, value
        active, touched = touched, active
        n_active = n_touched
    best, best_command = inf, -1
    for c in range(n_commands):
        closing = value[end, c]
        if end_command >= 0 and c != end_command:
            closing += w_change
        if closing < best:
            best, best_command = closing, c
    for i in range(n_active):  # leave both tables all inf for the next call
        value[active[i], :] = inf
    return best, best_command


@lazy_jit
def backward_steps(indptr, indices, end, goal, steps):
    """``steps[p]``: the fewest commands from pose p to ``end`` in the graph whose reverse edges are
    the CSR (``indptr``, ``indices``: the poses one command before each pose), never passing through
    ``goal`` unless it is ``end``; ``len(steps)`` (more than any path) where ``end`` is out of reach.
    A breadth-first search backwards from ``end``."""
    n = len(steps)
    steps[:] = n
    queue = np.empty(n, dtype=np.int64)
    steps[end] = 0
    queue[0] = end
    head, tail = 0, 1
    while head < tail:
        q = queue[head]
        head += 1
        if q == goal and q != end:  # a path through the goal would have stopped there
            continue
        for edge in range(indptr[q], indptr[q + 1]):
            p = indices[edge]
            if steps[p] == n:
                steps[p] = steps[q] + 1
                queue[tail] = p
                tail += 1


def usable_table(sim: Simulator) -> np.ndarray:
    """``usable[phase, pose, command]``: the command is valid from the pose when it is executed at a
    clock of that phase of the moving obstacles' period (one phase on a static map): the simulator's
    table and its blocked keys, as :meth:`~htetro_opt.model.Simulator.run` checks them."""
    n, c = sim.n_poses, sim.n_commands
    static = sim.next[:n, :c] != sim.dead
    if not sim.workspace.moving:
        return static[None]
    usable = np.repeat(static[None], sim.workspace.period, axis=0)
    for phase in range(sim.workspace.period):
        keys = sim.blocked_keys(phase)
        usable[phase, keys // sim.n_columns, keys % sim.n_columns] = False
    return usable


def reverse_graph(target: np.ndarray, usable: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The poses one command before each pose, as CSR (``indptr``, ``indices``), over the commands
    valid at some phase (a lower bound on the commands needed at any clock) and without the commands
    that leave the pose unchanged."""
    n_poses = target.shape[0]
    anytime = usable.any(axis=0)
    source, command = np.nonzero(anytime)
    successor = target[source, command]
    moves = successor != source
    source, successor = source[moves], successor[moves]
    order = np.argsort(successor, kind="stable")
    indptr = np.zeros(n_poses + 1, dtype=np.int64)
    np.cumsum(np.bincount(successor, minlength=n_poses), out=indptr[1:])
    return indptr, np.ascontiguousarray(source[order], dtype=np.int64)
