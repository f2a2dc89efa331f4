r"""Every quantity ecofmaps names, once: symbol, long name, units, display, range.

Dataset attributes, plot labels, table columns, the command line's rows and the range checks
all read :data:`QUANTITIES`, keyed by the quantity's name in the Python API. ``units`` is the
SI unit in CF/UDUNITS spelling; ``display_unit`` and ``display_factor`` the tribologist's."""

import dataclasses
import math

import numpy as np


@dataclasses.dataclass(frozen=True)
class Quantity:
    r"""One named quantity."""

    words: str
    symbol: str
    latex: str
    units: str = "1"
    kind: str = "dimensionless"
    display_unit: str = ""
    display_factor: float = 1.0
    valid: str | None = None
    label: str | None = None
    axis_unit: str | None = None

    @property
    def long_name(self) -> str:
        """Words and symbol: the netCDF ``long_name``."""
        return f"{self.words} {self.symbol}" if self.symbol else self.words


def _length(words, symbol="", latex="", valid=None, **extra) -> Quantity:
    return Quantity(words, symbol, latex, "m", "length", "µm", 1e6, valid, **extra)


def _force(words, symbol="", latex="", valid=None, **extra) -> Quantity:
    return Quantity(words, symbol, latex, "N", "force", "N", 1.0, valid, **extra)


def _number(words, symbol="", latex="", valid=None, **extra) -> Quantity:
    return Quantity(words, symbol, latex, valid=valid, **extra)


#: Valid ranges: name -> (test on an array, words); each rejects NaN, all but one +inf.
RANGES = {
    "positive": (lambda a: (a > 0) & (a < math.inf), "0 < {name} < inf"),
    "positive_or_inf": (lambda a: a > 0, "0 < {name} <= inf"),
    "non_negative": (lambda a: (a >= 0) & (a < math.inf), "0 <= {name} < inf"),
    "finite": (lambda a: (a > -math.inf) & (a < math.inf), "-inf < {name} < inf"),
}

# Units of energy wear, and of S/P: SI, kind, display unit, factor (range, label, axis unit).
_JOULES = ("J", "energy", "J")
_PER_JOULE = ("m3 J-1", "wear_rate", "µm³/J", 1e18)
_PER_NEWTON_METRE = ("m3 N-1 m-1", "archard", "mm³/(N·m)", 1e9)
_PER_METRE = ("m-1", "stiffness_ratio", "1/mm", 1e-3, "positive_or_inf", "stiffness over load")

