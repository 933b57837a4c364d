"""Tests of the htetro-opt command line: plan, simulate, scenarios, plots and error reporting."""

from __future__ import annotations

import json
import os
import stat
import subprocess
import sys
from pathlib import Path

import pytest

from htetro_opt.cli import main
from htetro_opt.scenarios import list_scenarios, list_tilesets, load_tileset

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"

# 10 x 9 map: an 8 x 7 free room (x 1..8, y 1..7) inside a wall ring.
ROOM = """\
##########
#........#
#........#
#........#
#........#
#........#
#........#
#........#
##########"""

# Two 6 x 6 rooms separated by a solid wall: nothing in the left room reaches the right one.
TWO_ROOMS = """\
###############
#......#......#
#......#......#
#......#......#
#......#......#
#......#......#
#......#......#
###############"""


def pose(x, y, shape, heading=0) -> str:
    return f'[[roadmap]]\nx = {x}\ny = {y}\nshape = "{shape}"\nheading = {heading}\n'


def scenario(path: Path, grid: str = ROOM, roadmap: str = "", name: str | None = None, extra: str = "") -> str:
    name = name or path.stem
    path.write_text(f'name = "{name}"\nsource = "test"\n{extra}\ngrid = """\n{grid}\n"""\n{roadmap}')
    return str(path)


def run(capsys, argv):
    """main(argv) -> (exit code, stdout, stderr)."""
    code = main(argv)
    out, err = capsys.readouterr()
    return code, out, err


def run_json(capsys, argv):
    code, out, err = run(capsys, argv)
    assert code == 0, err
    assert err == ""
    lines = out.strip().splitlines()
    assert len(lines) == 1, out  # exactly one JSON object on one line
    return json.loads(lines[0])


def assert_one_error_line(code, out, err, *words):
    assert code == 2
    assert out == ""
    lines = err.splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith("error: ")
    assert "Traceback" not in err
    for word in words:
        assert word in lines[0], (word, lines[0])


@pytest.fixture(scope="module")
def room(tmp_path_factory) -> str:
    """Start O at (2, 2) heading 0; goal I lying along x (heading 1) at (6, 5)."""
    path = tmp_path_factory.mktemp("cli") / "room.toml"
    return scenario(path, roadmap=pose(2, 2, "O") + pose(6, 5, "I", 1))


@pytest.fixture(scope="module")
def plan_out(room):
    import io
    from contextlib import redirect_stderr, redirect_stdout

    out, err = io.StringIO(), io.StringIO()
    with redirect_stdout(out), redirect_stderr(err):
        code = main(["plan", room, "--json"])
    assert code == 0 and err.getvalue() == ""
    lines = out.getvalue().strip().splitlines()
    assert len(lines) == 1
    return json.loads(lines[0])


@pytest.fixture
def near(tmp_path) -> str:
    """Start O at (2, 2), goal O at (4, 2): two x+ apart."""
    return scenario(tmp_path / "near.toml", roadmap=pose(2, 2, "O") + pose(4, 2, "O"))


# --------------------------------------------------------------------------------------------------
# plan


def test_plan_json_keys_and_optimal_time(plan_out):
    assert set(plan_out) == {"scenario", "method", "success", "message", "reached", "commands", "time", "objectives",
                             "leg_ends", "failed_leg", "runtime_s", "time_limited", "additions", "info"}
    assert plan_out["success"] is plan_out["reached"] is True
    assert plan_out["scenario"] == "room"
    assert plan_out["method"] == "astar"  # the default exact method
    assert plan_out["reached"] is True
    assert isinstance(plan_out["commands"], list) and all(isinstance(t, str) for t in plan_out["commands"])
    # Lower bound: 7 unit translations (Manhattan distance of B2), one rotation (2.0: the goal heading
    # differs and a shapeshift keeps the heading) and one shapeshift O -> I (3.0).
    assert plan_out["time"] == pytest.approx(12.0)
    assert sorted(plan_out["commands"]).count("sI") == 1
    assert isinstance(plan_out["objectives"], dict) and plan_out["objectives"]
    assert isinstance(plan_out["runtime_s"], float) and plan_out["runtime_s"] >= 0


def test_plan_astar_gives_the_same_time(capsys, room, plan_out):
    astar = run_json(capsys, ["plan", room, "--method", "astar", "--json"])
    assert astar["method"] == "astar"
    assert astar["reached"] is True
    assert astar["time"] == pytest.approx(plan_out["time"])


def test_plan_commands_replay_in_simulate(capsys, room, plan_out):
    sim = run_json(capsys, ["simulate", room, "--commands", ",".join(plan_out["commands"]), "--json"])
    assert sim["valid"] is True
    assert sim["reached"] is True
    assert sim["executed"] == len(plan_out["commands"])
    assert sim["time"] == pytest.approx(plan_out["time"])
    assert sim["final"] == {"x": 6, "y": 5, "shape": "I", "heading": 1}


def test_plan_unreachable_goal_is_not_a_crash(capsys, tmp_path):
    path = scenario(tmp_path / "apart.toml", grid=TWO_ROOMS, roadmap=pose(2, 2, "O") + pose(10, 3, "O"))
    out = run_json(capsys, ["plan", path, "--json"])
    assert out["reached"] is False
    assert out["scenario"] == "apart"


def test_plan_text_output_and_plot(capsys, tmp_path, near):
    png = tmp_path / "plan.png"
    code, out, err = run(capsys, ["plan", near, "--plot", str(png)])
    assert code == 0 and err == ""
    lines = out.strip().splitlines()
    assert len(lines) == 2
    assert "reached" in lines[0] and "NOT" not in lines[0]
    assert lines[1].split() == ["x+", "x+"]
    assert png.read_bytes()[:8] == PNG_SIGNATURE
    assert png.stat().st_size > 1000


# --------------------------------------------------------------------------------------------------
# simulate


def test_simulate_json_keys_and_reached(capsys, near):
    out = run_json(capsys, ["simulate", near, "--commands", "x+,x+", "--json"])
    assert {"valid", "reached", "executed", "final", "time"} <= set(out)
    assert out["valid"] is True and out["reached"] is True
    assert out["executed"] == 2
    assert out["final"] == {"x": 4, "y": 2, "shape": "O", "heading": 0}
    assert out["time"] == pytest.approx(2.0)


def test_simulate_passing_the_goal_is_not_reaching_it(capsys, near):
    out = run_json(capsys, ["simulate", near, "--commands", "x+ x+ x+", "--json"])
    assert out["valid"] is True and out["reached"] is False
    assert out["final"]["x"] == 5
    back = run_json(capsys, ["simulate", near, "--commands", "x+ x+ x+ x-", "--json"])
    assert back["reached"] is True and back["time"] == pytest.approx(4.0)


def test_simulate_rotation_and_shapeshift_times(capsys, room):
    out = run_json(capsys, ["simulate", room, "--commands", "x+ x+ y+ y+ r+ sI", "--json"])
    assert out["valid"] is True
    assert out["final"] == {"x": 4, "y": 4, "shape": "I", "heading": 1}
    assert out["time"] == pytest.approx(4 * 1.0 + 2.0 + 3.0)
    assert out["reached"] is False


