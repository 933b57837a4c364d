"""``"cpsat"``, the tiling as an exact cover solved by OR-Tools' CP-SAT.

One Boolean per placement (allowed pattern × anchor, all four cells free) and ``AddExactlyOne``
over the placements covering each free cell. The placements are declared, in the backtracker's
order, as a decision strategy, and CP-SAT's portfolio search takes turns between it and its own
heuristics, with propagation and clause learning. Presolve, probing, symmetry detection and
inprocessing are off: on 24 × 24 to 64 × 64 grids they cost seconds and find nothing. It runs on
one worker with a ``random_seed`` (0, or drawn from ``seed`` with ``shuffle=True``) and the pattern
order, so a seed gives one tiling, reproducibly, and other seeds others. It takes a few seconds on
64 × 64 grids and proves untileability where the backtracker would search for long. Building the
model counts against ``time_limit`` (on a free 256 × 256 grid it takes seconds): the clock is read
while it is built, and CP-SAT gets what is left.

:func:`_cpsat_covers` is the general form the ``auto`` portfolio (``_portfolio``) uses too: cells
that must be covered exactly once, cells that may be covered at most once, and a budget of CP-SAT's
deterministic time. ortools is imported only there, when a model is built, so that importing the
package does not import it.
"""

from __future__ import annotations

import time as _time

import numpy as np

from htetro_opt._interrupt import on_signal
from htetro_opt.errors import TilingError
from htetro_opt.solvers.tiling._common import (
    _check_clock,
    _OutOfWork,
    _pattern_order,
    _placements,
    _TimeLimit,
    _WorkLimit,
)

_BUILD_CHUNK = 1 << 15  # CP-SAT variables or constraints built between two looks (~0.1 s)
_LOAD_SHARE = 0.25  # CP-SAT's model load, as a share of the model's build time (see _cpsat_covers)


def _cpsat_tilings(occ, patterns, seed, deadline, limit, budget=None):
    """Up to ``limit`` tilings by CP-SAT; [] when infeasible; _TimeLimit when out of time with none
    (_WorkLimit when out of ``budget``, ``[deterministic time left]`` or None)."""
    return _cpsat_covers(~occ, np.zeros_like(occ), patterns, seed, deadline, limit, budget=budget)


