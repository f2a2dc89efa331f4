"""Integer codes that carry their own words: the regimes and statuses results hold per point,
stored as integers, each knowing its ``label`` (as printed) and ``reason`` (why a value is NaN)."""

import enum
import sys
import warnings
from pathlib import Path

import numpy as np

# Warnings point at the first line outside the package: the caller's call.
_PACKAGE = str(Path(__file__).resolve().parent)


class RegimeWarning(RuntimeWarning):
    """A concrete call returned NaN because a point is outside the gross-slip regime."""


class Code(enum.IntEnum):
    """An integer code with a ``label`` and the ``reason`` a value is NaN under it (or '')."""

    def __new__(cls, value: int, label: str, reason: str = ""):
        member = int.__new__(cls, value)
        member._value_, member.label, member.reason = value, label, reason
        return member

    @classmethod
    def flag_attrs(cls) -> dict:
        """CF ``flag_values`` and ``flag_meanings`` attributes of a variable holding the codes."""
        return {
            "flag_values": np.array([int(code) for code in cls], dtype=np.int32),
            "flag_meanings": " ".join(code.name.lower() for code in cls),
        }


def warn(message: str, category: type[Warning]) -> None:
    """``warnings.warn`` attributed to the caller's line: the first frame outside ecofmaps."""
    frame, level = sys._getframe(1), 2  # stacklevel 2: the frame that called warn()
    while frame is not None and frame.f_code.co_filename.startswith(_PACKAGE):
        frame, level = frame.f_back, level + 1
    warnings.warn(message, category, stacklevel=level)


def warn_nan(values, codes, kind: type[Code], quantity: str) -> None:
    """Warn when a concrete result holds NaN for a reason its code gives, naming the reason."""
    nan = np.isnan(np.asarray(values))
    if not nan.any():
        return
    codes = np.asarray(codes)
    for code in kind:
        count = int(np.count_nonzero(nan & (codes == code)))
        if count and code.reason:
            warn(
                f"{quantity} is NaN at {count} of {nan.size} point(s): {code.reason}", RegimeWarning
            )