def test_simulate_executed_counts_commands_before_the_first_invalid(capsys, near):
    # O at (2, 2) covers x 2..3; the room ends at x = 8, so the 6th x+ hits the wall.
    out = run_json(capsys, ["simulate", near, "--commands", "x+ x+ x+ x+ x+ x+ y+ y+", "--json"])
    assert out["valid"] is False
    assert out["executed"] == 5
    assert out["first_invalid"] == 5
    assert out["final"] == {"x": 7, "y": 2, "shape": "O", "heading": 0}
    assert out["time"] == pytest.approx(5.0)
    assert out["reached"] is False


def test_simulate_reached_needs_the_whole_sequence_valid(capsys, near):
    # x+ x+ lands on the goal; the following y- puts B1 into the bottom wall and is not executed: the
    # sequence as a whole is invalid, so it does not count as reaching the goal.
    out = run_json(capsys, ["simulate", near, "--commands", "x+,x+,y-,y-", "--json"])
    assert out["valid"] is False and out["executed"] == 2 and out["first_invalid"] == 2
    assert out["final"] == {"x": 4, "y": 2, "shape": "O", "heading": 0}
    assert out["reached"] is False
    assert run_json(capsys, ["simulate", near, "--commands", "x+,x+", "--json"])["reached"] is True
    assert out["time"] == pytest.approx(2.0)
    # One valid step past the goal before the invalid command: the prefix no longer ends on it.
    past = run_json(capsys, ["simulate", near, "--commands", "x+,x+,x+,y-", "--json"])
    assert past["valid"] is False and past["executed"] == 3 and past["reached"] is False


def test_simulate_empty_sequence(capsys, near):
    out = run_json(capsys, ["simulate", near, "--commands", "", "--json"])
    assert out["valid"] is True and out["executed"] == 0 and out["time"] == 0.0
    assert out["final"] == {"x": 2, "y": 2, "shape": "O", "heading": 0}
    assert out["reached"] is False


def test_simulate_text_output(capsys, near):
    code, out, err = run(capsys, ["simulate", near, "--commands", "x+ x+ x+ x+ x+ x+"])
    assert code == 0 and err == ""
    assert "INVALID at command index 5 (0-based)" in out and "executed 5 of 6" in out


def test_simulate_plot(capsys, tmp_path, near):
    png = tmp_path / "sim.png"
    out = run_json(capsys, ["simulate", near, "--commands", "x+ x+ x+ x+ x+ x+", "--json", "--plot", str(png)])
    assert out["executed"] == 5
    assert png.read_bytes()[:8] == PNG_SIGNATURE


@pytest.mark.parametrize("command", [["plan"], ["simulate", "--commands", "x+"]])
def test_plot_into_missing_directory(capsys, tmp_path, near, command):
    target = tmp_path / "missing" / "out.png"
    argv = [command[0], near, *command[1:], "--json", "--plot", str(target)]
    code, out, err = run(capsys, argv)
    assert_one_error_line(code, out, err, "missing")
    assert not target.exists() and not target.parent.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["near.toml"]


# --------------------------------------------------------------------------------------------------
# scenarios


def test_scenarios_json_lists_the_bundled_scenarios_and_tilesets(capsys):
    out = run_json(capsys, ["scenarios", "--json"])
    assert [row["name"] for row in out["scenarios"]] == list_scenarios()
    assert [row["name"] for row in out["tilesets"]] == list_tilesets()


def test_scenarios_text_lists_one_name_per_line(capsys):
    code, out, err = run(capsys, ["scenarios"])
    assert code == 0 and err == ""
    scenarios, tilesets = out.split("labelled tilesets")
    assert [line.split()[0] for line in scenarios.splitlines() if line.strip()] == list_scenarios()
    assert [line.split()[0] for line in tilesets.splitlines()[1:] if line.strip()] == list_tilesets()


# --------------------------------------------------------------------------------------------------
# errors: one "error: " line on stderr, nothing on stdout, exit 2


def test_unknown_scenario_name(capsys):
    assert_one_error_line(*run(capsys, ["plan", "no_such_scenario", "--json"]), "no_such_scenario")


def test_malformed_toml(capsys, tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text('name = "bad"\nsource = \n')
    assert_one_error_line(*run(capsys, ["plan", str(path), "--json"]), "bad.toml", "line 2")


def test_ragged_grid(capsys, tmp_path):
    grid = ROOM.replace("#........#\n##########", "#.......#\n##########")
    path = scenario(tmp_path / "ragged.toml", grid=grid, roadmap=pose(2, 2, "O") + pose(4, 2, "O"))
    assert_one_error_line(*run(capsys, ["plan", path]), "ragged.toml", "row 8", "ragged")


def test_colliding_start(capsys, tmp_path):
    # O at (8, 3): B3 and B4 at x = 9, the right wall.
    path = scenario(tmp_path / "hit.toml", roadmap=pose(8, 3, "O") + pose(4, 2, "O"))
    assert_one_error_line(*run(capsys, ["simulate", path, "--commands", "x+"]), "hit.toml", "roadmap[1]", "(9, 3)")


def test_goal_outside_the_map(capsys, tmp_path):
    # I lying along x at (1, 5): blocks (2, 5), (1, 5), (0, 5), (-1, 5).
    path = scenario(tmp_path / "out.toml", roadmap=pose(2, 2, "O") + pose(1, 5, "I", 1))
    assert_one_error_line(*run(capsys, ["plan", path]), "out.toml", "roadmap[2]", "outside", "(-1, 5)")


def test_unknown_shape(capsys, tmp_path):
    path = scenario(tmp_path / "shape.toml", roadmap=pose(2, 2, "O") + pose(4, 2, "X"))
    assert_one_error_line(*run(capsys, ["plan", path, "--json"]), "'X'", "roadmap[2]")


def test_unknown_command_token(capsys, near):
    code, out, err = run(capsys, ["simulate", near, "--commands", "x+, y+ ,zz,x+", "--json"])
    assert_one_error_line(code, out, err, "'zz'", "position 3")


def test_plan_without_goal(capsys, tmp_path):
    path = scenario(tmp_path / "lonely.toml", roadmap=pose(2, 2, "O"))
    assert_one_error_line(*run(capsys, ["plan", path, "--json"]), "lonely", "goal")


def test_simulate_without_start(capsys, tmp_path):
    path = scenario(tmp_path / "empty.toml")
    assert_one_error_line(*run(capsys, ["simulate", path, "--commands", "x+"]), "empty", "start")


def test_plan_on_continuous_scenario(capsys, tmp_path):
    path = tmp_path / "cont.toml"
    path.write_text('name = "cont"\nsource = "t"\nwidth = 5\nheight = 5\n[[robots]]\nstart = [1, 1]\ngoal = [4, 4]\n')
    # grid-only methods refuse a continuous scenario; its own methods plan it (tests/solvers/continuous/test_cli.py)
    assert_one_error_line(*run(capsys, ["plan", str(path), "--method", "dijkstra"]), "continuous")
    out = run_json(capsys, ["plan", str(path), "--method", "exact", "--json"])
    assert out["reached"] is True


def test_no_command_shows_the_usage_and_the_commands(capsys):
    code, out, err = run(capsys, [])
    assert code == 2 and out == ""
    assert err.startswith("usage: htetro-opt") and "Traceback" not in err
    for command in ("scenarios", "plan", "simulate", "tile", "sequence", "study"):
        assert command in err


@pytest.mark.parametrize("argv,words", [
    (["plan"], ["required", "scenario"]),
    (["simulate", "{near}"], ["required", "--commands"]),
    (["plan", "{near}", "--bogus"], ["unrecognized", "--bogus"]),
    (["frobnicate"], ["invalid choice", "frobnicate"]),
    (["plan", "{near}", "--method", "genetic"], ["invalid choice", "genetic"]),
    (["plan", "{near}", "--seed", "abc"], ["--seed", "abc"]),
    (["plan", "{near}", "--clearance", "-1"], ["--clearance"]),
    (["simulate", "{near}", "--commands", "x+", "--clearance", "nan"], ["--clearance"]),
])
def test_usage_errors(capsys, near, argv, words):
    argv = [a.replace("{near}", near) for a in argv]
    assert_one_error_line(*run(capsys, argv), *words)


def test_malformed_map_yaml_is_one_error_line(capsys, tmp_path):
    (tmp_path / "m.yaml").write_text("image: m.pgm\nresolution: [0.05\n")
    path = tmp_path / "ros.toml"
    path.write_text('name = "ros"\nsource = "t"\nmap = "m.yaml"\n')
    assert_one_error_line(*run(capsys, ["simulate", str(path), "--commands", "x+"]), "m.yaml")


def test_non_numeric_robot_radius_is_an_error_line(capsys, tmp_path):
    path = tmp_path / "cont.toml"
    path.write_text('name = "c"\nsource = "t"\nwidth = 5\nheight = 5\nrobot_radius = "big"\n'
                    '[[robots]]\nstart = [1, 1]\ngoal = [4, 4]\n')
    assert_one_error_line(*run(capsys, ["plan", str(path)]), "robot_radius")


def test_console_script_exit_codes(tmp_path, near):
    exe = Path(sys.executable).parent / "htetro-opt"
    assert exe.exists(), exe
    bad = subprocess.run([str(exe), "simulate", near, "--commands", "x+ zz"],
                         capture_output=True, text=True, timeout=600)  # a hang guard
    assert bad.returncode == 2
    assert bad.stdout == ""
    assert "Traceback" not in bad.stderr
    assert bad.stderr.splitlines() == [bad.stderr.strip()] and bad.stderr.startswith("error: unknown command 'zz'")
    good = subprocess.run([str(exe), "simulate", near, "--commands", "x+ x+", "--json"],
                          capture_output=True, text=True, timeout=600)  # a hang guard
    assert good.returncode == 0, good.stderr
    assert json.loads(good.stdout)["reached"] is True


def test_plot_file_gets_a_normal_file_mode(capsys, tmp_path, near):
    out = tmp_path / "mode.png"
    old = os.umask(0o022)
    try:
        assert main(["plan", near, "--plot", str(out)]) == 0
    finally:
        os.umask(old)
    assert stat.S_IMODE(out.stat().st_mode) == 0o644
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".htetro-")]


