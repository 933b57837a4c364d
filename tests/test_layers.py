"""The packages import one way: each imports only from its own floor and those below it.

model (3) and scenarios (4) sit under problems (5) and operators (6), then algorithms (7), solvers (8),
and studies, viz and the command line on top. Every import statement counts, a deferred one inside a
function too; the private top-level modules (``_validation``, ``_lazy``, …) and ``errors`` are the floor.
"""

import ast
import subprocess
import sys
from pathlib import Path

import htetro_opt

PACKAGE = Path(htetro_opt.__file__).parent
FLOORS = {"model": 3, "scenarios": 4, "problems": 5, "operators": 6, "algorithms": 7, "solvers": 8,
          "studies": 9, "viz": 9, "cli": 9}


def _floor(module: str) -> int | None:
    parts = module.split(".")
    if parts[0] != "htetro_opt":
        return None
    return FLOORS.get(parts[1], 0) if len(parts) > 1 else 0


def _imports(path: Path, module: str):
    """(line, imported module) of every import statement in ``path``, relative ones resolved."""
    package = module if path.name == "__init__.py" else module.rpartition(".")[0]
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            yield from ((node.lineno, alias.name) for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[:len(package.split(".")) - node.level + 1]
                yield node.lineno, ".".join(base + ([node.module] if node.module else []))
            else:
                yield node.lineno, node.module


def test_no_module_imports_from_a_floor_above_its_own():
    upward = []
    for path in sorted(PACKAGE.rglob("*.py")):
        parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
        module = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
        own = _floor(module)
        for line, target in _imports(path, module):
            floor = _floor(target)
            if floor is not None and floor > own:
                upward.append(f"{path.relative_to(PACKAGE.parent)}:{line} imports {target}")
    assert upward == []


def test_the_model_loads_its_continuous_geometry_only_when_used():
    code = ("import sys, htetro_opt.model as m; print('shapely' in sys.modules); "
            "m.apf_population, m.visibility_path; print('shapely' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                         cwd=PACKAGE.parent).stdout.split()
    assert out == ["False", "True"]


def test_the_continuous_solvers_re_export_the_geometry_they_share():
    import htetro_opt.model as model
    import htetro_opt.scenarios as scenarios
    import htetro_opt.solvers.continuous as continuous

    for name in ("apf_depths", "apf_paths", "apf_population", "turning_points", "lattice_graph", "visibility_path",
                 "SAFETY_MARGIN"):
        assert getattr(continuous, name) is getattr(model, name), name
    assert continuous.check_scenario is scenarios.check_continuous_scenario
