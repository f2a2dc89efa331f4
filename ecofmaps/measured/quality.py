r"""Steps 6 and 7 of the loop pipeline: the judgement of each cycle (the :data:`REASONS`, flags
turned into NaN, ``quality`` strings and refusals, once), the tally of a whole recording, and
the per-cycle table; ``docs/method-loops.md`` ("Judging each cycle")."""

import collections

import numpy as np
import xarray as xr

from ecofmaps import _nomenclature as nomenclature
from ecofmaps._codes import warn
from ecofmaps.measured.cycles import LEAST_LEVEL, MIN_SAMPLES, NOISE_LEVEL, Cycles
from ecofmaps.model.regimes import GROSS_SLIP, INVALID, PARTIAL_SLIP, Regime, regime_condition

#: Joins the reasons of one cycle in ``quality``.
SEPARATOR = "+"
#: Scope of a reason that refuses the cycle: every per-cycle quantity.
ALL = "all"
#: Plausible displacement amplitudes: outside, the unit is wrong (``implausible-amplitude``). [m]
AMPLITUDE_RANGE = (0.5e-6, 50e-3)
#: Plausible coefficients of friction: outside, the load or force is wrong (``implausible-cof``).
COF_RANGE = (0.01, 3.0)
#: The amplitudes and coefficients of friction that the ranges allow, in words.
_AMPLITUDES = f"{AMPLITUDE_RANGE[0] * 1e6:g} µm to {AMPLITUDE_RANGE[1] * 1e3:g} mm"
_COFS = f"{COF_RANGE[0]:g} to {COF_RANGE[1]:g}"
#: Displacement amplitudes above this are reciprocating sliding rather than fretting (still
#: analysed the same way; the results' ``motion`` attribute says so). [m]
FRETTING_AMPLITUDE = 300e-6
#: A recorded normal load that swings by more than this share of its mean within a cycle
#: (highest less lowest) leaves the values given at the cycle's mean load off (``load-swing``).
LOAD_SWING = 0.2
#: The per-cycle values that scale with the normal load (given at each cycle's own load).
LOAD_SCALED = ("max_force", "dissipated_energy", "stiffness", "force_offset", "force_drift_se")
#: A loop whose area :math:`\oint Q\,d\Delta` is below minus this share of :math:`4\Delta^*Q^*`
#: runs anticlockwise; a smaller negative area is noise.
ANTICLOCKWISE_SHARE = 0.05
#: The noise's bound on the lift of an extreme, σ√(2 ln n), must be below this share of a
#: cycle's amplitudes (``noise-amplitude``; half the peak-to-peak is then at most 10 % high).
NOISE_SHARE = 0.15
#: A stick segment must explain all but this share of the displacement's variance along it.
UNEXPLAINED_SHARE = 0.2
#: Fewest slipping samples of each branch in the central part of the stroke.
SLIP_SAMPLES = 8
#: μ(ξ) varies along the stroke when the means over the inner and the outer half of the
#: central part differ by this share of μ and by this many standard errors.
VARIATION = 0.03
VARIATION_SIGNIFICANCE = 4.0
#: Blocks of the central part whose means give the scatter of μ(ξ) (batch means).
SCATTER_BLOCKS = 8
#: The GICoF is flagged where the block means of μ(ξ) scatter about a straight line by
#: this share of μ (standard deviation) beyond the noise.
GICOF_WIGGLE = 0.015

#: How the quantities are measured on a loop (the netCDF ``comment`` attribute).
_COMMENTS = {
    "slip_amplitude": "half the loop's width at Q = 0",
    "dissipated_energy": "the loop's area",
    "stiffness": "slope of the stick segments",
    "regime": "GROSS_SLIP when the energy ratio exceeds gross_slip_threshold, else PARTIAL_SLIP; "
    "INVALID where the cycle is refused",
    "quality": "'ok' or the reasons for NaN, joined by '+' (ecofmaps.measured.quality)",
}
#: The GICoF and the crossings it is read at; the slip and what it gives.
GICOF = (
    "gicof",
    "gicof_forward",
    "gicof_backward",
    "crossing_displacement_forward",
    "crossing_displacement_backward",
)
_SLIP = ("slip_amplitude", "ecof")
#: The values read along the stroke (:func:`ecofmaps.resolve_loops`).
RESOLVED = ("mu_resolved", "mu_resolved_se", "aspect_ratio")

