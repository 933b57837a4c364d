"""docs/model.md and docs/formats.md stay true.

Every table the code also holds is compared with the code (footprints, hinge triples, block-command
transitions, command tokens and durations, sweep sizes, scenario keys, JSON fields), every Python
example runs, every example file loads (and a grid scenario's goal is reached by the planner), and
every command-line example prints the JSON shown.

Conventions of the pages that these tests rely on:

- a fenced block whose info string names a file (```toml corridor.toml) is that file's complete text;
  ``.toml`` files are scenarios, ``.txt`` files labelled tilesets, the others (YAML, PGM) their maps;
- an HTML comment ``<!-- NAME -->`` right above a table names it (``table: commands``,
  ``keys: grid slit_room.toml``, ``fields: plan``); ``<!-- loads-as: FILE -->`` above a fenced
  block gives the text grid that FILE loads as;
- a ```sh block holding one ``htetro-opt … --json`` line, followed by a ```json block, is a command and
  the output it prints.
"""

import json
import math
import re
import shlex
import tomllib
from dataclasses import fields
from pathlib import Path

import pytest

from htetro_opt.cli import main
from htetro_opt.errors import HtetroError
from htetro_opt.model import (
    COMMANDS,
    FOOTPRINTS,
    N_NAMED,
    N_STATES,
    SEED004_COMMANDS,
    SHAPES,
    STATE_NAMES,
    TOKENS,
    Timing,
    command_id,
    shape_index,
    sweep_tables,
)
from htetro_opt.model.robot import HINGE_STATES
from htetro_opt.scenarios import ContinuousScenario, Scenario, format_grid, load_scenario, load_tileset, parse_scenario
from htetro_opt.scenarios import loader

ROOT = Path(__file__).resolve().parents[1]
MODEL = (ROOT / "docs" / "model.md").read_text(encoding="utf-8")
FORMATS = (ROOT / "docs" / "formats.md").read_text(encoding="utf-8")

_FENCE = re.compile(r"^```([^\n]*)\n(.*?)^```[ \t]*$", re.M | re.S)


def fenced(text):
    """(language, file name or None, body, position) of every fenced block, in order."""
    blocks = []
    for match in _FENCE.finditer(text):
        info = match.group(1).split()
        blocks.append((info[0] if info else "", info[1] if len(info) > 1 else None, match.group(2), match.start()))
    return blocks


def table(text, name):
    """(header, rows) of the markdown table right below ``<!-- name -->``, cells stripped."""
    marker = f"<!-- {name} -->"
    assert text.count(marker) == 1, f"expected one table marked {marker}"
    lines = text.split(marker, 1)[1].strip("\n").splitlines()
    rows = []
    for line in lines:
        if not line.startswith("|"):
            break
        rows.append([cell.strip() for cell in line.strip().strip("|").split("|")])
    assert len(rows) >= 3, f"no table below {marker}"
    return rows[0], rows[2:]


def plain(cell):
    """A cell without its backticks."""
    return cell.replace("`", "").strip()


def ticked(cell):
    """The backticked words of a cell."""
    return re.findall(r"`([^`]+)`", cell)


def number(cell):
    """A documented number: '1.0', '√2', '√2 ≈ 1.414'."""
    word = plain(cell).split()[0]
    return math.sqrt(float(word[1:] or 1)) if word.startswith("√") else float(word)


def offset(cell):
    x, y = cell.replace("−", "-").strip("()").split(",")
    return [int(x), int(y)]


_HINGE = {"π/2": 1, "π": 2, "3π/2": 3}


def hinges(cell):
    return tuple(_HINGE[a.strip()] for a in cell.strip("()").split(","))


# --- the model: states, commands, timing, sweeps ---------------------------------------------------------


def test_the_state_tables_are_the_robots_states():
    _, named = table(MODEL, "table: named-states")
    _, intermediate = table(MODEL, "table: intermediate-states")
    assert [row[0] for row in named] == list(SHAPES)
    assert len(intermediate) == N_STATES - N_NAMED == 16
    rows = named + intermediate
    assert [row[0] for row in rows] == list(STATE_NAMES)
    for row in rows:
        s = shape_index(row[0])
        assert hinges(row[1]) == HINGE_STATES[s], row[0]
        assert [offset(c) for c in row[2:6]] == FOOTPRINTS[s, 0].tolist(), row[0]