def test_simulate_runs_in_the_true_world_and_plan_in_the_known_map(capsys, tmp_path):
    # A hidden obstacle right of the start: unknown to the planner, there when the plan is executed.
    path = scenario(tmp_path / "hidden.toml", roadmap=pose(2, 2, "O") + pose(6, 2, "O"), extra="hidden = [[4, 2]]")
    plan = run_json(capsys, ["plan", path, "--json"])
    assert plan["reached"] is True and plan["commands"] == ["x+"] * 4
    out = run_json(capsys, ["simulate", path, "--commands", ",".join(plan["commands"]), "--json"])
    assert out["valid"] is False and out["executed"] == 0 and out["reached"] is False  # x+ reaches x = 4


# --------------------------------------------------------------------------------------------------
# plan with the GAs over command chromosomes (Cheng et al. 2020)

GA_FAST = ["--method", "htetro-ga", "--pop-size", "16", "--max-gen", "60", "--patience", "20", "--max-length", "20"]


@pytest.fixture(scope="module")
def ga_out(room):
    import io
    from contextlib import redirect_stderr, redirect_stdout

    out, err = io.StringIO(), io.StringIO()
    near_goal = Path(room).with_name("ga_room.toml")
    scenario(near_goal, roadmap=pose(2, 2, "O") + pose(6, 4, "O"))
    with redirect_stdout(out), redirect_stderr(err):
        code = main(["plan", str(near_goal), *GA_FAST, "--seed", "4", "--json"])
    assert code == 0 and err.getvalue() == ""
    return str(near_goal), json.loads(out.getvalue())


def test_plan_ga_json_fields(ga_out):
    _, out = ga_out
    exact_keys = {"scenario", "method", "reached", "commands", "time", "objectives", "runtime_s"}
    assert exact_keys <= set(out)
    assert {"reach_generation", "front", "legs", "fitness", "generations"} <= set(out)
    assert out["method"] == "htetro-ga"
    assert out["reached"] is True and out["fitness"]["f_gr"] == 1.0
    assert 1 <= out["reach_generation"] <= out["generations"]
    assert out["front"], "the leading front is listed"
    for member in out["front"]:
        assert set(member["fitness"]) == {"f_gr", "f_t", "f_sm", "f_sf"}
        assert member["fitness"]["f_gr"] == 1.0  # F0 holds goal-reaching individuals once one exists
        assert member["time"] == pytest.approx(sum(1.0 if t[0] in "xy" else 2.0 if t[0] == "r" else 3.0
                                                   for t in member["commands"]))
    # The selected (multi-objective) solution is what `commands` holds, and it is a front member.
    selected = out["legs"][0]["selected"]["multi_objective"]
    assert selected["commands"] == out["commands"]
    assert selected["commands"] in [m["commands"] for m in out["front"]]


def test_plan_ga_commands_replay_in_simulate(capsys, ga_out):
    path, out = ga_out
    replay = run_json(capsys, ["simulate", path, "--commands", ",".join(out["commands"]), "--json"])
    assert replay["valid"] and replay["reached"]
    assert replay["time"] == pytest.approx(out["time"])


def test_plan_ga_same_seed_same_plan(capsys, ga_out):
    path, out = ga_out
    again = run_json(capsys, ["plan", path, *GA_FAST, "--seed", "4", "--json"])
    assert again["commands"] == out["commands"] and again["front"] == out["front"]


def test_plan_ga_text_and_plot(capsys, tmp_path, ga_out):
    path, _ = ga_out
    png = tmp_path / "ga.png"
    code, out, err = run(capsys, ["plan", path, *GA_FAST, "--seed", "4", "--plot", str(png)])
    assert code == 0 and err == ""
    assert "reached" in out and "generations" in out and "leading front" in out
    assert png.read_bytes().startswith(PNG_SIGNATURE)


@pytest.mark.parametrize("method", ["nsga2", "nsga3"])
def test_plan_with_pymoo_algorithms(capsys, ga_out, method):
    path, _ = ga_out
    out = run_json(capsys, ["plan", path, *GA_FAST, "--method", method, "--json"])
    assert out["method"] == method and out["front"]


@pytest.mark.parametrize("option,value", [("--pop-size", "1"), ("--max-gen", "0"), ("--patience", "0"),
                                          ("--max-length", "0")])
def test_plan_ga_bad_options_are_one_error_line(capsys, near, option, value):
    assert_one_error_line(*run(capsys, ["plan", near, "--method", "htetro-ga", option, value]), option, value)


def test_plan_unknown_method_is_a_usage_error(capsys, near):
    assert_one_error_line(*run(capsys, ["plan", near, "--method", "moead"]), "moead")


# --------------------------------------------------------------------------------------------------
# tile and sequence (seed 003)

