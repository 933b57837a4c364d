"""Morphology layers and the hTetro workspace graph of Cheng et al. 2019 (Def. 4–5), as integer arrays.

A *layer* is the paper's morphology s = (θB1, θB2, θB3, θB4): one (state, heading) of the robot model.
The paper's three are ``O`` = (0, 0, −π, −π) = O at heading 0, ``vI`` = (0, 0, 0, 0) = I at heading 0
and ``hI`` = (−π/2, −π/2, −π/2, −π/2) = I at heading 3 (:meth:`~htetro_opt.model.Pose.from_q`); any of
the 28 named poses is written ``SHAPE@H`` (``L@1``).

The workspace graph has one vertex per (layer, B2 cell) whose footprint is free, numbered
``v = layer * H * W + y * W + x``. Its edges are the translations the
:class:`~htetro_opt.model.Simulator` finds valid (cost 1, one command) and, at one cell, the switches
between two layers, costing the fewest of Cheng et al. 2019's block commands (``1l`` … ``4r``, B2 fixed)
that take one layer to the other through any of the 23 states × 4 headings with every step valid
there. Those costs come from one breadth-first search per layer over the simulator's own transition
table's rows (:func:`~htetro_opt.model.simulate.transitions_at`, a few thousand free cells at a time:
the whole table is ~760 MB at 384 x 384), for every cell of a chunk at once (a block command keeps B2
on its cell). On the free plane: vI ↔ hI 1 command, vI ↔ O 2, O ↔ hI 3.

Table 1 of the paper lists other command counts for these switches (its q_c column and eq. 5); its
§IV-C text (vI → hI one ``2r``, vI → O two ``3r``) is what the model's commands give, and wins.
"""

from __future__ import annotations

import re
import reprlib
from collections import deque
from collections.abc import Iterable
from dataclasses import dataclass
from functools import cached_property

import numpy as np
from scipy.sparse import csr_matrix

from htetro_opt.errors import PlanningError, UnknownShapeError
from htetro_opt.model.commands import SEED004_COMMANDS, command_id, command_set
from htetro_opt.model.robot import FOOTPRINTS, N_HEADINGS, N_STATES, Pose, shape_index
from htetro_opt.model.simulate import Simulator, _check_pose, transitions_at
from htetro_opt.model.sweeps import sweep_tables
from htetro_opt.model.workspace import Workspace, check_workspace

__all__ = ["Layer", "LayerGraph", "parse_layers", "workspace_graph", "stripe_graph", "MOVES", "SWITCH_COMMANDS"]

MOVES = ("x+", "x-", "y+", "y-")
"""The four translations, in the order of :attr:`LayerGraph.move`'s second axis."""
SWITCH_COMMANDS = ("1l", "1r", "2l", "2r", "3l", "3r", "4l", "4r")
"""Cheng et al. 2019's block commands, in its Table 1 order: the order that breaks ties between switch paths."""
_SHIFTS = {"x+": (1, 0), "x-": (-1, 0), "y+": (0, 1), "y-": (0, -1)}
_ALIASES = {"O": ("O", 0), "vI": ("I", 0), "hI": ("I", 3)}
_CHUNK_CELLS = 4096
"""Free cells whose rows of the transition table (23 states x 4 headings x 13 commands, int64: ~9.6 KB a
cell) are computed and searched at a time: the layer graph never holds the whole table (~760 MB at 384 x 384)."""
_FORMS = "O, vI, hI or SHAPE@H (a shape of I O L J Z S T and a heading 0-3, e.g. L@1)"


@dataclass(frozen=True)
class Layer:
    """One morphology layer: its name, the robot state (a named shape) and the heading."""

    name: str
    shape: str
    heading: int

    @property
    def state(self) -> int:
        return shape_index(self.shape)

    def pose(self, x: int, y: int) -> Pose:
        return Pose(x, y, self.shape, self.heading)


