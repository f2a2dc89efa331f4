"""Measured fretting loops: cycles, per-cycle analysis, the stroke-resolved reading, model fits
and synthetic recordings."""

from ecofmaps.measured.analysis import analyze_loops
from ecofmaps.measured.fit import LoopFit, fit_loop
from ecofmaps.measured.long_test import long_recording, write_long_recording
from ecofmaps.measured.quality import LoopQualityWarning
from ecofmaps.measured.resolved import resolve_analyzed_loops, resolve_loops
from ecofmaps.measured.synthetic import scar_example_path, synthetic_recording

__all__ = [
    "LoopFit",
    "LoopQualityWarning",
    "analyze_loops",
    "fit_loop",
    "long_recording",
    "resolve_analyzed_loops",
    "resolve_loops",
    "scar_example_path",
    "synthetic_recording",
    "write_long_recording",
]
