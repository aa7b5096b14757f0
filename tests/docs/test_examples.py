"""The example notebooks in docs/examples run from start to end (nbclient, one kernel each)."""
from pathlib import Path

import pytest

nbclient = pytest.importorskip("nbclient")
nbformat = pytest.importorskip("nbformat")

REPO = Path(__file__).resolve().parents[2]
#: Per notebook (s): quickstart runs 0.3 s of the reduced case (~10 s warm, ~40 s with the
#: first compilation of the kernels) plus the kernel start and imports.
TIMEOUT_S = 180


@pytest.mark.parametrize("name", ["quickstart.ipynb"])
def test_notebook_runs(name, tmp_path):
    # a copy in a tree like the repository's, so the notebook's outputs (runs/) stay out of it
    examples = tmp_path / "docs" / "examples"
    examples.mkdir(parents=True)
    (tmp_path / "cases").symlink_to(REPO / "cases")
    notebook = nbformat.read(REPO / "docs" / "examples" / name, as_version=4)
    client = nbclient.NotebookClient(notebook, timeout=TIMEOUT_S, kernel_name="python3",
                                     resources={"metadata": {"path": str(examples)}})
    client.execute()
    outputs = [o for cell in notebook.cells if cell.cell_type == "code" for o in cell.outputs]
    assert not [o for o in outputs if o.output_type == "error"]
    text = "".join(o.get("text", "") for o in outputs if o.output_type == "stream")
    assert "debris" in text and "peak contact force" in text
    assert any("image/png" in o.get("data", {}) for o in outputs)   # the plot
    assert (examples / "runs" / "quickstart" / "timeseries.npz").is_file()
