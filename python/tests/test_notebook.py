"""The tutorial notebook (docs/tutorial.ipynb) runs from top to bottom in a fresh kernel, and is kept without
outputs (the repository stays small; the outputs are the reader's to make)."""

import pathlib

import pytest

nbformat = pytest.importorskip("nbformat")
nbclient = pytest.importorskip("nbclient")

TUTORIAL = pathlib.Path(__file__).resolve().parents[2] / "docs" / "tutorial.ipynb"


def test_tutorial_is_committed_without_outputs():
    notebook = nbformat.read(TUTORIAL, as_version=4)
    nbformat.validate(notebook)
    for cell in notebook.cells:
        if cell.cell_type == "code":
            assert cell.outputs == [] and cell.execution_count is None, cell.source[:60]


def test_tutorial_runs_every_cell(tmp_path):
    notebook = nbformat.read(TUTORIAL, as_version=4)
    client = nbclient.NotebookClient(
        notebook, timeout=600, kernel_name="python3", resources={"metadata": {"path": str(tmp_path)}}
    )
    client.execute()  # a failing cell raises CellExecutionError with its traceback
    outputs = [o for cell in notebook.cells if cell.cell_type == "code" for o in cell.outputs]
    assert not [o for o in outputs if o.output_type == "error"]
    # The figures and the animation were displayed.
    images = [o for o in outputs if "data" in o and ("image/png" in o["data"] or "image/gif" in o["data"])]
    assert len(images) >= 6, [list(o.get("data", {})) for o in outputs]
