"""A test's sliding condition and the transition to gross slip (docs/lab.md)."""

import numpy as np
import xarray as xr

from ecofmaps import _nomenclature as nomenclature
from ecofmaps._inputs import check, si_units
from ecofmaps.measured.measure import loop_ratios
from ecofmaps.measured.quality import has_reason, regime_ratio
from ecofmaps.model.regimes import regime_condition, sliding_condition_of

#: Energy ratio A of a sphere on a flat at the transition, on the contact's displacement. [1]
MINDLIN_ENERGY_RATIO = 0.2
#: Opening ratio B of a sphere on a flat at the transition, on the contact's displacement. [1]
MINDLIN_OPENING_RATIO = 2 ** (1 / 3) - 1
#: Cycles whose amplitudes differ by less than this share are at one amplitude. [1]
_SAME_AMPLITUDE = 0.01
#: Cycles where the regime changes that :func:`sliding_condition_line` names.
_CHANGES_SHOWN = 5
#: Fewest ``mindlin-stick`` cycles whose spring stands for an unknown rig's stiffness.
_SPRINGS = 3
#: Fewest cycles surely in gross slip whose GICoF stands for the sliding friction.
_SURE_CYCLES = 3
#: Q*/P within this many robust standard deviations of the sliding friction has saturated.
_SATURATED_SPREAD = 3.0
#: Q*/P within this share of the sliding friction has saturated, whatever the spread. [1]
_SATURATED_SHARE = 1e-3


def campaign_of(results) -> list:
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
    """The cycle numbers, normal load [N] and variables ``names`` [SI] of a test over its cycles;
    the forces and energies of a minority of cycles flagged ``implausible-cof`` NaN."""
    if "cycle" not in results:
        raise ValueError(
            "results: no cycle numbers (a 'cycle' coordinate or column): give the results of "
            "ecofmaps.analyze_loops or the table ecofmaps loops writes"
        )
    missing = [name for name in names if name not in results]
    if missing:
        words = ", ".join(f"'{n}' ({nomenclature.QUANTITIES[n].long_name})" for n in missing)
        raise ValueError(f"results: no {words}; give the results of ecofmaps.analyze_loops")
    values = {n: np.asarray(results[n].values, dtype=np.float64) for n in (*names, "cycle")}
    if "quality" in results:  # a force gone wild in a few cycles: not the contact's forces
        wild = has_reason(results["quality"].values, "implausible-cof")
        if wild.sum() < 0.5 * wild.size:
            for name in set(names) & {"dissipated_energy", "max_force"}:
                values[name] = np.where(wild, np.nan, values[name])
    if "normal_load" in results:
        values["load"] = np.asarray(results["normal_load"].values, dtype=np.float64)
    elif "load" in results:
        values["load"] = np.broadcast_to(float(results["load"]), values["cycle"].shape)
    elif "cof_max" in results and "max_force" in results:  # a table without the load
        values["load"] = np.asarray(results.max_force / results.cof_max, dtype=np.float64)
    else:
        raise ValueError("results: no normal load ('load', 'normal_load' or 'cof_max')")
    return values


def rig_of(tests: list, rig_stiffness):
    """``rig_stiffness``, else the one every test was analysed with (attrs), else None. [N/m]"""
    if rig_stiffness is not None:
        return rig_stiffness
    given = {test.attrs.get("rig_stiffness") for test in tests}
    return given.pop() if len(given) == 1 else None


def _spring(tests: list, rig_stiffness):
    """:func:`rig_of`, else the median spring of three ``mindlin-stick`` cycles or more. [N/m]"""
    rig_stiffness = rig_of(tests, rig_stiffness)
    if rig_stiffness is not None or not all("quality" in t and "stiffness" in t for t in tests):
        return rig_stiffness
    springs = np.concatenate(
        [t["stiffness"].values[has_reason(t["quality"].values, "mindlin-stick")] for t in tests]
    )
    return float(np.median(springs)) if springs.size >= _SPRINGS else None


