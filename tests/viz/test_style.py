"""htetro_opt.viz._style: the viz modules import one another without a circle, and the one colour-bar
helper labels the bar it adds."""

import ast
from pathlib import Path

import numpy as np

import htetro_opt.viz
from htetro_opt.viz._style import _colour_bar, _pyplot

VIZ = Path(htetro_opt.viz.__file__).parent


def viz_imports(path: Path) -> set[str]:
    """The viz modules a module imports anywhere in it (at the top or inside a function)."""
    found = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.ImportFrom) and node.module:
            names = [node.module] + [f"{node.module}.{a.name}" for a in node.names]
        elif isinstance(node, ast.Import):
            names = [a.name for a in node.names]
        else:
            continue
        modules = {n.split(".")[2] for n in names if n.startswith("htetro_opt.viz.")}
        found |= {m for m in modules if (VIZ / f"{m}.py").exists()}
    return found


def test_no_two_viz_modules_import_each_other_in_a_circle():
    graph = {p.stem: viz_imports(p) - {p.stem} for p in VIZ.glob("*.py") if p.stem != "__init__"}
    assert graph["_style"] == set()  # the shared style imports no plot module
    done, path = set(), []

    def visit(module):
        assert module not in path, f"import circle: {' -> '.join(path[path.index(module):] + [module])}"
        if module in done:
            return
        path.append(module)
        for imported in sorted(graph[module]):
            visit(imported)
        path.pop()
        done.add(module)

    for module in sorted(graph):
        visit(module)


def test_colour_bar_is_labelled_beside_its_axes():
    fig, ax = _pyplot().subplots()
    image = ax.imshow(np.arange(6.0).reshape(2, 3))
    bar = _colour_bar(ax, image, "temperature", shrink=0.5, fontsize=7)
    assert fig.axes == [ax, bar.ax]
    assert bar.ax.get_ylabel() == "temperature" and bar.ax.yaxis.label.get_fontsize() == 7
    assert bar.ax.get_position().height < ax.get_position().height  # shrunk
