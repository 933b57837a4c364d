"""``htetro-opt plan`` on continuous scenarios (Nazarahari et al. 2019): JSON keys, plots, one
``error:`` line and exit 2 for every bad input, and the README's synopsis line against the parser."""

import json
import re
from pathlib import Path

import pytest

from htetro_opt.cli import build_parser, main

README = (Path(__file__).resolve().parents[3] / "README.md").read_text()


def run(capsys, *argv):
    code = main(["plan", *argv])
    out, err = capsys.readouterr()
    return code, out, err


@pytest.mark.parametrize("method, extra", [("ega", []), ("ega-paper", ["--max-gen", "5"]),
                                           ("nsga2", ["--max-gen", "5"]), ("exact", []), ("astar", ["--grid", "0.5"]),
                                           ("prm", ["--seed", "2"]), ("rrt", ["--time-limit", "5"]),
                                           ("pso", ["--pop-size", "6", "--max-gen", "5", "--grid", "0.5"])])
def test_json_keys_per_method(capsys, method, extra):
    code, out, err = run(capsys, "ega08_slits2", "--method", method, "--json", *extra)
    assert code == 0, err
    data = json.loads(out)
    keys = {"scenario", "method", "success", "message", "reached", "paths", "objectives", "min_robot_distance",
            "conflicts", "runtime_s", "time_limited", "additions", "info"}
    assert set(data) == keys | ({"front"} if method == "nsga2" else set())
    assert data["reached"] and data["method"] == method and len(data["paths"]) == 1
    assert set(data["objectives"]) == {"length", "smoothness_deg", "safety", "min_clearance"}


def test_exact_is_the_default_and_the_egas_seed_repeats(capsys):
    assert json.loads(run(capsys, "ega07_slits1", "--json")[1])["method"] == "exact"  # as on grids: the optimum
    code, out, _ = run(capsys, "ega07_slits1", "--method", "ega", "--json", "--seed", "4", "--max-gen", "4")
    again = run(capsys, "ega07_slits1", "--method", "ega", "--json", "--seed", "4", "--max-gen", "4")[1]
    data = json.loads(out)
    assert code == 0 and data["method"] == "ega" and out.split('"runtime_s"')[0] == again.split('"runtime_s"')[0]
    assert data["info"]["pop_size"] == 10 and data["info"]["max_gen"] == 4


def test_weights_normalise_radius_and_text_output(capsys, tmp_path):
    code, out, err = run(capsys, "ega04_corridor1", "--method", "ega", "--weights", "1,0.5,0", "--path", "spline",
                         "--max-gen", "3", "--json")
    assert code == 0, err
    assert json.loads(out)["info"]["weights"] == [1.0, 0.5, 0.0]
    code, out, err = run(capsys, "ega04_corridor1", "--method", "ega", "--normalise", "--max-gen", "2", "--safety",
                         "min")
    assert code == 0, err
    assert out.startswith("ega04_corridor1: reached (ega") and "length" in out
    code, out, err = run(capsys, "ega_cross4", "--robot-radius", "0.3", "--method", "exact", "--json",
                         "--plot", str(tmp_path / "cross.png"))
    assert code == 0, err
    assert (tmp_path / "cross.png").stat().st_size > 0
    assert json.loads(out)["conflicts"]  # planned alone, the robots meet


@pytest.mark.parametrize("argv, words", [
    (["ega07_slits1", "--method", "dijkstra"], "is not a method of continuous planning"),
    (["three_slit", "--method", "ega"], "is not a method of grid-path planning"),
    (["three_slit", "--safety", "min"], "--safety applies to continuous scenarios only"),
    (["ega07_slits1", "--diagonals"], "--diagonals applies to grid scenarios only"),
    (["ega07_slits1", "--gif", "x.gif"], "--gif applies to grid scenarios only"),
    (["ega07_slits1", "--clearance", "0.5"], "--clearance applies to grid scenarios only"),
    (["ega07_slits1", "--method", "ega", "--grid", "0"], "--grid must be"),
    (["ega07_slits1", "--method", "ega", "--grid", "11"], "grid must be"),
    (["ega07_slits1", "--method", "ega", "--weights", "1,2"], "three numbers"),
    (["ega07_slits1", "--method", "ega", "--weights", "0,0,0"], "must not all be zero"),
    (["ega07_slits1", "--method", "ega", "--weights", "1,x,0"], "three comma-separated numbers"),
    (["ega07_slits1", "--method", "ega", "--weights", "1,0,0", "--normalise"], "not both"),
    (["ega07_slits1", "--method", "nsga2", "--weights", "1,0,0"], "--weights applies to ega and ega-paper only"),
    (["ega07_slits1", "--method", "exact", "--path", "spline"], "--path applies to the GA methods"),
    (["ega07_slits1", "--method", "astar", "--seed", "1"], "--seed applies to the GA methods"),
    (["ega07_slits1", "--method", "exact", "--grid", "0.5"], "--grid applies to the GA methods (ega, ega-paper, "
                                                              "nsga2), astar and pso only, not to exact"),
    (["ega07_slits1", "--robot-radius", "Q"], "--robot-radius must be"),
    (["ega07_slits1", "--robot-radius", "3"], "(radius 3) lies outside"),
    (["ega07_slits1", "--method", "ega", "--pop-size", "1"], "--pop-size"),
    (["ega07_slits1", "--method", "ega", "--time-limit", "5"], "--time-limit applies to rrt only"),
    (["ega07_slits1", "--method", "rrt", "--time-limit", "0"], "--time-limit must be a positive"),
    (["ega07_slits1", "--method", "rrt", "--path", "spline"], "--path applies to the GA methods"),
    (["ega07_slits1", "--method", "prm", "--pop-size", "5"], "--pop-size applies to the GA methods (ega, ega-paper, "
                                                              "nsga2) and pso only, not to prm"),
    (["ega07_slits1", "--method", "prm", "--grid", "0.5"], "--grid applies to the GA methods (ega, ega-paper, "
                                                            "nsga2), astar and pso only, not to prm"),
    (["ega07_slits1", "--method", "pso", "--weights", "1,0,0"], "--weights applies to ega and ega-paper only"),
    (["three_slit", "--method", "prm"], "is not a method of grid-path planning"),
    (["three_slit", "--time-limit", "3"], "--time-limit applies to the GA methods"),
])
def test_bad_inputs_give_one_error_line_and_exit_2(capsys, argv, words):
    code, out, err = run(capsys, *argv)
    assert code == 2 and out == ""
    assert err.count("\n") == 1 and err.startswith("error: ") and words in err, err


def test_baseline_seeds_repeat_on_the_command_line(capsys):
    for method in ("prm", "rrt", "pso"):
        first = run(capsys, "ega01_random1", "--method", method, "--seed", "3", "--json")[1]
        again = run(capsys, "ega01_random1", "--method", method, "--seed", "3", "--json")[1]
        assert json.loads(first)["paths"] == json.loads(again)["paths"], method


def test_the_readme_synopsis_line_matches_the_parser():
    entry = next(e for e in re.findall(r"^htetro-opt plan CONTINUOUS.*?(?=^htetro-opt )", README, flags=re.M | re.S))
    plan = next(a for a in build_parser()._actions if a.__class__.__name__ == "_SubParsersAction").choices["plan"]
    options = {s: a for a in plan._actions for s in a.option_strings}
    for flag in re.findall(r"(--[a-z-]+)", entry):
        assert flag in options, flag
    (listed,) = re.findall(r"--method ([a-z0-9|-]+)", entry)
    assert set(listed.split("|")) <= set(options["--method"].choices)
