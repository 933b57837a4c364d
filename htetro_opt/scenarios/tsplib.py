"""TSPLIB ``.tsp`` files (Reinelt 1991, "TSPLIB — a traveling salesman problem library"): the costs of a
symmetric (TSP) or asymmetric (ATSP) instance, under TSPLIB's own rounding: its coordinates and their
metric, or its explicit matrix. A coordinate instance's matrix (:attr:`TsplibInstance.cost`) is built only
when asked for; ``SequencingInstance.from_tsplib`` keeps the types of :data:`IMPLICIT_TYPES` as coordinates.

Read: ``TYPE`` TSP or ATSP; ``EDGE_WEIGHT_TYPE``

- ``EUC_2D`` / ``EUC_3D``: ``nint(√(Δx² + Δy²))``, ``nint(v) = ⌊v + 0.5⌋``; ``CEIL_2D``: ``⌈√…⌉``;
  ``MAN_2D`` / ``MAN_3D``: ``nint(|Δx| + |Δy|)``; ``MAX_2D`` / ``MAX_3D``: ``max(nint|Δx|, nint|Δy|)``;
- ``ATT`` (pseudo-Euclidean): ``r = √((Δx² + Δy²) / 10)``, ``t = nint(r)``, ``t + 1`` if ``t < r`` else ``t``;
- ``GEO``: coordinates are degrees.minutes (``DDD.MM``); ``lat = π (deg + 5 min / 3) / 180`` with
  ``deg`` the integer part (truncated, as TSPLIB's FAQ and its published optima have it, not
  ``nint`` as the 1995 document prints), ``π = 3.141592``, and
  ``d = ⌊6378.388 · acos(½((1 + q1) q2 − (1 − q1) q3)) + 1⌋`` with ``q1 = cos(lon_i − lon_j)``,
  ``q2 = cos(lat_i − lat_j)``, ``q3 = cos(lat_i + lat_j)``;
- ``EXPLICIT`` with ``EDGE_WEIGHT_FORMAT`` ``FULL_MATRIX`` (the only one for ATSP), ``UPPER_ROW``,
  ``LOWER_ROW``, ``UPPER_DIAG_ROW``, ``LOWER_DIAG_ROW`` and their ``…_COL`` twins (a column-wise upper
  triangle lists what the row-wise lower one does).

``DISPLAY_DATA_SECTION`` is skipped; ``FIXED_EDGES_SECTION``, other problem types (HCP, CVRP, SOP)
and other edge-weight types are refused with a :class:`~htetro_opt.errors.ScenarioError` naming them.
Node numbers are 1…n in the file and 0…n−1 in the matrix.

Examples
--------
>>> tsp = parse_tsplib('''NAME : square
... TYPE : TSP
... DIMENSION : 4
... EDGE_WEIGHT_TYPE : EUC_2D
... NODE_COORD_SECTION
... 1 0 0
... 2 0 3
... 3 4 3
... 4 4 0
... EOF''')
>>> tsp.name, tsp.cost[0].tolist()   # √(4² + 3²) = 5
('square', [0.0, 3.0, 5.0, 4.0])
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path

import numpy as np

from htetro_opt.errors import ScenarioError
from htetro_opt.scenarios._paths import as_path

__all__ = ["TsplibInstance", "EDGE_WEIGHT_TYPES", "EDGE_WEIGHT_FORMATS", "IMPLICIT_TYPES", "tsplib_distances",
           "tsplib_legs", "parse_tsplib", "load_tsplib"]

_COORDINATE_TYPES = {"EUC_2D": 2, "CEIL_2D": 2, "MAN_2D": 2, "MAX_2D": 2, "ATT": 2, "GEO": 2,
                     "EUC_3D": 3, "MAN_3D": 3, "MAX_3D": 3}
EDGE_WEIGHT_TYPES: tuple[str, ...] = ("EXPLICIT",) + tuple(_COORDINATE_TYPES)
"""The ``EDGE_WEIGHT_TYPE`` values read."""

# format → (upper triangle?, diagonal included?), or None for the full matrix
_FORMATS = {"FULL_MATRIX": None, "UPPER_ROW": (True, False), "LOWER_ROW": (False, False),
            "UPPER_DIAG_ROW": (True, True), "LOWER_DIAG_ROW": (False, True), "UPPER_COL": (False, False),
            "LOWER_COL": (True, False), "UPPER_DIAG_COL": (False, True), "LOWER_DIAG_COL": (True, True)}
EDGE_WEIGHT_FORMATS: tuple[str, ...] = tuple(_FORMATS)
"""The ``EDGE_WEIGHT_FORMAT`` values read with ``EDGE_WEIGHT_TYPE: EXPLICIT``."""

_SECTIONS = ("NODE_COORD_SECTION", "EDGE_WEIGHT_SECTION", "DISPLAY_DATA_SECTION", "FIXED_EDGES_SECTION",
             "DEPOT_SECTION", "DEMAND_SECTION", "TOUR_SECTION")
_KEY = re.compile(r"^\s*([A-Z_]+)\s*(?::\s*(.*?))?\s*$")


IMPLICIT_TYPES: tuple[str, ...] = ("EUC_2D", "CEIL_2D", "ATT", "GEO")
"""The coordinate types whose :class:`~htetro_opt.problems.SequencingInstance` keeps its costs implicit
(coordinates and the metric, no n × n matrix: ``SequencingInstance.from_tsplib``); the other types' instances
hold :attr:`TsplibInstance.cost`."""


@dataclass(frozen=True, eq=False)  # holds arrays: identity equality
class TsplibInstance:
    """A TSPLIB instance: its coordinates or explicit weights, and what the header said.

    ``coords`` holds the node coordinates as the file gives them (``DDD.MM`` for ``GEO``; None for
    ``EXPLICIT``), ``weights`` the matrix of an ``EXPLICIT`` section (None for coordinates).
    :attr:`cost` is the cost matrix under TSPLIB's rounding, ``cost[i, j]`` the cost from node ``i + 1``
    to node ``j + 1`` (integers, as floats), built from the coordinates when first asked for: 8·n²
    bytes, which a large instance need not pay (``SequencingInstance.from_tsplib``).
    """

    name: str
    type: str
    edge_weight_type: str
    weights: np.ndarray | None = None
    coords: np.ndarray | None = None
    comment: str = ""

    @property
    def dimension(self) -> int:
        return len(self.weights) if self.coords is None else len(self.coords)

    @cached_property
    def cost(self) -> np.ndarray:
        """The (n, n) cost matrix (read-only), computed from the coordinates at the first call."""
        if self.weights is not None:
            return self.weights
        cost = tsplib_distances(self.coords, self.edge_weight_type)
        cost.setflags(write=False)
        return cost


def _nint(v: np.ndarray) -> np.ndarray:
    return np.floor(v + 0.5)


def _geo_radians(v: np.ndarray) -> np.ndarray:
    degrees = np.trunc(v)
    return 3.141592 * (degrees + 5.0 * (v - degrees) / 3.0) / 180.0


def _check_coordinates(coords, edge_weight_type: str) -> tuple[str, np.ndarray]:
    """(the type, upper case; the coordinates as an (n, k) float array), validated."""
    kind = str(edge_weight_type).upper()
    if kind not in _COORDINATE_TYPES:
        raise ScenarioError(f"unknown TSPLIB EDGE_WEIGHT_TYPE {edge_weight_type!r}: expected one of "
                            f"{', '.join(_COORDINATE_TYPES)} for coordinates")
    try:
        x = np.asarray(coords, dtype=float)
    except (TypeError, ValueError) as err:
        raise ScenarioError(f"TSPLIB coordinates must be numbers, got {coords!r}") from err
    k = _COORDINATE_TYPES[kind]
    if x.ndim != 2 or x.shape[1] != k:
        raise ScenarioError(f"{kind} needs {k} coordinates per node, got shape {x.shape}")
    return kind, x


def _metric(xa: np.ndarray, xb: np.ndarray, kind: str) -> np.ndarray:
    """TSPLIB's distance between the coordinate rows ``xa`` and ``xb`` (broadcast; the last axis the
    coordinates), the same nodes included (GEO gives them 1: callers zero them)."""
    if kind == "GEO":
        lat_a, lon_a = _geo_radians(xa[..., 0]), _geo_radians(xa[..., 1])
        lat_b, lon_b = _geo_radians(xb[..., 0]), _geo_radians(xb[..., 1])
        q1 = np.cos(lon_a - lon_b)
        q2 = np.cos(lat_a - lat_b)
        q3 = np.cos(lat_a + lat_b)
        arc = np.arccos(np.clip(0.5 * ((1.0 + q1) * q2 - (1.0 - q1) * q3), -1.0, 1.0))
        return np.floor(6378.388 * arc + 1.0)
    delta = np.abs(xa - xb)
    if kind.startswith("MAN"):
        return _nint(delta.sum(-1))
    if kind.startswith("MAX"):
        return _nint(delta).max(-1)
    if kind == "ATT":
        r = np.sqrt((delta ** 2).sum(-1) / 10.0)
        t = _nint(r)
        return np.where(t < r, t + 1.0, t)
    if kind == "CEIL_2D":
        return np.ceil(np.sqrt((delta ** 2).sum(-1)))
    return _nint(np.sqrt((delta ** 2).sum(-1)))


def tsplib_legs(coords, edge_weight_type: str, a, b) -> np.ndarray:
    """TSPLIB's distances of the legs ``a[k] → b[k]`` (node indices 0…n−1), without a matrix.

    Raises
    ------
    ScenarioError
        As :func:`tsplib_distances`.

    Examples
    --------
    >>> tsplib_legs([[0, 0], [3, 4], [1, 1]], "EUC_2D", [0, 0, 2], [1, 2, 2]).tolist()   # √2 → 1; itself 0
    [5.0, 1.0, 0.0]
    """
    kind, x = _check_coordinates(coords, edge_weight_type)
    a, b = np.asarray(a, dtype=np.int64), np.asarray(b, dtype=np.int64)
    return np.where(a == b, 0.0, _metric(x[a], x[b], kind))


def tsplib_distances(coords, edge_weight_type: str) -> np.ndarray:
    """The (n, n) matrix of TSPLIB distances between node coordinates (module docstring).

    Computed a block of rows at a time, so that its temporaries stay near 64 MB whatever n: the
    matrix itself is 8·n² bytes.

    Raises
    ------
    ScenarioError
        On an edge-weight type that is not a coordinate type of :data:`EDGE_WEIGHT_TYPES`, or
        coordinates of the wrong shape.

    Examples
    --------
    >>> tsplib_distances([[0, 0], [3, 4], [1, 1]], "ATT").tolist()[0]   # √(25/10) = 1.58 → 2; √(2/10) → 1
    [0.0, 2.0, 1.0]
    """
    kind, x = _check_coordinates(coords, edge_weight_type)
    n = len(x)
    d = np.empty((n, n))
    step = max(1, (1 << 20) // max(1, n))  # rows a block: about 8 MB a temporary
    for r in range(0, n, step):
        d[r:r + step] = _metric(x[r:r + step, None, :], x[None, :, :], kind)
    np.fill_diagonal(d, 0.0)
    return d


class _Reader:
    """Line-by-line reading with the file name and line number in every error."""

    def __init__(self, text: str, where: str):
        self.lines = text.splitlines()
        self.where = where
        self.i = 0

    def error(self, message: str, line: int | None = None) -> ScenarioError:
        line = self.i if line is None else line
        return ScenarioError(f"{self.where}, line {line}: {message}" if line else f"{self.where}: {message}")

    def numbers(self) -> tuple[list[str], int]:
        """The whitespace-separated tokens up to the next keyword line or EOF, and the first line."""
        tokens, first = [], self.i + 1
        while self.i < len(self.lines):
            line = self.lines[self.i].strip()
            head = line.split(":", 1)[0].split()[0] if line else ""
            if head == "EOF" or head in _SECTIONS or (re.fullmatch(r"[A-Z_]+", head) and ":" in line):
                break
            self.i += 1
            tokens.extend(line.split())
        return tokens, first


def _floats(reader: _Reader, tokens: list[str], first: int, what: str) -> np.ndarray:
    try:
        return np.array([float(t) for t in tokens], dtype=float)
    except ValueError:
        bad = next(t for t in tokens if not _is_number(t))
        raise reader.error(f"{what} must be numbers, got {bad!r}", first) from None


def _is_number(token: str) -> bool:
    try:
        float(token)
    except ValueError:
        return False
    return True


def _explicit(reader: _Reader, values: np.ndarray, n: int, fmt: str, first: int) -> np.ndarray:
    layout = _FORMATS[fmt]
    if layout is None:
        expected = n * n
    else:
        upper, diagonal = layout
        expected = n * (n + 1) // 2 if diagonal else n * (n - 1) // 2
    if len(values) != expected:
        raise reader.error(f"EDGE_WEIGHT_SECTION in {fmt} of DIMENSION {n} needs {expected} numbers, "
                           f"got {len(values)}", first)
    if layout is None:
        return values.reshape(n, n).copy()
    rows, cols = (np.triu_indices(n, 0 if diagonal else 1) if upper else np.tril_indices(n, 0 if diagonal else -1))
    m = np.zeros((n, n))
    m[rows, cols] = values  # both index sets run row by row, as the format lists the numbers
    m[cols, rows] = values
    return m


def parse_tsplib(text: str, *, where: str = "TSPLIB text") -> TsplibInstance:
    """Read a TSPLIB ``.tsp`` (or ``.atsp``) text.

    Parameters
    ----------
    text : str
        The file's content.
    where : str, keyword-only
        Its name in error messages (a file path).

    Returns
    -------
    TsplibInstance
        The cost matrix under TSPLIB's rounding (module docstring).

    Raises
    ------
    ScenarioError
        Naming the line: an unsupported TYPE, EDGE_WEIGHT_TYPE or EDGE_WEIGHT_FORMAT, a missing or
        bad DIMENSION, a section with too few or too many numbers, node numbers outside 1…n or
        repeated, a FIXED_EDGES_SECTION, or no data section.

    Examples
    --------
    >>> parse_tsplib('''TYPE: TSP
    ... DIMENSION: 3
    ... EDGE_WEIGHT_TYPE: EXPLICIT
    ... EDGE_WEIGHT_FORMAT: UPPER_ROW
    ... EDGE_WEIGHT_SECTION
    ... 1 2
    ... 3
    ... EOF''').cost.tolist()
    [[0.0, 1.0, 2.0], [1.0, 0.0, 3.0], [2.0, 3.0, 0.0]]
    """
    if not isinstance(text, str):
        raise ScenarioError(f"TSPLIB text must be a str, got {type(text).__name__}")
    reader = _Reader(text, where)
    header: dict[str, tuple[str, int]] = {}
    comments = []
    coords = weights = None
    while reader.i < len(reader.lines):
        line = reader.lines[reader.i].strip()
        reader.i += 1
        if not line:
            continue
        match = _KEY.match(line)
        key = match.group(1) if match else None
        if key == "EOF":
            break
        if key in _SECTIONS:
            tokens, first = reader.numbers()
            if key == "NODE_COORD_SECTION":
                coords = (tokens, first)
            elif key == "EDGE_WEIGHT_SECTION":
                weights = (tokens, first)
            elif key != "DISPLAY_DATA_SECTION":
                raise reader.error(f"{key} is not supported (only the cost matrix of a TSP or ATSP is read)", first - 1)
            continue
        if match is None or match.group(2) is None:
            raise reader.error(f"expected 'KEY : VALUE' or a section name, got {line!r}")
        if key == "COMMENT":
            comments.append(match.group(2))
        else:
            header[key] = (match.group(2), reader.i)

    def value(key: str, default: str | None = None) -> str | None:
        return header[key][0].strip().upper() if key in header else default

    kind = value("TYPE", "TSP")
    if kind not in ("TSP", "ATSP"):
        raise reader.error(f"TYPE {kind} is not supported: expected TSP or ATSP", header["TYPE"][1])
    if "DIMENSION" not in header:
        raise reader.error("DIMENSION is missing")
    try:
        n = int(header["DIMENSION"][0])
    except ValueError:
        n = 0
    if n < 1:
        raise reader.error(f"DIMENSION must be a positive integer, got {header['DIMENSION'][0]!r}",
                           header["DIMENSION"][1])
    weight_type = value("EDGE_WEIGHT_TYPE")
    if weight_type is None:
        raise reader.error("EDGE_WEIGHT_TYPE is missing")
    if weight_type not in EDGE_WEIGHT_TYPES:
        raise reader.error(f"unknown EDGE_WEIGHT_TYPE {weight_type}: expected one of {', '.join(EDGE_WEIGHT_TYPES)}",
                           header["EDGE_WEIGHT_TYPE"][1])
    name = header["NAME"][0].strip() if "NAME" in header else Path(where).stem
    node_coords = None
    if weight_type == "EXPLICIT":
        fmt = value("EDGE_WEIGHT_FORMAT", "FULL_MATRIX" if kind == "ATSP" else None)
        if fmt not in _FORMATS:
            line = header["EDGE_WEIGHT_FORMAT"][1] if "EDGE_WEIGHT_FORMAT" in header else None
            raise reader.error(f"EDGE_WEIGHT_FORMAT {fmt} is not supported: expected one of "
                               f"{', '.join(EDGE_WEIGHT_FORMATS)}", line)
        if kind == "ATSP" and fmt != "FULL_MATRIX":
            raise reader.error(f"an ATSP needs EDGE_WEIGHT_FORMAT FULL_MATRIX, got {fmt}", header["EDGE_WEIGHT_FORMAT"][1])
        if weights is None:
            raise reader.error("EDGE_WEIGHT_TYPE EXPLICIT needs an EDGE_WEIGHT_SECTION")
        values = _floats(reader, weights[0], weights[1], "edge weights")
        cost = _explicit(reader, values, n, fmt, weights[1])
        if not np.isfinite(cost).all():
            raise reader.error("edge weights must be finite", weights[1])
    else:
        if coords is None:
            raise reader.error(f"EDGE_WEIGHT_TYPE {weight_type} needs a NODE_COORD_SECTION")
        k = _COORDINATE_TYPES[weight_type]
        tokens, first = coords
        values = _floats(reader, tokens, first, "node coordinates")
        if len(values) != n * (k + 1):
            raise reader.error(f"NODE_COORD_SECTION of DIMENSION {n} needs {n} lines of a node number and {k} "
                               f"coordinates ({n * (k + 1)} numbers), got {len(values)} numbers", first)
        rows = values.reshape(n, k + 1)
        ids = rows[:, 0]
        if not (np.all(ids == np.rint(ids)) and np.array_equal(np.sort(ids), np.arange(1, n + 1))):
            raise reader.error(f"NODE_COORD_SECTION must number the nodes 1…{n}, each once", first)
        node_coords = np.empty((n, k))
        node_coords[ids.astype(np.int64) - 1] = rows[:, 1:]
        if not np.isfinite(node_coords).all():
            raise reader.error("node coordinates must be finite", first)
    if weight_type == "EXPLICIT":
        cost.setflags(write=False)
    else:
        cost = None  # TsplibInstance.cost computes the matrix when first asked for
        node_coords.setflags(write=False)
    return TsplibInstance(name, kind, weight_type, cost, node_coords, " ".join(comments))


def load_tsplib(path: str | Path) -> TsplibInstance:
    """Read a TSPLIB file (see :func:`parse_tsplib`); the name defaults to the file's stem.

    Raises
    ------
    ScenarioError
        If the file cannot be read or is malformed.
    """
    path = as_path(path, "path")
    try:
        text = path.read_text(encoding="utf-8", errors="replace")
    except OSError as err:
        raise ScenarioError(f"cannot read TSPLIB file {str(path)!r}: {err.strerror or err}") from err
    return parse_tsplib(text, where=str(path))
