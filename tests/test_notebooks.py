"""The notebooks in notebooks/ are stored run, with their outputs; they use only public names
of ecofmaps; and they still run from top to bottom (`python notebooks/run.py` refreshes them)."""

import ast
import importlib
import importlib.util
from pathlib import Path

import nbformat
import pytest

FOLDER = Path(__file__).parents[1] / "notebooks"
NOTEBOOKS = sorted(FOLDER.glob("*.ipynb"))
IDS = [path.name for path in NOTEBOOKS]


def _code(notebook) -> str:
    """The notebook's Python, IPython's magics (%config, %matplotlib) left out."""
    cells = [cell.source for cell in notebook.cells if cell.cell_type == "code"]
    lines = "\n".join(cells).splitlines()
    return "\n".join(line for line in lines if not line.lstrip().startswith("%"))


def _non_public_names(code: str) -> list[str]:
    """Every ``ecofmaps...`` name the code imports or reads that is not in its module's
    ``__all__`` (``from ecofmaps.x import y``, ``import ecofmaps``, ``ecofmaps.x.y``)."""
    found = []

    def resolved(module, names):
        """The object at ``module.names[0].names[1]...``, public step by step, or None."""
        value = module
        for name in names:
            if type(value).__name__ != "module":
                return value  # an attribute of a public object: its own business
            if name not in getattr(value, "__all__", ()):
                found.append(f"{value.__name__}.{name}")
                return None
            value = getattr(value, name)
        return value

    ecofmaps = importlib.import_module("ecofmaps")
    modules = {}  # local name: the ecofmaps module it stands for
    tree = ast.parse(code)
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                if alias.name.split(".")[0] == "ecofmaps":
                    names = alias.name.split(".")[1:]
                    modules[alias.asname or "ecofmaps"] = resolved(ecofmaps, names)
        elif isinstance(node, ast.ImportFrom) and (node.module or "").split(".")[0] == "ecofmaps":
            module = resolved(ecofmaps, node.module.split(".")[1:])
            for alias in node.names if module is not None else ():
                value = resolved(module, [alias.name])
                if type(value).__name__ == "module":
                    modules[alias.asname or alias.name] = value
    for node in ast.walk(tree):
        chain = []
        while isinstance(node, ast.Attribute):
            chain.insert(0, node.attr)
            node = node.value
        if isinstance(node, ast.Name) and modules.get(node.id) is not None and chain:
            resolved(modules[node.id], chain)
    return sorted(set(found))


def test_the_check_of_public_names_finds_an_internal_one():
    code = "import ecofmaps\nfrom ecofmaps.io.tables import results_table\necofmaps.energy_cof\n"
    assert _non_public_names(code) == ["ecofmaps.io.tables"]
    assert _non_public_names("import ecofmaps\necofmaps._inputs\n") == ["ecofmaps._inputs"]


@pytest.mark.parametrize("path", NOTEBOOKS, ids=IDS)
def test_notebook_uses_only_public_names(path):
    assert _non_public_names(_code(nbformat.read(path, as_version=4))) == []


@pytest.mark.parametrize("path", NOTEBOOKS, ids=IDS)
def test_notebook_is_stored_run_with_its_outputs(path):
    notebook = nbformat.read(path, as_version=4)
    code = [cell for cell in notebook.cells if cell.cell_type == "code"]
    assert all(cell.execution_count for cell in code), "stored without running every cell"
    outputs = [output for cell in code for output in cell.outputs]
    assert not [output for output in outputs if output.output_type == "error"]
    assert any("image/png" in output.get("data", {}) for output in outputs)


@pytest.mark.slow
@pytest.mark.parametrize("path", NOTEBOOKS, ids=IDS)
def test_notebook_runs(path):
    """Run as `python notebooks/run.py` runs it (which raises on a cell's error, naming the
    cell): the kernel inherits the test session's private ECOFMAPS_CACHE and MPLBACKEND."""
    spec = importlib.util.spec_from_file_location("notebooks_run", FOLDER / "run.py")
    run = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(run)
    notebook = run.executed(path)
    outputs = [output for cell in notebook.cells for output in cell.get("outputs", [])]
    assert not [output for output in outputs if output.output_type == "error"]
