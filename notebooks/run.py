"""Run the notebooks and store them with their outputs.

    python notebooks/run.py              # every notebook here
    python notebooks/run.py loops.ipynb  # one (a name in this folder)

Each runs from top to bottom in a fresh kernel in this folder, as tests/test_notebooks.py runs
it; a cell that raises stops it and nothing is written. Its images are stored in 256 colours
(a third of the bytes). Needs the extra ``test`` (nbclient, ipykernel).
"""

import base64
import io
import sys
from pathlib import Path

import nbformat
from nbclient import NotebookClient
from PIL import Image

HERE = Path(__file__).resolve().parent
NOTEBOOKS = sorted(HERE.glob("*.ipynb"))


def executed(path: Path) -> nbformat.NotebookNode:
    """The notebook at ``path``, run: its code cells hold their outputs.

    Raises nbclient's ``CellExecutionError``, naming the cell and its traceback, on an error.
    The kernel inherits this process's environment (its ``ECOFMAPS_CACHE``, for one).
    """
    notebook = nbformat.read(path, as_version=4)
    client = NotebookClient(
        notebook,
        timeout=600,
        kernel_name="python3",
        record_timing=False,  # no timestamps: a run changes the file only where outputs do
        resources={"metadata": {"path": str(path.parent)}},
    )
    client.execute()
    return notebook


def small_png(data: str) -> str:
    """A base64 PNG output in at most 256 colours."""
    image = Image.open(io.BytesIO(base64.b64decode(data))).convert("RGB").quantize(256)
    stored = io.BytesIO()
    image.save(stored, format="png", optimize=True)
    return base64.b64encode(stored.getvalue()).decode("ascii")


def main(names: list[str]) -> None:
    for path in [HERE / name for name in names] or NOTEBOOKS:
        notebook = executed(path)
        for cell in notebook.cells:
            for output in cell.get("outputs", []):
                if "image/png" in output.get("data", {}):
                    output.data["image/png"] = small_png(output.data["image/png"])
        nbformat.write(notebook, path)
        print(f"{path.name}: {path.stat().st_size / 1e3:.0f} kB")


if __name__ == "__main__":
    main(sys.argv[1:])
