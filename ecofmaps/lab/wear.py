"""Energy wear, Archard's coefficients and the closure of the loops on the scar (docs/lab.md)."""

import numpy as np
import xarray as xr

from ecofmaps import _nomenclature as nomenclature
from ecofmaps._inputs import check, si_units
from ecofmaps.lab.regime import campaign_of, fitted_line, line_root, per_cycle, rig_of, set_with_se
from ecofmaps.model.profiles import ScarProfile
from ecofmaps.model.simulation import fretting_loop


def cycle_sum(cycle, value):
    """Σ of a per-cycle ``value`` over cycles 1 to the last recorded, and its standard error."""
    kept = np.isfinite(value)
    n, v = cycle[kept], value[kept]
    if n.size == 0:
        raise ValueError("no cycle has a value to sum: every one is NaN (skipped or flagged)")
    gaps = np.diff(n)
    if np.any(gaps <= 0) or n[0] < 1:
        raise ValueError("results: the cycle numbers must be 1 or more and increasing")
    weight = np.concatenate([gaps, [0.0]]) / 2 + np.concatenate([[0.0], gaps]) / 2
    weight[[0, -1]] += 0.5  # the end cycles count whole
    weight[0] += n[0] - 1
    if n.size < 3:
        return float(weight @ v), np.nan
    left, right = gaps[:-1] / (n[2:] - n[:-2]), gaps[1:] / (n[2:] - n[:-2])
    off = v[1:-1] - (right * v[:-2] + left * v[2:])
    sigma2 = np.mean(off**2 / (1 + left**2 + right**2))
    return float(weight @ v), float(np.sqrt(sigma2 * np.sum(weight**2)))


def cumulated_energy(results) -> tuple[float, float]:
    """ΣE_d [J] of a test over cycles 1 to the last recorded, and its standard error."""
    cycles = per_cycle(results, ("dissipated_energy",))
    return cycle_sum(cycles["cycle"], cycles["dissipated_energy"])


def _worn_volume(profile: ScarProfile, length) -> tuple[float, float]:
    """Worn volume [m³] of a line of ``length``, or of a round scar (None), and its error."""
    x = np.asarray(profile.position)
    residual = np.asarray(profile.height) - profile.reference_height - profile.reference_slope * x
    width = float(profile.half_width)
    inside = np.abs(x) <= width
    if length is not None:
        weight, total, volume, scale = np.ones(x.size), 2 * width, float(profile.worn_area), length
    else:  # the volume of revolution of each side's depth, the two averaged
        edge = np.interp([-width, width], x, residual)
        at = np.concatenate([[-width], x[inside], [width]])
        depth = np.maximum(-np.concatenate([edge[:1], residual[inside], edge[1:]]), 0.0)
        weight, total, scale = np.pi * np.abs(x), np.pi * width**2, 1.0
        volume = float(np.pi * np.trapezoid(np.abs(at) * depth, at))
    shoulders = residual[np.abs(x) > 2 * width]
    if shoulders.size < 5:
        return volume * scale, np.nan
    noise = 1.4826 * np.median(np.abs(shoulders - np.median(shoulders)))
    spacing = float(np.median(np.diff(x)))
    terms = np.sum(weight[inside] ** 2) * spacing**2 + total**2 / shoulders.size
    return volume * scale, float(noise * np.sqrt(terms)) * scale


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
    return {
        "cumulated_energy": energy,
        "wear_volume": volume,
        "energy_wear_coefficient": _ratio(*volume, *energy),
        "archard_slip": _ratio(*volume, *cycle_sum(cycle, 4 * load * cycles["slip_amplitude"])),
        "archard_nominal": _ratio(*volume, *cycle_sum(cycle, 4 * load * cycles["amplitude"])),
    }


