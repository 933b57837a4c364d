"""malaga_building: a real building's ROS map in the box, checked against its image, its provenance
and an independent search."""

from __future__ import annotations

import fnmatch
import re
import tomllib
from collections import deque
from pathlib import Path

import numpy as np
import pytest
import yaml
from PIL import Image

from htetro_opt.errors import ScenarioError
from htetro_opt.model import Simulator
from htetro_opt.scenarios import ContinuousScenario, list_scenarios, load_ros_map, load_scenario, parse_scenario, scenario_path
from htetro_opt.solvers.grid_paths import plan_exact

ROOT = Path(__file__).resolve().parents[2]
NAME = "malaga_building"


@pytest.fixture(scope="module")
def scenario():
    return load_scenario(NAME)


@pytest.fixture(scope="module")
def files():
    toml = scenario_path(NAME)
    data = tomllib.loads(toml.read_text(encoding="utf-8"))
    meta_path = toml.parent / data["map"]
    meta = yaml.safe_load(meta_path.read_text(encoding="utf-8"))
    return toml, meta_path, meta


def free_from_image(meta_path: Path, meta: dict) -> np.ndarray:
    """map_server's trinary reading, written here from its documentation with Pillow: p = (255 − v) / 255,
    free when p < free_thresh; row 0 of the result is the image's bottom row."""
    with Image.open(meta_path.parent / meta["image"]) as image:
        assert image.format == "PPM" and image.mode == "L"  # Pillow's reader of binary PGM
        pixels = np.asarray(image, dtype=np.float64)
    p = (255.0 - pixels) / 255.0
    return np.flipud(p < meta["free_thresh"])


def test_it_loads_as_a_real_building_at_one_block_a_cell(scenario, files):
    _, _, meta = files
    ws = scenario.workspace
    assert (ws.width, ws.height, ws.cell_size) == (177, 214, 0.25)
    assert meta["resolution"] == 0.25 and meta["negate"] == 0
    assert (meta["occupied_thresh"], meta["free_thresh"]) == (0.65, 0.196)  # ROS's defaults, not tuned
    free = int((~ws.occupancy).sum())
    assert 15_000 < free < 20_000  # a hall of about 1,100 m², not an empty or a solid image
    assert (scenario.start.shape, scenario.goal.shape) == ("O", "O")


def test_its_cells_are_the_image_s_pixels_at_the_yaml_s_thresholds(scenario, files):
    _, meta_path, meta = files
    free = free_from_image(meta_path, meta)
    assert np.array_equal(scenario.workspace.occupancy, ~free)
    # unknown pixels (between the thresholds) are obstacles: there are some, and none is free
    with Image.open(meta_path.parent / meta["image"]) as image:
        p = (255.0 - np.flipud(np.asarray(image, dtype=np.float64))) / 255.0
    unknown = (p >= meta["free_thresh"]) & (p <= meta["occupied_thresh"])
    assert unknown.any() and scenario.workspace.occupancy[unknown].all()