#: Every quantity by its name in the API.
QUANTITIES: dict[str, Quantity] = {
    "amplitude": _length("displacement amplitude", "Δ*", r"\Delta^*", "positive"),
    "load": _force("normal load", "P", "P", "positive"),
    "stiffness": Quantity(
        "rig stiffness", "S", "S", "N m-1", "stiffness", "MN/m", 1e-6, "positive_or_inf"
    ),
    "mu": _number("contact coefficient of friction", "μ", r"\mu", "positive"),
    "aspect_ratio": _number("groove aspect ratio", "z_o/x_o", "z_o/x_o", "non_negative"),
    "groove_half_width": _length("groove half-width", "x_o", "x_o", "positive"),
    "scar_depth": _length("wear scar depth", "D", "D", "non_negative"),
    "scar_half_width": _length("wear scar half-width", "W", "W", "positive"),
    "smoothing": _length("slope smoothing length of a scar profile", "", "", "non_negative"),
    "scar_position": _length("position across the scar", "X", "X"),
    "scar_height": _length("height of the scar profile", "z", "z"),
    "scar_slope": _number("slope of the scar profile", "g = dz/dX", "g = dz/dX"),
    "shape": _number("scar shape"),
    "groove": _number("groove: the scar profile, or the parabola of the same D/W (eq. 11)"),
    "stiffness_ratio": Quantity(
        "rig stiffness over normal load", "S/P", "S/P", *_PER_METRE, "(MN/m)/kN = 1/mm"
    ),
    "compliance_ratio": _number(
        "compliance ratio", "λ = P/(S Δ*)", r"\lambda = P/(S\Delta^*)", "non_negative"
    ),
    "displacement": _length("applied displacement", "Δ", r"\Delta", "finite"),
    "force": _force("tangential force", "Q", "Q", "finite"),
    "force_ratio": _number("tangential force over normal load", "Q/P", "Q/P", label=""),
    "point": _number("point round the loop"),
    "slip_amplitude": _length("slip amplitude", "δ*", r"\delta^*"),
    "slip_ratio": _number(
        "slip amplitude over displacement amplitude", "δ*/Δ*", r"\delta^*/\Delta^*"
    ),
    "max_force": _force("peak tangential force", "Q*", "Q^*"),
    "dissipated_energy": Quantity(
        "dissipated energy per cycle", "E_d", "E_d", "J", "energy", "mJ", 1e3
    ),
    "ecof": _number("energy coefficient of friction", "μ_E", r"\mu_E", "positive"),
    "ecof_ratio": _number("energy CoF over contact CoF", "μ_E/μ", r"\mu_E/\mu", label=""),
    "regime": _number("regime"),
    "cycle": _number("cycle number"),
    "cof_max": _number("peak coefficient of friction", "Q*/P", "Q^*/P"),
    "energy_ratio": _number("energy ratio", "A = E_d/(4Δ*Q*)", r"A = E_d/(4\Delta^* Q^*)"),
    "gicof": _number("geometry-independent coefficient of friction (GICoF)"),
    "gicof_forward": _number("GICoF on the rising-displacement branch"),
    "gicof_backward": _number("GICoF on the falling-displacement branch"),
    "crossing_displacement_forward": _length("displacement where Q = SΔ, rising branch"),
    "crossing_displacement_backward": _length("displacement where Q = SΔ, falling branch"),
    "displacement_offset": _length("displacement offset removed (loop centre)"),
    "force_offset": _force("force offset removed (loop centre)"),
    "normal_load": _force("normal load over the cycle (mean of the recorded load)", "P", "P"),
    "force_drift_se": _force(
        "standard error of the offset between the loop's branches left by the drift correction"
    ),
    "loop_displacement": _length("applied displacement, centred", "Δ", r"\Delta"),
    "loop_force": _force("tangential force, centred", "Q", "Q"),
    "stick_residual": _length("root mean square displacement off the stick lines"),
    "quality": _number("'ok', or why the values of the cycle are NaN"),
    "opening_ratio": _number("opening ratio", "B = δ*/Δ*", r"B = \delta^*/\Delta^*"),
    "contact_amplitude": _length("contact displacement amplitude", "Δ* - Q*/S", ""),
    "contact_energy_ratio": _number("energy ratio on the contact's displacement", "A_c"),
    "contact_opening_ratio": _number("opening ratio on the contact's displacement", "B_c"),
    "gross_slip": _number("gross slip (1) or partial slip (0)"),
    "transition_amplitude": _length("transition displacement amplitude", "Δ_t", r"\Delta_t"),
    "transition_contact_amplitude": _length("contact's transition amplitude", "δ_t", r"\delta_t"),
    "transition_mu": _number("coefficient of friction at the transition", "μ_t = Q*/P", r"\mu_t"),
    "cumulated_energy": Quantity("cumulated dissipated energy", "ΣE_d", r"\Sigma E_d", *_JOULES),
    "wear_volume": Quantity("wear volume", "V", "V", "m3", "volume", "mm³", 1e9),
    "energy_wear_coefficient": Quantity("energy wear coefficient", "α", r"\alpha", *_PER_JOULE),
    "archard_slip": Quantity("Archard's k on the slip", "k_δ", r"k_\delta", *_PER_NEWTON_METRE),
    "archard_nominal": Quantity(
        "Archard's k on the amplitude", "k_Δ", r"k_\Delta", *_PER_NEWTON_METRE
    ),
    "campaign_energy_wear_coefficient": Quantity(
        "energy wear coefficient (fit)", "α", r"\alpha", *_PER_JOULE
    ),
    "threshold_energy": Quantity("threshold energy of wear", "E_th", "E_{th}", *_JOULES),
    "loop_residual": _number("root mean square force off the model's loop, over Q*"),
    "scar_residual": _length("root mean square height of the implied scar off the profile"),
    "scar_relative_residual": _number("scar residual over the scar depth"),
    "implied_scar": _length("scar implied by the loops", "h(ξ) = ∫g dξ", r"h(\xi)"),
    "position": _length("contact position, centred", "ξ = Δ - Q/S", r"\xi = \Delta - Q/S"),
    "slope": _number("groove slope felt by the contact", "g(ξ)", r"g(\xi)"),
    "felt_profile": _length("felt groove profile, zero at the centre", "h(ξ) = ∫g dξ", r"h(\xi)"),
    "force_forward": _force(
        "tangential force on the forward slip branch, centred", "Q+(ξ)", r"Q_+(\xi)"
    ),
    "force_backward": _force(
        "tangential force on the backward slip branch, centred", "Q-(ξ)", r"Q_-(\xi)"
    ),
    "mu_resolved": _number("coefficient of friction averaged over the central stroke", "μ", r"\mu"),
    "mu_resolved_se": _number("standard error of the resolved coefficient of friction"),
    "tilt": _number("mean groove slope g0 of g ≈ g0 + kξ"),
    "position_offset": _length("contact position of the loop centre in the recording"),
    "position_min": _length("lower end of the range where both branches slip"),
    "position_max": _length("upper end of the range where both branches slip"),
    "displacement_noise": _length("standard deviation of the displacement noise"),
    "force_noise": _force("standard deviation of the force noise"),
    "displacement_drift": _length("displacement drift per cycle"),
    "correction_factor": _number("contact CoF over energy CoF", "μ/μ_E", r"\mu/\mu_E"),
    "shortcut_error": _number(
        "error of the contact CoF corrected with the D/W shortcut",
        "μ'/μ - 1",
        r"\mu'/\mu - 1",
        display_unit="%",
        display_factor=100.0,
    ),
}