def _ratios(cycles: dict, rig_stiffness):
    """The cycles' ratios, the regime's energy ratio, where they are in gross slip, and whether
    the force decided it (without S, where Q*/P reached the sliding friction: docs/lab.md)."""
    if rig_stiffness is not None:
        check("rig_stiffness", rig_stiffness, "positive_or_inf", "N/m")
    values = (cycles[n] for n in ("amplitude", "max_force", "dissipated_energy"))
    ratios = loop_ratios(*values, cycles.get("slip_amplitude", np.nan), rig_stiffness)
    ratio = regime_ratio(ratios, rig_stiffness)
    gross = ratio > MINDLIN_ENERGY_RATIO
    if rig_stiffness is not None:
        return ratios, ratio, gross, False
    cof = cycles["max_force"] / cycles["load"]
    friction = cycles.get("gicof", np.full(cof.shape, np.nan))
    sure = gross & np.isfinite(friction) & np.isfinite(cof)
    if np.count_nonzero(sure) < _SURE_CYCLES:
        return ratios, ratio, gross, False
    mu = float(np.median(friction[sure]))
    spread = 1.4826 * float(np.median(np.abs(cof[sure] - np.median(cof[sure]))))
    with np.errstate(invalid="ignore"):
        saturated = cof >= mu - max(_SATURATED_SPREAD * spread, _SATURATED_SHARE * mu)
    return ratios, ratio, gross | saturated, True


@si_units(rig_stiffness="stiffness")
def sliding_condition(results, rig_stiffness=None) -> xr.Dataset:
    r"""The energy and opening ratios of each cycle of a test, and its sliding condition.

    Gross slip where the energy ratio exceeds Mindlin's :math:`A_t = 0.2` (docs/lab.md).

    Parameters
    ----------
    results : xarray.Dataset
        One test's results from :func:`ecofmaps.analyze_loops`.
    rig_stiffness : float, optional
        The rig's own stiffness :math:`S` (not the loops' stick slope), to read the ratios on
        the contact's displacement :math:`\Delta - Q/S` too and decide the regime there; by
        default ``results.attrs["rig_stiffness"]``, else a sphere's spring, else the force
        decides (docs/lab.md, "Which S"). [N/m]

    Returns
    -------
    condition : xarray.Dataset
        Over ``cycle``: ``energy_ratio`` :math:`A`, ``opening_ratio`` :math:`B`,
        ``contact_amplitude`` [m], ``contact_energy_ratio``, ``contact_opening_ratio`` (NaN
        without :math:`S`), ``gross_slip`` (1, 0, NaN); attributes ``sliding_condition``
        (``'partial slip'``, ``'mixed slip'`` or ``'gross slip'``) and ``regime_changes_at``.

    References
    ----------
    S. Fouvry et al. (1995), Wear 185, 35-46; L. Vincent et al. (1992), ASTM STP 1159, 33-48;
    Z.R. Zhou, L. Vincent (1995), Wear 181-183, 531-536; R.D. Mindlin, H. Deresiewicz (1953),
    J. Appl. Mech. 20, 327-344 (titles in docs/lab.md).

    Examples
    --------
    >>> import ecofmaps
    >>> results = ecofmaps.analyze_loops(*ecofmaps.fretting_loop(50e-6, 450.0, 35e6, 0.8, 0), 450.0)
    >>> condition = ecofmaps.sliding_condition(results, rig_stiffness=35e6)
    >>> condition.attrs["sliding_condition"], round(float(condition.contact_energy_ratio[0]), 3)
    ('gross slip', 1.0)
    """
    (results,) = campaign_of(results)
    names = ("amplitude", "max_force", "dissipated_energy", "slip_amplitude")
    cycles = per_cycle(results, names + ("gicof",) * ("gicof" in results))
    ratios, ratio, gross, _ = _ratios(cycles, _spring([results], rig_stiffness))
    gross = np.where(np.isfinite(ratio), gross, np.nan)
    condition, changes = sliding_condition_of(cycles["cycle"], gross)
    data = {name: ("cycle", value, nomenclature.attrs(name)) for name, value in ratios.items()}
    data["gross_slip"] = ("cycle", gross, nomenclature.attrs("gross_slip"))
    attrs = {"sliding_condition": condition, "regime_changes_at": changes}
    return xr.Dataset(data, coords={"cycle": results["cycle"].values}, attrs=attrs)


def fitted_line(x, y):
    """Least-squares line ``y = a + b (x - x0)``: x0, a, b and their covariance."""
    x0 = float(np.mean(x))
    design = np.stack([np.ones_like(x), x - x0], axis=-1)
    (a, b), rss, *_ = np.linalg.lstsq(design, y, rcond=None)
    dof = x.size - 2
    scale = float(rss[0]) / dof if dof > 0 and rss.size else np.nan
    return x0, a, b, scale * np.linalg.inv(design.T @ design)


def line_root(x0, a, b, cov, level):
    """Where the line of :func:`fitted_line` reaches ``level``, and its standard error."""
    u = (level - a) / b
    variance = (cov[0, 0] + 2 * u * cov[0, 1] + u * u * cov[1, 1]) / (b * b)
    return x0 + u, float(np.sqrt(variance))


