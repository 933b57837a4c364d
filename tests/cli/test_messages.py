"""The command line's errors in a user's words: one ``error:`` line, exit 2, checked before any work,
naming what can be typed and what a value would cost."""

from __future__ import annotations

import pytest

from htetro_opt.cli import main


def _error(capsys, argv):
    code = main(argv)
    out, err = capsys.readouterr()
    assert code == 2 and out == "" and err.count("\n") == 1 and err.startswith("error: "), err
    return err


@pytest.mark.parametrize("argv, words", [
    (["plan", "three_slit", "--method", "htetro-ga", "--pop-size", "1000000000"],
     ["--pop-size 1,000,000,000", "TiB", "at most 100,000"]),
    (["plan", "three_slit", "--method", "htetro-ga", "--max-gen", "1000000000000"], ["--max-gen", "years", "at most"]),
    (["plan", "ega07_slits1", "--method", "ega", "--pop-size", "1000000"], ["--pop-size", "GiB", "at most 10,000"]),
    (["cover", "coverage_16x7", "--budget", "1000000000"], ["--budget", "GiB", "at most 10,000,000"]),
])
def test_a_size_too_large_is_refused_with_what_it_would_cost(capsys, argv, words):
    err = _error(capsys, argv)
    assert all(w in err for w in words), err


def test_a_missing_file_is_a_missing_file(capsys, tmp_path):
    assert "file not found" in _error(capsys, ["plan", str(tmp_path / "no_such_map.toml")])
    assert "is a folder, not a file" in _error(capsys, ["plan", str(tmp_path)])
    assert "not a bundled name" in _error(capsys, ["plan", "no_such_map"])  # a name, not a path: the names listed


def test_the_exact_sequencers_limit_counts_the_waypoints_the_user_has(capsys, tmp_path):
    path = tmp_path / "forty.tsp"
    coords = "\n".join(f"{i + 1} {i * 7 % 41} {i * 13 % 37}" for i in range(40))
    path.write_text(f"NAME : forty\nTYPE : TSP\nDIMENSION : 40\nEDGE_WEIGHT_TYPE : EUC_2D\nNODE_COORD_SECTION\n"
                    f"{coords}\nEOF\n")
    err = _error(capsys, ["sequence", str(path), "--method", "exact"])
    assert "has 40 (41 as the open path" in err and "at most 40" in err


def test_a_flag_value_is_named_in_the_command_lines_words(capsys):
    err = _error(capsys, ["plan", "three_slit", "--method", "htetro-ga", "--patience", "0"])
    assert "--patience must be a positive integer, got 0" in err and "None" not in err
    err = _error(capsys, ["study", "small", "--workers", "0"])
    assert "--workers" in err and "None" not in err
