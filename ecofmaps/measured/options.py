"""The options of the analysis of measured loops, checked in one place, and its errors.

Every way into the pipeline (:func:`ecofmaps.analyze_loops`, :func:`ecofmaps.resolve_loops`,
the command line, long runs and resumed runs) takes its options through
:func:`check_options` and its defaults from :data:`DEFAULTS`, so a run is described by the
same dictionary whatever started it.
"""

from __future__ import annotations

import numpy as np

from ecofmaps._inputs import check
from ecofmaps.measured.per_cycle import GROSS_SLIP_THRESHOLD
from ecofmaps.measured.quality import LoopQualityWarning

__all__ = [
    "DEFAULTS",
    "NAN_POLICIES",
    "ImplausibleScaleError",
    "ImplausibleScaleWarning",
    "MissingSampleError",
    "check_options",
    "default_options",
    "missing_sample_error",
    "no_cycle_error",
]

#: What the analysis does with missing samples: skip their cycles, or raise.
NAN_POLICIES = ("skip", "raise")

#: The defaults of :func:`ecofmaps.analyze_loops`' options (see there for their meaning).
DEFAULTS = {
    "hysteresis": 0.5,
    "stick_window": (0.05, 0.45),
    "crossing_window": 0.7,
    "gross_slip_threshold": GROSS_SLIP_THRESHOLD,
}


class MissingSampleError(ValueError):
    """A missing sample where ``nan_policy='raise'``: ``sample`` is its 0-based index."""

    def __init__(self, sample: int, message: str):
        self.sample = int(sample)
        super().__init__(message)


class ImplausibleScaleWarning(LoopQualityWarning):
    """Cycles whose amplitude or coefficient of friction is outside what a unit or a load
    makes plausible (``implausible-amplitude``, ``implausible-cof``): the load given or the
    unit assumed for a channel is likely wrong.

    A :class:`~ecofmaps.measured.quality.LoopQualityWarning`, so filtering that one filters
    this one too; ``warnings.filterwarnings("error", category=ImplausibleScaleWarning)``
    turns only the checks of scale into errors.
    """


class ImplausibleScaleError(ValueError):
    """Every cycle refused, some for an amplitude outside what the displacement's unit makes
    plausible (``implausible-amplitude``): the unit assumed is likely wrong."""


def missing_sample_error(sample: int) -> MissingSampleError:
    """The error for the missing sample ``sample`` (0-based) with ``nan_policy='raise'``."""
    return MissingSampleError(
        sample,
        f"sample {sample} is missing (NaN or empty); nan_policy='skip' analyses the cycles "
        "without missing samples and reports the others as skipped",
    )


def no_cycle_error(samples: int) -> ValueError:
    """The error for a recording of ``samples`` samples without a complete cycle."""
    return ValueError(
        f"too few samples for one cycle: no complete cycle in {samples} samples "
        "(the loop does not close, or the recording does not oscillate)"
    )


def check_options(
    load, hysteresis, stick_window, crossing_window, gross_slip_threshold, flip_force
) -> dict:
    """The options of :func:`ecofmaps.analyze_loops`, checked (a ValueError naming the one
    that is not valid), as keyword arguments of
    :func:`ecofmaps.measured.per_cycle.measure_cycles`."""
    check("load", load, "positive", "N")
    if np.ndim(load) != 0:
        raise ValueError("load must be a single value [N]")
    if not 0.0 < hysteresis < 1.0:
        raise ValueError(f"hysteresis must satisfy 0 < hysteresis < 1; got {hysteresis!r}")
    low, high = (float(share) for share in stick_window)
    if not 0.0 <= low < high <= 1.0:
        raise ValueError(f"stick_window must satisfy 0 <= low < high <= 1; got {stick_window!r}")
    if not crossing_window > 0.0:
        raise ValueError(
            f"crossing_window must satisfy crossing_window > 0; got {crossing_window!r}"
        )
    if not 0.0 < gross_slip_threshold < 1.0:
        raise ValueError(
            "gross_slip_threshold must satisfy 0 < gross_slip_threshold < 1; "
            f"got {gross_slip_threshold!r}"
        )
    if not isinstance(flip_force, bool | np.bool_):
        raise ValueError(f"flip_force must be True or False; got {flip_force!r}")
    return {
        "hysteresis": float(hysteresis),
        "stick_window": (low, high),
        "crossing_window": float(crossing_window),
        "gross_slip_threshold": float(gross_slip_threshold),
        "flip_force": bool(flip_force),
    }


def default_options(load, flip_force=False) -> dict:
    """:func:`check_options` with the :data:`DEFAULTS` for the others (what the command
    line and a long analysis use)."""
    return check_options(load, **DEFAULTS, flip_force=flip_force)
