"""Reported energy coefficients of friction corrected to the contact one."""

from ecofmaps.correction.inversion import contact_cof, correct_ecof, correction_factor
from ecofmaps.correction.lookup import lookup_correction
from ecofmaps.correction.outcomes import (
    AMBIGUOUS_ECOF_MIN,
    LAMBDA_INFINITY,
    CorrectionStatus,
    Interval,
    ecof_fall,
)

__all__ = [
    "AMBIGUOUS_ECOF_MIN",
    "LAMBDA_INFINITY",
    "CorrectionStatus",
    "Interval",
    "contact_cof",
    "correct_ecof",
    "correction_factor",
    "ecof_fall",
    "lookup_correction",
]