def _layer(token) -> Layer:
    if not isinstance(token, str):
        raise UnknownShapeError(f"unknown layer {reprlib.repr(token)}: expected {_FORMS}")
    text = token.strip()
    if text in _ALIASES:
        shape, heading = _ALIASES[text]
    else:
        match = re.fullmatch(r"([IOLJZST])@([0-3])", text)
        if not match:
            raise UnknownShapeError(f"unknown layer {token!r}: expected {_FORMS}")
        shape, heading = match.group(1), int(match.group(2))
    name = next((alias for alias, value in _ALIASES.items() if value == (shape, heading)), f"{shape}@{heading}")
    return Layer(name, shape, heading)


def parse_layers(layers) -> tuple[Layer, ...]:
    """The morphology set S: layers from tokens (a comma-separated string or a sequence).

    ``O``, ``vI`` and ``hI`` are the paper's three; ``SHAPE@H`` is any named shape at heading H
    (``I@0`` is ``vI``, which is also the name it gets). A repeated layer counts once.

    Raises
    ------
    UnknownShapeError
        Naming the token and the accepted forms.

    Examples
    --------
    >>> [layer.name for layer in parse_layers("O, hI, I@0, L@1")]
    ['O', 'hI', 'vI', 'L@1']
    >>> parse_layers("Q")
    Traceback (most recent call last):
    ...
    htetro_opt.errors.UnknownShapeError: unknown layer 'Q': expected O, vI, hI or SHAPE@H (a shape of I O L J Z S T and a heading 0-3, e.g. L@1)
    """
    if isinstance(layers, Layer):
        return (layers,)
    if isinstance(layers, str):
        tokens = [t for t in re.split(r"[,\s]+", layers) if t]
    elif isinstance(layers, Iterable):
        tokens = [t.name if isinstance(t, Layer) else t for t in layers]
    else:
        raise UnknownShapeError(f"layers must be a string or a sequence of layer tokens ({_FORMS}), "
                                f"got {reprlib.repr(layers)}")
    parsed = list(dict.fromkeys(_layer(t) for t in tokens))
    if not parsed:
        raise UnknownShapeError(f"layers must name at least one layer: {_FORMS}")
    return tuple(parsed)


