"""Start-up (issue 25, item 6): the command line imports no solver library, and a small exact plan neither
imports numba nor scipy's sparse graphs and images; a second process builds no swept-cell table. Each check runs
in a fresh interpreter and reads its ``sys.modules``: what is imported, never how long it took."""

import json
import os
import subprocess
import sys

import pytest

HEAVY = ("numba", "scipy.sparse", "scipy.ndimage", "pymoo", "networkx", "matplotlib", "skfem", "ortools")


def imported_after(code: str, env=None) -> tuple[list[str], str]:
    """The HEAVY modules imported by ``code`` in a new process, and what it printed before."""
    probe = f"{code}\nimport sys\nprint('\\nIMPORTED', sorted(m for m in {HEAVY!r} if m in sys.modules))"
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True,
                         env={**os.environ, **(env or {})}).stdout
    printed, _, modules = out.rpartition("\nIMPORTED ")
    return eval(modules), printed  # a list of str, printed by repr


def test_importing_the_command_line_and_building_its_parser_imports_no_solver_library():
    modules, _ = imported_after("from htetro_opt.cli import build_parser\nbuild_parser()")
    assert modules == []


@pytest.mark.parametrize("args", [["plan", "three_slit", "--json"],
                                  ["plan", "random", "--method", "dijkstra", "--json"]])
def test_a_small_exact_plan_imports_neither_numba_nor_scipys_graphs(args):
    modules, printed = imported_after(f"from htetro_opt.cli import main\nmain({args!r})")
    assert json.loads(printed)["reached"] is True
    assert modules == []


def test_a_second_process_loads_the_swept_cell_tables(tmp_path):
    code = ("from htetro_opt.model import sweeps\nbuilt = []\nbuild = sweeps._build_sweep_tables\n"
            "sweeps._build_sweep_tables = lambda c: built.append(c) or build(c)\n"
            "sweeps.sweep_tables(0.0)\nprint(len(built))")
    env = {"HTETRO_OPT_CACHE_DIR": str(tmp_path)}
    assert [imported_after(code, env)[1].strip() for _ in range(2)] == ["1", "0"]
