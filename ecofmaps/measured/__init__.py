"""Measured fretting loops: cycles, per-cycle analysis, the stroke-resolved reading, model fits
and synthetic recordings."""

from ecofmaps._lazy import lazy_names

#: Each public name, by the module that defines it (imported on first use).
_PUBLIC = {
    "ecofmaps.measured.analysis": ("analyze_loops", "resolve_loops"),
    "ecofmaps.measured.fit": ("LoopFit", "fit_loop"),
    "ecofmaps.measured.quality": (
        "ImplausibleScaleError",
        "ImplausibleScaleWarning",
        "LoopQualityWarning",
    ),
    "ecofmaps.measured.resolve": ("resolve_analyzed_loops",),
    "ecofmaps.measured.synthetic": (
        "long_recording",
        "scar_example_path",
        "synthetic_recording",
        "write_long_recording",
    ),
}

__getattr__, __dir__, __all__ = lazy_names(__name__, _PUBLIC)