#: Each reason a cycle can be flagged for, in ``quality``'s order: (meaning, quantities NaN).
REASONS = {
    "missing-samples": ("a missing sample (NaN or an empty cell): skipped, not analysed", ALL),
    "no-reversal": (
        "no reversal where the drive's period puts this cycle: smaller than the reversal "
        f"detector's least band ({LEAST_LEVEL * 100:g} % of the whole recording's, and "
        f"{NOISE_LEVEL:g} standard deviations of the displacement's noise), or none (the rig "
        "at rest): not analysed",
        ALL,
    ),
    "load-not-positive": (
        "the recorded normal load is zero or negative at a sample of the cycle (its samples "
        "are missing to the force's scaling): not analysed",
        ALL,
    ),
    "few-samples": (f"fewer than {MIN_SAMPLES} samples in the cycle, fewer than a loop needs", ALL),
    "constant-force": ("the force does not vary over the cycle (a dead channel)", ALL),
    "implausible-amplitude": (
        f"the displacement amplitude is outside {_AMPLITUDES}: the displacement is not in the "
        "unit assumed (a column without a unit is read in µm)",
        ALL,
    ),
    "noise-amplitude": (
        "the displacement or force amplitude does not stand clear of the noise: σ√(2 ln n), the "
        "most the noise of n samples is expected to lift an extreme (σ from second differences), "
        f"exceeds {NOISE_SHARE * 100:g} % of half the peak-to-peak (read too large)",
        ALL,
    ),
    "several-loops": (
        "the displacement turns back within a branch, by more than the reversal detector's "
        "band (several loops under one cycle number)",
        ALL,
    ),
    "anticlockwise": (
        f"the loop runs anticlockwise (area below -{ANTICLOCKWISE_SHARE * 100:g} % of 4Δ*Q*): "
        "force and displacement recorded positive in opposite directions (see flip_force), "
        "time reversed, or the columns swapped",
        ALL,
    ),
    "energy-ratio-above-1": ("the loop's area exceeds its bounding box 4Δ*Q* (A > 1)", ALL),
    "negative-stiffness": ("the stick sides slope down (S < 0)", ALL),
    "no-stick": (
        "no straight stick side after the reversals: the stick lines leave more than "
        f"{UNEXPLAINED_SHARE * 100:g} % of the displacement's variance along them unexplained",
        ALL,
    ),
    "no-zero-crossing": ("a branch does not cross Q = 0 between measured samples: no loop", ALL),
    "negative-area": (
        f"no area within the noise (-{ANTICLOCKWISE_SHARE * 100:g} % of 4Δ*Q* < area < 0)",
        ("dissipated_energy", "energy_ratio", "ecof"),
    ),
    "negative-slip": ("δ* <= 0: the zero-force crossings in the wrong order", _SLIP),
    "slip-beyond-amplitude": (
        "δ* > Δ* beyond rounding: the zero-force crossings lie outside the loop's extremes as "
        "read through the noise (the noise of a near-rigid loop, or a misread extreme)",
        (*_SLIP, "opening_ratio", "contact_opening_ratio"),
    ),
    "curved-stick": (
        "the stick sides are curved (a polymer, micro-slip): no straight line gives S",
        ("stiffness", *GICOF, *RESOLVED),
    ),
    "curved-stick-sliding": (
        "the stick sides are curved (a sphere's Mindlin stick, micro-slip) but the loop slides "
        "at Q* where the stick line crosses it: no straight line gives S, the GICoF is read",
        ("stiffness", *RESOLVED),
    ),
    "mindlin-stick": (
        "the stick sides follow Mindlin's law behind a spring (a sphere): the stiffness is the "
        "spring's, the GICoF Q/P on the sliding part; not read along the stroke",
        ("crossing_displacement_forward", "crossing_displacement_backward", *RESOLVED),
    ),
    "no-crossing": (
        "a branch's crossing with Q = SΔ is not on the measured loop (between its samples, "
        "within their force range)",
        GICOF,
    ),
    "implausible-cof": (
        f"a coefficient of friction outside {_COFS} (the ECoF or GICoF in gross slip): the load "
        "given or the force's unit is wrong, not the contact",
        ("ecof", "cof_max", *GICOF, *RESOLVED),
    ),
    "load-swing": (
        f"the recorded normal load swings by more than {LOAD_SWING * 100:g} % of its mean "
        "within the cycle: the values that scale with the load, given at its mean, are off",
        LOAD_SCALED,
    ),
    "partial-slip": (
        "partial slip: the energy ratio A is not above the threshold; the contact slips only "
        "at its edges, and Q*/P (cof_max, kept) is a lower bound of μ",
        ("ecof", *GICOF, *RESOLVED),
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
        f"fewer than {SLIP_SAMPLES} slipping samples of a branch in the central part of the "
        "stroke (a sparse or digitised loop): friction cannot be read along the stroke",
        RESOLVED,
    ),
    "mu-varies": (
        "the friction read along the stroke differs between the inner and the outer half of "
        f"its central part by more than {VARIATION * 100:g} % and {VARIATION_SIGNIFICANCE:g} "
        "standard errors (not the model's loop)",
        RESOLVED,
    ),
    "gicof-varies": (
        "the friction read along the stroke wiggles beyond the noise (its means over "
        f"{SCATTER_BLOCKS} blocks of the central part scatter about a straight line by more "
        f"than {GICOF_WIGGLE * 100:g} % of μ: chatter): the GICoF, read at one position, is "
        "not the contact's mean friction",
        GICOF,
    ),
}

