"""The per-cycle results of measured loops as a table in the tribologist's units (a quantity
``name`` becomes the column ``name_<unit>``, the regime its label)."""

from __future__ import annotations

import csv
import io

import numpy as np
import pandas as pd
import xarray as xr

from ecofmaps import _nomenclature as nomenclature
from ecofmaps.model.regimes import Regime

#: The quantities of :func:`ecofmaps.analyze_loops` in the results table, in order.
RESULT_QUANTITIES = (
    "cycle",
    "amplitude",
    "slip_amplitude",
    "normal_load",
    "max_force",
    "dissipated_energy",
    "ecof",
    "cof_max",
    "energy_ratio",
    "opening_ratio",
    "contact_amplitude",
    "contact_energy_ratio",
    "contact_opening_ratio",
    "stiffness",
    "gicof",
    "regime",
    "mu_resolved",
    "mu_resolved_se",
    "aspect_ratio",
    "quality",
)

#: Rows of a table formatted at once by :func:`csv_text`.
_ROWS = 1 << 14

#: The table's column names, in order.
RESULT_COLUMNS = tuple(nomenclature.column(name) for name in RESULT_QUANTITIES)


def results_table(results: xr.Dataset) -> pd.DataFrame:
    """The per-cycle results of :func:`ecofmaps.analyze_loops` in the tribologist's units, a row
    per cycle, in the columns of :data:`RESULT_COLUMNS` they hold (see ``docs/loops.md``)."""
    columns = {}
    for name, column in zip(RESULT_QUANTITIES, RESULT_COLUMNS, strict=True):
        if name not in results:
            continue
        values = results[name].values
        if name == "regime":  # the codes' labels, as ecofmaps map and model print them
            labels = {int(code): code.label for code in Regime}
            columns[column] = [labels[code] for code in values.tolist()]
        elif np.issubdtype(values.dtype, np.number) and name != "cycle":
            columns[column] = nomenclature.display(name, values)
        else:
            columns[column] = values
    return pd.DataFrame(columns)


def results_csv(results: xr.Dataset, *, file: str | None = None, header: bool = True) -> str:
    """The per-cycle results (or a stretch of their cycles) as the text of ``ecofmaps loops
    --out``, with a first column ``file`` naming the recording if given."""
    table = results_table(results)
    if file is not None:
        table.insert(0, "file", file)
    return csv_text(table, header=header)


def csv_text(table: pd.DataFrame, *, header: bool = True) -> str:
    """``table`` as CSV text, numbers to 6 significant digits: what ``table.to_csv(index=False,
    float_format="%.6g", lineterminator="\\n", header=header)`` writes, in half the time."""
    stream = io.StringIO()
    writer = csv.writer(stream, lineterminator="\n")
    if header:
        writer.writerow(table.columns)
    arrays = [table[name].to_numpy() for name in table.columns]
    for start in range(0, len(table), _ROWS):  # a few MB of Python strings at a time
        columns = []
        for values in (array[start : start + _ROWS] for array in arrays):
            if values.dtype.kind == "f":
                texts = list(map("%.6g".__mod__, values.tolist()))
                for k in np.flatnonzero(np.isnan(values)).tolist():
                    texts[k] = ""
            else:
                texts = values.tolist()
            columns.append(texts)
        writer.writerows(zip(*columns, strict=True))
    return stream.getvalue()


def read_results(path) -> list[xr.Dataset]:
    """The per-cycle results in SI of a table ``ecofmaps loops --out`` wrote (CSV) or of a
    netCDF file of :func:`ecofmaps.analyze_loops`: a Dataset over ``cycle`` per recording
    (per value of a ``file`` column); a ValueError naming a file that is not such a table."""
    try:
        if str(path).endswith(".nc"):
            with xr.open_dataset(path) as results:
                return [results.load()]
        table = pd.read_csv(path, skipinitialspace=True)
    except (OSError, ValueError, pd.errors.ParserError) as error:
        raise ValueError(f"{path}: not a results table ({error})") from None
    columns = dict(zip(RESULT_COLUMNS, RESULT_QUANTITIES, strict=True))
    known = [c for c in table.columns if c in columns and c not in ("regime", "quality")]
    if not known:
        raise ValueError(f"{path}: not a results table (none of the columns of ecofmaps loops)")
    groups = table.groupby("file", sort=False) if "file" in table else [(None, table)]
    factor = {c: nomenclature.QUANTITIES[columns[c]].display_factor for c in known}
    found = []
    for name, rows in groups:
        data = {columns[c]: ("row", rows[c].to_numpy() / factor[c]) for c in known if c != "cycle"}
        results = xr.Dataset(data, attrs={} if name is None else {"file": name})
        if "cycle" in known:
            cycles = ("row", rows["cycle"].to_numpy())
            results = results.assign_coords(cycle=cycles).swap_dims(row="cycle")
        found.append(results)
    return found
