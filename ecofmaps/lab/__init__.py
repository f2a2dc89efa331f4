"""A fretting lab's daily numbers from the per-cycle results of :func:`ecofmaps.analyze_loops`:
a test's sliding condition, the transition to gross slip, energy wear with Archard's
coefficients, and the closure of the loops on the scar profile. The method, its formulas and
the field's notation are in docs/lab.md."""

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
