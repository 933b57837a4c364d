"""``python -m htetro_opt.cli.warmup``: a first run in a fresh install compiles and says so; a later process compiles
nothing and loads every kernel it runs from numba's on-disk cache."""

import os
import re
import subprocess
import sys

import pytest

from htetro_opt.errors import ParameterError
from htetro_opt.cli.warmup import JOBS, warm_up


def test_a_first_warm_up_compiles_and_says_so_a_second_compiles_nothing(tmp_path):
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "numba"), "HTETRO_OPT_CACHE_DIR": str(tmp_path / "ours")}
    runs = [subprocess.run([sys.executable, "-m", "htetro_opt.cli.warmup", "plan"], capture_output=True, text=True,
                           check=True, env=env) for _ in range(2)]
    counts = [tuple(int(v) for v in re.fullmatch(r"kernels: (\d+) compiled, (\d+) loaded from numba's on-disk cache",
                                                  r.stdout.strip()).groups()) for r in runs]
    (compiled, loaded), (compiled_again, loaded_again) = counts
    assert compiled >= 2 and loaded == 0  # the exact planner's two searches at least
    assert "compiling the numerical kernels" in runs[0].stderr
    assert compiled_again == 0 and loaded_again >= 2
    assert "compiling" not in runs[1].stderr
    assert any((tmp_path / "numba").rglob("*.nbi")) and any((tmp_path / "ours").glob("sweeps-*.npz"))


def test_an_unknown_part_is_refused_before_any_work():
    with pytest.raises(ParameterError, match="unknown warm-up part.*'planning'.*plan, sequence"):
        warm_up(["planning"])


def test_the_sequence_part_writes_a_tsplib_file_of_coordinates():
    """The sequence part's TSPLIB job reads a 12-city EUC_2D file (written to a temporary folder when the
    job runs), posed as a coordinate instance: the kernels of costs computed from coordinates compile too."""
    from htetro_opt.cli.warmup import _TSPLIB, _WARMUP_TSP
    from htetro_opt.problems import SequencingInstance
    from htetro_opt.scenarios.tsplib import parse_tsplib

    assert any(_TSPLIB in args for args in JOBS["sequence"])
    tsp = parse_tsplib(_WARMUP_TSP)
    inst = SequencingInstance.from_tsplib(tsp)
    assert inst.n == 12 and inst.implicit and inst.metric == "EUC_2D"
