"""The notebooks under notebooks/: committed clean, and naming their papers by authors and year.

Their execution is not part of this file: nbmake runs them top to bottom with the small settings,

    HTETRO_OPT_SMALL=1 pytest --nbmake notebooks/

Here only what the committed files hold is checked (the ipynb JSON, read with the standard library):
no outputs or execution counts (so that diffs show only what was written), the small-settings switch,
and the papers named as docs/model.md names them, never by an internal seed number.
"""

import json
import re
from pathlib import Path

import pytest

NOTEBOOK_DIR = Path(__file__).resolve().parents[1] / "notebooks"
NOTEBOOKS = sorted(NOTEBOOK_DIR.glob("*.ipynb"))

# The paper each notebook reproduces, as docs/model.md names it.
PAPERS = {
    "00_quickstart.ipynb": "Cheng et al. 2020",
    "01_htetro_ga_pareto.ipynb": "Cheng et al. 2020",
    "02_heat_conduction.ipynb": "Do et al. 2021",
    "03_enhanced_ga.ipynb": "Nazarahari et al. 2019",
    "04_tiling_sequencing.ipynb": "Le et al. 2018",
    "05_stripe_coverage.ipynb": "Cheng et al. 2019",
}
AUTHORS_AND_YEAR = re.compile(r"\b[A-Z][a-z]+ et al\. (19|20)\d\d\b")
# "seed 0", "seed 000", "seed 003", "seed003", "SEED000_…": internal names of the papers' work packages.
SEED_NAME = re.compile(r"\bseed[\s_-]*0", re.IGNORECASE)
SMALL_SWITCH = 'os.environ.get("HTETRO_OPT_SMALL") == "1"'


def _load(path: Path) -> dict:
    return json.loads(path.read_text(encoding="utf-8"))


def _text(notebook: dict, kind: str | None = None) -> str:
    """The sources of the cells (of one kind), joined; a source is a string or a list of lines."""
    return "\n".join("".join(cell["source"]) for cell in notebook["cells"] if kind in (None, cell["cell_type"]))


def test_the_expected_notebooks_exist():
    assert set(PAPERS) <= {path.name for path in NOTEBOOKS}


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.name)
def test_notebook_has_no_outputs_or_execution_counts(path):
    notebook = _load(path)
    assert notebook["nbformat"] == 4
    code = [cell for cell in notebook["cells"] if cell["cell_type"] == "code"]
    assert code, f"{path.name} has no code cell"
    for index, cell in enumerate(notebook["cells"]):
        where = f"{path.name}, cell {index}"
        if cell["cell_type"] == "code":
            assert cell["outputs"] == [], f"{where} has outputs: clear them before committing"
            assert cell["execution_count"] is None, f"{where} has an execution count: clear it before committing"
        assert "execution" not in cell.get("metadata", {}), f"{where} has execution timings in its metadata"
        assert "attachments" not in cell, f"{where} carries attachments"
    assert "widgets" not in notebook["metadata"], f"{path.name} carries widget state"


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.name)
def test_notebook_names_its_paper_by_authors_and_year(path):
    text = _text(_load(path))
    if path.name in PAPERS:
        assert PAPERS[path.name] in text
    else:
        assert AUTHORS_AND_YEAR.search(text), f"{path.name} names no paper by authors and year"
    found = SEED_NAME.search(text)
    assert found is None, f"{path.name} says {found.group(0)!r}: name the paper by authors and year"


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.name)
def test_notebook_reads_the_small_settings_switch(path):
    notebook = _load(path)
    assert SMALL_SWITCH in _text(notebook, "code")
    assert notebook["metadata"]["kernelspec"]["name"] == "python3"


def test_the_name_checks_can_fail():
    assert SEED_NAME.search("as in seed 003's Table 1") and SEED_NAME.search("SEED000_COMMANDS")
    assert SEED_NAME.search("Seed 0 reaches the goal")
    assert not SEED_NAME.search("seed=0, seeds 0-4, seed 1")
    assert AUTHORS_AND_YEAR.search("Le et al. 2018 tile the map") and not AUTHORS_AND_YEAR.search("Le 2018")
