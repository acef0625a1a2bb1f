"""Every notebook in analysis/notebooks executes headless on the fixture runs."""
from pathlib import Path

import nbformat
import pytest
from nbclient import NotebookClient

NOTEBOOKS = Path(__file__).resolve().parents[2] / "analysis" / "notebooks"


def parameters_cell(notebook):
    cells = [cell for cell in notebook.cells if "parameters" in cell.metadata.get("tags", [])]
    assert len(cells) == 1, "each notebook has one cell tagged 'parameters'"
    return cells[0]


@pytest.mark.parametrize("path", sorted(NOTEBOOKS.glob("*.ipynb")), ids=lambda p: p.stem)
def test_notebook_executes(path, tmp_path, full_run, periodic_run):
    notebook = nbformat.read(path, as_version=4)
    parameters_cell(notebook).source = (f"RUN_DIRS = [{str(full_run[0])!r}, {str(periodic_run[0])!r}]\n"
                                        f"OUT_DIR = {str(tmp_path)!r}")
    NotebookClient(notebook, timeout=120, kernel_name="python3",
                   resources={"metadata": {"path": str(NOTEBOOKS)}}).execute()
    errors = [output for cell in notebook.cells if cell.cell_type == "code"
              for output in cell.outputs if output.output_type == "error"]
    assert not errors
    images = [output for cell in notebook.cells if cell.cell_type == "code"
              for output in cell.outputs if "image/png" in output.get("data", {})]
    assert images, "the notebook shows figures"


def test_notebooks_hold_no_logic():
    """Cells call the package; no function or class definitions live in a notebook."""
    for path in NOTEBOOKS.glob("*.ipynb"):
        for cell in nbformat.read(path, as_version=4).cells:
            if cell.cell_type == "code":
                assert "def " not in cell.source and "class " not in cell.source, path.name