class LayerGraph:
    """The workspace graph of one map and morphology set, as integer arrays (Def. 4–5).

    Parameters
    ----------
    workspace : Workspace
    layers : str or sequence
        The morphology set S (:func:`parse_layers`).
    clearance : float, keyword-only
        δ in cells (MODEL.md §4), for every validity check.

    Attributes
    ----------
    sim : Simulator
        On Cheng et al. 2019's 13 commands, compiled on first use: every edge is one of its valid
        transitions, found from its table's rows at a few thousand cells at a time
        (:func:`~htetro_opt.model.simulate.transitions_at`), never the whole table.
    layers : tuple of Layer
    valid : ndarray of bool, shape (L, H, W)
        The layer's pose with B2 on the cell is free.
    move : ndarray of bool, shape (L, 4, H, W)
        The translation :data:`MOVES` ``[d]`` is valid from there.
    switch_cost : ndarray of int, shape (L, L, H, W)
        Fewest block commands from layer a to layer b with B2 on the cell, −1 where impossible
        (0 on the diagonal where the pose is valid).
    footprint : ndarray of int, shape (N,  4)
        Flat cells ``y * W + x`` of every vertex's four blocks (meaningless where not valid).

    Examples
    --------
    >>> lg = LayerGraph(Workspace(np.zeros((8, 8), dtype=bool)), "O,vI,hI")
    >>> [int(lg.switch_cost[a, b, 4, 4]) for a, b in ((1, 2), (1, 0), (0, 2))]  # vI-hI, vI-O, O-hI
    [1, 2, 3]
    >>> lg.switch_tokens((4, 4), 1, 0)
    ['3r', '3r']
    """

    def __init__(self, workspace: Workspace, layers, *, clearance: float = 0.0) -> None:
        check_workspace(workspace)
        self.layers = parse_layers(layers)
        self.workspace = workspace
        self.clearance = clearance
        self.tables = sweep_tables(clearance)
        self.command_ids = np.array(command_set(tokens=SEED004_COMMANDS), dtype=np.int64)
        self.width, self.height = workspace.width, workspace.height
        hw = self.width * self.height
        self.n_layers = L = len(self.layers)
        self.n_nodes = L * hw
        self._pose_base = np.array([(layer.state * 4 + layer.heading) * hw for layer in self.layers], dtype=np.int64)
        self._pose_ids = (self._pose_base[:, None] + np.arange(hw)[None, :]).reshape(-1)  # simulator pose ids

        def column(token: str) -> int:
            return int(np.flatnonzero(self.command_ids == command_id(token))[0])

        self._stop, self._moves = column("stop"), [column(t) for t in MOVES]
        self._switch_columns = [column(t) for t in SWITCH_COMMANDS]
        self._cell_rows: dict = {}  # cell -> its transitions, for switch_tokens
        valid = np.zeros((L, hw), dtype=bool)
        move = np.zeros((L, 4, hw), dtype=bool)
        cost = np.full((L, L, hw), -1, dtype=np.int64)
        # B2's cell is one of every pose's cells: only free cells have a valid pose, and a block command keeps
        # B2 where it is, so each cell's switches are its own (the chunks are independent)
        free = np.flatnonzero(~workspace.occupancy.reshape(-1))
        for lo in range(0, len(free), _CHUNK_CELLS):
            cells = free[lo:lo + _CHUNK_CELLS]
            self._chunk(cells, valid, move, cost)
        self.valid = valid.reshape(L, self.height, self.width)
        self.move = move.reshape(L, 4, self.height, self.width)
        self.switch_cost = cost.reshape(L, L, self.height, self.width)
        xs, ys = np.meshgrid(np.arange(self.width), np.arange(self.height))
        fp = np.stack([FOOTPRINTS[layer.state, layer.heading] for layer in self.layers])  # (L, 4, 2)
        fx = xs.reshape(1, hw, 1) + fp[:, None, :, 0]
        fy = ys.reshape(1, hw, 1) + fp[:, None, :, 1]
        self.footprint = (fy.clip(0, self.height - 1) * self.width + fx.clip(0, self.width - 1)).reshape(-1, 4)
        self._fy = fy.reshape(-1, 4)

    def _rows(self, cells: np.ndarray) -> np.ndarray:
        """The simulator's ``next`` rows at some flat cells, shape (n, states, 4, commands), −1 where dead
        (:func:`~htetro_opt.model.simulate.transitions_at`: the same sweep check as the table's)."""
        xy = np.column_stack([cells % self.width, cells // self.width])
        return transitions_at(self.workspace, xy, commands=SEED004_COMMANDS, clearance=self.clearance)

    def _chunk(self, cells: np.ndarray, valid, move, cost) -> None:
        """``valid``, ``move`` and ``switch_cost`` at some free cells, from their rows of the transition table:
        one breadth-first search over the block commands per source layer, every cell of the chunk at once."""
        rows = self._rows(cells)  # (n, S, 4, C)
        n, n_states = rows.shape[:2]
        per_cell = n_states * N_HEADINGS
        hw = self.width * self.height
        states = [(layer.state, layer.heading) for layer in self.layers]
        for a, (s, h) in enumerate(states):
            valid[a, cells] = rows[:, s, h, self._stop] >= 0
            for d, c in enumerate(self._moves):
                move[a, d, cells] = (rows[:, s, h, c] >= 0) & valid[a, cells]
        switch = rows[..., self._switch_columns].reshape(n, per_cell, len(self._switch_columns))
        ok = switch >= 0
        if (ok & (switch % hw != cells[:, None, None])).any():
            raise PlanningError("internal error: a block command moved B2 off its cell")
        # a block command's target (state, heading) does not depend on the cell, only whether it is valid there:
        # cells with the same valid block commands have the same switch costs, searched once (most of a map's
        # cells are open floor, one pattern)
        packed = np.packbits(ok.reshape(n, -1), axis=1)
        keys = np.ascontiguousarray(packed).view(np.dtype((np.void, packed.shape[1]))).ravel()
        _, first, inverse = np.unique(keys, return_index=True, return_inverse=True)
        inverse = inverse.ravel()
        n_patterns = len(first)
        local = np.where(ok[first], np.arange(n_patterns)[:, None, None] * per_cell + switch[first] // hw, -1).reshape(
            n_patterns * per_cell, -1)
        dead = n_patterns * per_cell
        local[local < 0] = dead
        local = np.vstack([local, np.full((1, local.shape[1]), dead)])
        ids = inverse * per_cell
        for a, (s, h) in enumerate(states):
            dist = self._block_distances(local, np.arange(n_patterns) * per_cell + s * N_HEADINGS + h, dead)
            for b, (s2, h2) in enumerate(states):
                cost[a, b, cells] = np.where(valid[a, cells] & valid[b, cells], dist[ids + s2 * N_HEADINGS + h2], -1)

    @staticmethod
    def _block_distances(local: np.ndarray, sources: np.ndarray, dead: int) -> np.ndarray:
        """Fewest block commands from any source pose to every pose of its cell (−1: none), B2 fixed;
        ``local`` the chunk's switch transitions in its own pose numbers (``dead``: none)."""
        dist = np.full(dead + 1, -1, dtype=np.int64)
        dist[sources] = 0
        frontier, k = sources, 0
        fresh = np.zeros(len(dist), dtype=bool)
        while len(frontier):
            k += 1
            reached = local[frontier].ravel()
            reached = reached[reached != dead]
            reached = reached[dist[reached] < 0]
            dist[reached] = k
            # the new poses, sorted and each once (np.unique, by hashing, took 3.9 s on a 128 x 128 map)
            fresh[reached] = True
            frontier = np.flatnonzero(fresh)
            fresh[frontier] = False
        return dist[:-1]

    @cached_property
    def sim(self) -> Simulator:
        """The map's :class:`~htetro_opt.model.Simulator` on Cheng et al. 2019's 13 commands, compiled on
        first use (the tiling-tsp baseline's legs; the planner itself needs only rows of its table, and the
        whole table is (92 poses a cell x cells + 1) x 14 int32, ~760 MB at 384 x 384, twice that once run)."""
        return Simulator(self.workspace, commands=SEED004_COMMANDS, clearance=self.clearance)

    def check_pose(self, pose, what: str = "pose") -> int:
        """The simulator's check of a pose (inside the map, collision-free), without compiling it: its pose id.

        Raises
        ------
        ConfigurationError
            Naming ``what`` and the offending cells.
        """
        return _check_pose(self.workspace, self.tables, N_STATES, pose, what, None)

    # --- vertices ------------------------------------------------------------------------------
    def node(self, layer: int, x: int, y: int) -> int:
        return (layer * self.height + y) * self.width + x

    def node_of(self, pose: Pose) -> int | None:
        """The vertex of a pose, None if its (shape, heading) is not a layer of S."""
        for i, layer in enumerate(self.layers):
            if (layer.shape, layer.heading) == (pose.shape, pose.heading):
                return self.node(i, pose.x, pose.y)
        return None

    def decode(self, v: int) -> tuple[int, int, int]:
        """(layer, x, y) of a vertex."""
        layer, cell = divmod(int(v), self.width * self.height)
        return layer, cell % self.width, cell // self.width

    def pose(self, v: int) -> Pose:
        layer, x, y = self.decode(v)
        return self.layers[layer].pose(x, y)

    def pose_id(self, v: int) -> int:
        """The simulator's pose id of a vertex."""
        return int(self._pose_ids[v])

    @cached_property
    def node_valid(self) -> np.ndarray:
        """``valid`` flattened to vertex ids, shape (N,)."""
        return self.valid.reshape(-1)

    @cached_property
    def rows(self) -> tuple[np.ndarray, np.ndarray]:
        """Lowest and highest footprint row of every vertex."""
        return self._fy.min(axis=1), self._fy.max(axis=1)

    @cached_property
    def gain(self) -> int:
        """Most cells one command of S adds to the union of visited footprints (the search's g):
        the largest translation gain of a layer, and 3 for a switch (B2's cell is shared)."""
        best = 3 if self.n_layers > 1 else 1
        for layer in self.layers:
            cells = {tuple(c) for c in FOOTPRINTS[layer.state, layer.heading].tolist()}
            for dx, dy in _SHIFTS.values():
                best = max(best, len({(x + dx, y + dy) for x, y in cells} - cells))
        return best

    # --- edges ---------------------------------------------------------------------------------
    @cached_property
    def edges(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(source, target, cost)`` of every directed edge: translations, then switches."""
        hw, w = self.width * self.height, self.width
        src, dst, cost = [], [], []
        for d, token in enumerate(MOVES):
            dx, dy = _SHIFTS[token]
            v = np.flatnonzero(self.move[:, d].reshape(-1))
            src.append(v)
            dst.append(v + dx + dy * w)
            cost.append(np.ones(len(v), dtype=np.int64))
        flat = self.switch_cost.reshape(self.n_layers, self.n_layers, hw)
        for a in range(self.n_layers):
            for b in range(self.n_layers):
                if a != b:
                    cells = np.flatnonzero(flat[a, b] > 0)
                    src.append(a * hw + cells)
                    dst.append(b * hw + cells)
                    cost.append(flat[a, b, cells])
        return np.concatenate(src), np.concatenate(dst), np.concatenate(cost)

    @cached_property
    def matrix(self) -> csr_matrix:
        """The graph as a sparse matrix of edge costs (scipy.sparse.csgraph's input)."""
        src, dst, cost = self.edges
        return csr_matrix((cost.astype(float), (src, dst)), shape=(self.n_nodes, self.n_nodes))

    def edge_tokens(self, u: int, v: int) -> list[str]:
        """The commands of the edge u → v: one translation, or the switch's block commands."""
        lu, xu, yu = self.decode(u)
        lv, xv, yv = self.decode(v)
        if lu == lv:
            shift = (xv - xu, yv - yu)
            for token, value in _SHIFTS.items():
                if value == shift:
                    return [token]
        elif (xu, yu) == (xv, yv):
            return self.switch_tokens((xu, yu), lu, lv)
        raise PlanningError(f"internal error: no edge from {self.pose(u)} to {self.pose(v)}")

    def switch_tokens(self, cell, a: int, b: int) -> list[str]:
        """The block commands of the cheapest switch from layer a to layer b at a cell (B2 fixed),
        ties broken by Table 1's command order (a breadth-first search at that cell).

        Raises
        ------
        PlanningError
            If no valid switch exists there.
        """
        x, y = (int(c) for c in cell)
        flat = y * self.width + x
        rows = self._cell_rows.get(flat)
        if rows is None:
            self._fetch(np.array([flat]))
            rows = self._cell_rows[flat]
        hw = self.width * self.height
        # poses of this cell by (state, heading): a block command keeps B2 on it (the table's rows, −1 dead)
        start = self.layers[a].state * N_HEADINGS + self.layers[a].heading
        goal = self.layers[b].state * N_HEADINGS + self.layers[b].heading
        parent = {start: None}
        queue = deque([start])
        while queue and goal not in parent:
            p = queue.popleft()
            for token, q in zip(SWITCH_COMMANDS, rows[p].tolist()):
                if q >= 0 and q // hw not in parent:
                    parent[q // hw] = (p, token)
                    queue.append(q // hw)
        if goal not in parent:
            raise PlanningError(f"no switch from layer {self.layers[a].name} to {self.layers[b].name} at ({x}, {y})")
        tokens = []
        while parent[goal] is not None:
            goal, token = parent[goal]
            tokens.append(token)
        return tokens[::-1]

    def _fetch(self, cells: np.ndarray) -> None:
        """The block commands' rows of the transition table at some cells, for :meth:`switch_tokens`: one
        :func:`~htetro_opt.model.simulate.transitions_at` call for them all (its set-up, ~5 ms, was most of
        a call for one cell), int32, the cache emptied first when it is full."""
        if len(self._cell_rows) + len(cells) > _CHUNK_CELLS:
            self._cell_rows.clear()
        rows = self._rows(cells)[..., self._switch_columns].astype(np.int32)
        rows = rows.reshape(len(cells), -1, len(self._switch_columns))
        self._cell_rows.update(zip(cells.tolist(), rows))

    def commands_of(self, path: list[int]) -> list[str]:
        """The command tokens that drive a vertex path."""
        tokens: list[str] = []
        hw = self.width * self.height
        step = _CHUNK_CELLS // 2
        for lo in range(0, len(path) - 1, step):
            part = np.asarray(path[lo:lo + step + 1], dtype=np.int64)
            switch = (part[:-1] // hw != part[1:] // hw) & (part[:-1] % hw == part[1:] % hw)
            cells = np.unique(part[:-1][switch] % hw)
            cells = cells[[c not in self._cell_rows for c in cells.tolist()]] if len(cells) else cells
            if len(cells):
                self._fetch(cells)
            for u, v in zip(part[:-1].tolist(), part[1:].tolist()):
                tokens += self.edge_tokens(u, v)
        return tokens


def workspace_graph(lg: LayerGraph):
    """The workspace graph G of Def. 5 as a ``networkx.Graph``, for inspection, tests and small maps.

    Nodes are ``(layer name, x, y)`` for every valid vertex; edges carry ``weight`` (commands) and
    ``kind`` (``"translation"`` or ``"switch"``). The planner itself works on :class:`LayerGraph`'s arrays.

    Examples
    --------
    >>> g = workspace_graph(LayerGraph(Workspace(np.zeros((4, 4), dtype=bool)), "O"))
    >>> g.number_of_nodes(), g.number_of_edges()  # a 3 x 3 grid of O poses
    (9, 12)
    """
    import networkx as nx

    g = nx.Graph()
    for v in np.flatnonzero(lg.node_valid):
        layer, x, y = lg.decode(v)
        g.add_node((lg.layers[layer].name, x, y), pose=lg.pose(v))
    src, dst, cost = lg.edges
    for u, v, c in zip(src.tolist(), dst.tolist(), cost.tolist()):
        lu, xu, yu = lg.decode(u)
        lv, xv, yv = lg.decode(v)
        g.add_edge((lg.layers[lu].name, xu, yu), (lg.layers[lv].name, xv, yv), weight=c,
                   kind="translation" if lu == lv else "switch")
    return g


def stripe_graph(graph, rows):
    """The stripe layer graph SLG_k of Def. 7: the subgraph view of :func:`workspace_graph`'s graph
    induced by the vertices whose footprints lie in ``rows = (lowest, highest + 1)``.

    Examples
    --------
    >>> g = workspace_graph(LayerGraph(Workspace(np.zeros((4, 4), dtype=bool)), "O"))
    >>> sorted(stripe_graph(g, (0, 2)).nodes)
    [('O', 0, 1), ('O', 1, 1), ('O', 2, 1)]
    """
    low, high = rows
    keep = [n for n, data in graph.nodes(data=True)
            if low <= int(data["pose"].cells()[:, 1].min()) and int(data["pose"].cells()[:, 1].max()) < high]
    return graph.subgraph(keep)

