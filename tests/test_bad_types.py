"""Arguments of the wrong type raise the fitting HtetroError, naming the argument, before any work.

Each case calls one public function with one argument of the wrong type (a string for a workspace, a
number for a path, None for a command string, …) and checks that the error is the expected
:class:`~htetro_opt.errors.HtetroError` subclass, that it is not a bare ``TypeError``,
``AttributeError``, ``IndexError`` or ``ValueError`` raised from deep inside, and that its message
names the argument.
"""

import numpy as np
import pytest

from htetro_opt.errors import (
    ConfigurationError,
    HtetroError,
    OutputError,
    ParameterError,
    ScenarioError,
    TilesetFormatError,
    UnknownCommandError,
    UnknownShapeError,
)
from htetro_opt.model import (
    MovingObstacle,
    Pose,
    Simulator,
    Timing,
    Workspace,
    block_poses,
    command_set,
    format_commands,
    grid_distance,
    parse_commands,
    simulate,
    simulate_coverage,
)
from htetro_opt.model.tiles import identify_tile, patterns_of, tile_poses
from htetro_opt.problems import (
    CommandPathProblem,
    SequencingInstance,
    SequencingProblem,
    block_locations,
    cost_matrix,
    path_cost,
    safety_field,
)
from htetro_opt.scenarios import (
    Tileset,
    format_grid,
    format_tileset,
    load_ros_map,
    load_scenario,
    load_scenario_file,
    load_tileset,
    parse_scenario,
    parse_tileset,
    read_pgm,
    save_tileset,
    scenario_path,
    tileset_path,
)
from htetro_opt.operators.commands import polish_sum
from htetro_opt.solvers.grid_paths import plan_exact, plan_ga, plan_max_fitness_sum, plan_path
from htetro_opt.solvers.sequencing import (
    double_bridge,
    held_karp,
    improve,
    improve_batch,
    nearest_neighbour,
    nearest_neighbour_paths,
    or_opt,
    sequence_waypoints,
    solve_local,
    two_opt,
)
from htetro_opt.solvers.tiling import enumerate_tilings, find_tiles, tile_workspace

WS = Workspace(np.zeros((6, 6), dtype=bool))
SIM = Simulator(WS)
START, GOAL = Pose(1, 1, "O", 0), Pose(3, 2, "O", 0)
ROADMAP = [START, GOAL]
TILESET = parse_tileset("1a 1b 1c 1d\n2a 2b 2c 2d\n3a 3b 3c 3d")
INSTANCE = SequencingInstance.from_tileset(TILESET)
COST = INSTANCE.cost