@si_units(length="length")
def energy_wear(results, profile, length=None, contact="line") -> xr.Dataset:
    r"""Energy wear of a fretting test, or of a campaign: ΣE_d, V, α and Archard's k.

    The sums, volumes and fit: docs/lab.md, "Energy wear".

    Parameters
    ----------
    results : xarray.Dataset or list of xarray.Dataset
        Each test's results from :func:`ecofmaps.analyze_loops` over its recorded cycles
        (``cycle`` numbers them as driven: a rig may record every N-th).
    profile : ScarProfile or list of ScarProfile
        Each test's levelled scar profile (:func:`ecofmaps.read_scar_profile`); of a
        sphere's, through its centre.
    length : float or list of float
        Length of the line contact; none for a sphere. [m]
    contact : {'line', 'sphere'}
        ``'line'``, :math:`V = L\int d\,dx`, or ``'sphere'``, a round scar of volume
        :math:`V = \pi\int_{-W}^{W}|x|\,d(x)\,dx` (each side turned about its axis, averaged).

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
        For results without cycles, energies or a load, a profile without a scar, a length
        not in metres (0 < L < 1 m), missing for a line or given for a sphere, or lists of
        unequal length.

    References
    ----------
    S. Fouvry et al. (1996), Wear 200, 186-205; S. Fouvry et al. (2003), Wear 255, 287-298;
    J.F. Archard (1953), J. Appl. Phys. 24, 981-988; G.B. Thomas et al. (2010), Thomas'
    Calculus, §6.2 (titles in docs/lab.md).

    Examples
    --------
    >>> import numpy as np, xarray as xr, ecofmaps
    >>> results = xr.Dataset(  # recorded every 500th cycle
    ...     {"amplitude": ("cycle", [50e-6] * 3), "slip_amplitude": ("cycle", [40e-6] * 3),
    ...      "dissipated_energy": ("cycle", [0.06] * 3)},
    ...     coords={"cycle": [1, 500, 1000], "load": 450.0})
    >>> x = np.linspace(-400e-6, 400e-6, 801)
    >>> z = np.where(np.abs(x) < 100e-6, 3e-6 * ((x / 100e-6) ** 2 - 1), 0.0)
    >>> wear = ecofmaps.energy_wear(results, ecofmaps.scar_profile(x, z), length=5e-3)
    >>> print(f"{float(wear.cumulated_energy):.0f} J, {float(wear.energy_wear_coefficient):.4g}")
    60 J, 3.333e-14
    """
    tests = campaign_of(results)
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
        set_with_se(data, name, *(values[0] if single else values.T), dims=dims)
    if not single:  # V = α(ΣE_d - E_th) fitted over the tests
        x0, a, b, cov = fitted_line(data["cumulated_energy"][1], data["wear_volume"][1])
        set_with_se(data, "campaign_energy_wear_coefficient", b, float(np.sqrt(cov[1, 1])))
        set_with_se(data, "threshold_energy", *line_root(x0, a, b, cov, 0.0))
    return xr.Dataset(data)


def _reading(results, resolved):
    """The rows of the last cycle with a GICoF, a kept loop and a reading along the stroke."""
    (results,) = campaign_of(results)
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


@si_units(rig_stiffness="stiffness")
def loop_scar_closure(results, resolved, profile, rig_stiffness=None) -> xr.Dataset:
    r"""How well a test's last loop and its loops' felt groove close on the measured scar.

    On the last cycle with a GICoF and a reading along the stroke (docs/lab.md).

    Parameters
    ----------
    results : xarray.Dataset
        One test's results of :func:`ecofmaps.analyze_loops` with ``keep_loops=True``.
    resolved : xarray.Dataset
        The same recording read along the stroke, :func:`ecofmaps.resolve_loops`.
    profile : ScarProfile
        The scar's levelled trace (:func:`ecofmaps.read_scar_profile`) [m], centred on the
        scar, which is taken to lie under the loops' centre.
    rig_stiffness : float, optional
        The rig's stiffness :math:`S` for the model's loop; by default as in
        :func:`sliding_condition`, else the one the reading along the stroke used. [N/m]

    Returns
    -------
    closure : xarray.Dataset
        ``loop_residual``: root mean square of the measured force less the model's on the
        same branch, over :math:`Q^*` [1]; ``scar_residual`` [m], ``scar_relative_residual``
        (over the depth :math:`D`) [1]: root mean square height of the implied scar less the
        profile's. The curves: ``loop_displacement``, ``loop_force`` (over ``point``) and
        ``model_displacement``, ``model_force`` (over ``model_point``) [m], [N];
        ``implied_scar`` :math:`h(\xi)`, ``scar_height`` :math:`z(\xi)` over ``position``
        :math:`\xi` [m]. Scalars ``cycle``, ``mu`` (the GICoF), ``stiffness`` [N/m].

    Raises
    ------
    ValueError
        For results without kept loops or a GICoF, a ``resolved`` not read along the stroke,
        no cycle with both, a profile without a scar or not in metres, or a
        ``rig_stiffness`` below half the loops' stick slope.

    References
    ----------
    X. Jin, W. Sun, P.H. Shipway (2016), Derivation of a wear scar geometry-independent
    coefficient of friction from fretting loops exhibiting non-Coulomb frictional
    behaviour: eq. 9, 10, 17-18, Fig. 10.
    """
    loop, reading = _reading(results, resolved)
    rig_stiffness = rig_of([loop], rig_stiffness)
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
    model_displacement, model_force = fretting_loop(
        float(loop.amplitude), load, rig_stiffness, mu, profile=profile, mapping="physical"
    )
    kept = np.isfinite(loop.loop_displacement.values) & np.isfinite(loop.loop_force.values)
    displacement, force = loop.loop_displacement.values[kept], loop.loop_force.values[kept]
    # the model's force at each point's displacement, on the branch the point moves along
    top = int(np.nanargmax(model_displacement))
    rising = np.interp(displacement, model_displacement[: top + 1], model_force[: top + 1])
    falling = np.interp(displacement, model_displacement[top:][::-1], model_force[top:][::-1])
    step = np.diff(displacement, append=displacement[-1] + (displacement[-1] - displacement[-2]))
    off = force - np.where(step >= 0, rising, falling)
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
