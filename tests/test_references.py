"""Every public name whose docstring cites an equation of the paper says which paper."""

import importlib
import inspect
import re

import pytest

import ecofmaps
from ecofmaps import paper

SUBPACKAGES = ("correction", "io", "maps", "measured", "model")


def _public():
    names = {name: getattr(ecofmaps, name) for name in ecofmaps.__all__ if name != "__version__"}
    for package in SUBPACKAGES:
        module = importlib.import_module(f"ecofmaps.{package}")
        names.update({f"{package}.{n}": getattr(module, n) for n in module.__all__})
    return {name: obj for name, obj in names.items() if callable(obj)}


PUBLIC = _public()
CITES_AN_EQUATION = re.compile(r"\beq\.\s*\d")


def _references(doc: str) -> str:
    """The text of the numpydoc References section, whitespace collapsed ('' if none)."""
    found = re.search(
        r"\n\s*References\n\s*-{10}\n(.*?)(\n\s*\n\s*\w[\w ]*\n\s*-{3,}\n|$)", doc, re.S
    )
    return " ".join(found.group(1).split()) if found else ""


def test_some_public_names_cite_equations():
    citing = [name for name, obj in PUBLIC.items() if CITES_AN_EQUATION.search(obj.__doc__ or "")]
    assert len(citing) >= 25 and "energy_cof" in citing and "analyze_loops" in citing


@pytest.mark.parametrize("name", sorted(PUBLIC))
def test_a_docstring_that_cites_an_equation_has_references(name):
    doc = inspect.getdoc(PUBLIC[name]) or ""
    if not CITES_AN_EQUATION.search(doc.split("References")[0]):
        return
    references = _references("\n" + doc)
    assert references.startswith(f"{paper.CITATION}: eq. "), (name, references)
    cited = set(re.findall(r"\d+", references[len(paper.CITATION) :]))
    in_text = set(re.findall(r"\beqs?\.\s*(\d+)", doc.split("References")[0]))
    assert in_text <= cited | _ranges(references), (name, in_text - cited)


def _ranges(references: str) -> set:
    """Every equation number inside the ranges ``a-b`` of ``references``."""
    return {
        str(n) for a, b in re.findall(r"(\d+)-(\d+)", references) for n in range(int(a), int(b) + 1)
    }
