r"""Plausibility of measured loops: the ``quality`` of each cycle and what it leaves NaN.

:func:`ecofmaps.analyze_loops` checks every cycle before it reports a number (issue 9): a
loop must run clockwise in the :math:`(\Delta, Q)` plane (force positive in the direction
of positive displacement), have a positive area no larger than its bounding box
(:math:`0 \le A \le 1`), a slip amplitude :math:`0 < \delta^* \le \Delta^*`, straight stick
sides of positive slope :math:`S > 0` after its reversals, a force that varies, and its
crossings (at :math:`Q = 0` and with :math:`Q = S\Delta`) on the measured loop: between
measured samples of their branch and within the measured range (issue 11; so
:math:`\delta^* \le \Delta^*` needs no check of its own). A value that cannot be stood
behind is NaN, and the cycle's ``quality`` says why.

The vocabulary
--------------
``quality`` is ``'ok'``, or the reasons of :data:`REASONS` that apply, in the order of
that table, joined by ``'+'`` (``'negative-slip+curved-stick'``): the reasons hold only
lower-case letters, digits and hyphens, so ``quality.split('+')`` gives them back and the
column needs no quoting in a CSV file. Each reason names the quantities it leaves NaN
(its *scope*). A reason whose scope is every quantity (:data:`ALL`) refuses the cycle: it
is not a loop that can be read as recorded, and its ``regime`` is ``INVALID``. The others
leave the rest of the cycle's numbers standing; ``'not-gross-slip'`` is the partial-slip
regime, where the ECoF and the GICoF are not defined. The last four reasons come from the
reading along the stroke (:func:`ecofmaps.resolve_loops`, or ``analyze_loops(...,
resolve=True)``), which adds them with :func:`add_reason` and leaves only its own values NaN.
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "ALL",
    "ANTICLOCKWISE_SHARE",
    "REASONS",
    "RESOLVED",
    "SEPARATOR",
    "LoopQualityWarning",
    "add_reason",
    "apply_quality",
    "has_reason",
    "quality_strings",
    "quality_summary",
    "refused",
    "summary_of_counts",
]


class LoopQualityWarning(UserWarning):
    """Cycles of a recording were flagged in ``quality``, or its units look wrong."""


#: Joins the reasons of one cycle in ``quality``.
SEPARATOR = "+"

#: A loop whose area :math:`\oint Q\,d\Delta` is below minus this share of
#: :math:`4\Delta^*Q^*` runs anticlockwise; a smaller negative area is noise on a loop
#: without area (the one definition, also for :func:`ecofmaps.fit_loop`).
ANTICLOCKWISE_SHARE = 0.05

#: Scope of a reason that refuses the cycle: every per-cycle quantity.
ALL = "all"

_GICOF = (
    "gicof",
    "gicof_forward",
    "gicof_backward",
    "crossing_displacement_forward",
    "crossing_displacement_backward",
)
_SLIP = ("slip_amplitude", "ecof")
#: The values read along the stroke (:func:`ecofmaps.resolve_loops`).
RESOLVED = ("mu_resolved", "mu_resolved_se", "aspect_ratio")

#: Every reason a cycle can be flagged for, in the order they are listed in ``quality``:
#: name -> (what it means, the quantities it leaves NaN).
REASONS = {
    "missing-samples": (
        "the cycle holds a missing sample (NaN or an empty cell): skipped, not analysed",
        ALL,
    ),
    "few-samples": ("fewer samples in the cycle than a loop needs (MIN_SAMPLES)", ALL),
    "constant-force": ("the force does not vary over the cycle (a dead channel)", ALL),
    "implausible-amplitude": (
        "the displacement amplitude is below 0.5 µm or above 50 mm: the displacement is not "
        "in the unit assumed (a column without a unit is read in µm)",
        ALL,
    ),
    "several-loops": (
        "the displacement turns back within a branch, by more than the reversal detector's "
        "band (several loops under one cycle number)",
        ALL,
    ),
    "anticlockwise": (
        "the loop runs anticlockwise (area below -5 % of 4Δ*Q*): force and displacement "
        "recorded positive in opposite directions (see flip_force), time reversed, or the "
        "columns swapped",
        ALL,
    ),
    "energy-ratio-above-1": ("the loop's area exceeds its bounding box 4Δ*Q* (A > 1)", ALL),
    "negative-stiffness": ("the stick sides slope down (S < 0)", ALL),
    "no-stick": (
        "no straight stick side after the reversals: the stick lines leave more than 20 % "
        "of the displacement's variance along them unexplained",
        ALL,
    ),
    "no-zero-crossing": (
        "a branch does not cross zero force between its measured samples: no loop",
        ALL,
    ),
    "negative-area": (
        "no area within the noise (-5 % of 4Δ*Q* < area < 0)",
        ("dissipated_energy", "energy_ratio", "ecof"),
    ),
    "negative-slip": ("δ* <= 0: the zero-force crossings in the wrong order", _SLIP),
    "curved-stick": (
        "the stick sides are curved (a polymer, micro-slip): no straight line gives S",
        ("stiffness", *_GICOF, *RESOLVED),
    ),
    "no-crossing": (
        "a branch's crossing with Q = SΔ is not on the measured loop (between its samples, "
        "within their force range)",
        _GICOF,
    ),
    "implausible-cof": (
        "a coefficient of friction outside 0.01 to 3 (the ECoF or GICoF in gross slip): the "
        "load given or the force's unit is wrong, not the contact",
        ("ecof", "cof_max", *_GICOF, *RESOLVED),
    ),
    "not-gross-slip": (
        "partial slip: the energy ratio A is not above the threshold",
        ("ecof", *_GICOF, *RESOLVED),
    ),
    "stiffness-mismatch": (
        "the stiffness does not fit the stick sides: a given S tilts them beyond the noise, "
        "or the one fitted on them for the stroke-resolved reading slopes down",
        RESOLVED,
    ),
    "no-overlap": (
        "no range of contact positions around the loop's centre where both branches slip "
        "(a slip within the noise)",
        RESOLVED,
    ),
    "few-slip-samples": (
        "fewer than eight slipping samples of a branch in the central part of the stroke (a "
        "sparse or digitised loop): friction cannot be read along the stroke",
        RESOLVED,
    ),
    "mu-varies": (
        "the friction read along the stroke differs between the inner and the outer half of "
        "its central part by more than 3 % and four standard errors (not the model's loop)",
        RESOLVED,
    ),
    "gicof-varies": (
        "the friction read along the stroke wiggles beyond the noise (its means over eighths "
        "of the central part scatter about a straight line by more than 1.5 % of μ: chatter, "
        "stick-slip): the GICoF, read at one position, is not the contact's mean friction",
        _GICOF,
    ),
}


def _refusing(flags: dict, size: int) -> np.ndarray:
    """True for the cycles that a flag whose scope is every quantity refuses."""
    refusing = np.zeros(size, dtype=bool)
    for reason, flag in flags.items():
        if REASONS[reason][1] == ALL:
            refusing |= flag
    return refusing


def _by_text(quality, function) -> np.ndarray:
    """``function(text)`` for each cycle's ``quality``, computed once per distinct text."""
    texts, inverse = np.unique(np.ravel(quality), return_inverse=True)
    return np.array([function(text) for text in texts], dtype=bool)[inverse]