#: The reasons that the reading along the stroke adds (their flags do not warn).
READING_REASONS = (
    "stiffness-mismatch",
    "no-overlap",
    "few-slip-samples",
    "mu-varies",
    "gicof-varies",
)

#: What to do about a recorded normal load that is negative.
COMPRESSION = "is it recorded negative in compression? Give it with the other sign (-Fz)."

#: What to do about a recording whose every cycle is refused for a reason, the first that
#: applies; with loops anticlockwise and stick sides sloping down, :data:`_FLIP_HINT`.
_HINTS = {
    "missing-samples": "Every cycle holds a missing sample (NaN or an empty cell).",
    "load-not-positive": "The recorded normal load is zero or negative in every cycle: "
    + COMPRESSION,
    "load-swing": f"The recorded normal load swings by more than {LOAD_SWING:.0%} of its mean "
    "within every cycle: is the load column the normal load, and is it held steady?",
    "noise-amplitude": "The amplitudes do not stand clear of the noise: is the rig moving, "
    "and the displacement and force recorded with less noise than the loop?",
    "anticlockwise": "The loops run anticlockwise with stick sides sloping up: the recording "
    "runs backwards in time, or the displacement and force columns are swapped.",
    "constant-force": "The force does not vary: is the force channel connected?",
    "implausible-amplitude": f"The displacement amplitude is outside {_AMPLITUDES}: the "
    "displacement is not in the unit assumed. analyze_loops takes metres; on the command "
    "line, --displacement-unit gives the column's unit (a column without a unit in its name "
    "or the file is read in µm).",
}
_FLIP_HINT = (
    "The loops run anticlockwise with stick sides sloping down: the force is recorded "
    "positive against the displacement. If so, read it with the other sign: "
    "flip_force=True (on the command line, --flip-force)."
)
_LAST_HINT = (
    "Is it a recording of fretting loops, with the displacement and the force in their own columns?"
)

#: The recorded values that a refused cycle keeps.
_RECORDED = ("normal_load",)


class LoopQualityWarning(UserWarning):
    """Cycles of a recording were flagged in ``quality``, or its units look wrong."""


class ImplausibleScaleWarning(LoopQualityWarning):
    """Cycles of an implausible amplitude or coefficient of friction (a wrong unit or load):
    a :class:`LoopQualityWarning` that ``warnings.filterwarnings`` can turn alone into errors."""


class ImplausibleScaleError(ValueError):
    """Every cycle refused, some for an implausible amplitude: the unit assumed is wrong."""


def _attrs(name: str) -> dict:
    return nomenclature.attrs(name, _COMMENTS)


def regime_ratio(values: dict, rig_stiffness) -> np.ndarray:
    """The energy ratio deciding each cycle's regime (the contact's if the rig's is known). [1]"""
    return values["energy_ratio" if rig_stiffness is None else "contact_energy_ratio"]


def gross_slip(values: dict, options) -> np.ndarray:
    """True for the cycles whose :func:`regime_ratio` exceeds ``gross_slip_threshold``."""
    return regime_ratio(values, options.rig_stiffness) > options.gross_slip_threshold


def _outside(value, bounds):
    return np.isfinite(value) & ((value < bounds[0]) | (value > bounds[1]))


def scale_flags(values: dict, options) -> dict:
    """The checks of scale (reason -> per cycle): an amplitude outside :data:`AMPLITUDE_RANGE`,
    a gross-slip ECoF or GICoF outside :data:`COF_RANGE` (not Q*/P: a deep groove raises it)."""
    scaled = _outside(values["amplitude"], AMPLITUDE_RANGE)
    cof = _outside(values["ecof"], COF_RANGE) | _outside(values["gicof"], COF_RANGE)
    cof &= gross_slip(values, options) & ~scaled
    return {"implausible-amplitude": scaled, "implausible-cof": cof}