STRIP = """\
........
........
...##...
...##..."""


def test_tile_writes_a_labelled_tileset_that_covers_the_map(capsys, tmp_path):
    path = scenario(tmp_path / "strip.toml", grid=STRIP)
    out_file = tmp_path / "strip.txt"
    out = run_json(capsys, ["tile", path, "--out", str(out_file), "--json"])
    assert out["tiles"] == 7 and out["out"] == str(out_file) and not out["overlapping"]
    tileset = load_tileset(out_file)
    assert tileset.complete and not tileset.overlapping and len(tileset) == 7
    assert all(p is not None for p in tileset.poses)  # written with the robot's footprints


def test_tile_prints_the_tileset_and_honours_allowed_shapes(capsys, tmp_path):
    path = scenario(tmp_path / "square.toml", grid="....\n....\n....\n....")
    code, out, err = run(capsys, ["tile", path, "--shapes", "O", "--method", "cpsat"])
    assert code == 0 and err == ""
    rows = [line.split() for line in out.splitlines()]
    assert len(rows) == 4 and all(len(r) == 4 for r in rows)
    out = run_json(capsys, ["tile", path, "--shapes", "I", "--json"])
    assert out["shapes"] == {"I": 4}


@pytest.mark.parametrize("grid, words", [
    (".....\n.....", ["10", "multiple of 4"]),
    ("...#.\n...#.", ["region", "(0, 1)", "6 free cells"]),
])
def test_tile_untileable_map_is_one_error_line(capsys, tmp_path, grid, words):
    path = scenario(tmp_path / "bad.toml", grid=grid)
    assert_one_error_line(*run(capsys, ["tile", path]), *words)


def test_tile_not_proven_within_the_time_limit_is_one_error_line(capsys, tmp_path):
    # 64 x 62 has no tiling by T (4 must divide both sides), passes every pre-check, and is not
    # proven so in half a second: the one error line says that nothing was proven
    path = scenario(tmp_path / "t_only.toml", grid="\n".join(["." * 64] * 62))
    assert_one_error_line(*run(capsys, ["tile", path, "--shapes", "T", "--time-limit", "0.5"]),
                          "proven impossible within the time limit of 0.5 s")


def test_tile_unknown_shape_is_one_error_line(capsys, tmp_path):
    path = scenario(tmp_path / "square.toml", grid="....\n....")
    assert_one_error_line(*run(capsys, ["tile", path, "--shapes", "OQ"]), "Q")


def test_sequence_a_bundled_paper_tileset_exactly(capsys):
    out = run_json(capsys, ["sequence", "paper_6x6_fig13a", "--method", "exact", "--json"])
    assert set(out) >= {"order", "cost", "runtime_s", "method", "success", "info"}
    assert sorted(out["order"]) == list(range(1, 10)) and out["order"][0] == 1
    assert out["info"]["optimal"] is True
    # the reported cost is the eq.-2 cost of the reported order
    from htetro_opt.problems import SequencingInstance
    from htetro_opt.scenarios import tileset_path

    inst = SequencingInstance.from_tileset(load_tileset(tileset_path("paper_6x6_fig13a")))
    assert out["cost"] == pytest.approx(inst.path_cost([inst.ids.index(t) for t in out["order"]]))
    for solver in ("ortools", "ga", "local"):
        other = run_json(capsys, ["sequence", "paper_6x6_fig13a", "--method", solver, "--time-limit", "2", "--json"])
        if solver == "local":  # a heuristic: no better than the optimum
            assert other["cost"] >= out["cost"] - 1e-9
        else:
            assert other["cost"] == pytest.approx(out["cost"], rel=1e-6), solver


@pytest.mark.parametrize("solver", ["zigzag", "zigzag2", "spiral", "spiral2", "greedy", "ga-plain"])
def test_sequence_baselines_visit_every_tile_once_from_the_start(capsys, solver):
    seed = ["--seed", "3"] if solver in ("greedy", "ga-plain") else []  # the patterns draw from no seed
    out = run_json(capsys, ["sequence", "paper_11x11_fig13d", "--method", solver, "--start", "5", *seed, "--json"])
    assert out["order"][0] == 5 and sorted(out["order"]) == list(range(1, 29))


def test_sequence_a_scenario_tiles_it_first_and_free_start_is_no_worse(capsys, tmp_path):
    path = scenario(tmp_path / "strip.toml", grid=STRIP)
    fixed = run_json(capsys, ["sequence", path, "--method", "exact", "--json"])
    free = run_json(capsys, ["sequence", path, "--method", "exact", "--start", "free", "--json"])
    assert fixed["waypoints"] == free["waypoints"] == 7
    assert free["cost"] <= fixed["cost"] + 1e-9


def test_sequence_same_seed_same_order_and_plot(capsys, tmp_path):
    argv = ["sequence", "paper_8x7_fig13b", "--method", "ga-plain", "--seed", "7", "--json"]
    assert run_json(capsys, argv)["order"] == run_json(capsys, argv)["order"]
    png = tmp_path / "seq.png"
    code, out, err = run(capsys, ["sequence", "paper_8x7_fig13b", "--method", "spiral", "--plot", str(png)])
    assert code == 0 and png.read_bytes().startswith(PNG_SIGNATURE)
    assert "cost" in out


def test_sequence_weights_change_the_cost(capsys):
    equal = run_json(capsys, ["sequence", "paper_6x6_fig13a", "--method", "exact", "--json"])
    b_only = run_json(capsys, ["sequence", "paper_6x6_fig13a", "--method", "exact", "--weights", "0,1,0,0", "--json"])
    assert b_only["weights"] == [0, 1, 0, 0] and b_only["cost"] != pytest.approx(equal["cost"])


@pytest.mark.parametrize("argv, words", [
    (["--start", "99"], ["no tile 99"]),
    (["--start", "first"], ["--start", "free"]),
    (["--weights", "1,2"], ["weights"]),
    (["--weights", "a,b,c,d"], ["--weights"]),
    (["--time-limit", "0"], ["--time-limit"]),
    (["--shapes", "O"], ["--shapes"]),
])
def test_sequence_bad_options_are_one_error_line(capsys, argv, words):
    assert_one_error_line(*run(capsys, ["sequence", "paper_6x6_fig13a", *argv]), *words)


def test_sequence_bad_tileset_files_are_one_error_line(capsys, tmp_path):
    bad = tmp_path / "bad.txt"
    bad.write_text("1a 1b 1c 1d\n2a 2b 2c 2x\n")
    assert_one_error_line(*run(capsys, ["sequence", str(bad)]), "2x", "row 2", "column 4")
    bad.write_text("1a 1b 1c 1d\n2a 2b 2c .\n")
    assert_one_error_line(*run(capsys, ["sequence", str(bad)]), "tile 2", "no block d")
    assert_one_error_line(*run(capsys, ["sequence", str(tmp_path / "none.txt")]), "none.txt")


def test_sequence_exact_refuses_large_instances_clearly(capsys, tmp_path):
    big = scenario(tmp_path / "big.toml", grid="\n".join(["." * 16] * 12))
    assert_one_error_line(*run(capsys, ["sequence", big, "--method", "exact"]), "48", "40")


