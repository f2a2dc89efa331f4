"""docs/ explains every output of ecofmaps loops (each column of its table, each quality flag
and each attribute of analyze_loops' results), and the site built from docs/ holds every page
and every public name, in MkDocs' strict mode: the docs cannot fall behind the code."""

import contextlib
import io
import os
import pkgutil
import re
import subprocess
import sys
import warnings
from pathlib import Path

import pytest

import ecofmaps
from ecofmaps import paper
from ecofmaps.io.tables import RESULT_COLUMNS
from ecofmaps.measured.quality import REASONS

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
REFERENCE = DOCS / "reference"
#: Public modules without a reference page: the command line is documented by its --help.
NOT_IN_REFERENCE = {"cli"}


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
    displacement, force = ecofmaps.synthetic_recording(**paper.EXAMPLE_2, cycles=3)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        results = ecofmaps.analyze_loops(displacement, force, paper.LOAD, resolve=True)
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


def _documented_objects() -> list[str]:
    """What the reference pages render: the names after ``:::``."""
    pages = "\n".join(page.read_text(encoding="utf-8") for page in REFERENCE.glob("*.md"))
    return re.findall(r"^::: ([\w.]+)$", pages, flags=re.MULTILINE)


def _public_packages() -> set[str]:
    names = {info.name for info in pkgutil.iter_modules(ecofmaps.__path__)}
    return {f"ecofmaps.{name}" for name in names if not name.startswith("_")} - {
        f"ecofmaps.{name}" for name in NOT_IN_REFERENCE
    }


def test_every_public_package_has_a_reference_page():
    assert _public_packages() <= set(_documented_objects())


@pytest.mark.slow
def test_site_builds_in_strict_mode_with_every_page_and_name(tmp_path):
    """The command docs/index.md gives, into a temporary folder: no warning, every page of
    docs/ in the site and in its navigation, an entry for every public name of every package."""
    for module in ("mkdocs", "material", "mkdocstrings_handlers.python"):
        pytest.importorskip(module, reason='the site needs the extra "docs"')
    site = tmp_path / "site"
    done = subprocess.run(
        [sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(site)],
        cwd=ROOT,
        env=dict(os.environ, NO_MKDOCS_2_WARNING="1"),
        capture_output=True,
        text=True,
        timeout=900,
    )
    assert done.returncode == 0, done.stdout + done.stderr
    assert "WARNING" not in done.stderr, done.stderr

    home = (site / "index.html").read_text(encoding="utf-8")
    for page in DOCS.rglob("*.md"):
        url = page.relative_to(DOCS).with_suffix("").as_posix()
        url = url.removesuffix("index") if url.endswith("index") else url + "/"
        assert (site / url / "index.html").is_file(), page
        assert f'href="{url or "."}"' in home or f'href="./{url}"' in home, page

    html = "\n".join(page.read_text(encoding="utf-8") for page in site.rglob("*.html"))
    for package in sorted(_public_packages()):
        module = __import__(package, fromlist=["__all__"])
        missing = [name for name in module.__all__ if f'id="{package}.{name}"' not in html]
        assert not missing, package
    # Each name of ecofmaps: an entry of its own, or a link to its package's entry.
    index = (site / "reference" / "index.html").read_text(encoding="utf-8")
    packages = {name.removeprefix("ecofmaps.") for name in _public_packages()}
    missing = [
        name
        for name in ecofmaps.__all__
        if name not in packages | NOT_IN_REFERENCE
        and f'id="ecofmaps.{name}"' not in index
        and not re.search(rf'href="[^"]*#ecofmaps\.\w+\.{re.escape(name)}"', index)
    ]
    assert not missing


def test_the_deepening_groove_example_shows_the_ecof_rising(loops_page):
    """The example of a groove that deepens runs as written, and prints what the page says."""
    example = re.search(r"## A groove that deepens\n.*?```python\n(.*?)```", loops_page, re.S)
    printed = re.search(r"## A groove that deepens\n.*?```text\n(.*?)```", loops_page, re.S)
    output = io.StringIO()
    with warnings.catch_warnings(), contextlib.redirect_stdout(output):
        warnings.simplefilter("ignore")
        exec(compile(example.group(1), "docs/loops.md", "exec"), {})
    assert output.getvalue().split() == printed.group(1).split()
    first, last = (line.split() for line in printed.group(1).splitlines()[2::2])
    assert float(last[1]) > float(first[1]) + 0.05  # the ECoF rises ...
    assert abs(float(last[2]) - float(first[2])) < 0.02  # ... the GICoF stays at μ