def test_the_block_command_table_is_the_transition_table():
    header, rows = table(MODEL, "table: block-commands")
    tables = sweep_tables(0.0)
    assert [row[0] for row in rows] == list(SHAPES)
    for row in rows:
        s = shape_index(row[0])
        for token, cell in zip(header[1:], row[1:]):
            c = command_id(token)
            expected = STATE_NAMES[tables.next_state[s, c]] if tables.legal[s, c] else "—"
            assert cell == expected, (row[0], token)


def test_the_command_table_lists_every_token_with_its_kind_and_duration():
    _, rows = table(MODEL, "table: commands")
    tokens = [plain(row[0]) for row in rows]
    assert len(tokens) == len(set(tokens))
    assert set(tokens) == set(TOKENS)
    timing = Timing()
    for token, kind, _, duration in rows:
        token = plain(token)
        assert COMMANDS[command_id(token)].kind == kind, token
        assert number(duration) == pytest.approx(timing.duration(token), abs=1e-12), token


def test_the_timing_table_is_timings_defaults():
    _, rows = table(MODEL, "table: timing")
    default = Timing()
    assert {plain(row[0]) for row in rows} == {f.name for f in fields(Timing)}
    for name, value, tokens in rows:
        name = plain(name)
        assert number(value) == pytest.approx(getattr(default, name), abs=1e-12), name
        assert set(plain(tokens).split()) == {c.token for c in COMMANDS if c.kind == name}, name


def test_the_cheng_2019_table_is_its_command_set_in_order():
    _, rows = table(MODEL, "table: cheng2019")
    assert [plain(row[1]) for row in rows] == list(SEED004_COMMANDS)
    assert {row[0].split()[0]: plain(row[1]) for row in rows[1:5]} == {"F": "y+", "B": "y-", "L": "x-", "R": "x+"}


def test_the_sweep_size_tables_are_the_computed_sweeps():
    counts = sweep_tables(0.0).counts
    header, (row,) = table(MODEL, "table: rotation-sweeps")
    assert header[1:] == list(SHAPES)
    for shape, cell in zip(SHAPES, row[1:]):
        for token in ("r+", "r-"):
            assert counts[shape_index(shape), 0, command_id(token)] == int(cell), (shape, token)
    header, rows = table(MODEL, "table: shapeshift-sweeps")
    assert header[1:] == list(SHAPES)
    assert [row[0] for row in rows] == list(SHAPES)
    for row in rows:
        got = [int(counts[shape_index(row[0]), 0, command_id("s" + target)]) for target in SHAPES]
        assert got == [int(cell) for cell in row[1:]], row[0]


def test_the_python_examples_of_the_model_run():
    blocks = [body for language, _, body, _ in fenced(MODEL) if language == "python"]
    assert len(blocks) >= 4
    for body in blocks:
        exec(compile(body, "docs/model.md", "exec"), {})


# --- the formats: example files, scenario keys, tilesets -------------------------------------------------


@pytest.fixture(scope="module")
def examples(tmp_path_factory):
    """The folder holding every named example file of formats.md."""
    folder = tmp_path_factory.mktemp("docs")
    names = []
    for _, name, body, _ in fenced(FORMATS):
        if name is not None:
            assert name not in names, f"two examples named {name}"
            names.append(name)
            (folder / name).write_text(body, encoding="utf-8")
    return folder


def _named(suffix):
    return [name for _, name, _, _ in fenced(FORMATS) if name and name.endswith(suffix)]


def test_there_are_examples_of_every_kind():
    assert len(_named(".toml")) >= 4
    assert len(_named(".txt")) >= 3
    assert _named(".yaml") and _named(".pgm")


