"""Wear-scar profiles (profilometer traces) in text files, read as recordings are, into the
model's :class:`~ecofmaps.model.profiles.ScarProfile` (``docs/profiles.md``)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ecofmaps._codes import warn
from ecofmaps.io.files import FileLineError
from ecofmaps.io.recording_types import RecordingError
from ecofmaps.io.text import text_blocks
from ecofmaps.model.profiles import ScarProfile, ScarProfileWarning, scar_profile_and_findings


class ScarProfileError(FileLineError):
    """A damaged or unusable scar-profile file: the message names the file and the line."""


def read_scar_profile(
    path,
    *,
    x_column="x",
    z_column="z",
    x_unit=None,
    z_unit=None,
    level=True,
    half_width=None,
    smoothing=None,
    remove_outliers=True,
) -> ScarProfile:
    """Read a wear-scar profile (a profilometer trace across the scar) from a text file.

    Parameters
    ----------
    path : str or os.PathLike
        A text file as :func:`ecofmaps.read_recording` reads (a header, a sample a line).
    x_column, z_column : str
        The position and height columns, found as by :func:`ecofmaps.read_recording`.
    x_unit, z_unit : str, optional
        Their units of length (``'um'``, ``'mm'``, ...): by default the column name's, else µm.
    level, half_width, smoothing, remove_outliers
        As in :func:`ecofmaps.scar_profile` (lengths in m), but levelled by default.

    Returns
    -------
    profile : ScarProfile
        In SI units (m), positions relative to the scar's centre.

    Warns
    -----
    ScarProfileWarning
        Those of :func:`ecofmaps.scar_profile`, naming the file and the lines.

    Raises
    ------
    ScarProfileError
        For a damaged file (a missing column, a bad line or cell, positions not strictly
        increasing, no data) or a trace that is not a usable scar: naming the file and line.
    ValueError
        For a unit that is not a length.

    Examples
    --------
    >>> import ecofmaps
    >>> from ecofmaps.measured.synthetic import scar_example_path
    >>> p = ecofmaps.read_scar_profile(scar_example_path())
    >>> round(float(p.half_width) * 1e6), round(float(p.aspect_ratio), 3)
    (500, 0.16)
    """
    path = Path(path)
    columns = {"x": x_column, "z": z_column}
    options = {"columns": columns, "x_unit": x_unit, "z_unit": z_unit, "nan_policy": "raise"}
    try:
        blocks = text_blocks(path, options)
        layout = next(blocks)
        parts = list(blocks)
    except RecordingError as error:  # the same damage, named as a profile's
        raise ScarProfileError(path, error.line or 1, error.message) from None
    if not parts:
        raise ScarProfileError(path, layout.header_line, "no data after the header")
    x, z = (np.concatenate([part[0][role] for part in parts]) for role in ("x", "z"))
    lines = np.concatenate([part[1] for part in parts])
    steps = np.diff(x)
    if np.any(steps <= 0.0):
        i = int(np.argmax(steps <= 0.0))
        typed = x / layout.scales["x"]  # the positions as the file gives them
        kind = "repeats" if steps[i] == 0.0 else "goes back from"
        raise ScarProfileError(
            path,
            lines[i + 1],
            f"position {float(typed[i + 1])!r} {kind} {float(typed[i])!r} on line {lines[i]}: "
            f"column {x_column!r} must increase strictly (sort the trace and drop repeated "
            "positions)",
        )
    try:
        profile, findings = scar_profile_and_findings(
            x, z, half_width, smoothing, level, remove_outliers
        )
    except ValueError as error:
        raise ScarProfileError(
            path, lines[0], f"the trace (lines {lines[0]}-{lines[-1]}): {error}"
        ) from None
    for finding in findings:
        text = finding.text([f"line {lines[i]}" for i in finding.samples])
        located = ScarProfileWarning(
            f"{path}: {text}",
            alternative=finding.alternative,
            alternative_name=finding.alternative_name,
        )
        warn(located, ScarProfileWarning)
    return profile
