"""Cheng et al. 2020's path planning as a pymoo problem: variable-length motion-command chromosomes.

An individual is one object variable holding an integer array of global command ids (see
:func:`~htetro_opt.model.parse_commands`). A population is evaluated as one batch by the shared
:class:`~htetro_opt.model.Simulator` with the paper's child termination (MODEL.md §5): a child stops
at its first invalid command, on reaching the goal, or at the end of its genes, and the executed
prefix is what is scored. The four objectives are the paper's eqs. 3–6, negated for minimisation:
``F = (−f_gr, −f_t, −f_sm, −f_sf)``.

- **Goal reachability** (eq. 3): ``f_gr = 1 / (1 + W_A*(B2's cell))`` with ``W_A*`` the 4-connected
  grid distance to the goal's B2 cell over free cells (``f_gr = 0`` where the goal cannot be reached
  on the grid). ``f_gr = 1`` exactly when the goal configuration is reached: a child standing on the
  goal cell in another morphology or heading counts half a cell away (``f_gr = 2/3``), a choice of ours.
- **Time** (eq. 4): ``f_t = 1 − Σ t / t_max`` with ``t_max = l_p,max × t_translation``.
- **Smoothness** (eq. 5): ``f_sm = 1 − (number of changes between neighbouring commands) / (l_p − 1)``.
- **Safety** (eq. 6): ``f_sf = 1 − Σ_i Σ_blocks D(block cell) / (l_p λ_sp)`` over the poses after each
  executed command, where ``D`` sums ``1 / ‖offset‖`` over the obstacle cells (static obstacles and
  out-of-map cells) among the 12 cells within 2 cells of a block centre, and ``λ_sp = 6 + 2√2``.

An empty executed prefix (``l_p = 0``) scores ``f_t = f_sm = f_sf = 1``; with ``l_p = 1``,
``f_sm = 1``.
"""

from __future__ import annotations

import math
from typing import Sequence

import numpy as np
from pymoo.core.problem import Problem

from htetro_opt._jit import lazy_jit
from htetro_opt._validation import check_int
from htetro_opt.errors import ParameterError, ScenarioError
from htetro_opt.model.commands import SEED000_COMMANDS, Timing
from htetro_opt.model.robot import FOOTPRINTS, Pose, as_pose
from htetro_opt.model.simulate import SimulationResult, Simulator, check_memory, compile_bytes
from htetro_opt.model.workspace import Workspace, check_workspace, grid_distance

__all__ = [
    "CommandPathProblem",
    "SAFETY_COEFFICIENT",
    "SAFETY_PATTERN",
    "safety_field",
]