@si_units(rig_stiffness="stiffness")
def transition(results, rig_stiffness=None) -> xr.Dataset:
    r"""The transition from partial to gross slip, from an amplitude sweep or a campaign.

    The method: docs/lab.md, "The transition".

    Parameters
    ----------
    results : xarray.Dataset or list of xarray.Dataset
        :func:`ecofmaps.analyze_loops`' results of one test at amplitudes across the
        transition, or of several tests at one load and several amplitudes.
    rig_stiffness : float, optional
        As in :func:`sliding_condition`; without it ``contact_amplitude`` is NaN. [N/m]

    Returns
    -------
    transition : xarray.Dataset
        ``amplitude`` :math:`\Delta_t` [m], ``contact_amplitude``
        :math:`\delta_t = \Delta_t - \mu_t P/S` [m] and ``mu`` :math:`\mu_t = Q^*/P`, each
        with its standard error (``_se``; ``mu_se`` NaN, its ``comment`` saying why,
        without a GICoF).

    Raises
    ------
    ValueError
        When the cycles never cross the transition or are all at one amplitude.

    References
    ----------
    Those of :func:`sliding_condition`.

    Examples
    --------
    Four one-cycle tests (Δ*, Q*, E_d) on a sphere at 450 N behind 35 MN/m (Δ_t = 16.3 µm):

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
    tests = campaign_of(results)
    rig_stiffness = _spring(tests, rig_stiffness)
    names += ("gicof",) * all("gicof" in test for test in tests)
    cycles = [per_cycle(test, names) for test in tests]
    pooled = {name: np.concatenate([c[name] for c in cycles]) for name in (*names, "load")}
    _, ratio, gross, by_force = _ratios(pooled, rig_stiffness)
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
    below, above = amplitude[level == low].mean(), amplitude[level == high].mean()
    if by_force:  # where Q* reaches μP: between the two amplitudes
        at, at_se = 0.5 * (below + above), 0.0
    else:
        at, at_se = line_root(*fitted_line(amplitude[fitted], ratio[fitted]), MINDLIN_ENERGY_RATIO)
    # the crossing may lie anywhere between the two amplitudes
    at_se = float(np.hypot(np.nan_to_num(at_se), (above - below) / np.sqrt(12)))
    mu, mu_se = _sliding_friction(gross, level, split, cof, friction)
    force = float(np.mean(load[fitted])) / (np.nan if rig_stiffness is None else rig_stiffness)
    found = ((at, at_se), (at - mu * force, float(np.hypot(at_se, force * mu_se))), (mu, mu_se))
    data = {}
    for name, (value, se) in zip(nomenclature.TRANSITION, found, strict=True):
        set_with_se(data, name, value, se, quantity=f"transition_{name}")
    if not np.isfinite(friction[gross]).any():
        data["mu_se"][2]["comment"] = (  # why μ_t from Q*/P has no standard error
            "no GICoF in the results: mu is Q*/P of the first gross-slip cycles, a peak read "
            "through white noise but not through chatter or a force that rises along the stroke, "
            "by amounts the results do not hold"
        )
    return xr.Dataset(data)


def _sliding_friction(gross, level, split, cof, friction):
    """μ_t and its standard error (docs/lab.md, "The transition")."""
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

    widen = float(t.ppf(0.975, means.size - 1)) / 2.0  # ±2 se: Student's 95 % interval
    return float(np.mean(means)), float(widen * np.std(means, ddof=1) / np.sqrt(means.size))


def set_with_se(data: dict, name: str, value, se, dims=(), quantity=None) -> None:
    """Put ``name`` and ``name_se`` (its standard error) into ``data`` with their attrs."""
    attrs = nomenclature.attrs(quantity or name)
    data[name] = (dims, value, attrs)
    words = "standard error of the " + attrs["long_name"]
    data[f"{name}_se"] = (dims, se, {**attrs, "long_name": words})


def sliding_condition_line(results: xr.Dataset) -> str:
    """The sliding condition of results in words, with the first cycles where it changes."""
    condition, changes = regime_condition(results)
    changes = changes.tolist()
    if not changes:
        return condition
    shown = ", ".join(str(c) for c in changes[:_CHANGES_SHOWN])
    more = f", ... ({len(changes)} changes)" if len(changes) > _CHANGES_SHOWN else ""
    return f"{condition} (the regime changes at cycle{'s' * (len(changes) > 1)} {shown}{more})"
