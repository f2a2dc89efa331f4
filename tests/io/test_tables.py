"""The results table as CSV text: :func:`ecofmaps.io.tables.csv_text` writes what pandas'
``to_csv`` writes, byte for byte, and a table made of blocks is the table made whole."""

import hypothesis.extra.numpy as hnp
import numpy as np
import pandas as pd
import pytest
from hypothesis import given
from hypothesis import strategies as st

from ecofmaps import analyze_loops
from ecofmaps.io.tables import csv_text, results_csv, results_table
from ecofmaps.measured.synthetic import synthetic_recording
from ecofmaps.paper import EXAMPLE_2, LOAD


def pandas_text(table, header=True):
    return table.to_csv(index=False, float_format="%.6g", lineterminator="\n", header=header)


ODD_FLOATS = [0.0, -0.0, np.nan, np.inf, -np.inf, 1e-300, 5e-324, 1.7976931348623157e308,
              123456.5, 999999.5, 0.1 + 0.2, -2.5e-7, 1.0, 100.0, 1234567.0]  # fmt: skip
ODD_TEXTS = ["", "ok", "a,b", 'say "hi"', "two\nlines", "cr\rhere", " spaced ", "μ (ξ)",
             "missing-samples+anticlockwise", "x", "tab\tin", "'"]  # fmt: skip


@pytest.mark.parametrize("header", [True, False])
def test_odd_values_as_pandas_writes_them(header):
    size = len(ODD_FLOATS)
    with np.errstate(over="ignore"):  # the largest double is inf in float32
        small = np.array(ODD_FLOATS, dtype=np.float32)
    table = pd.DataFrame(
        {
            "cycle": np.arange(size, dtype=np.int64) - 3,
            "ecof": np.array(ODD_FLOATS),
            "small": small,
            "kept": np.arange(size) % 3 == 0,
            "quality": (ODD_TEXTS * 2)[:size],
            'a "quoted", name': np.linspace(-1.0, 1.0, size),
        }
    )
    assert csv_text(table, header=header) == pandas_text(table, header=header)


def test_no_rows():
    table = pd.DataFrame({"a": np.zeros(0), "b": np.array([], dtype=object)})
    assert csv_text(table) == pandas_text(table) == "a,b\n"
    assert csv_text(table, header=False) == pandas_text(table, header=False) == ""


@given(
    hnp.arrays(np.float64, st.integers(0, 40), elements=st.floats(allow_subnormal=True)),
    st.lists(st.text(max_size=6), min_size=40, max_size=40),
)
def test_any_floats_and_texts_as_pandas_writes_them(values, texts):
    table = pd.DataFrame({"value": values, "text": texts[: values.size]})
    assert csv_text(table) == pandas_text(table)


def test_a_table_of_blocks_is_the_table_made_whole():
    """What the long analysis does: the lines of each block, joined, under one header."""
    displacement, force = synthetic_recording(**EXAMPLE_2, cycles=12, force_noise=2.0, seed=5)
    results = analyze_loops(displacement, force, LOAD)
    whole = pandas_text(results_table(results))
    assert results_csv(results) == whole
    blocks = [results.isel(cycle=slice(a, a + 5)) for a in range(0, results.cycle.size, 5)]
    header = results_csv(results.isel(cycle=slice(0, 0)))
    assert header + "".join(results_csv(b, header=False) for b in blocks) == whole
    named = results_table(results)
    named.insert(0, "file", "rig 3, test 7.csv")
    assert results_csv(results, file="rig 3, test 7.csv") == pandas_text(named)


def test_rows_formatted_a_few_at_a_time(monkeypatch):
    """Long tables are formatted a stretch of rows at a time: the same text."""
    from ecofmaps.io import tables

    monkeypatch.setattr(tables, "_ROWS", 4)
    values = np.linspace(-1.0, 1.0, 11)
    values[[2, 4, 5]] = np.nan
    table = pd.DataFrame(
        {"cycle": np.arange(11), "ecof": values, "quality": ["ok", "a,b"] * 5 + ["x"]}
    )
    assert csv_text(table) == pandas_text(table)