def quality_strings(flags: dict, size: int) -> np.ndarray:
    """The ``quality`` of ``size`` cycles from boolean ``flags`` (reason -> per cycle).

    A refused cycle lists only the reasons that refuse it; a reason whose NaN another of
    the cycle's reasons covers, and more, is left out (``'no-crossing'`` in partial slip).
    """
    refusing = _refusing(flags, size)
    code = np.zeros(size, dtype=np.int64)
    for bit, reason in enumerate(REASONS):
        if reason in flags:
            scope = REASONS[reason][1]
            keep = refusing if scope == ALL else ~refusing
            # A reason whose NaN another present reason covers and more is left out.
            for other, flag in flags.items():
                wider = REASONS[other][1]
                if scope != ALL and wider != ALL and set(scope) < set(wider):
                    keep = keep & ~flag
            code |= (flags[reason] & keep).astype(np.int64) << bit
    codes, inverse = np.unique(code, return_inverse=True)
    names = list(REASONS)
    texts = [
        SEPARATOR.join(names[bit] for bit in range(len(names)) if value >> bit & 1) or "ok"
        for value in codes
    ]
    # One shared str per distinct quality: 8 bytes a cycle, however long the reasons.
    return np.array(texts, dtype=object)[inverse]


def add_reason(quality, where, reason: str) -> np.ndarray:
    """``quality`` with ``reason`` added to the cycles ``where`` (kept in table order)."""
    if reason not in REASONS:
        raise ValueError(f"unknown quality reason {reason!r}; known: {', '.join(REASONS)}")
    order = list(REASONS)
    quality = np.asarray(quality, dtype=str)

    def added(text):
        reasons = {reason} | (set() if text == "ok" else set(text.split(SEPARATOR)))
        return SEPARATOR.join(sorted(reasons, key=order.index))

    texts, inverse = np.unique(quality, return_inverse=True)
    updated = np.array([added(text) for text in texts], dtype=str)[inverse].reshape(quality.shape)
    return np.where(where, updated, quality)


def has_reason(quality, reason: str) -> np.ndarray:
    """True for the cycles whose ``quality`` lists ``reason``."""
    return _by_text(quality, lambda text: reason in text.split(SEPARATOR))


def refused(quality) -> np.ndarray:
    """True for the cycles refused (a reason whose scope is every quantity)."""
    return _by_text(
        quality,
        lambda text: any(REASONS.get(r, ("", ()))[1] == ALL for r in text.split(SEPARATOR)),
    )


def apply_quality(values: dict, flags: dict) -> dict:
    """``values`` (name -> per-cycle array) with NaN where a flag's scope reaches."""
    size = next(iter(values.values())).size
    refusing = _refusing(flags, size)
    result = {name: np.where(refusing, np.nan, value) for name, value in values.items()}
    for reason, flag in flags.items():
        scope = REASONS[reason][1]
        if scope != ALL:
            for name in set(scope) & set(result):
                result[name] = np.where(flag, np.nan, result[name])
    return result


def quality_summary(quality) -> str:
    """One line: how many cycles are ``'ok'``, how many were skipped for missing samples,
    and how many carry each other reason."""
    texts, counts = np.unique(np.ravel(quality), return_counts=True)
    return summary_of_counts(dict(zip(texts.tolist(), counts.tolist(), strict=True)))


def summary_of_counts(counts) -> str:
    """:func:`quality_summary` from the number of cycles of each distinct ``quality``."""
    per_reason = {}
    for text, count in counts.items():
        if text != "ok":
            for reason in text.split(SEPARATOR):
                per_reason[reason] = per_reason.get(reason, 0) + int(count)
    skipped = per_reason.pop("missing-samples", 0)
    order = list(REASONS)
    flagged = ", ".join(
        f"{reason} {per_reason[reason]}"
        for reason in sorted(per_reason, key=lambda r: order.index(r) if r in order else 99)
    )
    cycles = sum(int(c) for c in counts.values())
    summary = f"{cycles} cycle{'' if cycles == 1 else 's'}: {int(counts.get('ok', 0))} ok"
    if skipped:
        summary += f", {skipped} skipped (missing samples)"
    return summary + (f"; {flagged}" if flagged else "")
