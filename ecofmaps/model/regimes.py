"""The regimes of a fretting contact, as integer codes that maps and results store: the
model's (gross slip, full stick, self-locking, ...) and the measured loops' (gross or partial
slip). docs/model.md and docs/loops.md say what each means."""

from __future__ import annotations

import numpy as np

from ecofmaps._codes import Code


class Regime(Code):
    """Regime codes returned by :func:`ecofmaps.slip_regime`, stored in maps and in the
    results of :func:`ecofmaps.analyze_loops`; ``docs/model.md`` and ``docs/loops.md`` say
    when each holds.

    Attributes
    ----------
    GROSS_SLIP, NO_GROSS_SLIP, SELF_LOCKING, INVALID, BEYOND_PROFILE
        The model's regimes: codes 0 to 4.
    PARTIAL_SLIP
        A measured loop in partial slip (Mindlin's regime): code 5.

    References
    ----------
    O. Vingsbo, S. Söderberg (1988), On fretting maps, Wear 126, 131-147.
    S. Fouvry, P. Kapsa, L. Vincent (1995), Analysis of sliding behaviour for fretting
    loadings: determination of transition criteria, Wear 185, 35-46.
    """

    GROSS_SLIP = 0, "gross slip"
    NO_GROSS_SLIP = (
        1,
        "no gross slip",
        "no gross slip (the rig's deflection takes the whole stroke: mu * load / (stiffness * "
        "amplitude) >= 1 in a groove flat at its centre), so the energy coefficient of "
        "friction is undefined",
    )
    SELF_LOCKING = (
        2,
        "self-locking",
        "self-locking (rigid rig with mu * groove slope >= 1 in the stroke: the pad jams on "
        "the groove flank)",
    )
    INVALID = 3, "invalid", "invalid input"
    BEYOND_PROFILE = (
        4,
        "beyond the profile",
        "the pad slips beyond an end of the scar profile (the trace is too short for this stroke)",
    )
    PARTIAL_SLIP = (
        5,
        "partial slip",
        "partial slip (the energy ratio at most the threshold: the contact slips only at its "
        "edges), so the ECoF and GICoF are not read; Q*/P is a lower bound of mu",
    )


GROSS_SLIP, NO_GROSS_SLIP, SELF_LOCKING, INVALID, BEYOND_PROFILE, PARTIAL_SLIP = Regime

#: A test's sliding conditions (Vincent et al. 1992; Zhou & Vincent 1995): every cycle in
#: partial slip, the regime changing during the test, every cycle in gross slip.
SLIDING_CONDITIONS = ("partial slip", "mixed slip", "gross slip")


def sliding_condition_of(cycle, gross_slip) -> tuple[str, np.ndarray]:
    """A test's sliding condition (:data:`SLIDING_CONDITIONS`) and the first cycles of each new
    regime, from each cycle's number and ``gross_slip`` (1 or 0; NaN: no regime, left out)."""
    gross_slip = np.asarray(gross_slip, dtype=np.float64)
    known = np.isfinite(gross_slip)
    if not known.any():
        raise ValueError("results: no cycle with a regime (every cycle refused)")
    regimes = gross_slip[known] > 0.5
    changes = np.asarray(cycle)[known][1:][regimes[1:] != regimes[:-1]].astype(np.int64)
    kind = 1 if changes.size else (2 if regimes.all() else 0)
    return SLIDING_CONDITIONS[kind], changes


def regime_condition(results) -> tuple[str, np.ndarray]:
    """:func:`sliding_condition_of` the ``regime`` column of :func:`ecofmaps.analyze_loops`."""
    regime = results["regime"].values
    gross = np.where(regime == INVALID, np.nan, regime == GROSS_SLIP)
    return sliding_condition_of(results["cycle"].values, gross)
