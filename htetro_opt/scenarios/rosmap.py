"""ROS ``map_server`` maps: a YAML file and its PGM image.

The YAML keys ``image``, ``resolution``, ``negate``, ``occupied_thresh`` and ``free_thresh`` are
honoured as map_server does in trinary mode: a pixel of value v (max value m) has occupancy
probability p = (m − v) / m (p = v / m when ``negate``); p > occupied_thresh is an obstacle,
p < free_thresh is free, anything between is unknown and treated as an obstacle. Image rows are top
first and are flipped so that row 0 is the bottom row. When a cell size larger than the resolution is
asked for, each cell gathers ``cell_size / resolution`` pixels a side and is free only if all are; the
image is padded with blocked pixels to whole cells (row 0 stays the image's bottom row).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import yaml

from htetro_opt._validation import check_real
from htetro_opt.errors import MapFormatError, ParameterError, ScenarioError
from htetro_opt.scenarios._paths import as_path

__all__ = ["read_pgm", "load_ros_map"]


def read_pgm(path: str | Path) -> tuple[np.ndarray, int]:
    """Read a binary (P5) or plain (P2) PGM image.

    Returns
    -------
    image : ndarray of int, shape (rows, cols), rows top first
    maxval : int
        The maximum pixel value of the header.
    """
    path = as_path(path, "path")
    try:
        data = path.read_bytes()
    except OSError as err:
        raise ScenarioError(f"{path}: cannot read image: {err.strerror or err}") from err
    tokens: list[bytes] = []
    pos = 0
    while len(tokens) < 4:
        while pos < len(data) and data[pos : pos + 1].isspace():
            pos += 1
        if data[pos : pos + 1] == b"#":
            while pos < len(data) and data[pos : pos + 1] not in (b"\n", b"\r"):
                pos += 1
            continue
        start = pos
        while pos < len(data) and not data[pos : pos + 1].isspace():
            pos += 1
        if start == pos:
            raise MapFormatError(f"{path}: truncated PGM header")
        tokens.append(data[start:pos])
    magic = tokens[0]
    if magic not in (b"P2", b"P5"):
        raise MapFormatError(f"{path}: not a PGM image (magic {magic!r}, expected P2 or P5)")
    try:
        width, height, maxval = (int(t) for t in tokens[1:])
    except ValueError as err:
        raise MapFormatError(f"{path}: malformed PGM header {tokens[1:]!r}") from err
    if width <= 0 or height <= 0 or not 0 < maxval < 65536:
        raise MapFormatError(f"{path}: bad PGM size {width} x {height} or max value {maxval}")
    if magic == b"P5":
        dtype = np.uint8 if maxval < 256 else np.dtype(">u2")
        body = data[pos + 1 :]
        need = width * height * np.dtype(dtype).itemsize
        if len(body) < need:
            raise MapFormatError(f"{path}: PGM data holds {len(body)} bytes, {need} expected")
        image = np.frombuffer(body[:need], dtype=dtype).reshape(height, width)
    else:
        try:
            values = [int(v) for v in data[pos:].split()]
        except ValueError as err:
            raise MapFormatError(f"{path}: non-numeric pixel in plain PGM") from err
        if len(values) != width * height:
            raise MapFormatError(f"{path}: {len(values)} pixels, {width * height} expected")
        image = np.array(values).reshape(height, width)
    image = image.astype(np.int64)
    if image.max(initial=0) > maxval:
        raise MapFormatError(f"{path}: pixel value above the header's max value {maxval}")
    return image, maxval


def load_ros_map(yaml_path: str | Path, *, cell_size: float | None = None) -> tuple[np.ndarray, float]:
    """Load a ROS map_server map as an occupancy grid.

    Parameters
    ----------
    yaml_path : str or Path
        The map's YAML file; its ``image`` is resolved relative to it.
    cell_size : float, optional, keyword-only
        Cell width in metres; a whole multiple of the map's resolution (default: the resolution).

    Returns
    -------
    occupancy : ndarray of bool, shape (H, W), ``occ[y, x]`` with row 0 at the bottom
    cell_size : float

    Raises
    ------
    ScenarioError
        If the YAML cannot be read or lacks a key, or the cell size is not a multiple of the resolution.
    MapFormatError
        If the image is not a valid PGM.
    """
    yaml_path = as_path(yaml_path, "yaml_path")
    try:
        cell_size = check_real(cell_size, "cell_size", minimum=0.0, include_minimum=False, allow_none=True)
    except ParameterError as err:
        raise ScenarioError(f"{yaml_path}: {err}") from err
    try:
        meta = yaml.safe_load(yaml_path.read_text(encoding="utf-8"))
    except OSError as err:
        raise ScenarioError(f"{yaml_path}: cannot read map: {err.strerror or err}") from err
    except UnicodeDecodeError as err:
        raise ScenarioError(f"{yaml_path}: not a text YAML file (give the map's .yaml, not its image)") from err
    except yaml.YAMLError as err:
        mark = getattr(err, "problem_mark", None)
        where = f" at line {mark.line + 1}, column {mark.column + 1}" if mark is not None else ""
        problem = getattr(err, "problem", None) or "cannot parse"
        raise ScenarioError(f"{yaml_path}: malformed YAML{where}: {problem}") from err
    if not isinstance(meta, dict):
        raise ScenarioError(f"{yaml_path}: a map YAML must be a mapping")
    for key in ("image", "resolution"):
        if key not in meta:
            raise ScenarioError(f"{yaml_path}: missing key {key!r}")
    values = {}
    for key, default, bounds in (("resolution", None, {"minimum": 0.0, "include_minimum": False}),
                                 ("occupied_thresh", 0.65, {"minimum": 0.0, "maximum": 1.0}),
                                 ("free_thresh", 0.196, {"minimum": 0.0, "maximum": 1.0})):
        value = meta.get(key, default)
        if isinstance(value, str):  # PyYAML reads 5e-2 (no dot) as a string
            try:
                value = float(value)
            except ValueError:
                pass  # check_real names it
        try:
            values[key] = check_real(value, repr(key), **bounds)
        except ParameterError as err:
            raise ScenarioError(f"{yaml_path}: {err}") from err
    resolution, occupied, free = values["resolution"], values["occupied_thresh"], values["free_thresh"]
    try:
        negate = bool(int(meta.get("negate", 0)))
    except (TypeError, ValueError) as err:
        raise ScenarioError(f"{yaml_path}: 'negate' must be 0 or 1, got {meta.get('negate')!r}") from err
    if free > occupied:
        raise ScenarioError(f"{yaml_path}: need free_thresh <= occupied_thresh, got {free:g} > {occupied:g}")
    if meta.get("mode", "trinary") not in ("trinary", "scale"):
        raise ScenarioError(f"{yaml_path}: map mode {meta['mode']!r} is not supported (trinary or scale)")
    image, maxval = read_pgm(yaml_path.parent / str(meta["image"]))
    p = image / maxval if negate else (maxval - image) / maxval
    blocked = ~(p < free)  # occupied and unknown pixels
    blocked = blocked[::-1]
    if cell_size is None or math.isclose(cell_size, resolution):
        return blocked, resolution
    factor = cell_size / resolution
    n = int(round(factor))
    if n < 1 or not math.isclose(factor, n, rel_tol=1e-6):
        raise ScenarioError(
            f"{yaml_path}: cell size {cell_size} m is not a whole multiple of the resolution {resolution} m"
        )
    # Pad to whole cells with blocked pixels: a cell partly off the image is not known to be free.
    h, w = -(-blocked.shape[0] // n), -(-blocked.shape[1] // n)
    padded = np.ones((h * n, w * n), dtype=bool)
    padded[: blocked.shape[0], : blocked.shape[1]] = blocked
    return padded.reshape(h, n, w, n).any(axis=(1, 3)), float(cell_size)