CASES = [
    # --- model: poses, commands, workspaces, the simulator ------------------------------------------
    ("Pose x", lambda: Pose("a", 1, "O", 0), ConfigurationError, "x"),
    ("Pose heading", lambda: Pose(1, 1, "O", 7), ConfigurationError, "heading"),
    ("Pose shape", lambda: Pose(1, 1, "Q", 0), UnknownShapeError, "'Q'"),
    ("Pose shape int", lambda: Pose(1, 1, 5, 0), UnknownShapeError, "5"),
    ("Pose.of y", lambda: Pose.of(1, 1.5, "O"), ConfigurationError, "y"),
    ("Pose.from_q", lambda: Pose.from_q(5), ConfigurationError, "q"),
    ("block_poses", lambda: block_poses("abc"), ParameterError, "hinges"),
    ("parse_commands None", lambda: parse_commands(None), ParameterError, "commands"),
    ("parse_commands nested", lambda: parse_commands([["x+"]]), UnknownCommandError, "['x+']"),
    ("format_commands", lambda: format_commands("abc"), ParameterError, "ids"),
    ("format_commands id", lambda: format_commands([99]), UnknownCommandError, "99"),
    ("command_set tokens", lambda: command_set(tokens=5), ParameterError, "tokens"),
    ("Timing", lambda: Timing(rotation="slow"), ParameterError, "rotation"),
    ("Workspace str", lambda: Workspace("abc"), ScenarioError, "occupancy"),
    ("Workspace None", lambda: Workspace(None), ScenarioError, "occupancy"),
    ("Workspace strings", lambda: Workspace([["a", "b"]]), ScenarioError, "occupancy"),
    ("Workspace moving", lambda: Workspace(np.zeros((3, 3), bool), moving=5), ScenarioError, "moving"),
    ("Workspace moving item", lambda: Workspace(np.zeros((3, 3), bool), moving=[5]), ScenarioError, "moving"),
    ("MovingObstacle cells", lambda: MovingObstacle("abc", [[0, 0]]), ScenarioError, "cells"),
    ("grid_distance workspace", lambda: grid_distance("abc", (0, 0)), ParameterError, "workspace"),
    ("grid_distance goal", lambda: grid_distance(WS, "ab"), ConfigurationError, "goal"),
    ("Simulator workspace", lambda: Simulator("abc"), ParameterError, "workspace"),
    ("Simulator commands", lambda: Simulator(WS, commands=5), ParameterError, "commands"),
    ("Simulator timing", lambda: Simulator(WS, timing="fast"), ParameterError, "timing"),
    ("Simulator diagonals", lambda: Simulator(WS, diagonals="yes"), ParameterError, "diagonals"),
    ("run token string", lambda: SIM.run("x+,x+", START), ParameterError, "sequences"),
    ("run tokens", lambda: SIM.run([["x+", "x+"]], START), ParameterError, "sequences[0]"),
    ("run float ids", lambda: SIM.run([[0.5]], START), ParameterError, "sequences[0]"),
    ("run start", lambda: SIM.run([[0]], "abc"), ConfigurationError, "start"),
    ("run start id", lambda: SIM.run([[0]], 10**9), ConfigurationError, "start"),
    ("run roadmap", lambda: SIM.run([[0]], START, roadmap=5), ParameterError, "roadmap"),
    ("run t0", lambda: SIM.run([[0]], START, t0="a"), ParameterError, "t0"),
    ("run repair", lambda: SIM.run([[0]], START, repair=3), ParameterError, "repair"),
    ("simulate", lambda: simulate("abc", [[0]], START), ParameterError, "workspace"),
    ("check_pose", lambda: SIM.check_pose(5), ConfigurationError, "pose"),
    ("simulate_coverage waypoints", lambda: simulate_coverage("abc", [0]), ParameterError, "got str 'abc'"),
    ("simulate_coverage order", lambda: simulate_coverage(TILESET, "abc"), ParameterError, "order"),
    ("patterns_of", lambda: patterns_of(5), ParameterError, "shapes"),
    ("identify_tile", lambda: identify_tile("abc"), ConfigurationError, "cells"),
    ("tile_poses", lambda: tile_poses(None), ConfigurationError, "cells"),
    # --- scenarios ------------------------------------------------------------------------------------
    ("load_scenario", lambda: load_scenario(123), ScenarioError, "scenario must be a bundled name or a file path"),
    ("load_scenario None", lambda: load_scenario(None), ScenarioError, "None"),
    ("scenario_path", lambda: scenario_path(1.5), ScenarioError, "1.5"),
    ("load_scenario_file", lambda: load_scenario_file(123), ScenarioError, "path"),
    ("parse_scenario", lambda: parse_scenario("grid = '..'"), ScenarioError, "data"),
    ("format_grid", lambda: format_grid("abc"), ScenarioError, "occupancy"),
    ("load_ros_map", lambda: load_ros_map(123), ScenarioError, "yaml_path"),
    ("read_pgm", lambda: read_pgm(None), ScenarioError, "path"),
    ("load_tileset", lambda: load_tileset(123), ScenarioError, "path"),
    ("tileset_path", lambda: tileset_path(123), ScenarioError, "tileset must be a bundled name or a file path"),
    ("format_tileset", lambda: format_tileset("abc"), ParameterError, "tileset"),
    ("save_tileset tileset", lambda: save_tileset("abc", "x.txt"), ParameterError, "tileset"),
    ("save_tileset path", lambda: save_tileset(TILESET, 123), OutputError, "path"),
    ("Tileset blocks", lambda: Tileset(np.zeros((2, 4), bool), "abc", (1,)), TilesetFormatError, "blocks"),
    ("Tileset.from_poses", lambda: Tileset.from_poses(np.zeros((2, 4), bool), ["abc"]), ConfigurationError,
     "poses[0]"),
    ("Tileset.index", lambda: TILESET.index(None), TilesetFormatError, "None"),
    # --- problems -------------------------------------------------------------------------------------
    ("SequencingInstance cost", lambda: SequencingInstance("abc", np.zeros((1, 4, 2))), ParameterError, "cost"),
    ("SequencingInstance blocks", lambda: SequencingInstance(np.zeros((1, 1)), "abc"), ParameterError, "blocks"),
    ("from_tileset", lambda: SequencingInstance.from_tileset("abc"), ParameterError, "tileset"),
    ("cost_matrix", lambda: cost_matrix("abc"), ParameterError, "blocks"),
    ("path_cost cost", lambda: path_cost("abc", [0, 1]), ParameterError, "cost"),
    ("path_cost order", lambda: path_cost(COST, "abc"), ParameterError, "order"),
    ("block_locations tiles", lambda: block_locations(np.zeros((2, 4), bool), 5), ParameterError, "tiles"),
    ("CommandPathProblem workspace", lambda: CommandPathProblem("abc", START, GOAL), ParameterError, "workspace"),
    ("CommandPathProblem start", lambda: CommandPathProblem(WS, "abc", GOAL), ConfigurationError, "start"),
    ("SequencingProblem", lambda: SequencingProblem("abc"), ParameterError, "instance"),
    ("safety_field", lambda: safety_field("abc"), ParameterError, "occupancy"),
    # --- solvers --------------------------------------------------------------------------------------
    ("plan_path roadmap", lambda: plan_path(WS, "abc"), ParameterError, "roadmap"),
    ("plan_path workspace", lambda: plan_path("abc", ROADMAP), ParameterError, "workspace"),
    ("plan_path callable workspace", lambda: plan_path(None, ROADMAP, method=lambda sim, r: []), ParameterError,
     "workspace"),
    ("plan_exact roadmap", lambda: plan_exact(WS, "abc"), ParameterError, "roadmap"),
    ("plan_exact roadmap items", lambda: plan_exact(WS, [1, 2]), ConfigurationError, "roadmap[0]"),
    ("plan_exact roadmap int", lambda: plan_exact(WS, 5), ParameterError, "roadmap"),
    ("plan_exact timing", lambda: plan_exact(WS, ROADMAP, timing="x"), ParameterError, "timing"),
    ("plan_exact commands", lambda: plan_exact(WS, ROADMAP, commands=5), ParameterError, "commands"),
    ("plan_exact diagonals", lambda: plan_exact(WS, ROADMAP, diagonals="no"), ParameterError, "diagonals"),
    ("plan_ga roadmap", lambda: plan_ga(WS, "abc"), ParameterError, "roadmap"),
    ("plan_ga workspace", lambda: plan_ga(3, ROADMAP), ParameterError, "workspace"),
    ("plan_max_fitness_sum workspace", lambda: plan_max_fitness_sum("abc", START, GOAL), ParameterError, "workspace"),
    ("plan_max_fitness_sum start", lambda: plan_max_fitness_sum(WS, "abc", GOAL), ConfigurationError, "start"),
    ("plan_max_fitness_sum max_length", lambda: plan_max_fitness_sum(WS, START, GOAL, max_length="x"),
     ParameterError, "max_length"),
    ("polish_sum problem", lambda: polish_sum("abc", [1]), ParameterError, "problem"),
    ("polish_sum sequence", lambda: polish_sum(CommandPathProblem(WS, START, GOAL, max_length=5), "abc"),
     ParameterError, "sequence"),
    ("polish_sum window", lambda: polish_sum(CommandPathProblem(WS, START, GOAL, max_length=5), [1], window="x"),
     ParameterError, "polish_window"),
    ("tile_workspace", lambda: tile_workspace("abc"), ParameterError, "workspace"),
    ("tile_workspace name", lambda: tile_workspace(np.zeros((2, 2), bool), name=5), ParameterError, "name"),
    ("find_tiles", lambda: find_tiles(None), ParameterError, "occupancy"),
    ("enumerate_tilings", lambda: enumerate_tilings(5), ParameterError, "workspace"),
    ("sequence_waypoints", lambda: sequence_waypoints("abc", method="exact"), ParameterError, "instance"),
    ("sequence_waypoints auto", lambda: sequence_waypoints(COST), ParameterError, "instance"),
    ("held_karp", lambda: held_karp("abc"), ParameterError, "cost"),
    ("held_karp start", lambda: held_karp(COST, start="a"), ParameterError, "start"),
    ("nearest_neighbour", lambda: nearest_neighbour(None), ParameterError, "cost"),
    ("nearest_neighbour_paths priority", lambda: nearest_neighbour_paths(COST, [0], priority="abc"),
     ParameterError, "priority"),
    ("two_opt order", lambda: two_opt(COST, "abc"), ParameterError, "order"),
    ("two_opt fixed_start", lambda: two_opt(COST, [0, 1, 2], fixed_start="yes"), ParameterError, "fixed_start"),
    ("or_opt", lambda: or_opt(COST, None), ParameterError, "order"),
    ("improve", lambda: improve(COST, [0, 1, 2], segment_lengths="ab"), ParameterError, "segment_lengths"),
    ("improve_batch", lambda: improve_batch(COST, "abc"), ParameterError, "orders"),
    ("improve_batch deadline", lambda: improve_batch(COST, [[0, 1, 2]], deadline="soon"), ParameterError,
     "deadline"),
    ("double_bridge", lambda: double_bridge("abc", 1), ParameterError, "order"),
    ("solve_local", lambda: solve_local("abc"), ParameterError, "instance"),
]


@pytest.mark.parametrize("call, expected, named", [case[1:] for case in CASES], ids=[case[0] for case in CASES])
def test_a_wrong_type_raises_the_fitting_htetro_error_naming_the_argument(call, expected, named):
    with pytest.raises(HtetroError) as info:
        call()
    assert isinstance(info.value, expected), f"{type(info.value).__name__}: {info.value}"
    assert named in str(info.value), str(info.value)
    assert len(str(info.value)) < 400, str(info.value)


def test_the_cases_cover_the_layers():
    assert len(CASES) >= 50
    assert len({case[0] for case in CASES}) == len(CASES)


def test_bad_types_are_refused_before_any_work(monkeypatch):
    """A roadmap or instance of the wrong type is refused before a simulator is compiled or a method run."""
    def compile_nothing(self):
        raise AssertionError("the transition table was compiled before the arguments were checked")

    monkeypatch.setattr(Simulator, "_transition_table", compile_nothing)
    with pytest.raises(ParameterError, match="roadmap"):
        plan_path(WS, "abc")
    calls = []
    with pytest.raises(ParameterError, match="instance"):
        sequence_waypoints("abc", method=lambda instance, **_: calls.append(instance))
    assert calls == []