def attrs(name: str, comments=None) -> dict:
    """The netCDF ``long_name`` and ``units`` of ``name``, and its ``comment`` in ``comments``."""
    described = {"long_name": QUANTITIES[name].long_name, "units": QUANTITIES[name].units}
    return described | ({"comment": comments[name]} if name in (comments or {}) else {})


def axis_label(name: str, plain: bool = False) -> str:
    r"""A plot axis label, ``Slip amplitude $\delta^*$ [µm]`` (``δ*`` if ``plain``)."""
    quantity = QUANTITIES[name]
    words = quantity.words if quantity.label is None else quantity.label
    mark = quantity.symbol if plain else quantity.latex and f"${quantity.latex}$"
    unit = quantity.axis_unit or quantity.display_unit or "1"
    return " ".join(part for part in (words[:1].upper() + words[1:], mark, f"[{unit}]") if part)


def column(name: str) -> str:
    """The column name of quantity ``name`` in tables: the name and its display unit."""
    unit = QUANTITIES[name].display_unit
    return f"{name}_{unit.replace('µ', 'u').replace('/', '_per_')}" if unit else name


def display(name: str, value) -> np.ndarray:
    """``value`` [SI] of quantity ``name`` in its display unit."""
    return np.asarray(value) * QUANTITIES[name].display_factor


def with_se(name: str, value: float, se: float) -> str:
    """``value ± se`` of quantity ``name`` [SI] in its display unit: the error to two
    significant digits, the value to its decimal place (else to four significant digits).

    >>> with_se("transition_amplitude", 16.1959e-6, 0.347947e-6), with_se("mu", 0.8, 0.0)
    ('16.20 ± 0.35 µm', '0.8000 ± 0')
    """
    quantity = QUANTITIES[name]
    value, se = value * quantity.display_factor, se * quantity.display_factor
    if np.isfinite(se) and se > 0:
        decimals = max(0, 1 - math.floor(math.log10(se)))
        shown = f"{value:.{decimals}f} ± {se:.{decimals}f}"
    else:
        shown = np.format_float_positional(value, 4, unique=False, fractional=False, trim="k")
        shown = shown.rstrip(".") + (" ± 0" if se == 0 else "")
    return f"{shown} {quantity.display_unit}".rstrip()


def texts_with_se(found, names, quantity: str = "{}") -> list[tuple[str, str]]:
    """Each of ``names`` in ``found`` as (``quantity.format(name)``, its :func:`with_se` text)."""
    rows = [(quantity.format(n), float(found[n]), float(found[f"{n}_se"])) for n in names]
    return [(q, with_se(q, value, se)) for q, value, se in rows]


#: The numbers of :func:`ecofmaps.transition` (quantities ``transition_<name>``), in order.
TRANSITION = ("amplitude", "contact_amplitude", "mu")


def transition_texts(found) -> list[tuple[str, str]]:
    """:func:`texts_with_se` of :func:`ecofmaps.transition`'s Δ_t, δ_t (or what it needs), μ_t."""
    texts = texts_with_se(found, TRANSITION, "transition_{}")
    if np.isnan(float(found.contact_amplitude)):
        texts[1] = (
            texts[1][0],
            "needs --rig-stiffness (the rig's own; without it Δ_t is read on the applied "
            "displacement, and lands high)",
        )
    return texts


def within(name: str, value):
    """Boolean array: where ``value`` lies in the valid range of ``name``."""
    return RANGES[QUANTITIES[name].valid][0](value)
