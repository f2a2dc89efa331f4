"""A fretting lab's daily numbers from the per-cycle results of :func:`ecofmaps.analyze_loops`:
a test's sliding condition, the transition to gross slip, energy wear with Archard's
coefficients, and the closure of the loops on the scar profile. The method, its formulas and
the field's notation are in docs/lab.md.
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from ecofmaps import _nomenclature as nomenclature
from ecofmaps._inputs import check, si_units
from ecofmaps.measured.measure import loop_ratios
from ecofmaps.measured.quality import has_reason, regime_ratio, sliding_condition_of
from ecofmaps.model.profiles import ScarProfile
from ecofmaps.model.simulation import fretting_loop

__all__ = [
    "MINDLIN_ENERGY_RATIO",
    "MINDLIN_OPENING_RATIO",
    "energy_wear",
    "loop_scar_closure",
    "per_cycle",
    "sliding_condition",
    "transition",
]

#: Energy ratio A of a sphere on a flat at the transition, on the contact's displacement. [1]
MINDLIN_ENERGY_RATIO = 0.2
#: Opening ratio B of a sphere on a flat at the transition, on the contact's displacement. [1]
MINDLIN_OPENING_RATIO = 2 ** (1 / 3) - 1
#: Cycles whose amplitudes differ by less than this share are at one amplitude. [1]
_SAME_AMPLITUDE = 0.01
#: Fewest ``mindlin-stick`` cycles whose spring stands for an unknown rig's stiffness.
_SPRINGS = 3
#: Why μ_t from Q*/P has no standard error.
_PEAK_BIASED = (
    "no GICoF in the results: mu is Q*/P of the first gross-slip cycles, a peak that the "
    "force's noise biases up by an amount the results do not hold"
)


def _tests(results) -> list:
    """``results`` as a list of Datasets (one test, or a campaign)."""
    tests = list(results) if isinstance(results, list | tuple) else [results]
    for test in tests:
        if not isinstance(test, xr.Dataset):
            raise TypeError(
                "results must be the xarray.Dataset of ecofmaps.analyze_loops (or a list of "
                f"them), got {type(test).__name__}"
            )
    if not tests:
        raise ValueError("results: an empty list; give at least one test's results")
    return tests


def per_cycle(results: xr.Dataset, names) -> dict:
    """The cycle numbers, the normal load [N] and the variables ``names`` [SI] of a test, as
    float arrays over its cycles."""
    if "cycle" not in results.coords and "cycle" not in results:
        raise ValueError(
            "results: no cycle numbers (a 'cycle' coordinate or column): give the results of "
            "ecofmaps.analyze_loops or the table ecofmaps loops writes"
        )
    missing = [name for name in names if name not in results]
    if missing:
        words = ", ".join(f"'{n}' ({nomenclature.QUANTITIES[n].long_name})" for n in missing)
        raise ValueError(f"results: no {words}; give the results of ecofmaps.analyze_loops")
    values = {n: np.asarray(results[n].values, dtype=np.float64) for n in (*names, "cycle")}
    if "normal_load" in results:
        values["load"] = np.asarray(results["normal_load"].values, dtype=np.float64)
    elif "load" in results.coords or "load" in results:
        values["load"] = np.broadcast_to(float(results["load"]), values["cycle"].shape)
    elif "cof_max" in results and "max_force" in results:  # a table without the load
        values["load"] = np.asarray(results.max_force / results.cof_max, dtype=np.float64)
    else:
        raise ValueError("results: no normal load ('load', 'normal_load' or 'cof_max')")
    return values


def _rig(tests: list, rig_stiffness):
    """``rig_stiffness``, else the one the tests were analysed with (``rig_stiffness`` in their
    attrs, all the same), else None."""
    if rig_stiffness is not None:
        return rig_stiffness
    given = {test.attrs.get("rig_stiffness") for test in tests}
    return given.pop() if len(given) == 1 else None


def _spring(tests: list, rig_stiffness):
    """:func:`_rig`, else the median spring behind the stick of the tests' ``mindlin-stick``
    cycles (three or more: a sphere's gross-slip loops), else None. [N/m]"""
    rig_stiffness = _rig(tests, rig_stiffness)
    if rig_stiffness is not None or not all("quality" in t and "stiffness" in t for t in tests):
        return rig_stiffness
    springs = np.concatenate(
        [t["stiffness"].values[has_reason(t["quality"].values, "mindlin-stick")] for t in tests]
    )
    return float(np.median(springs)) if springs.size >= _SPRINGS else None


def _ratios(cycles: dict, rig_stiffness):
    """The cycles' energy and opening ratios (on the contact's displacement NaN without the
    rig's stiffness), the energy ratio that decides the regime, and where it says gross slip."""
    if rig_stiffness is not None:
        check("rig_stiffness", rig_stiffness, "positive_or_inf", "N/m")
    names = ("amplitude", "max_force", "dissipated_energy")
    slip = cycles.get("slip_amplitude", np.nan)
    ratios = loop_ratios(*(cycles[n] for n in names), slip, rig_stiffness)
    ratio = regime_ratio(ratios, rig_stiffness)
    return ratios, ratio, ratio > MINDLIN_ENERGY_RATIO


@si_units(rig_stiffness="stiffness")
def sliding_condition(results, rig_stiffness=None) -> xr.Dataset:
    r"""The energy and opening ratios of each cycle of a test, and its sliding condition.

    Parameters
    ----------
    results : xarray.Dataset
        One test's results from :func:`ecofmaps.analyze_loops`.
    rig_stiffness : float, optional
        The rig's own stiffness :math:`S` (not the loops' stick slope, which is the rig and
        the contact in series). With it the ratios are also read on the contact's
        displacement :math:`\Delta - Q/S` and the regime is decided there. By default the
        one ``results`` were analysed with (``results.attrs["rig_stiffness"]``, from
        ``analyze_loops(..., rig_stiffness=)`` or ``--rig-stiffness``), else the median
        spring behind the stick of three ``mindlin-stick`` cycles or more (a sphere's), if
        any. [N/m]

    Returns
    -------
    condition : xarray.Dataset
        Over ``cycle``: ``energy_ratio`` :math:`A = E_d/(4\Delta^*Q^*)` and
        ``opening_ratio`` :math:`B = \delta^*/\Delta^*` on the applied displacement;
        ``contact_amplitude`` :math:`\Delta^* - Q^*/S` [m], ``contact_energy_ratio`` and
        ``contact_opening_ratio`` on the contact's (NaN without ``rig_stiffness``);
        ``gross_slip`` (1, 0, or NaN for a cycle without an energy ratio). Attributes
        ``sliding_condition`` (``'partial slip'``, ``'mixed slip'`` or ``'gross slip'``) and
        ``regime_changes_at`` (the cycles where the regime changes).

    Notes
    -----
    Gross slip where the energy ratio exceeds Mindlin's :math:`A_t = 0.2`: docs/lab.md,
    "Energy and opening ratios, on which displacement".

    References
    ----------
    S. Fouvry, P. Kapsa, L. Vincent (1995), Wear 185, 35-46; L. Vincent, Y. Berthier,
    M. Godet (1992), ASTM STP 1159, 33-48; Z.R. Zhou, L. Vincent (1995), Wear 181-183,
    531-536; R.D. Mindlin, H. Deresiewicz (1953), J. Appl. Mech. 20, 327-344 (titles in
    docs/lab.md).

    Examples
    --------
    >>> import numpy as np, ecofmaps
    >>> displacement, force = ecofmaps.fretting_loop(50e-6, 450.0, 35e6, 0.8, 0.0)
    >>> results = ecofmaps.analyze_loops(np.asarray(displacement), np.asarray(force), 450.0)
    >>> condition = ecofmaps.sliding_condition(results, rig_stiffness=35e6)
    >>> condition.attrs["sliding_condition"], round(float(condition.contact_energy_ratio[0]), 3)
    ('gross slip', 1.0)
    """
    (results,) = _tests(results)
    names = ("amplitude", "max_force", "dissipated_energy", "slip_amplitude")
    cycles = per_cycle(results, names)
    ratios, ratio, gross = _ratios(cycles, _spring([results], rig_stiffness))
    gross = np.where(np.isfinite(ratio), gross, np.nan)
    condition, changes = sliding_condition_of(cycles["cycle"], gross)
    data = {name: ("cycle", value, nomenclature.attrs(name)) for name, value in ratios.items()}
    data["gross_slip"] = ("cycle", gross, nomenclature.attrs("gross_slip"))
    attrs = {"sliding_condition": condition, "regime_changes_at": changes}
    return xr.Dataset(data, coords={"cycle": results["cycle"].values}, attrs=attrs)


def _line(x, y):
    """Least-squares line ``y = a + b (x - x0)``: x0, a, b and their covariance (NaN below
    three points)."""
    x0 = float(np.mean(x))
    design = np.stack([np.ones_like(x), x - x0], axis=-1)
    (a, b), rss, *_ = np.linalg.lstsq(design, y, rcond=None)
    dof = x.size - 2
    scale = float(rss[0]) / dof if dof > 0 and rss.size else np.nan
    return x0, a, b, scale * np.linalg.inv(design.T @ design)


def _root(x0, a, b, cov, level):
    """Where the line of :func:`_line` reaches ``level``, and its standard error."""
    u = (level - a) / b
    variance = (cov[0, 0] + 2 * u * cov[0, 1] + u * u * cov[1, 1]) / (b * b)
    return x0 + u, float(np.sqrt(variance))


@si_units(rig_stiffness="stiffness")
def transition(results, rig_stiffness=None) -> xr.Dataset:
    r"""The transition from partial to gross slip, from an amplitude sweep or a campaign.

    Parameters
    ----------
    results : xarray.Dataset or list of xarray.Dataset
        The results of :func:`ecofmaps.analyze_loops` of one test at amplitudes that vary
        across the transition (the variable-displacement method), or of several tests at
        one load and several amplitudes.
    rig_stiffness : float, optional
        The rig's own stiffness :math:`S`, as for :func:`sliding_condition` (by default the
        one every test was analysed with); without it ``contact_amplitude`` is NaN. [N/m]

    Returns
    -------
    transition : xarray.Dataset
        ``amplitude`` :math:`\Delta_t` [m], ``contact_amplitude``
        :math:`\delta_t = \Delta_t - \mu_t P/S` [m] and ``mu``
        :math:`\mu_t = Q^*/P` at the transition (read as the gross-slip cycles' GICoF), each
        with its standard error (``_se``; ``mu_se`` NaN, its ``comment`` saying why, for
        results without a GICoF).

    Raises
    ------
    ValueError
        When the cycles never cross the transition (all in partial slip, or all in gross
        slip), naming the amplitudes they span, or are all at one amplitude.

    Notes
    -----
    The cycles split by amplitude where the fewest fall on the wrong side of
    :math:`A_t = 0.2`, and a line through the energy ratios either side: docs/lab.md,
    "The transition".

    References
    ----------
    Those of :func:`sliding_condition`.

    Examples
    --------
    Four tests on a sphere (Mindlin: μ = 0.8, δ_t = 6 µm) at 450 N behind a 35 MN/m rig,
    one cycle each (Δ* [m], Q* [N], E_d [J]); the true Δ_t = δ_t + μP/S is 16.3 µm:

    >>> import xarray as xr, ecofmaps
    >>> cycles = [(14e-6, 324.7, 0.7016e-3), (15.5e-6, 350.8, 1.194e-3),
    ...           (17e-6, 360.0, 2.757e-3), (19e-6, 360.0, 5.637e-3)]
    >>> tests = [xr.Dataset({"amplitude": ("cycle", [a]), "max_force": ("cycle", [q]),
    ...                      "dissipated_energy": ("cycle", [e])},
    ...                     coords={"cycle": [1], "load": 450.0}) for a, q, e in cycles]
    >>> found = ecofmaps.transition(tests, rig_stiffness=35e6)
    >>> print(f"{float(found.amplitude) * 1e6:.1f} µm, mu_t = {float(found.mu):.2f}")
    16.0 µm, mu_t = 0.80
    """
    names = ("amplitude", "max_force", "dissipated_energy")
    tests = _tests(results)
    rig_stiffness = _spring(tests, rig_stiffness)
    names += ("gicof",) * all("gicof" in test for test in tests)
    cycles = [per_cycle(test, names) for test in tests]
    pooled = {name: np.concatenate([c[name] for c in cycles]) for name in (*names, "load")}
    _, ratio, gross = _ratios(pooled, rig_stiffness)
    known = np.isfinite(ratio) & np.isfinite(pooled["load"])
    order = np.argsort(pooled["amplitude"][known], kind="stable")
    cof = pooled["max_force"] / pooled["load"]
    friction = pooled.get("gicof", np.full(cof.size, np.nan))
    if all("quality" in test for test in tests):  # not read where the stick line meets a curve
        curved = [has_reason(t["quality"].values, "curved-stick-sliding") for t in tests]
        friction = np.where(np.concatenate(curved), np.nan, friction)
    amplitude, ratio, gross, cof, friction, load = (
        v[known][order] for v in (pooled["amplitude"], ratio, gross, cof, friction, pooled["load"])
    )
    if not gross.size:
        raise ValueError("results: no cycle with an energy ratio (every cycle refused)")
    if gross.all() or not gross.any():
        words = ("gross", "above", "smaller") if gross.any() else ("partial", "at most", "larger")
        regime, bound, other = words
        raise ValueError(
            f"results never cross the transition: every cycle is in {regime} slip (energy "
            f"ratio {bound} {MINDLIN_ENERGY_RATIO}, amplitudes {amplitude.min() * 1e6:.4g} to "
            f"{amplitude.max() * 1e6:.4g} µm); test {other} amplitudes"
        )
    level = np.concatenate([[0], np.cumsum(np.diff(amplitude) > _SAME_AMPLITUDE * amplitude[1:])])
    if not level[-1]:
        raise ValueError(
            f"results: every cycle is at one amplitude ({amplitude.mean() * 1e6:.4g} µm): the "
            "regime changes during the test, not across amplitudes; a transition needs a sweep "
            "or tests at several amplitudes"
        )
    # the split with the fewest cycles on the wrong side (noise may mix a few)
    wrong = np.cumsum(gross)[:-1] + np.cumsum((~gross)[::-1])[::-1][1:]
    split = int(np.argmin(wrong)) + 1
    if not gross[split:].any():
        raise ValueError(
            "results: the cycles in gross slip are at smaller amplitudes than those in partial "
            "slip: not a transition (is the rig's stiffness right?)"
        )
    low, high = level[split - 1], level[split]
    if low == high:  # the split falls among the cycles at one amplitude: the next ones too
        low, high = low - 1, high + 1
    fitted = (level >= low) & (level <= high)
    at, at_se = _root(*_line(amplitude[fitted], ratio[fitted]), MINDLIN_ENERGY_RATIO)
    # the crossing may lie anywhere between the two amplitudes
    bracket = (amplitude[level == high].mean() - amplitude[level == low].mean()) / np.sqrt(12)
    at_se = float(np.hypot(np.nan_to_num(at_se), bracket))
    mu, mu_se = _sliding_friction(gross, level, split, cof, friction)
    force = float(np.mean(load[fitted])) / (np.nan if rig_stiffness is None else rig_stiffness)
    values = {
        "amplitude": (at, at_se),
        "contact_amplitude": (at - mu * force, float(np.hypot(at_se, force * mu_se))),
        "mu": (mu, mu_se),
    }
    data = {}
    for name, (value, se) in values.items():
        _with_se(data, name, value, se, quantity=f"transition_{name}")
    if not np.isfinite(friction[gross]).any():
        data["mu_se"][2]["comment"] = _PEAK_BIASED
    return xr.Dataset(data)


def _sliding_friction(gross, level, split, cof, friction):
    """μ_t and its standard error: the mean GICoF of each amplitude in the upper half of the
    gross-slip cycles', averaged; else Q*/P above the ``split`` (se NaN: :data:`_PEAK_BIASED`)."""
    sliding = gross & np.isfinite(friction)
    if not sliding.any():
        first = gross & (level == level[split:][gross[split:]][0])
        return float(np.mean(cof[first])), np.nan
    # the upper half: a sphere's loops just above the transition slide too little to read
    sliding &= level >= np.median(level[sliding])
    # each amplitude's mean: a trend with the amplitude is scatter, not averaged away
    means = np.array([np.mean(friction[sliding & (level == k)]) for k in np.unique(level[sliding])])
    if means.size < 2:
        return float(means[0]), np.nan
    from scipy.stats import t  # 0.4 s to import: when a transition is sought

    # ±2 se: Student's 95 % interval of the mean of n
    widen = float(t.ppf(0.975, means.size - 1)) / 2.0
    return float(np.mean(means)), float(widen * np.std(means, ddof=1) / np.sqrt(means.size))


def cycle_sum(cycle, value):
    """Σ of a per-cycle ``value`` over cycles 1 to the last recorded, and its standard error
    (docs/lab.md, "Energy wear"); ``ValueError`` if no cycle has a value."""
    kept = np.isfinite(value)
    n, v = cycle[kept], value[kept]
    if n.size == 0:
        raise ValueError("no cycle has a value to sum: every one is NaN (skipped or flagged)")
    if np.any(np.diff(n) <= 0) or n[0] < 1:
        raise ValueError("results: the cycle numbers must be 1 or more and increasing")
    gaps = np.diff(n)
    weight = np.concatenate([gaps, [0.0]]) / 2 + np.concatenate([[0.0], gaps]) / 2
    weight[[0, -1]] += 0.5  # the end cycles count whole
    weight[0] += n[0] - 1
    if n.size < 3:
        return float(weight @ v), np.nan
    left, right = gaps[:-1] / (n[2:] - n[:-2]), gaps[1:] / (n[2:] - n[:-2])
    off = v[1:-1] - (right * v[:-2] + left * v[2:])
    sigma2 = np.mean(off**2 / (1 + left**2 + right**2))
    return float(weight @ v), float(np.sqrt(sigma2 * np.sum(weight**2)))


def _worn_volume(profile: ScarProfile, length) -> tuple[float, float]:
    """Worn volume [m³] of a line contact of ``length``, or of a round scar (``length`` None),
    and its standard error from the shoulders' noise."""
    x = np.asarray(profile.position)
    residual = np.asarray(profile.height) - profile.reference_height - profile.reference_slope * x
    width = float(profile.half_width)
    inside = np.abs(x) <= width
    if length is not None:
        weight, total, volume = np.ones(x.size), 2 * width, float(profile.worn_area)
    else:  # the volume of revolution of each side's depth, the two averaged
        edge = np.interp([-width, width], x, residual)
        at = np.concatenate([[-width], x[inside], [width]])
        depth = np.maximum(-np.concatenate([edge[:1], residual[inside], edge[1:]]), 0.0)
        weight, total = np.pi * np.abs(x), np.pi * width**2
        volume = float(np.pi * np.trapezoid(np.abs(at) * depth, at))
    shoulders = residual[np.abs(x) > 2 * width]
    if shoulders.size < 5:
        return volume * (length or 1.0), np.nan
    noise = 1.4826 * np.median(np.abs(shoulders - np.median(shoulders)))
    spacing = float(np.median(np.diff(x)))
    terms = np.sum(weight[inside] ** 2) * spacing**2 + total**2 / shoulders.size
    se = float(noise * np.sqrt(terms))
    return (volume, se) if length is None else (volume * length, se * length)


def _ratio(top, top_se, bottom, bottom_se):
    """top/bottom and its standard error (independent relative errors)."""
    value = top / bottom
    return value, abs(value) * float(np.hypot(top_se / top, bottom_se / bottom))


def _scar(profile) -> None:
    """Raise unless ``profile`` is a ScarProfile with a scar."""
    if not isinstance(profile, ScarProfile):
        raise TypeError(
            "profile must be a ScarProfile (ecofmaps.read_scar_profile or "
            f"ecofmaps.scar_profile), got {type(profile).__name__}"
        )
    area = float(profile.worn_area)
    if not area > 0.0:
        raise ValueError(
            f"profile: no scar (worn area {area:g} m²): the trace shows no groove below the "
            "unworn surface"
        )


def _one_test(results, profile, length) -> dict:
    """Energy wear of one test: each value with its standard error."""
    _scar(profile)
    cycles = per_cycle(results, ("amplitude", "slip_amplitude", "dissipated_energy"))
    if not np.isfinite(cycles["dissipated_energy"]).any():
        raise ValueError("results: no cycle has a dissipated energy ('dissipated_energy')")
    cycle, load = cycles["cycle"], cycles["load"]
    energy = cycle_sum(cycle, cycles["dissipated_energy"])
    volume = _worn_volume(profile, length)
    slip = cycle_sum(cycle, 4 * load * cycles["slip_amplitude"])
    nominal = cycle_sum(cycle, 4 * load * cycles["amplitude"])
    return {
        "cumulated_energy": energy,
        "wear_volume": volume,
        "energy_wear_coefficient": _ratio(*volume, *energy),
        "archard_slip": _ratio(*volume, *slip),
        "archard_nominal": _ratio(*volume, *nominal),
    }


def _with_se(data: dict, name: str, value, se, dims=(), quantity=None) -> None:
    """Put ``name`` and ``name_se`` (its standard error) into ``data`` with their attrs."""
    attrs = nomenclature.attrs(quantity or name)
    data[name] = (dims, value, attrs)
    words = "standard error of the " + attrs["long_name"]
    data[f"{name}_se"] = (dims, se, {**attrs, "long_name": words})


@si_units(length="length")
def energy_wear(results, profile, length=None, contact="line") -> xr.Dataset:
    r"""Energy wear of a fretting test, or of a campaign: ΣE_d, V, α and Archard's k.

    Parameters
    ----------
    results : xarray.Dataset or list of xarray.Dataset
        Each test's results from :func:`ecofmaps.analyze_loops` over its recorded cycles
        (a rig may record every N-th cycle: ``cycle`` numbers them as driven).
    profile : ScarProfile or list of ScarProfile
        Each test's levelled wear-scar profile across the scar
        (:func:`ecofmaps.read_scar_profile`); of a sphere's, through its centre.
    length : float or list of float
        Length of the line contact, along which the worn area is the same; none for a
        sphere. [m]
    contact : {'line', 'sphere'}
        ``'line'``: :math:`V = L\int d\,dx`, the worn area times ``length``; ``'sphere'``
        (a round scar): :math:`V = \pi\int_{-W}^{W}|x|\,d(x)\,dx`, the volume of
        revolution of the worn depth :math:`d`, the two sides averaged. The pile-up apart.

    Returns
    -------
    wear : xarray.Dataset
        ``cumulated_energy`` :math:`\sum E_d` [J], ``wear_volume`` :math:`V` [m³],
        ``energy_wear_coefficient`` :math:`\alpha = V/\sum E_d` [m³/J], ``archard_slip``
        :math:`V/\sum 4P\delta^*` and ``archard_nominal`` :math:`V/\sum 4P\Delta^*`
        [m³/(N·m)], each with its standard error (``_se``); over ``test`` for a campaign,
        with ``campaign_energy_wear_coefficient`` :math:`\alpha` and
        ``threshold_energy`` :math:`E_{th}` of :math:`V = \alpha(\sum E_d - E_{th})`.

    Raises
    ------
    ValueError
        For results without cycles, energies (or all NaN) or a load, a profile without a
        scar, a length not in metres (0 < L < 1 m), a line without a length or a sphere with
        one, or lists of unequal length.

    Notes
    -----
    Sums over the cycles driven, linear between those recorded; a round scar's volume by
    cylindrical shells; a campaign's fit needs three tests for its errors: docs/lab.md,
    "Energy wear".

    References
    ----------
    S. Fouvry, P. Kapsa, L. Vincent (1996), Wear 200, 186-205; S. Fouvry, T. Liskiewicz,
    P. Kapsa, S. Hannel, E. Sauger (2003), Wear 255, 287-298; J.F. Archard (1953), J. Appl.
    Phys. 24, 981-988; G.B. Thomas et al. (2010), Thomas' Calculus, §6.2 (titles in
    docs/lab.md).

    Examples
    --------
    >>> import numpy as np, xarray as xr, ecofmaps
    >>> cycles = np.array([1, 500, 1000])  # recorded every 500th cycle
    >>> results = xr.Dataset(
    ...     {"amplitude": ("cycle", [50e-6] * 3), "slip_amplitude": ("cycle", [40e-6] * 3),
    ...      "dissipated_energy": ("cycle", [0.06, 0.06, 0.06])},
    ...     coords={"cycle": cycles, "load": 450.0})
    >>> x = np.linspace(-400e-6, 400e-6, 801)
    >>> z = np.where(np.abs(x) < 100e-6, 3e-6 * ((x / 100e-6) ** 2 - 1), 0.0)
    >>> profile = ecofmaps.scar_profile(x, z, smoothing=0)
    >>> wear = ecofmaps.energy_wear(results, profile, length=5e-3)
    >>> print(f"{float(wear.cumulated_energy):.0f} J, {float(wear.wear_volume) * 1e9:.3f} mm³")
    60 J, 0.002 mm³
    >>> print(f"alpha = {float(wear.energy_wear_coefficient) * 1e18:.4g} µm³/J")
    alpha = 3.333e+04 µm³/J

    The same trace through the centre of a sphere's round scar, a paraboloid of volume
    :math:`\pi D W^2/2` = 47 124 µm³:

    >>> round_scar = ecofmaps.energy_wear(results, profile, contact="sphere")
    >>> print(f"{float(round_scar.wear_volume) * 1e18:.0f} µm³")
    47119 µm³
    """
    tests = _tests(results)
    single = not isinstance(results, list | tuple)
    several = isinstance(profile, list | tuple) and not isinstance(profile, ScarProfile)
    profiles = list(profile) if several else [profile]
    if contact not in ("line", "sphere"):
        raise ValueError(f"contact = {contact!r}: 'line' or 'sphere' (a round scar)")
    if (length is None) == (contact == "line"):
        raise ValueError(
            "length: a line contact's length in metres, e.g. length=5e-3"
            if length is None
            else "length: a sphere's round scar has no length (give contact='line' for a line)"
        )
    kind = object if length is None else np.float64  # a sphere's None for each test
    lengths = np.atleast_1d(np.asarray(length, dtype=kind))
    if len(profiles) != len(tests) or lengths.ndim > 1 or lengths.size not in (1, len(tests)):
        raise ValueError(
            f"give one profile and one length per test: {len(tests)} results, "
            f"{len(profiles)} profiles, {lengths.size} lengths"
        )
    lengths = np.broadcast_to(lengths, (len(tests),))
    for each in lengths:
        if each is not None and not 0.0 < each < 1.0:
            raise ValueError(
                f"length = {float(each):g} m: a line contact's length in metres (0 < L < 1 m; "
                "5 mm is 5e-3, or give a pint Quantity)"
            )
    found = [_one_test(*each) for each in zip(tests, profiles, lengths, strict=True)]
    dims = () if single else ("test",)
    data = {}
    for name in found[0]:
        values = np.array([f[name] for f in found])
        _with_se(data, name, *(values[0] if single else values.T), dims=dims)
    if not single:  # V = α(ΣE_d - E_th) fitted over the tests
        x0, a, b, cov = _line(data["cumulated_energy"][1], data["wear_volume"][1])
        _with_se(data, "campaign_energy_wear_coefficient", b, float(np.sqrt(cov[1, 1])))
        _with_se(data, "threshold_energy", *_root(x0, a, b, cov, 0.0))
    return xr.Dataset(data)


def _reading(results, resolved):
    """The rows of ``results`` and ``resolved`` of the last cycle with a GICoF, a kept loop
    and a reading along the stroke."""
    (results,) = _tests(results)
    if "loop_displacement" not in results or "gicof" not in results:
        raise ValueError(
            "results: no loops ('loop_displacement', 'loop_force') or no 'gicof': give "
            "ecofmaps.analyze_loops(displacement, force, load, keep_loops=True)"
        )
    if not isinstance(resolved, xr.Dataset) or "felt_profile" not in resolved:
        raise ValueError(
            "resolved: no reading along the stroke ('slope', 'felt_profile' over 'position'): "
            "give ecofmaps.resolve_loops(displacement, force, load, stiffness) of the same "
            "recording (analyze_loops(..., resolve=True) keeps only its per-cycle values)"
        )
    read = resolved.cycle.values[np.isfinite(resolved.felt_profile).sum("position").values > 2]
    found = results.cycle.values[np.isfinite(results.gicof.values)]
    common = np.intersect1d(read, found)
    if not common.size:
        raise ValueError(
            "results, resolved: no cycle has both a GICoF and a reading along the stroke "
            "(see their 'quality'); are they of the same recording?"
        )
    return results.sel(cycle=common[-1]), resolved.sel(cycle=common[-1])


def _branch_force(displacement, loop_displacement, loop_force):
    """The force of the loop (Δ, Q) at ``displacement``, on the branch each point moves along."""
    top = int(np.nanargmax(loop_displacement))
    rising = np.interp(displacement, loop_displacement[: top + 1], loop_force[: top + 1])
    falling = np.interp(displacement, loop_displacement[top:][::-1], loop_force[top:][::-1])
    step = np.diff(displacement, append=displacement[-1] + (displacement[-1] - displacement[-2]))
    return np.where(step >= 0, rising, falling)


@si_units(rig_stiffness="stiffness")
def loop_scar_closure(results, resolved, profile, rig_stiffness=None) -> xr.Dataset:
    r"""How well a test's last loop and its loops' felt groove close on the measured scar.

    Parameters
    ----------
    results : xarray.Dataset
        One test's results of :func:`ecofmaps.analyze_loops` with ``keep_loops=True``.
    resolved : xarray.Dataset
        The same recording read along the stroke, :func:`ecofmaps.resolve_loops`.
    profile : ScarProfile
        The scar's levelled profilometer trace (:func:`ecofmaps.read_scar_profile`), in
        metres, centred on the scar, which is taken to lie under the loops' centre.
    rig_stiffness : float, optional
        The rig's stiffness :math:`S` for the model's loop; by default the one ``results``
        were analysed with, as for :func:`sliding_condition`, else the stiffness the reading
        along the stroke used (the loops' stick slope, unless given to it). [N/m]

    Returns
    -------
    closure : xarray.Dataset
        ``loop_residual``: root mean square of the measured loop's force less the model's
        at the same displacement on the same branch, over :math:`Q^*` [1];
        ``scar_residual`` [m] and ``scar_relative_residual`` (over the depth :math:`D`) [1]:
        root mean square height of the implied scar less the profile's over the slip
        range. The curves: ``loop_displacement``, ``loop_force`` (the measured loop, over
        ``point``) [m], [N]; ``model_displacement``, ``model_force`` (over
        ``model_point``) [m], [N]; ``implied_scar`` :math:`h(\xi)` and ``scar_height``
        :math:`z(\xi)` over ``position`` :math:`\xi` [m]. Scalars ``cycle``, ``mu`` (the
        GICoF) and ``stiffness`` [N/m].

    Raises
    ------
    ValueError
        For results without kept loops or a GICoF, a ``resolved`` that is not a reading
        along the stroke, no cycle with both, a profile without a scar or not in the loops'
        units (metres), or a ``rig_stiffness`` below half the loops' stick slope.

    Notes
    -----
    On the last cycle with a GICoF (eq. 17-18) and a reading along the stroke, against the
    model's loop on the profile (eq. 9-10): docs/lab.md, "Loop-scar closure".

    References
    ----------
    X. Jin, W. Sun, P.H. Shipway (2016), Derivation of a wear scar geometry-independent
    coefficient of friction from fretting loops exhibiting non-Coulomb frictional
    behaviour: eq. 9, 10, 17-18, Fig. 10.
    """
    loop, reading = _reading(results, resolved)
    rig_stiffness = _rig([loop], rig_stiffness)
    _scar(profile)
    slip, width = float(loop.slip_amplitude), float(profile.half_width)
    trace = np.asarray(profile.position)
    position = reading.position.values[np.isfinite(reading.felt_profile.values)]
    if not 0.1 < width / slip < 1e4 or position[0] < trace[0] or position[-1] > trace[-1]:
        raise ValueError(
            f"profile: a scar {2 * width:.3g} m wide, traced from {trace[0]:.3g} to "
            f"{trace[-1]:.3g} m, for loops that slip {2 * slip:.3g} m over "
            f"{position[0]:.3g} to {position[-1]:.3g} m: give both in metres"
        )
    slope = float(loop.stiffness)
    if rig_stiffness is None:
        rig_stiffness = float(reading.stiffness)
    check("rig_stiffness", rig_stiffness, "positive_or_inf", "N/m")
    if rig_stiffness < slope / 2:
        raise ValueError(
            f"rig_stiffness = {rig_stiffness:.4g} N/m is below the loops' stick slope "
            f"{slope:.4g} N/m, the rig and the contact in series: give it in N/m"
        )
    load = float(loop["normal_load" if "normal_load" in loop else "load"])
    mu, peak = float(loop.gicof), float(loop.max_force)
    model = fretting_loop(
        float(loop.amplitude), load, rig_stiffness, mu, profile=profile, mapping="physical"
    )
    model_displacement, model_force = (np.asarray(v, dtype=np.float64) for v in model)
    kept = np.isfinite(loop.loop_displacement.values) & np.isfinite(loop.loop_force.values)
    displacement, force = loop.loop_displacement.values[kept], loop.loop_force.values[kept]
    off = force - _branch_force(displacement, model_displacement, model_force)
    implied = reading.felt_profile.values[np.isfinite(reading.felt_profile.values)]
    height = np.interp(position, trace, np.asarray(profile.height))
    implied = implied + np.mean(height - implied)
    scar = float(np.sqrt(np.mean((implied - height) ** 2)))
    values = {
        "loop_residual": ((), float(np.sqrt(np.mean(off**2))) / peak),
        "scar_residual": ((), scar),
        "scar_relative_residual": ((), scar / float(profile.depth)),
        "mu": ((), mu),
        "stiffness": ((), float(rig_stiffness)),
        "loop_displacement": ("point", displacement),
        "loop_force": ("point", force),
        "model_displacement": ("model_point", model_displacement),
        "model_force": ("model_point", model_force),
        "implied_scar": ("position", implied),
        "scar_height": ("position", height),
        "position": ("position", position),
    }
    quantity = {"mu": "gicof", "model_displacement": "displacement", "model_force": "force"}
    data = {n: (*v, nomenclature.attrs(quantity.get(n, n))) for n, v in values.items()}
    coords = {"cycle": int(loop.cycle), "position": data.pop("position")}
    return xr.Dataset(data, coords=coords)