def load_flags(missing, mean, lowest, highest) -> dict:
    """The checks of each cycle's recorded load (reason -> per cycle) from its mean, lowest and
    highest [N]; ``missing`` kept where the load is positive (elsewhere missing by design)."""
    bad = lowest <= 0.0  # and so the mean, if it is not positive
    with np.errstate(divide="ignore", invalid="ignore"):
        swing = (highest - lowest) / mean > LOAD_SWING
    return {"missing-samples": missing & ~bad, "load-not-positive": bad, "load-swing": swing & ~bad}


def judged(values: dict, flags: dict, options):
    """``values`` NaN where a flag reaches, the ``quality`` strings, the refusals and regimes."""
    size = next(iter(flags.values())).size
    refused = _refusing(flags, size)
    recorded = {k: values[k] for k in _RECORDED if k in values}  # a refused cycle's too
    values = {k: np.where(refused, np.nan, v) for k, v in values.items() if k not in recorded}
    for reason, flag in flags.items():
        scope = REASONS[reason][1]
        if scope != ALL:  # NaN where a flag's scope reaches
            for name in set(scope) & set(values):
                values[name] = np.where(flag, np.nan, values[name])
    sliding = gross_slip(values, options)
    regime = np.where(refused, INVALID, np.where(sliding, GROSS_SLIP, PARTIAL_SLIP))
    return values | recorded, quality_strings(flags, size), refused, regime


def cycle_results(values: dict, flags: dict, label, options) -> xr.Dataset:
    """The per-cycle Dataset of some cycles, ``values`` and ``flags`` judged once."""
    values, quality, _, regime = judged(values, flags, options)
    last = ("stick_residual", *_RECORDED)
    data = {k: ("cycle", v, _attrs(k)) for k, v in values.items() if k not in last}
    data["regime"] = ("cycle", regime.astype(np.int32), _attrs("regime") | Regime.flag_attrs())
    data |= {k: ("cycle", values[k], _attrs(k)) for k in last if k in values}
    data["quality"] = ("cycle", quality, _attrs("quality"))
    load = ((), options.load, _attrs("load"))
    return xr.Dataset(data, coords={"cycle": ("cycle", label, _attrs("cycle")), "load": load})