@pytest.mark.parametrize("name", _named(".toml"))
def test_every_scenario_example_loads_and_its_goal_is_reached(examples, name):
    from htetro_opt.solvers import plan_path

    scenario = load_scenario(examples / name)
    assert scenario.name == Path(name).stem
    if isinstance(scenario, ContinuousScenario):
        assert len(scenario.starts) == len(scenario.goals) >= 1
        return
    assert scenario.goal is not None
    plan = plan_path(scenario.workspace, scenario.roadmap)
    assert plan.reached, name
    assert plan.poses[-1].tolist() == [scenario.goal.x, scenario.goal.y, shape_index(scenario.goal.shape),
                                       scenario.goal.heading]


def test_the_full_example_has_every_grid_feature(examples):
    scenario = load_scenario(examples / "slit_room.toml")
    assert isinstance(scenario, Scenario)
    assert scenario.description and scenario.workspace.cell_size == 0.25
    assert len(scenario.workspace.moving) == 1 and scenario.workspace.period == 6
    assert scenario.hidden.tolist() == [[2, 6]]
    assert scenario.workspace.is_free(5, 3) and not scenario.workspace.is_free(5, 4)  # the slit


@pytest.mark.parametrize("name", _named(".txt"))
def test_every_tileset_example_loads(examples, name):
    tileset = load_tileset(examples / name)
    assert len(tileset) >= 1


def test_the_map_example_loads_as_the_grid_shown(examples):
    marker = "<!-- loads-as: "
    assert marker in FORMATS
    name = FORMATS.split(marker, 1)[1].split(" -->", 1)[0]
    position = FORMATS.index(marker)
    expected = next(body for _, _, body, at in fenced(FORMATS) if at > position)
    scenario = load_scenario(examples / name)
    assert format_grid(scenario.workspace.occupancy) == expected.strip()
    assert scenario.workspace.cell_size == 0.25  # the map's resolution


_KEY_TABLES = re.findall(r"<!-- (keys: (\w+) (\S+)) -->", FORMATS)


def _without(data, kind, key):
    """The parsed file with ``key`` removed (from its first entry, for a table of entries)."""
    entries = {"roadmap": "roadmap", "moving": "moving", "robots": "robots"}
    if kind in entries:
        del data[entries[kind]][0][key]
    else:
        del data[key]
    return data


def test_every_key_table_is_checked():
    assert {kind for _, kind, _ in _KEY_TABLES} == {"grid", "roadmap", "moving", "continuous", "robots"}


@pytest.mark.parametrize("marker, kind, example", _KEY_TABLES)
def test_the_key_tables_say_what_the_loader_requires(examples, marker, kind, example):
    header, rows = table(FORMATS, marker)
    assert header[:3] == ["key", "type", "required"]
    keys = [plain(row[0]) for row in rows]
    if kind == "grid":
        assert set(keys) == loader._GRID_KEYS
    if kind == "continuous":
        assert set(keys) == loader._CONTINUOUS_KEYS
    path = examples / example
    original = tomllib.loads(path.read_text(encoding="utf-8"))
    # as a file: a missing name falls back to the file's stem
    parse_scenario(original, base=examples, default_name=Path(example).stem)  # the example itself loads
    for key, required in ((plain(row[0]), row[2]) for row in rows):
        if required not in ("yes", "no"):
            assert required == "one of `grid`, `map`", key
            continue
        data = tomllib.loads(path.read_text(encoding="utf-8"))
        table_of_key = data[kind][0] if kind in ("roadmap", "moving", "robots") else data
        assert key in table_of_key, f"{example} should show the key {key!r}"
        if required == "yes":
            with pytest.raises(HtetroError):
                parse_scenario(_without(data, kind, key), base=examples, default_name=Path(example).stem)
        else:
            parse_scenario(_without(data, kind, key), base=examples, default_name=Path(example).stem)


def test_the_python_examples_of_the_formats_run(examples, monkeypatch):
    blocks = [body for language, _, body, _ in fenced(FORMATS) if language == "python"]
    assert blocks
    monkeypatch.chdir(examples)
    for body in blocks:
        exec(compile(body, "docs/formats.md", "exec"), {})


# --- the command line's JSON -------------------------------------------------------------------------------


