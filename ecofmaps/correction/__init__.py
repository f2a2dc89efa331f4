"""Reported energy coefficients of friction corrected to the contact one."""

from ecofmaps.correction.inversion import (
    CorrectionStatus,
    Interval,
    contact_cof,
    correct_ecof,
    correction_factor,
    ecof_fall,
    lookup_correction,
)

__all__ = [
    "CorrectionStatus",
    "Interval",
    "contact_cof",
    "correct_ecof",
    "correction_factor",
    "ecof_fall",
    "lookup_correction",
]