def test_a_coarser_cell_is_free_only_if_all_its_pixels_are(files):
    _, meta_path, meta = files
    free = free_from_image(meta_path, meta)
    occupancy, cell = load_ros_map(meta_path, cell_size=0.5)
    h, w = -(-free.shape[0] // 2), -(-free.shape[1] // 2)
    padded = np.zeros((2 * h, 2 * w), dtype=bool)  # pixels off the image are not known to be free
    padded[: free.shape[0], : free.shape[1]] = free
    assert cell == 0.5
    assert np.array_equal(occupancy, ~padded.reshape(h, 2, w, 2).all(axis=(1, 3)))


def test_it_says_where_it_comes_from_and_under_which_licence(scenario, files):
    toml, _, _ = files
    assert "https://github.com/MRPT/mrpt" in scenario.source
    assert "share/mrpt/datasets/malaga-cs-fac-building.simplemap.gz" in scenario.source
    assert re.search(r"commit [0-9a-f]{40}\b", scenario.source)
    assert "scripts/malaga_building.py" in scenario.source and (ROOT / "scripts" / "malaga_building.py").is_file()
    assert scenario.licence.startswith("BSD-3-Clause")
    notice = toml.parent / f"{NAME}.LICENSE"
    assert notice.name in scenario.licence
    text = notice.read_text(encoding="utf-8")
    # BSD-3-Clause asks that the copyright notice, the conditions and the disclaimer travel with the data
    for needed in ("Copyright (c)", "Redistributions in binary form must reproduce the above copyright notice",
                   "Neither the name of the copyright holder", 'PROVIDED BY THE COPYRIGHT HOLDERS AND CONTRIBUTORS "AS IS"'):
        assert needed in text


def test_every_file_beside_the_bundled_scenarios_is_packaged():
    # the map's image and its licence notice must reach an installed package, not only this checkout
    patterns = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["tool"]["setuptools"][
        "package-data"]["htetro_opt.scenarios"]
    data = scenario_path(NAME).parent
    for path in data.iterdir():
        if path.is_file():
            relative = f"data/{path.name}"
            assert any(fnmatch.fnmatch(relative, pattern) for pattern in patterns), relative


def test_every_scenario_with_a_licence_is_in_the_docs_table_with_it():
    page = (ROOT / "docs" / "scenarios.md").read_text(encoding="utf-8")
    table = [line for line in page.splitlines() if line.startswith("| ")]
    licensed = [name for name in list_scenarios() if load_scenario(name).licence]
    assert NAME in licensed
    for name in licensed:
        spdx = load_scenario(name).licence.split()[0]
        assert any(name in row and spdx in row for row in table), name


def o_shape_translation_time(occupancy: np.ndarray, start, goal) -> int | None:
    """The oracle: the fewest unit translations of the O-shape (heading 0) from start to goal, by a
    breadth-first search written from MODEL.md §4. The O-shape at B2 = (x, y) covers x..x+1 × y−1..y;
    an axis step is valid when the start and end footprints (a 3 × 2 or 2 × 3 box) are free."""
    h, w = occupancy.shape
    free = ~occupancy

    def box(x, y, a, b):  # the a × b box with lower-left cell (x, y) is inside and free
        return 0 <= x and x + a <= w and 0 <= y and y + b <= h and free[y : y + b, x : x + a].all()

    seen = {(start.x, start.y): 0}
    queue = deque([(start.x, start.y)])
    while queue:
        x, y = queue.popleft()
        if (x, y) == (goal.x, goal.y):
            return seen[x, y]
        for dx, dy in ((1, 0), (-1, 0), (0, 1), (0, -1)):
            nx, ny = x + dx, y + dy
            if (nx, ny) in seen:
                continue
            sweep = box(min(x, nx), min(y, ny) - 1, 2 + abs(dx), 2 + abs(dy))
            if sweep:
                seen[nx, ny] = seen[x, y] + 1
                queue.append((nx, ny))
    return None


def test_a_plan_across_the_hall_revalidates_and_is_no_slower_than_the_o_shape_alone(scenario):
    plan = plan_exact(scenario.workspace, scenario.roadmap)
    assert plan.reached
    replay = Simulator(scenario.true_workspace()).run([plan.commands], scenario.start, roadmap=scenario.roadmap[1:])
    assert replay.valid[0] and replay.reached[0]
    assert replay.time[0] == pytest.approx(plan.time)
    oracle = o_shape_translation_time(scenario.workspace.occupancy, scenario.start, scenario.goal)
    assert oracle is not None
    assert plan.time <= oracle  # the exact optimum over all commands never loses to translations alone
    manhattan = abs(scenario.goal.x - scenario.start.x) + abs(scenario.goal.y - scenario.start.y)
    assert oracle >= manhattan  # the oracle itself: one cell a translation


def test_a_licence_is_optional_text_and_survives_conversion():
    grid = {"name": "g", "grid": "....\n....\n....", "licence": "CC-BY-4.0"}
    assert parse_scenario(grid).licence == "CC-BY-4.0"
    assert parse_scenario({k: v for k, v in grid.items() if k != "licence"}).licence == ""
    with pytest.raises(ScenarioError, match="'licence' must be a string, got int"):
        parse_scenario({**grid, "licence": 3})
    field = {"name": "c", "licence": "CC0-1.0", "width": 4.0, "height": 4.0,
             "robots": [{"start": [1.0, 1.0], "goal": [3.0, 3.0]}]}
    assert parse_scenario(field).licence == "CC0-1.0"
    # a grid map taken as a continuous workspace keeps its terms
    assert ContinuousScenario.from_grid(load_scenario(NAME)).licence == load_scenario(NAME).licence