def _cli_examples():
    """(argv, documented output) of every ```sh command followed by a ```json block."""
    blocks = fenced(FORMATS)
    pairs = []
    for (language, _, body, _), (next_language, _, output, _) in zip(blocks, blocks[1:]):
        if language == "sh":
            (line,) = body.strip().splitlines()
            argv = shlex.split(line)
            assert argv[0] == "htetro-opt" and "--json" in argv
            assert next_language == "json"
            pairs.append((argv[1:], json.loads(output)))
    return pairs


def _same(doc, got, where="JSON"):
    if isinstance(doc, dict):
        assert isinstance(got, dict) and list(doc) == list(got), where
        for key in doc:
            if key != "runtime_s":
                _same(doc[key], got[key], f"{where}.{key}")
    elif isinstance(doc, list):
        assert isinstance(got, list) and len(doc) == len(got), where
        for i, (a, b) in enumerate(zip(doc, got)):
            _same(a, b, f"{where}[{i}]")
    elif isinstance(doc, float) and not isinstance(got, bool):
        assert got == pytest.approx(doc, rel=1e-6), where
    else:
        assert doc == got and type(doc) is type(got), where


def _run(capsys, argv):
    code = main(argv)
    out, err = capsys.readouterr()
    assert code == 0, err
    return json.loads(out)


def test_there_is_a_json_example_of_every_command():
    commands = [argv[0] for argv, _ in _cli_examples()]
    assert sorted(set(commands)) == ["cover", "plan", "sequence", "simulate", "tile"]


@pytest.mark.parametrize("argv, documented", _cli_examples(), ids=lambda v: " ".join(v) if isinstance(v, list) else "")
def test_the_cli_prints_the_json_shown(examples, monkeypatch, capsys, argv, documented):
    monkeypatch.chdir(examples)  # the sequence example reads the tileset example
    _same(documented, _run(capsys, argv))


@pytest.mark.parametrize("command", ["plan", "simulate", "tile", "sequence", "cover"])
def test_the_field_tables_list_the_json_fields(command):
    _, rows = table(FORMATS, f"fields: {command}")
    documented = next(out for argv, out in _cli_examples() if argv[0] == command)
    assert [plain(row[0]) for row in rows] == list(documented)


def test_the_ga_fields_table_lists_what_a_ga_plan_adds(examples, monkeypatch, capsys):
    monkeypatch.chdir(examples)
    out = _run(capsys, ["plan", "corridor.toml", "--method", "htetro-ga", "--pop-size", "6", "--max-gen", "2",
                        "--max-length", "8", "--json"])
    _, plan_rows = table(FORMATS, "fields: plan")
    _, rows = table(FORMATS, "fields: plan-ga")
    assert list(out) == [plain(row[0]) for row in plan_rows + rows]
    meaning = {plain(row[0]): set(ticked(row[1])) for row in rows}
    leg = out["legs"][0]
    assert set(leg) <= meaning["legs"]
    assert set(leg["selected"]) <= meaning["legs"]
    assert set(out["fitness"]) <= meaning["fitness"]
    assert set(out["front"][0]) <= meaning["front"]


def test_the_sequence_methods_add_the_fields_listed(examples):
    from htetro_opt.problems import SequencingInstance
    from htetro_opt.solvers import sequence_waypoints
    from htetro_opt.solvers.sequencing import SPEC

    section = FORMATS.split("Other methods' `info` holds their own fields", 1)[1]
    listed = {}
    for line in re.findall(r"^- (.*)$", section, flags=re.M):
        methods, extras = line.split(":", 1)
        for method in ticked(methods):
            listed[method] = set(ticked(extras))
    assert set(listed) == {"ortools", "local", "ga", "ga-plain", "zigzag", "zigzag2", "spiral", "spiral2", "greedy",
                           "ils", "fast-tsp", "lkh"}
    instance = SequencingInstance.from_tileset(load_tileset(examples / "tiles.txt"), start=1)
    for method in sorted(listed):
        taken = SPEC.method(method).takes  # LKH counts runs, not seconds; the patterns take neither
        options = {k: v for k, v in {"time_limit": 0.2, "seed": 0, "solution_limit": 10}.items() if taken(k)}
        result = sequence_waypoints(instance, method=method, **options)
        assert set(result.info) - {"additions"} == listed[method], method  # additions: a field of its own
