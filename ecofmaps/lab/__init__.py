"""A fretting lab's daily numbers from :func:`ecofmaps.analyze_loops`' results: the sliding
condition, the transition to gross slip, energy wear and the loops' closure on the scar
(method, formulas and the field's notation: docs/lab.md)."""

from ecofmaps.lab.regime import (
    MINDLIN_ENERGY_RATIO,
    MINDLIN_OPENING_RATIO,
    per_cycle,
    sliding_condition,
    transition,
)
from ecofmaps.lab.wear import energy_wear, loop_scar_closure

__all__ = [
    "MINDLIN_ENERGY_RATIO",
    "MINDLIN_OPENING_RATIO",
    "energy_wear",
    "loop_scar_closure",
    "per_cycle",
    "sliding_condition",
    "transition",
]