def _cpsat_covers(must, may, patterns, seed, deadline, limit, work=None, budget=None):
    """Up to ``limit`` sets of tiles covering each ``must`` cell exactly once and each ``may`` cell at
    most once (every tile touching a ``must`` cell), by CP-SAT; [] when there is none.

    Raises _TimeLimit when the deadline comes first, _OutOfWork when ``work`` (CP-SAT's
    deterministic seconds, the same on every machine) runs out first. ``budget`` is the caller's
    ``max_deterministic_time``: None, or ``[deterministic time left]``, shared by the calls of one
    search and charged with what this one spends; _WorkLimit when it runs out. The model's build counts
    against the deadline (on a free 256 × 256 grid, 1.2 million placements, it takes seconds in
    OR-Tools' Python layer), so the clock is read every :data:`_BUILD_CHUNK` variables or constraints
    and CP-SAT gets only what is left.
    """
    from ortools.sat.python import cp_model

    which, cells = _placements(must | may, patterns)
    touching = must[cells[..., 1], cells[..., 0]].any(axis=1)
    which, cells = which[touching], cells[touching]
    # placements in search order: anchor (cells[:, 0]) in scan order, then the seed's pattern order
    rank = np.empty(len(patterns), dtype=np.int64)
    rank[_pattern_order(len(patterns), seed)] = np.arange(len(patterns))
    by = np.lexsort((rank[which], cells[:, 0, 0], -cells[:, 0, 1]))
    cells = cells[by]
    began = _time.perf_counter()
    model = cp_model.CpModel()
    xs = []
    for start in range(0, len(cells), _BUILD_CHUNK):
        _check_clock(deadline)
        xs += [model.NewBoolVar("") for _ in range(min(_BUILD_CHUNK, len(cells) - start))]
    h, w = must.shape
    flat = (cells[..., 1] * w + cells[..., 0]).ravel()
    owner = np.repeat(np.arange(len(cells)), 4)
    by_cell = np.argsort(flat, kind="stable")
    bounds = np.searchsorted(flat[by_cell], np.arange(h * w + 1)).tolist()
    owner = owner[by_cell].tolist()
    for k, c in enumerate(np.flatnonzero(must.ravel()).tolist()):
        if k % _BUILD_CHUNK == 0:
            _check_clock(deadline)
        model.AddExactlyOne([xs[i] for i in owner[bounds[c]:bounds[c + 1]]])
    for k, c in enumerate(np.flatnonzero(may.ravel()).tolist()):
        if k % _BUILD_CHUNK == 0:
            _check_clock(deadline)
        if bounds[c + 1] - bounds[c] > 1:
            model.AddAtMostOne([xs[i] for i in owner[bounds[c]:bounds[c + 1]]])
    # The backtracker's order, declared as a search strategy: CP-SAT's portfolio (one worker) takes
    # turns between it and its own heuristics at each restart, with propagation and clause learning.
    # Declared in chunks with a look at the clock between them (one AddDecisionStrategy call over
    # 1.2 million variables takes seconds): consecutive CHOOSE_FIRST strategies branch exactly as
    # one over their concatenation, since CP-SAT moves to the next only when all of one are fixed.
    for start in range(0, len(xs), _BUILD_CHUNK):
        _check_clock(deadline)
        model.AddDecisionStrategy(xs[start:start + _BUILD_CHUNK], cp_model.CHOOSE_FIRST, cp_model.SELECT_MAX_VALUE)

    solver = cp_model.CpSolver()
    params = solver.parameters
    params.catch_sigint_signal = False  # Ctrl-C goes to Python (see htetro_opt._interrupt), not CP-SAT
    params.num_workers = 1  # one worker: the search, hence the tiling, is reproducible
    params.random_seed = 0 if seed is None else int(seed)
    params.search_branching = cp_model.PORTFOLIO_SEARCH
    # measured on 24 x 24 to 64 x 64 grids: presolve, probing and inprocessing cost seconds and
    # find nothing on an exact cover; the fixed search alone stalls on some maps (h_shape), and
    # CP-SAT's default parameters time out on 64 x 64 maps it solves in seconds like this
    params.cp_model_presolve = False
    params.cp_model_probing_level = 0
    params.linearization_level = 0
    params.symmetry_level = 0
    params.use_sat_inprocessing = False
    by_budget = budget is not None and (work is None or budget[0] <= work)  # which of the two can stop it
    if budget is not None:
        if budget[0] <= 0:
            raise _WorkLimit("max_deterministic_time")
        work = budget[0] if by_budget else work
    if work is not None:
        params.max_deterministic_time = work
    if deadline is not None:
        # CP-SAT loads the model without looking at its time limit: on the free 256 x 256 grid the
        # load took 0.8 s after a 6 s build (it overran a 3.8 s limit to 4.6 s), so a quarter of
        # the build's time, measured on this machine as it is loaded now, is set aside for it
        now = _time.perf_counter()
        left = deadline - now - _LOAD_SHARE * (now - began)
        if left <= 0:
            raise _TimeLimit("time limit")
        params.max_time_in_seconds = left

    found: list[list[np.ndarray]] = []

    def record(values) -> None:
        chosen = np.flatnonzero(np.asarray(values, dtype=np.int64)[:len(cells)])
        found.append([cells[i].copy() for i in chosen.tolist()])

    class _Collect(cp_model.CpSolverSolutionCallback):
        def on_solution_callback(self):  # OR-Tools' hook
            record(self.response_proto.solution)
            if len(found) >= limit:
                self.StopSearch()

    if limit > 1:
        params.enumerate_all_solutions = True
        with on_signal(solver.StopSearch):  # Ctrl-C stops CP-SAT now, not at its time limit
            status = solver.Solve(model, _Collect())
    else:
        with on_signal(solver.StopSearch):
            status = solver.Solve(model)
        if status in (cp_model.OPTIMAL, cp_model.FEASIBLE):
            record(solver.response_proto.solution)
    if budget is not None:
        budget[0] -= solver.deterministic_time
    if found:
        return found
    if status == cp_model.INFEASIBLE:
        return []
    if status == cp_model.UNKNOWN:
        if deadline is not None and _time.perf_counter() >= deadline - 1e-3:
            raise _TimeLimit("time limit")
        if by_budget:
            raise _WorkLimit("max_deterministic_time")
        if work is not None:
            raise _OutOfWork
        raise _TimeLimit("time limit")  # stopped by a signal handler that did not raise
    raise TilingError(f"CP-SAT ended with status {solver.StatusName(status)} on the tiling model")
