"""Scenario files and the bundled library of the papers' environments (shared/MODEL.md §6)."""

from __future__ import annotations

from importlib import resources
from pathlib import Path

from htetro_opt.errors import ScenarioError
from htetro_opt.scenarios._paths import as_path
from htetro_opt.scenarios.loader import (
    ContinuousScenario,
    Scenario,
    check_continuous_scenario,
    format_grid,
    load_scenario_file,
    parse_grid,
    parse_scenario,
)
from htetro_opt.scenarios.rosmap import load_ros_map, read_pgm
from htetro_opt.scenarios.tileset import (
    BLOCK_LETTERS,
    Tileset,
    format_tileset,
    load_tileset,
    parse_tileset,
    save_tileset,
)

__all__ = [
    "Scenario",
    "ContinuousScenario",
    "check_continuous_scenario",
    "load_scenario",
    "list_scenarios",
    "scenario_path",
    "list_tilesets",
    "tileset_path",
    "load_scenario_file",
    "parse_scenario",
    "parse_grid",
    "format_grid",
    "load_ros_map",
    "read_pgm",
    "Tileset",
    "BLOCK_LETTERS",
    "parse_tileset",
    "format_tileset",
    "load_tileset",
    "save_tileset",
]


def _data_dir() -> Path:
    return Path(str(resources.files("htetro_opt.scenarios") / "data"))


def list_scenarios() -> list[str]:
    """Names of the bundled scenarios, sorted."""
    return sorted(p.stem for p in _data_dir().glob("*.toml"))


def _bundled_or_file(name_or_path: str | Path, folder: Path, suffix: str, kind: str, names) -> Path:
    as_path(name_or_path, kind, expected="a bundled name or a file path")
    bundled = folder / f"{name_or_path}{suffix}"
    if isinstance(name_or_path, str) and "/" not in name_or_path and bundled.is_file():
        return bundled
    path = Path(name_or_path)
    if path.is_file():
        return path
    if path.suffix or "/" in str(name_or_path) or path.exists():  # meant as a file: say what is wrong with it
        what = "is a folder, not a file" if path.is_dir() else "file not found"
        raise ScenarioError(f"{kind} file {str(name_or_path)!r}: {what}")
    raise ScenarioError(f"no {kind} {str(name_or_path)!r}: not a bundled name ({', '.join(names())}) nor a file")


def scenario_path(name_or_path: str | Path) -> Path:
    """Path of a bundled scenario name, or the given path if it names a file.

    Raises
    ------
    ScenarioError
        If it is neither a bundled name nor an existing file.
    """
    return _bundled_or_file(name_or_path, _data_dir(), ".toml", "scenario", list_scenarios)


def load_scenario(name_or_path: str | Path) -> Scenario | ContinuousScenario:
    """Load a bundled scenario by name, or a scenario file by path.

    Raises
    ------
    ScenarioError
        If ``name_or_path`` is neither a bundled name nor an existing file (nor a str or path at
        all), or the file is malformed (see :func:`load_scenario_file`).

    Examples
    --------
    >>> scenario = load_scenario("three_slit")
    >>> scenario.workspace.width, scenario.start.shape
    (24, 'O')
    """
    return load_scenario_file(scenario_path(name_or_path))


def list_tilesets() -> list[str]:
    """Names of the bundled labelled tilesets (the figures of Le et al. 2018), sorted."""
    return sorted(p.stem for p in (_data_dir() / "tilesets").glob("*.txt"))


def tileset_path(name_or_path: str | Path) -> Path:
    """Path of a bundled tileset name, or the given path if it names a file.

    Raises
    ------
    ScenarioError
        If it is neither a bundled name nor an existing file.

    Examples
    --------
    >>> tileset_path("paper_11x11_fig13d").name
    'paper_11x11_fig13d.txt'
    """
    return _bundled_or_file(name_or_path, _data_dir() / "tilesets", ".txt", "tileset", list_tilesets)