class Tally:
    """What :func:`analyze_loops` says about a whole recording, from its parts' flags."""

    def __init__(self):
        self.counts = collections.Counter()  # cycles by quality
        self.cycles = self.refused = self.flagged = self.implausible_cof = self.scaled = 0
        self.every = dict.fromkeys(_HINTS, True)
        self.negative_stiffness = False
        self.amplitudes: list = []

    def add(self, quality, flags: dict, amplitude) -> None:
        """Count the cycles of a part: their ``quality``, ``flags`` and amplitudes as measured."""
        self.counts.update(np.asarray(quality).tolist())
        quiet = {"ok", "partial-slip", "mindlin-stick", *READING_REASONS}
        loud = _by_text(quality, lambda text: bool(set(text.split(SEPARATOR)) - quiet))
        self.flagged += int(loud.sum())
        self.cycles += amplitude.size
        self.refused += int(_refusing(flags, amplitude.size).sum())
        for reason in _HINTS:
            self.every[reason] &= reason in flags and bool(flags[reason].all())
        self.negative_stiffness |= bool(flags["negative-stiffness"].any())
        self.amplitudes.append(amplitude)
        self.implausible_cof += int(flags["implausible-cof"].sum())
        self.scaled += int(flags["implausible-amplitude"].sum())

    def merge(self, other: "Tally") -> None:
        """Count the parts ``other`` counted (in another process, say) as well."""
        self.counts.update(other.counts)
        for name in ("cycles", "refused", "flagged", "implausible_cof", "scaled"):
            setattr(self, name, getattr(self, name) + getattr(other, name))
        for reason in _HINTS:
            self.every[reason] &= other.every[reason]
        self.negative_stiffness |= other.negative_stiffness
        self.amplitudes += other.amplitudes

    @property
    def summary(self) -> str:
        """The one-line quality summary so far."""
        return _summary_of_counts(self.counts)

    def finish(self, results, cycles: Cycles, cycles_from: str, options) -> xr.Dataset:
        """Check the whole recording and give ``results`` (the parts, joined) its attributes."""
        summary, scaled = self.summary, self.scaled
        if self.cycles and self.refused == self.cycles:
            every = self.every  # the reasons that refuse every cycle
            hint = next((hint for reason, hint in _HINTS.items() if every[reason]), _LAST_HINT)
            if every["anticlockwise"] and self.negative_stiffness and not every["missing-samples"]:
                hint = _FLIP_HINT
            error = ImplausibleScaleError if scaled else ValueError
            raise error(f"no plausible cycle in the recording ({summary}). {hint}")
        if scaled:
            warn(
                f"{scaled} cycles have an amplitude outside {_AMPLITUDES}: is the displacement in "
                "metres (on the command line --displacement-unit; a column without a unit is read "
                "in µm)?",
                ImplausibleScaleWarning,
            )
        if self.implausible_cof:
            warn(
                f"{self.implausible_cof} cycles have a coefficient of friction outside {_COFS} "
                f"with the load of {float(results['load']):g} N: is the load right (load=, on the "
                "command line --load) and the force in newtons (--force-unit; a column without a "
                "unit is read in N)?",
                ImplausibleScaleWarning,
            )
        if self.flagged:
            warn(f"cycles flagged: {summary}", LoopQualityWarning)
        condition, changes = regime_condition(results)
        amplitude = np.concatenate(self.amplitudes) if self.amplitudes else np.zeros(0)
        amplitude = amplitude[np.isfinite(amplitude)]
        sliding = amplitude.size and float(np.median(amplitude)) > FRETTING_AMPLITUDE
        results.attrs |= {
            "title": "Fretting loops analysed cycle by cycle (ecofmaps.analyze_loops)",
            "cycles_from": cycles_from,
            "incomplete_cycles": cycles.incomplete_cycles,
            "dropped_samples": cycles.dropped_samples,
            "missing_samples": cycles.missing_samples,
            "first_missing_sample": cycles.first_missing,
            "skipped_cycles": _per_reason(self.counts)["missing-samples"],
            "gross_slip_threshold": options.gross_slip_threshold,
            "flip_force": int(options.flip_force),
            "quality_summary": summary,
            "sliding_condition": condition,
            "regime_changes_at": changes,
            "motion": "reciprocating sliding" if sliding else "fretting",
        }
        if options.rig_stiffness is not None:
            results.attrs["rig_stiffness"] = options.rig_stiffness
        return results


def _refusing(flags: dict, size: int) -> np.ndarray:
    """True for the cycles that a flag whose scope is every quantity refuses."""
    refusing = np.zeros(size, dtype=bool)
    for reason, flag in flags.items():
        if REASONS[reason][1] == ALL:
            refusing |= flag
    return refusing


def _by_text(quality, function, dtype=bool) -> np.ndarray:
    """``function(text)`` for each cycle's ``quality``, computed once per distinct text."""
    texts, inverse = np.unique(np.ravel(quality), return_inverse=True)
    return np.array([function(text) for text in texts], dtype=dtype)[inverse]


def quality_strings(flags: dict, size: int) -> np.ndarray:
    """The ``quality`` of ``size`` cycles from boolean ``flags`` (reason -> per cycle)."""
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
    texts = [
        SEPARATOR.join(name for bit, name in enumerate(REASONS) if value >> bit & 1) or "ok"
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

    return np.where(where, _by_text(quality, added, str).reshape(quality.shape), quality)


def has_reason(quality, reason: str) -> np.ndarray:
    """True for the cycles whose ``quality`` lists ``reason``."""
    return _by_text(quality, lambda text: reason in text.split(SEPARATOR))


def refused(quality) -> np.ndarray:
    """True for the cycles refused (a reason whose scope is every quantity)."""
    refusing = {reason for reason, (_, scope) in REASONS.items() if scope == ALL}
    return _by_text(quality, lambda text: bool(refusing & set(text.split(SEPARATOR))))


def quality_summary(quality) -> str:
    """One line: the cycles ``'ok'``, skipped for missing samples, and with each other reason."""
    texts, counts = np.unique(np.ravel(quality), return_counts=True)
    return _summary_of_counts(dict(zip(texts.tolist(), counts.tolist(), strict=True)))


def _per_reason(counts) -> collections.Counter:
    """The cycles flagged for each reason, from the number of each distinct ``quality``."""
    per_reason = collections.Counter()
    for text, count in counts.items():
        if text != "ok":
            per_reason.update(dict.fromkeys(text.split(SEPARATOR), int(count)))
    return per_reason


def _summary_of_counts(counts) -> str:
    """:func:`quality_summary` from the number of cycles of each distinct ``quality``."""
    per_reason = _per_reason(counts)
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
