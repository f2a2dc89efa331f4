"""docs/ explains every output of ecofmaps loops: each column of its table, each quality
flag and each attribute of analyze_loops' results (issue 22, item 5), so the docs cannot
fall behind the code."""

import re
import warnings
from pathlib import Path

import pytest

import ecofmaps
from ecofmaps.io.tables import RESULT_COLUMNS
from ecofmaps.measured.quality import REASONS

DOCS = Path(__file__).resolve().parents[1] / "docs"


@pytest.fixture(scope="module")
def loops_page():
    return (DOCS / "loops.md").read_text(encoding="utf-8")


def _table_rows(page: str) -> set[str]:
    """The names in the first cell of every table row: | `name` | ..."""
    return set(re.findall(r"^\| `([^`]+)` \|", page, flags=re.MULTILINE))


def test_every_column_of_the_table_is_explained(loops_page):
    missing = [
        column for column in ("file", *RESULT_COLUMNS) if column not in _table_rows(loops_page)
    ]
    assert not missing


def test_every_quality_flag_is_explained(loops_page):
    missing = [reason for reason in REASONS if reason not in _table_rows(loops_page)]
    assert not missing


def test_every_attribute_and_variable_of_the_results_is_named(loops_page):
    displacement, force = ecofmaps.synthetic_recording(
        amplitude=50e-6, load=450.0, stiffness=35e6, mu=0.8, aspect_ratio=0.2, cycles=3
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        results = ecofmaps.analyze_loops(displacement, force, 450.0, resolve=True)
    named = set(re.findall(r"`([a-z_]+)`", loops_page))
    internal = {"title", "gross_slip_threshold", "flip_force"}  # the options, echoed
    missing = [
        name
        for name in (*results.attrs, *results.data_vars)
        if name not in named
        and name not in internal
        and not any(name.startswith(base) for base in named if base.endswith("_"))
    ]
    assert not missing
