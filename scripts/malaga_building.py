"""Make the bundled ``malaga_building`` ROS map from MRPT's laser scans of a real building.

The scans are ``malaga-cs-fac-building.simplemap.gz`` of MRPT (BSD-3-Clause): 99 laser scans with
their SLAM poses, taken in the Computer Science faculty building of the University of Málaga. They ship
in MRPT's repository at ``share/mrpt/datasets/`` and in Debian's ``mrpt-common`` package at
``/usr/share/mrpt/datasets/``; MRPT's ``observations2map`` (Debian's ``mrpt-apps``) turns them into
an occupancy grid. This script

1. runs ``observations2map`` with ``malaga_building.ini`` beside this file: one grid of 5 cm cells
   (1080 × 1220), a serialized ``COccupancyGridMap2D`` (class-name byte ``0x80 | len``, the name,
   the version byte, bits per cell 8, size_x and size_y as uint32, x_min, x_max, y_min, y_max and the
   resolution as float32, then size_x × size_y int8 cells, row 0 at y_min). A cell holds MRPT's
   log-odds l of the cell being *free*: p_free = 1 / (1 + exp(−l / 16)) (``CLogOddsGridMapLUT``),
   0 unknown;
2. crops the grid to the bounding box of its known cells (l ≠ 0), grown to whole blocks of
   ``FACTOR`` × ``FACTOR`` pixels (unknown pixels pad it);
3. keeps, of each block, its least free pixel (the smallest l): a bundled pixel is free under
   map_server's thresholds exactly when all of its source pixels are, since the thresholds on p are
   monotone in l;
4. writes that as a binary PGM with MRPT's own grey levels, v = ⌊255 · p_free⌋ (what MRPT's
   ``getAsImage`` draws), top row first, and the map_server YAML beside it: resolution
   ``FACTOR`` × 0.05 m, ROS's default thresholds, the origin at the crop's corner in MRPT's frame.

Usage: ``python scripts/malaga_building.py [SIMPLEMAP] [OUT_DIR]``. With MRPT 2.5.8 (Debian 12) and
the defaults it rewrites ``htetro_opt/scenarios/data/malaga_building.{pgm,yaml}`` byte for byte.
"""

from __future__ import annotations

import gzip
import hashlib
import shutil
import struct
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
SOURCE = Path("/usr/share/mrpt/datasets/malaga-cs-fac-building.simplemap.gz")
OUT = HERE.parent / "htetro_opt" / "scenarios" / "data"
FACTOR = 5  # 0.05 m pixels -> 0.25 m cells, one hTetro block (as indoor_room)
NAME = "malaga_building"


def read_gridmap(path: Path) -> tuple[np.ndarray, float, float, float]:
    """The int8 log-odds cells (row 0 at y_min), the resolution and the map's (x_min, y_min)."""
    raw = path.read_bytes()
    if raw[:2] == b"\x1f\x8b":
        raw = gzip.decompress(raw)
    n = raw[0] & 0x7F
    name = raw[1 : 1 + n].decode("ascii")
    pos = 1 + n
    version, bits = raw[pos], raw[pos + 1]
    # versions 3 (MRPT 1.x) and 6 (MRPT 2.x) lay out the header and the cells alike
    if name.split("::")[-1] != "COccupancyGridMap2D" or version not in (3, 6) or bits != 8:
        raise SystemExit(f"{path}: expected an 8-bit COccupancyGridMap2D, got {name} v{version}, {bits} bits")
    size_x, size_y = struct.unpack_from("<II", raw, pos + 2)
    x_min, _x_max, y_min, _y_max, resolution = struct.unpack_from("<5f", raw, pos + 10)
    cells = np.frombuffer(raw, dtype=np.int8, count=size_x * size_y, offset=pos + 30).reshape(size_y, size_x)
    return cells, float(resolution), float(x_min), float(y_min)


def build_gridmap(simplemap: Path, folder: Path) -> Path:
    """Run MRPT's observations2map on the scans; the path of the grid it writes."""
    tool = shutil.which("observations2map")
    if tool is None:
        raise SystemExit("observations2map not found: install MRPT's apps (Debian: apt-get install mrpt-apps)")
    # it waits for a key press at the end: give it an empty standard input
    subprocess.run([tool, str(HERE / f"{NAME}.ini"), str(simplemap), str(folder / "map")], check=True,
                   input=b"\n", stdout=subprocess.DEVNULL)
    return folder / "map_gridmap_no00.gridmap"


def convert(gridmap: Path, out_dir: Path, factor: int = FACTOR) -> dict:
    """Steps 2–4 above; what was done, for the scenario's description."""
    cells, resolution, x_min, y_min = read_gridmap(gridmap)
    ys, xs = np.nonzero(cells)
    y0, x0 = int(ys.min()), int(xs.min())
    h = -(-(int(ys.max()) + 1 - y0) // factor)
    w = -(-(int(xs.max()) + 1 - x0) // factor)
    crop = np.zeros((h * factor, w * factor), dtype=np.int8)  # unknown pads the last blocks
    part = cells[y0 : y0 + h * factor, x0 : x0 + w * factor]
    crop[: part.shape[0], : part.shape[1]] = part
    least_free = crop.reshape(h, factor, w, factor).min(axis=(1, 3)).astype(np.float64)
    grey = np.floor(255.0 * (1.0 / (1.0 + np.exp(-least_free / 16.0)))).astype(np.uint8)
    out_dir.mkdir(parents=True, exist_ok=True)
    header = (f"P5\n# {NAME}: MRPT malaga-cs-fac-building.simplemap.gz, mapped at {resolution:g} m, cropped, "
              f"{factor} x {factor} pixels -> 1 (least free kept)\n{w} {h}\n255\n").encode("ascii")
    (out_dir / f"{NAME}.pgm").write_bytes(header + grey[::-1].tobytes())
    cell = round(resolution * factor, 6)
    origin = (round(x_min + x0 * resolution, 4), round(y_min + y0 * resolution, 4))
    (out_dir / f"{NAME}.yaml").write_text(
        f"image: {NAME}.pgm\n"
        "mode: trinary\n"
        f"resolution: {cell}\n"
        f"origin: [{origin[0]}, {origin[1]}, 0.0]\n"
        "negate: 0\n"
        "occupied_thresh: 0.65\n"
        "free_thresh: 0.196\n",
        encoding="utf-8",
    )
    return {"gridmap_sha256": hashlib.sha256(gridmap.read_bytes()).hexdigest(), "source_pixels": cells.shape[::-1], "source_resolution": resolution,
            "crop_pixels": (x0, y0, w * factor, h * factor), "bundled_size": (w, h), "resolution": cell,
            "origin": origin}


if __name__ == "__main__":
    args = sys.argv[1:]
    source = Path(args[0]) if args else SOURCE
    with tempfile.TemporaryDirectory() as folder:
        print(convert(build_gridmap(source, Path(folder)), Path(args[1]) if len(args) > 1 else OUT))