def test_console_script_output_into_a_closed_pipe_is_no_traceback():
    exe = Path(sys.executable).parent / "htetro-opt"
    proc = subprocess.Popen([str(exe), "scenarios"], stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    proc.stdout.close()  # the reader goes away before the first line is written, as `| head -0` would
    err = proc.stderr.read().decode()
    assert proc.wait(timeout=600) == 1  # a hang guard
    assert "Traceback" not in err and "BrokenPipeError" not in err


# --------------------------------------------------------------------------------------------------
# Output files: checked before the work, one error line, nothing half-written or left behind


def _leftovers(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir())


@pytest.mark.parametrize("where", ["missing folder", "onto a folder", "unwritable folder"])
def test_tile_out_that_cannot_be_written_is_one_error_line(capsys, tmp_path, where):
    if where == "missing folder":
        target = tmp_path / "missing" / "x.txt"
    elif where == "onto a folder":
        target = tmp_path / "a_folder"
        target.mkdir()
    else:
        if os.geteuid() == 0:
            pytest.skip("root writes into read-only folders")  # CI runs as root: the other two cases still run
        locked = tmp_path / "locked"
        locked.mkdir(mode=0o500)
        target = locked / "x.txt"
    code, out, err = run(capsys, ["tile", "tiling_6x6", "--out", str(target)])
    assert_one_error_line(code, out, err, "cannot write tileset", str(target))


def test_unwritable_output_file_is_one_error_line_even_as_root(capsys, tmp_path):
    # /proc/version exists and cannot be replaced, whoever runs the test
    assert_one_error_line(*run(capsys, ["tile", "tiling_6x6", "--out", "/proc/version"]), "cannot write tileset")


def test_a_bad_plot_path_fails_before_any_work_and_leaves_no_tileset(capsys, tmp_path):
    ok = tmp_path / "ok.txt"
    code, out, err = run(capsys, ["tile", "tiling_6x6", "--out", str(ok), "--plot", str(tmp_path / "nope" / "x.png")])
    assert_one_error_line(code, out, err, "cannot write plot", "does not exist")
    assert _leftovers(tmp_path) == []


def test_plan_checks_the_plot_path_before_planning(capsys, near, tmp_path, monkeypatch):
    import htetro_opt.solvers.grid_paths._dispatch as dispatch

    def must_not_run(*args, **kwargs):
        raise AssertionError("planned before checking the output path")

    monkeypatch.setattr(dispatch, "plan_path", must_not_run)
    code, out, err = run(capsys, ["plan", near, "--method", "htetro-ga", "--plot", str(tmp_path / "no" / "p.png")])
    assert_one_error_line(code, out, err, "cannot write plot")


@pytest.mark.parametrize("suffix,magic", [(".pdf", b"%PDF"), (".svg", b"<?xml"), (".png", PNG_SIGNATURE)])
def test_plot_format_follows_the_extension(capsys, near, tmp_path, suffix, magic):
    target = tmp_path / f"plan{suffix}"
    assert main(["plan", near, "--plot", str(target)]) == 0
    assert target.read_bytes().startswith(magic)


def test_plot_with_an_unknown_extension_is_refused_before_work(capsys, near, tmp_path):
    folder = tmp_path / "plots"
    folder.mkdir()
    assert_one_error_line(*run(capsys, ["plan", near, "--plot", str(folder / "x.docx")]), "docx", "pdf")
    assert _leftovers(folder) == []


@pytest.mark.parametrize("argv,words", [
    (["plan", "{near}", "--method", "htetro-ga", "--seed", "-1"], ["--seed", "-1"]),
    (["sequence", "paper_6x6_fig13a", "--method", "ortools", "--time-limit", "1e300"], ["--time-limit", "1e+300"]),
    (["sequence", "paper_6x6_fig13a", "--time-limit", "inf"], ["--time-limit", "inf"]),
    (["tile", "tiling_6x6", "--time-limit", "0"], ["--time-limit"]),
    (["tile", "tiling_6x6", "--shuffle", "--seed", "-3"], ["--seed", "-3"]),
    (["plan", "{near}", "--method", "nsga2", "--pop-size", "1"], ["--pop-size", "1"]),
])
def test_bad_numbers_are_one_error_line(capsys, near, argv, words):
    argv = [a.replace("{near}", near) for a in argv]
    assert_one_error_line(*run(capsys, argv), *words)


def test_plan_method_nsga2_runs_pymoos_nsga2(capsys, near):
    out = run_json(capsys, ["plan", near, *GA_FAST[2:], "--method", "nsga2", "--seed", "1", "--json"])
    assert out["method"] == "nsga2"


def test_tile_shuffle_gives_reproducible_other_tilings(capsys):
    fixed = run_json(capsys, ["tile", "tiling_10x10", "--json"])["tileset"]
    assert run_json(capsys, ["tile", "tiling_10x10", "--json"])["tileset"] == fixed
    assert_one_error_line(*run(capsys, ["tile", "tiling_10x10", "--seed", "5"]), "--seed", "--shuffle")
    shuffled = {run_json(capsys, ["tile", "tiling_10x10", "--shuffle", "--seed", str(s), "--json"])["tileset"]
                for s in range(4)}
    assert run_json(capsys, ["tile", "tiling_10x10", "--shuffle", "--seed", "0", "--json"])["tileset"] in shuffled
    assert len(shuffled | {fixed}) > 1


@pytest.mark.parametrize("option", [["--pop-size", "20"], ["--seed", "3"], ["--max-gen", "5"], ["--patience", "5"],
                                    ["--max-length", "30"]])
def test_ga_options_with_an_exact_method_are_refused(capsys, near, option):
    assert_one_error_line(*run(capsys, ["plan", near, "--method", "astar", *option]), option[0], "GA methods")


def test_plan_help_shows_the_ga_defaults(capsys):
    assert main(["plan", "--help"]) == 0
    text = " ".join(capsys.readouterr().out.split())
    for default in ("(default 50)", "(default 1000)", "(default 100 with --converge best", "(default 0)"):
        assert default in text


def test_a_ga_that_never_reaches_says_so_in_words(capsys, tmp_path):
    # the goal lies in the other room: no individual ever reaches it
    path = scenario(tmp_path / "apart.toml", grid=TWO_ROOMS, roadmap=pose(2, 2, "O") + pose(10, 2, "O"))
    code, out, err = run(capsys, ["plan", path, "--method", "htetro-ga", "--pop-size", "8", "--max-gen", "3",
                                  "--max-length", "10"])
    assert code == 0, err
    assert "goal first reached in no generation" in out and "None" not in out


# --------------------------------------------------------------------------------------------------
# Progress on stderr, late writes, inputs from files


def test_progress_is_shown_on_a_terminal_and_not_with_quiet(capsys, monkeypatch, near):
    import htetro_opt.cli._common as common

    monkeypatch.setattr(common, "_stderr_is_terminal", lambda: True)
    argv = ["plan", near, "--method", "htetro-ga", "--pop-size", "8", "--max-gen", "30", "--patience", "5",
            "--max-length", "20", "--json"]
    code, out, err = run(capsys, argv)
    assert code == 0 and json.loads(out)["method"] == "htetro-ga"  # stdout stays one JSON object
    assert "planning (htetro-ga)" in err and "/30 generations" in err and "best f_t" in err
    code, out, err = run(capsys, [*argv, "--quiet"])
    assert code == 0 and err == ""


def test_no_progress_when_stderr_is_not_a_terminal(capsys, near):
    code, out, err = run(capsys, ["sequence", "paper_6x6_fig13a", "--method", "greedy", "--json"])
    assert code == 0 and err == ""


def test_sequence_progress_reports_the_methods_own_counts(capsys, monkeypatch):
    import htetro_opt.cli._common as common

    monkeypatch.setattr(common, "_stderr_is_terminal", lambda: True)
    code, out, err = run(capsys, ["sequence", "paper_11x11_fig13d", "--method", "greedy", "--json"])
    assert code == 0
    assert "sequencing 28 waypoints (greedy)" in err and "10000/10000" in err and "best cost" in err


def test_a_plot_that_fails_after_the_work_still_prints_the_result(capsys, monkeypatch, near, tmp_path):
    import htetro_opt.viz as viz
    from htetro_opt.errors import OutputError

    def disk_full(figure, path, **kwargs):
        raise OutputError(f"cannot write plot {str(path)!r}: No space left on device")

    monkeypatch.setattr(viz, "save_figure", disk_full)
    code, out, err = run(capsys, ["plan", near, "--json", "--plot", str(tmp_path / "p.png")])
    assert code == 2
    assert json.loads(out)["reached"] is True  # the finished plan is not thrown away
    assert err.startswith("error: cannot write plot") and len(err.splitlines()) == 1


def test_a_tileset_that_fails_after_the_plot_leaves_neither(capsys, monkeypatch, tmp_path):
    import htetro_opt.scenarios as scenarios
    from htetro_opt.errors import OutputError

    def disk_full(tileset, path):
        raise OutputError("cannot write tileset: No space left on device")

    monkeypatch.setattr(scenarios, "save_tileset", disk_full)
    code, out, err = run(capsys, ["tile", "tiling_6x6", "--out", str(tmp_path / "t.txt"),
                                  "--plot", str(tmp_path / "t.png"), "--json"])
    assert code == 2 and err.startswith("error: cannot write tileset")
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("weights,words", [
    ("0,0,0,0", ["--weights", "positive sum"]),
    ("-1,1,1,1", ["--weights", "-1,1,1,1"]),
    ("1e308,1,1,1", ["--weights", "1e6"]),
    ("1,1,1", ["--weights", "four"]),
    ("a,b,c,d", ["--weights", "four"]),
])
def test_weights_errors_say_what_is_wrong(capsys, weights, words):
    code, out, err = run(capsys, ["sequence", "paper_6x6_fig13a", "--weights", weights])
    assert_one_error_line(code, out, err, *words)
    assert "Warning" not in err


def test_commands_from_a_file_and_from_stdin(capsys, monkeypatch, near, tmp_path):
    import io

    long = tmp_path / "long.txt"
    long.write_text("x+ x+\ny+, x+\n")
    from_file = run_json(capsys, ["simulate", near, "--commands", f"@{long}", "--json"])
    monkeypatch.setattr(sys, "stdin", io.StringIO("x+ x+ y+ x+"))
    from_stdin = run_json(capsys, ["simulate", near, "--commands", "-", "--json"])
    inline = run_json(capsys, ["simulate", near, "--commands", "x+,x+,y+,x+", "--json"])
    assert from_file == from_stdin == inline and inline["executed"] == 4
    assert_one_error_line(*run(capsys, ["simulate", near, "--commands", f"@{tmp_path / 'none.txt'}"]),
                          "--commands", "none.txt")


def test_sequence_help_shows_the_default_budgets(capsys):
    assert main(["sequence", "--help"]) == 0
    text = " ".join(capsys.readouterr().out.split())
    assert "10 s + 1 s per 50 waypoints, at most 60 s" in text and "exact: 60 s" in text


def test_bundled_tileset_is_named_not_located(capsys):
    out = run_json(capsys, ["sequence", "paper_6x6_fig13a", "--json"])
    assert out["tileset"] == "paper_6x6_fig13a"


def test_help_points_to_the_model_and_format_reference(capsys):
    assert main(["--help"]) == 0
    text = " ".join(capsys.readouterr().out.split())
    assert "docs/model.md" in text and "docs/formats.md" in text
    root = Path(__file__).resolve().parents[1]
    assert (root / "docs" / "model.md").is_file() and (root / "docs" / "formats.md").is_file()


@pytest.mark.parametrize("argv", [
    ["sequence", "paper_6x6_fig13a", "--time-limit", "0"],
    ["sequence", "paper_6x6_fig13a", "--time-limit", "inf"],
    ["tile", "tiling_6x6", "--time-limit", "-1"],
    ["tile", "tiling_6x6", "--shuffle", "--seed", "-3"],
    ["plan", "three_slit", "--method", "htetro-ga", "--seed", "-1"],
    ["sequence", "tiling_64x64", "--method", "exact"],
])
def test_cli_errors_speak_the_command_lines_language(capsys, argv):
    code, out, err = run(capsys, argv)
    assert_one_error_line(code, out, err)
    for library_word in ("or None", "max_size=", "method='", "time_limit ", "Generator"):
        assert library_word not in err, (library_word, err)


# --------------------------------------------------------------------------------------------------
# --gif


def test_plan_gif_has_frames_for_every_step(capsys, near, tmp_path):
    from PIL import Image

    gif = tmp_path / "plan.gif"
    out = run_json(capsys, ["plan", near, "--json", "--gif", str(gif)])
    assert gif.read_bytes()[:6] == b"GIF89a"
    assert Image.open(gif).n_frames == 4 * len(out["commands"]) + 1  # 4 frames a command, the start


def test_simulate_gif_shows_the_executed_prefix(capsys, near, tmp_path):
    from PIL import Image

    gif = tmp_path / "sim.gif"
    out = run_json(capsys, ["simulate", near, "--commands", "x+ x+ x+ x+ x+ x+", "--json", "--gif", str(gif)])
    assert out["executed"] == 5 and Image.open(gif).n_frames == 4 * 5 + 1


@pytest.mark.parametrize("name,words", [("missing/x.gif", ["cannot write animation", "does not exist"]),
                                        ("x.png", ["--gif", "GIF"])])
def test_a_bad_gif_path_is_refused_before_any_work(capsys, near, tmp_path, name, words):
    folder = tmp_path / "out"
    folder.mkdir()
    assert_one_error_line(*run(capsys, ["plan", near, "--gif", str(folder / name)]), *words)
    assert list(folder.iterdir()) == []


# --------------------------------------------------------------------------------------------------
# study NAME|FILE (the study runner)

TINY_STUDY = """\
name = "tiny"
task = "plan"
scenarios = ["three_slit", "h_shape"]
seeds = 2
[[methods]]
method = "exact"
[[methods]]
method = "htetro-ga"
pop_size = 8
max_gen = 5
patience = 3
"""


def test_study_file_runs_records_and_summarises(capsys, tmp_path):
    study = tmp_path / "tiny.toml"
    study.write_text(TINY_STUDY)
    out_dir = tmp_path / "out"
    code, out, err = run(capsys, ["study", str(study), "--executor", "serial", "--out", str(out_dir)])
    assert code == 0, err
    assert "| three_slit | exact |" in out and "| h_shape | htetro-ga |" in out
    records = [json.loads(line) for line in (out_dir / "tiny.jsonl").read_text().splitlines()]
    # the exact method runs once per map (no seed), the GA once per seed
    assert sorted((r["scenario"], r["method"], r["seed"]) for r in records if r.get("kind") != "reference") == [
        ("h_shape", "astar", None), ("h_shape", "htetro-ga", 0), ("h_shape", "htetro-ga", 1),
        ("three_slit", "astar", None), ("three_slit", "htetro-ga", 0), ("three_slit", "htetro-ga", 1)]
    exact = next(r for r in records if r["scenario"] == "three_slit" and r["method"] == "astar")
    assert exact["time"] == 33.0
    # resuming a finished study runs nothing again and gives the same summary
    again = run_json(capsys, ["study", str(study), "--executor", "serial", "--out", str(out_dir), "--resume",
                              "--json"])
    assert again["trials"] == 6 and len((out_dir / "tiny.jsonl").read_text().splitlines()) == len(records)


@pytest.mark.parametrize("text,words", [
    (TINY_STUDY.replace('"three_slit"', '"atlantis"'), ["atlantis"]),
    (TINY_STUDY.replace('method = "exact"', 'method = "simplex"'), ["simplex", "methods[0]"]),
    (TINY_STUDY.replace("pop_size = 8", "pop_size = 8\ncolour = 3"), ["colour", "methods[1]"]),
    (TINY_STUDY.replace("pop_size = 8", 'pop_size = "big"'), ["pop_size", "methods[1]"]),
    (TINY_STUDY.replace('task = "plan"', 'task = "cook"'), ["task", "cook"]),
    (TINY_STUDY.replace("seeds = 2", "seeds = -2"), ["seeds"]),
    (TINY_STUDY.replace('method = "exact"', 'method = "exact"\npop_size = 8'), ["pop_size", "methods[0]"]),
    (TINY_STUDY + "\nfrobnicate = 1\n", ["frobnicate"]),
    ("name = [\n", ["tiny.toml"]),
])
def test_bad_study_files_are_one_error_line_and_write_nothing(capsys, tmp_path, text, words):
    study = tmp_path / "tiny.toml"
    study.write_text(text)
    out_dir = tmp_path / "out"
    assert_one_error_line(*run(capsys, ["study", str(study), "--out", str(out_dir)]), *words)
    assert not out_dir.exists()


@pytest.mark.parametrize("argv,words", [
    (["study", "small", "--scheduler", "tcp://127.0.0.1:1"], ["--scheduler", "dask"]),
    (["study", "small", "--resume"], ["--resume", "--out"]),
    (["study", "small", "--time-limit", "3"], ["--time-limit", "le2018"]),
    (["study", "le2018", "--executor", "dask"], ["--executor", "le2018"]),
    (["study", "nonesuch"], ["nonesuch"]),
])
def test_study_options_that_do_not_fit_are_refused(capsys, argv, words):
    assert_one_error_line(*run(capsys, argv), *words)


def test_study_table4_prints_ours_beside_the_papers(capsys, tmp_path):
    study = tmp_path / "table4.toml"  # the name selects Table 4's trial and report
    study.write_text('name = "table4"\ntask = "plan"\nscenarios = ["three_slit"]\nseeds = 1\n'
                     'metrics = ["generations", "fitness", "gap"]\n'
                     '[[methods]]\nmethod = "htetro-ga"\npop_size = 12\nmax_gen = 5\npatience = 3\nmax_length = 100\n')
    out_dir = tmp_path / "out"
    code, out, err = run(capsys, ["study", str(study), "--executor", "serial", "--out", str(out_dir)])
    assert code == 0, err
    assert "| three_slit | 12 |" in out and "exact optimum" in out
    report = (out_dir / "table4_paper.md").read_text().strip()
    assert report.startswith("| environment") and report in out


def test_study_le2018_runs_on_the_runner_and_resumes(capsys, tmp_path):
    out_dir = tmp_path / "out"
    argv = ["study", "le2018", "--seeds", "1", "--time-limit", "0.2", "--out", str(out_dir)]
    code, out, err = run(capsys, argv)
    assert code == 0, err
    assert out.count("### Table") >= 5 and "Exact (CP-SAT)" in out
    assert sorted(p.name for p in out_dir.iterdir()) == ["le2018.csv", "le2018.jsonl", "le2018.md",
                                                         "le2018_paper.md"]
    lines = (out_dir / "le2018.jsonl").read_text().splitlines()
    again = run_json(capsys, [*argv, "--resume", "--json"])  # nothing left to run: the same records
    assert again["trials"] == len(again["records"]) and (out_dir / "le2018.jsonl").read_text().splitlines() == lines


# --------------------------------------------------------------------------------------------------
# plan --method heat (Do et al. 2021)


def test_plan_heat_json_and_replay(capsys):
    out = run_json(capsys, ["plan", "h_shape", "--method", "heat", "--weights", "1,0,1", "--json"])
    assert out["method"] == "heat" and out["reached"] is True
    assert set(out["info"]["fitness"]) == {"f_t", "f_sm", "f_sf", "f"} and out["info"]["weights"] == [1.0, 0.0, 1.0]
    exact = run_json(capsys, ["plan", "h_shape", "--diagonals", "--json"])
    assert out["time"] >= exact["time"] - 1e-9  # no method beats the proven optimum
    replay = run_json(capsys, ["simulate", "h_shape", "--commands", ",".join(out["commands"]), "--json"])
    assert replay["reached"] is True and replay["time"] == pytest.approx(out["time"])


@pytest.mark.parametrize("argv,words", [
    (["--method", "heat", "--weights", "0,0,0"], ["--weights"]),
    (["--method", "heat", "--weights", "1,2"], ["--weights"]),
    (["--method", "heat", "--pop-size", "5"], ["--pop-size", "heat"]),
    (["--method", "heat", "--t-max", "-1"], ["--t-max"]),
    (["--t-max", "5"], ["--t-max", "heat"]),
    (["--method", "htetro-ga", "--element", "p0"], ["--element", "heat"]),
    (["--method", "heat", "--band", "0"], ["--band"]),
    (["--method", "heat", "--band", "wide"], ["--band"]),
    (["--band", "4"], ["--band", "heat"]),
    (["--method", "heat", "--sensor-range", "0"], ["--sensor-range"]),
    (["--method", "heat", "--sensor-range", "2"], ["sensor_range", "3.162"]),
    (["--sensor-range", "6"], ["--sensor-range", "heat"]),
])
def test_plan_heat_bad_options(capsys, argv, words):
    assert_one_error_line(*run(capsys, ["plan", "h_shape", *argv]), *words)


def test_plan_heat_refuses_moving_obstacles(capsys):
    assert_one_error_line(*run(capsys, ["plan", "parallel_dynamic", "--method", "heat"]), "static")


def test_plan_heat_band_and_weights_in_the_json(capsys):
    whole = run_json(capsys, ["plan", "maze", "--method", "heat", "--weights", "1,1,1", "--json"])
    banded = run_json(capsys, ["plan", "maze", "--method", "heat", "--weights", "1,1,1", "--band", "2", "--json"])
    whole, banded = whole["info"], {**banded, **banded["info"]}
    assert whole["band"][0]["radius"] is None and banded["band"][0]["radius"] >= 2
    assert banded["band"][0]["cells"] < whole["band"][0]["cells"]
    assert banded["surrogate"][0] >= whole["surrogate"][0] - 1e-12  # a band is part of the whole graph
    replay = run_json(capsys, ["simulate", "maze", "--commands", ",".join(banded["commands"]), "--json"])
    assert replay["reached"] is True and replay["time"] == pytest.approx(banded["time"])


def test_plan_heat_with_a_sensor_replans_in_the_true_world(capsys, tmp_path):
    png = tmp_path / "heat.png"
    out = run_json(capsys, ["plan", "maze_partial", "--method", "heat", "--sensor-range", "6", "--json",
                            "--plot", str(png)])
    run = out["info"]
    assert out["reached"] is True and run["plans"] == len(run["replans"]) + 1 >= 2
    assert {"step", "pose", "revealed"} <= set(run["replans"][0])
    # simulate runs in the true world (hidden obstacles included): the executed commands are valid there
    replay = run_json(capsys, ["simulate", "maze_partial", "--commands", ",".join(out["commands"]), "--json"])
    assert replay["reached"] is True and replay["time"] == pytest.approx(out["time"])
    assert png.stat().st_size > 10_000 and png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


# --------------------------------------------------------------------------------------------------
# cover (Cheng et al. 2019)


def test_cover_json_keys_and_replay(capsys):
    out = run_json(capsys, ["cover", "coverage_16x7", "--shapes", "O,hI", "--stripes", "2,3,2", "--json"])
    assert {"scenario", "method", "shapes", "stripes", "start", "goal", "complete", "free", "coverable", "covered",
            "uncoverable", "action_cost", "time", "commands", "coverage_pct", "recovered_pct", "average_coverage_time",
            "coverable_pct", "path_length", "switches", "turns", "regions", "regions_optimal", "mopup_commands",
            "stripes_detail", "time_limited", "ends", "runtime_s"} <= set(out)
    assert out["ends"] == "sweep"
    assert out["coverable_pct"] == 100.0 and 0 < out["recovered_pct"] < 100
    # every command covers 4 cells' worth of pixels for one unit: the average over the free cells follows
    assert out["average_coverage_time"] == pytest.approx(4 * out["time"] / out["free"], rel=0.01)
    assert out["complete"] is False and out["uncoverable"] == [{"x": 0, "y": 0, "reason": "no-fit"}]
    assert out["covered"] == out["coverable"] == out["free"] - 1 and out["action_cost"] == len(out["commands"])
    assert out["stripes"] == [2, 3, 2] and len(out["stripes_detail"]) == 3
    replay = run_json(capsys, ["simulate", "coverage_16x7", "--commands", ",".join(out["commands"]), "--json"])
    assert replay["valid"] is True and replay["time"] == pytest.approx(out["time"])
    paper = run_json(capsys, ["cover", "coverage_16x7", "--shapes", "O,hI", "--stripes", "2,3,2", "--method",
                              "stripes-paper", "--json"])
    assert paper["stripes_detail"][-1]["borrowed"] >= 1  # the paper's Fig. 11: the top stripe borrows a row
    assert paper["additions"] == [] and paper["mopup_commands"] == 0
    assert paper["success"] is (not paper["missed"] and not paper["failed_regions"])


def test_cover_boustrophedon_and_auto_start(capsys):
    stripes = run_json(capsys, ["cover", "coverage_16x16", "--shapes", "O", "--json"])
    bous = run_json(capsys, ["cover", "coverage_16x16", "--method", "boustrophedon", "--shapes", "O", "--json"])
    assert stripes["complete"] and bous["complete"] and stripes["action_cost"] <= bous["action_cost"]
    assert stripes["goal"] is None and bous["method"] == "boustrophedon"
    code, out, err = run(capsys, ["cover", "coverage_16x7", "--start", "auto", "--shapes", "O,hI"])
    assert code == 0 and "commands" in out.splitlines()[0] and "region searches optimal" in out
    # the baseline runs no region search: its line does not count "0 of 0" of them
    code, out, err = run(capsys, ["cover", "coverage_16x7", "--method", "boustrophedon", "--shapes", "O,hI"])
    assert code == 0 and "commands" in out.splitlines()[0] and "region searches" not in out
    for method, more in (("stripes-paper", ["--additions", "greedy-fallback,mopup"]), ("tiling-tsp", [])):
        other = run_json(capsys, ["cover", "coverage_16x16", "--method", method, "--shapes", "O,vI,hI", *more,
                                  "--json"])
        assert other["complete"] and other["method"] == method and other["action_cost"] > stripes["action_cost"]


@pytest.mark.parametrize("argv,words", [
    (["--shapes", "Q"], ["Q", "SHAPE@H"]),
    (["--stripes", "3,3"], ["sum"]),
    (["--stripes", "0"], ["stripes"]),
    (["--region-columns", "0"], ["--region-columns"]),
    (["--budget", "0"], ["--budget"]),
    (["--time-limit", "0"], ["--time-limit"]),
    (["--shapes", "hI"], ["start", "--shapes"]),  # the roadmap's start is an O
    (["--method", "zigzag"], ["zigzag"]),
    (["--ends", "start"], ["--ends", "start"]),
    (["--method", "tiling-tsp"], ["103 cells"]),  # not a multiple of 4: TilingError
])
def test_cover_bad_options(capsys, argv, words):
    assert_one_error_line(*run(capsys, ["cover", "coverage_16x7", *argv]), *words)


def test_cover_ends_both_is_recorded_and_never_costlier(capsys):
    argv = ["cover", "coverage_16x7", "--shapes", "O,hI", "--stripes", "2,3,2", "--json"]
    sweep = run_json(capsys, argv)
    both = run_json(capsys, [*argv, "--ends", "both"])
    assert both["ends"] == "both" and sweep["ends"] == "sweep"
    assert both["action_cost"] <= sweep["action_cost"] and both["covered"] == sweep["covered"]
    replay = run_json(capsys, ["simulate", "coverage_16x7", "--commands", ",".join(both["commands"]), "--json"])
    assert replay["valid"] is True and replay["time"] == pytest.approx(both["time"])


def test_cover_refuses_a_continuous_scenario(capsys, tmp_path):
    path = tmp_path / "c.toml"
    path.write_text('width = 10.0\nheight = 10.0\nrobot_radius = 0.1\nobstacles = []\n'
                    '[[robots]]\nstart = [1.0, 1.0]\ngoal = [9.0, 9.0]\n')
    assert_one_error_line(*run(capsys, ["cover", str(path)]), "continuous")


def test_cover_plots(capsys, tmp_path):
    png, svg = tmp_path / "cover.png", tmp_path / "heat.svg"
    out = run_json(capsys, ["cover", "coverage_16x7", "--shapes", "O,hI", "--stripes", "2,3,2", "--json",
                            "--plot", str(png), "--coverage-plot", str(svg)])
    assert out["complete"] is False
    assert png.read_bytes().startswith(PNG_SIGNATURE) and svg.read_bytes().startswith(b"<?xml")


@pytest.mark.parametrize("flag,name,words", [
    ("--plot", "no/c.png", ["cannot write plot"]),
    ("--coverage-plot", "no/c.png", ["cannot write coverage plot"]),
    ("--coverage-plot", "c.docx", ["docx"]),
])
def test_cover_checks_plot_paths_before_planning(capsys, tmp_path, monkeypatch, flag, name, words):
    import htetro_opt.solvers.coverage as coverage

    def must_not_run(*args, **kwargs):
        raise AssertionError("planned before checking the output path")

    monkeypatch.setattr(coverage, "plan_coverage", must_not_run)
    assert_one_error_line(*run(capsys, ["cover", "coverage_16x7", flag, str(tmp_path / name)]), *words)
    assert list(tmp_path.iterdir()) == []
