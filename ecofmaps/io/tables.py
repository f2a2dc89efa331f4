"""The per-cycle results of measured loops as a table, in the tribologist's units.

The columns, their names and their units come from :mod:`ecofmaps._nomenclature`: a quantity
``name`` in SI becomes the column ``name_<unit>`` in its display unit (``amplitude_um``,
``stiffness_MN_per_m``); numbers keep their names; the regime is written as its label.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import xarray as xr

from ecofmaps import _nomenclature as nomenclature
from ecofmaps.model.regimes import Regime

__all__ = ["RESULT_COLUMNS", "results_table"]

#: The quantities of :func:`ecofmaps.analyze_loops` in the results table, in order.
RESULT_QUANTITIES = (
    "cycle",
    "amplitude",
    "slip_amplitude",
    "max_force",
    "dissipated_energy",
    "ecof",
    "cof_max",
    "energy_ratio",
    "stiffness",
    "gicof",
    "regime",
    "mu_resolved",
    "mu_resolved_se",
    "aspect_ratio",
    "quality",
)

#: The table's column names, in order.
RESULT_COLUMNS = tuple(nomenclature.column(name) for name in RESULT_QUANTITIES)


def results_table(results: xr.Dataset) -> pd.DataFrame:
    """The per-cycle results in the tribologist's units, one row per cycle.

    Parameters
    ----------
    results : xarray.Dataset
        From :func:`ecofmaps.analyze_loops`.

    Returns
    -------
    table : pandas.DataFrame
        The columns of :data:`RESULT_COLUMNS` that ``results`` holds: cycle, amplitude_um,
        slip_amplitude_um, max_force_N, dissipated_energy_mJ, ecof, cof_max,
        energy_ratio, stiffness_MN_per_m, gicof, regime, then (with ``resolve=True``)
        mu_resolved, mu_resolved_se, aspect_ratio, and quality.
    """
    columns = {}
    for name, column in zip(RESULT_QUANTITIES, RESULT_COLUMNS, strict=True):
        if name not in results:
            continue
        values = results[name].values
        if name == "regime":  # the codes' labels, as ecofmaps map and model print them
            columns[column] = [Regime(int(code)).label for code in values]
            continue
        numeric = np.issubdtype(values.dtype, np.number) and name != "cycle"
        columns[column] = nomenclature.display(name, values) if numeric else values
    return pd.DataFrame(columns)