@lazy_jit  # compiled on first use: importing the problem does not import numba
def _smoothness_safety(keys, local, executed, n_columns, pose_danger, changes, total):
    """Per sequence (column ``b`` of the (L + 1, B) ``keys``): the command changes among its first
    ``executed`` commands, and the danger of the poses after its commands summed in command order
    (those past ``executed`` adding 0.0, as the cumulative sum over the padded batch did, so the
    float sum is that sum bit for bit). :meth:`CommandPathProblem.fitness`'s loops, compiled
    (:func:`htetro_opt._jit.lazy_jit`): as numpy calls they made several (L, B) temporaries."""
    width = local.shape[1]
    for b in range(local.shape[0]):
        done = executed[b]
        count = 0
        for t in range(1, min(done, width)):
            if local[b, t] != local[b, t - 1]:
                count += 1
        changes[b] = count
        acc = 0.0
        for t in range(width):
            value = pose_danger[keys[t + 1, b] // n_columns] if t < done else 0.0
            acc = value if t == 0 else acc + value
        total[b] = acc


SAFETY_PATTERN = np.array(
    [(dx, dy) for dy in range(-2, 3) for dx in range(-2, 3) if 0 < dx * dx + dy * dy <= 4], dtype=np.int64
)
"""The 12 cell offsets within 2 cells of a block centre, centre excluded (MODEL.md §5)."""

SAFETY_COEFFICIENT = 6.0 + 2.0 * math.sqrt(2.0)
"""λ_sp: the sum of ``1 / ‖offset‖`` over :data:`SAFETY_PATTERN`, so a block walled in on all sides scores 1."""

_MISCONFIGURED_AT_GOAL = 0.5  # W_A* given to a child on the goal cell in the wrong morphology or heading
_POSES_PER_SLICE = 1 << 18  # poses whose tables are computed at a time


def _table_bytes(n_poses: int) -> int:
    """Peak bytes of the per-pose tables: f_gr and the safety penalty (float64 each), and the
    temporaries of one slice of poses (measured: 217 bytes a pose)."""
    return 16 * n_poses + 220 * min(n_poses, _POSES_PER_SLICE)


def safety_field(occupancy: np.ndarray) -> np.ndarray:
    """``D[y, x]``: the weighted count of obstacle cells around each cell (eq. 6's inner sum).

    Parameters
    ----------
    occupancy : ndarray of bool, shape (H, W)
        True on obstacles; cells outside the map count as obstacles.

    Returns
    -------
    ndarray of float, shape (H, W)

    Examples
    --------
    >>> field = safety_field(np.zeros((5, 5), dtype=bool))
    >>> float(field[2, 2]), round(float(field[0, 0]), 3)
    (0.0, 5.121)

    Raises
    ------
    ParameterError
        If ``occupancy`` is not a non-empty 2-D array of booleans or 0/1.
    """
    try:
        occupancy = Workspace(occupancy).occupancy
    except ScenarioError as err:  # an argument here, not a file's content
        raise ParameterError(str(err)) from err
    h, w = occupancy.shape
    framed = np.ones((h + 4, w + 4), dtype=bool)
    framed[2 : 2 + h, 2 : 2 + w] = occupancy
    field = np.zeros((h, w))
    for dx, dy in SAFETY_PATTERN:
        field += framed[2 + dy : 2 + dy + h, 2 + dx : 2 + dx + w] / math.hypot(dx, dy)
    return field


class CommandPathProblem(Problem):
    """Cheng et al. 2020's four-objective path problem from one configuration to the next.

    Parameters
    ----------
    workspace : Workspace or Simulator
        The map, or an already compiled simulator (then ``commands``, ``timing`` and ``clearance``
        are taken from it).
    start, goal : Pose
        The leg's start and goal configurations.
    max_length : int, keyword-only
        l_p,max: the length of the initial genes; sets ``t_max = max_length × t_translation`` and the
        mutation rate 1 / l_p,max. The paper uses 100 (200 for its spiral map).
    t0 : int, keyword-only
        Commands executed before this leg (the clock of moving obstacles).
    commands : sequence of str, optional, keyword-only
        The command alphabet (default: Cheng et al. 2020's thirteen commands).
    timing : Timing, optional, keyword-only
    clearance : float, keyword-only
        δ in cells (MODEL.md §4).

    Attributes
    ----------
    simulator : Simulator
    command_ids : ndarray of int
        The alphabet the operators draw from (global command ids).
    durations : ndarray of float
        Duration of every global command id.
    t_max : float

    Raises
    ------
    ConfigurationError
        If the start (at time ``t0``) or the goal collides or lies outside the map.
    ParameterError
        If ``max_length`` is not a positive integer, ``t0`` is negative, or ``workspace`` is neither
        a Workspace nor a Simulator.
    PlanningError
        If the simulator's and the problem's per-pose tables would not fit the memory budget
        (:func:`~htetro_opt.model.simulate.memory_budget`).

    Examples
    --------
    >>> from htetro_opt.model import parse_commands
    >>> ws = Workspace(np.zeros((12, 12), dtype=bool))
    >>> problem = CommandPathProblem(ws, Pose(4, 4, "O", 0), Pose(6, 4, "O", 0), max_length=10)
    >>> X = np.empty((1, 1), dtype=object)
    >>> X[0, 0] = parse_commands("x+,x+,y+")
    >>> (-problem.evaluate(X)).round(3).tolist()  # reaches the goal after two commands, far from obstacles
    [[1.0, 0.8, 1.0, 1.0]]
    """

    def __init__(
        self,
        workspace: Workspace | Simulator,
        start: Pose,
        goal: Pose,
        *,
        max_length: int = 100,
        t0: int = 0,
        commands: Sequence[str] | None = None,
        timing: Timing | None = None,
        clearance: float = 0.0,
    ) -> None:
        max_length = check_int(max_length, "max_length (l_p,max)", minimum=1)
        t0 = check_int(t0, "t0", minimum=0)
        start, goal = as_pose(start, "start"), as_pose(goal, "goal")
        if isinstance(workspace, Simulator):
            sim = workspace
        else:
            check_workspace(workspace, what="a Workspace or a Simulator")
            sim = Simulator(workspace, commands=commands if commands is not None else SEED000_COMMANDS,
                            timing=timing, clearance=clearance)
        self.simulator = sim
        self.start = start
        self.goal = goal
        self.t0 = t0
        self.start_id = sim.check_pose(self.start, what="start", t=self.t0)
        self.goal_id = sim.check_pose(self.goal, what="goal")
        self.max_length = max_length
        self.command_ids = sim.command_ids.copy()
        self.durations = sim.timing.durations()
        self.t_max = self.max_length * sim.timing.translation
        check_memory(_table_bytes(sim.n_poses) + compile_bytes(sim.n_poses, sim.n_commands),
                     f"the path problem's pose tables with the simulator's for this {sim.workspace.width} x "
                     f"{sim.workspace.height} map ({sim.n_poses // (sim.workspace.width * sim.workspace.height)} "
                     "poses a cell)", "use a smaller map or coarser cells")
        self._pose_reachability, self._pose_danger = self._pose_tables()
        super().__init__(n_var=1, n_obj=4, vtype=object, elementwise=False)

    def _pose_tables(self) -> tuple[np.ndarray, np.ndarray]:
        """f_gr and the safety penalty Σ_blocks D of every pose id (dead pose last)."""
        sim, ws = self.simulator, self.simulator.workspace
        distance = grid_distance(ws, (self.goal.x, self.goal.y))
        danger_field = safety_field(ws.occupancy)
        reachability = np.zeros(sim.n_poses + 1)
        danger = np.zeros(sim.n_poses + 1)
        for lo in range(0, sim.n_poses, _POSES_PER_SLICE):  # in slices: the temporaries are 13 times the tables
            ids = np.arange(lo, min(lo + _POSES_PER_SLICE, sim.n_poses))
            poses = sim.decode(ids)
            x, y, s, h = poses.T
            w_astar = distance[y, x]
            w_astar[(w_astar == 0) & (ids != self.goal_id)] = _MISCONFIGURED_AT_GOAL
            reachability[ids] = 1.0 / (1.0 + w_astar)
            blocks = FOOTPRINTS[s, h] + poses[:, None, :2]  # (slice, 4, 2)
            bx = blocks[..., 0].clip(0, ws.width - 1)
            by = blocks[..., 1].clip(0, ws.height - 1)
            danger[ids] = danger_field[by, bx].sum(axis=1)
        return reachability, danger

    # --- evaluation --------------------------------------------------------------------------
    def simulate(self, sequences, *, repair: np.random.Generator | None = None) -> SimulationResult:
        """Run sequences (global command ids) with the paper's child termination; with ``repair`` (a
        generator), each command that would be invalid is replaced by a valid one as it runs (see
        :meth:`~htetro_opt.model.Simulator.run`)."""
        return self.simulator.run(sequences, self.start_id, roadmap=[self.goal], t0=self.t0, stop_at_goal=True,
                                  repair=repair)

    def fitness(self, result: SimulationResult) -> np.ndarray:
        """The four fitnesses (f_gr, f_t, f_sm, f_sf) of a simulated batch, shape (B, 4)."""
        sim = self.simulator
        batch = len(result)
        executed = result.executed
        final = result.keys[executed, np.arange(batch)] // sim.n_columns
        f_gr = self._pose_reachability[final]
        f_t = 1.0 - result.time / self.t_max
        changes, total = np.empty(batch, dtype=np.int64), np.zeros(batch)
        _smoothness_safety(result.keys, result.local, np.asarray(executed, dtype=np.int64), sim.n_columns,
                                      self._pose_danger, changes, total)
        f_sm = np.where(executed > 1, 1.0 - changes / np.maximum(executed - 1, 1), 1.0)
        f_sf = np.where(executed > 0, 1.0 - total / (np.maximum(executed, 1) * SAFETY_COEFFICIENT), 1.0)
        return np.column_stack([f_gr, f_t, f_sm, f_sf])

    def outcomes(self, result: SimulationResult) -> dict[str, np.ndarray]:
        """What evaluation stores of a simulated batch: ``F`` (the negated fitnesses, shape (B, 4)) and
        the auxiliary columns ``reached``, ``executed``, ``time`` and ``end`` (the final pose id).

        :meth:`_evaluate` is this of :meth:`simulate`; the hTetro-GA calls it on the simulation that
        also repairs its offspring, so that each is simulated once.
        """
        return {
            "F": -self.fitness(result),
            "reached": result.reached,
            "executed": result.executed,
            "time": result.time,
            "end": result.keys[result.executed, np.arange(len(result))] // self.simulator.n_columns,
        }

    def _evaluate(self, X, out, *args, **kwargs):
        out.update(self.outcomes(self.simulate([x[0] for x in X])))
