"""Measured scar profiles as instruments give them: spikes and dropouts, pile-up ridges,
debris and roughness beside and in the track, ambiguous edges."""

import warnings

import numpy as np
import pytest

import ecofmaps
from ecofmaps.model.profiles import (
    OUTLIER_NEIGHBOURS,
    ScarProfileWarning,
    outlying_samples,
    scar_profile,
    scar_profile_and_findings,
)
from ecofmaps.paper import AMPLITUDE, LOAD, MU, STIFFNESS

UM = 1e-6
W, D = 200 * UM, 10 * UM  # the generated scars' half-width and depth
X = np.arange(-600.0, 600.01, 1.0) * UM  # a trace every 1 µm over 1.2 mm
POINT = dict(amplitude=AMPLITUDE, load=LOAD, stiffness=STIFFNESS, mu=MU)  # Example 2's rig


def scar(kind, x=X, half_width=W, depth=D):
    """A parabolic, flat-bottomed (half of the half-width flat) or V scar in a flat surface."""
    u = np.abs(x) / half_width
    wall = {"parabola": u * u, "flat": np.clip((u - 0.5) / 0.5, 0, 1) ** 2, "V": u}[kind]
    return np.where(u < 1.0, -depth * (1.0 - wall), 0.0)


def ridges(x, inner, height, width):
    """Pile-up ridges H sin²(πv) beside |x| = inner, v = (|x| - inner)/width in (0, 1)."""
    v = (np.abs(x) - inner) / width
    return np.where((v > 0.0) & (v < 1.0), height * np.sin(np.pi * v) ** 2, 0.0)


def bump(x, at, height, sigma):
    """A Gaussian bump (debris) or, with a negative height, a valley."""
    return height * np.exp(-0.5 * ((x - at) / sigma) ** 2)


def silently(function, *args, **kwargs):
    """Call ``function``; fail on any ScarProfileWarning."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", ScarProfileWarning)
        return function(*args, **kwargs)


def noise(seed, size, sigma=0.05 * UM):
    return sigma * np.random.default_rng(seed).normal(size=size)


# --- outliers ----------------------------------------------------------------------------


@pytest.mark.parametrize("kind", ["parabola", "flat", "V"])
@pytest.mark.parametrize("seed", [None, 1, 2, 3])
def test_clean_scars_lose_no_sample(kind, seed):
    """No false positive on a parabola, a flat bottom, a V (kinks at the edges and the
    bottom), exact or with noise, nor on a step between two samples."""
    z = scar(kind) + (0.0 if seed is None else noise(seed, X.size))
    assert not outlying_samples(X, z).any()
    profile = silently(scar_profile, X, z)
    assert not np.any(np.asarray(profile.replaced))
    step = np.where(X < 0.0, 0.0, -D) + (0.0 if seed is None else noise(seed, X.size))
    assert not outlying_samples(X, step).any()


def test_no_false_positive_in_white_noise():
    """6 scaled MADs of 8 neighbours: none of 2e5 samples of white noise is an outlier."""
    rng = np.random.default_rng(20261126)
    x = np.arange(20_000.0)
    flagged = sum(int(outlying_samples(x, rng.normal(size=x.size)).sum()) for _ in range(10))
    assert flagged == 0


def test_a_quantised_trace_loses_no_sample():
    """Heights in steps of 10 nm with 3 nm noise: constant stretches (their MAD is 0) with
    one-step blips, none an outlier; a blip of 7 steps is one."""
    steps = np.round((scar("parabola") + noise(13, X.size, 3e-9)) / 1e-8)
    assert np.count_nonzero(np.diff(steps)) > 100
    assert not outlying_samples(X, steps * 1e-8).any()
    steps[300] -= 7
    assert np.flatnonzero(outlying_samples(X, steps * 1e-8)).tolist() == [300]


@pytest.mark.slow
def test_a_dropout_gives_the_depth_and_ecof_of_the_clean_scar():
    """One dropout (a spike 40 µm down) inside the scar: replaced, the depth within 0.1 %
    and the ECoF within 1e-4 of the clean scar's; kept, it moves both by far more."""
    clean_z = scar("parabola") + ridges(X, W, 2 * UM, 60 * UM) + noise(7, X.size)
    spiked_z = clean_z.copy()
    spiked_z[650] -= 40 * UM  # x = +50 µm
    clean = silently(scar_profile, X, clean_z, level=True)
    where = r": sample 650 \(x = 50 µm, 39.9 µm below its neighbours\)$"
    with pytest.warns(ScarProfileWarning, match=r"^1 outlier\(s\) .*" + where):
        spiked = scar_profile(X, spiked_z, level=True)
    assert np.flatnonzero(np.asarray(spiked.replaced)).tolist() == [650]
    assert float(spiked.depth) == pytest.approx(float(clean.depth), rel=1e-3)
    assert float(spiked.half_width) == pytest.approx(float(clean.half_width), rel=1e-3)
    ecof = [float(ecofmaps.energy_cof(**POINT, profile=p)) for p in (clean, spiked)]
    assert ecof[1] == pytest.approx(ecof[0], rel=1e-4)
    kept = silently(scar_profile, X, spiked_z, level=True, remove_outliers=False)
    assert float(kept.depth) > 1.5 * float(clean.depth)
    moved = float(ecofmaps.energy_cof(**POINT, profile=kept)) / ecof[0] - 1.0
    assert abs(moved) > 1e-2


def test_a_run_of_dropouts_and_a_spike_at_the_end_are_replaced():
    """Up to OUTLIER_NEIGHBOURS - 1 outliers in a row, and one at the trace's first sample."""
    z = scar("flat") + noise(8, X.size)
    run = [400, 401, 402][: OUTLIER_NEIGHBOURS - 1]
    z[run] -= 30 * UM
    z[0] += 25 * UM
    with pytest.warns(ScarProfileWarning, match=r"4 outlier\(s\)") as caught:
        profile = scar_profile(X, z)
    assert caught[0].message.samples == (0, *run)
    assert float(profile.depth) == pytest.approx(D, rel=0.01)


# --- pile-up ridges, debris, roughness: known truth -----------------------------------------


@pytest.mark.parametrize("kind", ["parabola", "flat", "V"])
def test_ridges_debris_roughness_with_known_truth(kind):
    """Ridges 2 µm high and 60 µm wide beside the edges, debris in the track and on a
    shoulder, roughness in the track, tilt, offset and noise: the half-width between the
    ridges within 1 %, the depth below the shoulders' line within 4 % (the roughness is 0.4
    µm), the tilt to 1e-5, and no warning (the walls run into the ridges)."""
    z = scar(kind) + ridges(X, W, 2 * UM, 60 * UM)
    z += np.where(np.abs(X) < W, 0.4 * UM * np.sin(2 * np.pi * X / (23 * UM)), 0.0)
    z += bump(X, 60 * UM, 1.5 * UM, 4 * UM) + bump(X, -450 * UM, 2 * UM, 5 * UM)
    z += 3 * UM + 0.002 * X + noise(9, X.size)
    profile = silently(scar_profile, X, z)
    assert float(profile.half_width) == pytest.approx(W, rel=0.01)
    assert float(profile.depth) == pytest.approx(D, rel=0.04)
    assert float(profile.reference_slope) == pytest.approx(0.002, abs=1e-5)
    assert np.isnan(float(profile.alternative_half_width))


def test_the_reference_line_comes_from_beyond_wide_ridges():
    """Ridges half as wide as the scar, 40 % of its depth: the shoulders at 1.5 half-widths
    would lie on them; the line from beyond them gives the depth and the tilt."""
    z = scar("parabola") + ridges(X, W, 4 * UM, 150 * UM) + 0.001 * X + noise(10, X.size)
    profile = silently(scar_profile, X, z)
    assert float(profile.half_width) == pytest.approx(W, rel=0.005)
    assert float(profile.depth) == pytest.approx(D, rel=0.005)
    assert float(profile.reference_slope) == pytest.approx(0.001, abs=2e-5)


# --- the two tracks of the issue ---------------------------------------------------------

XI = np.arange(-400.0, 400.01, 0.5) * UM  # every 0.5 µm


def rough_band_track():
    """A disturbed band 200 µm wide (0.6 µm above the surface, rough) between ridges 25 µm
    wide cresting at ±112.5 µm, with one roughness valley 1.8 µm deep inside it: read before
    as a 6.5 µm half-width."""
    waves = ((0.25, 17.0, 0.3), (0.2, 9.3, 1.1), (0.15, 31.0, 2.0))
    rough = sum(a * np.sin(2 * np.pi * XI / (wave * UM) + p) for a, wave, p in waves)
    z = np.where(np.abs(XI) < 100 * UM, (0.6 + rough) * UM, 0.0)
    z += ridges(XI, 100 * UM, 1.2 * UM, 25 * UM) + bump(XI, 30 * UM, -1.8 * UM, 4 * UM)
    return z + noise(11, XI.size, 0.02 * UM)


def groove_in_band_track():
    """A groove 31 µm in half-width, 3 µm deep, in a band 170 µm wide between the crests of
    ridges 30 µm wide, its floor rough and 0.35 µm above the surface out to the ridges, with
    debris: read before as 31 µm."""
    z = np.where(np.abs(XI) < 31 * UM, -3 * UM * (1 - (XI / (31 * UM)) ** 2), 0.0)
    floor = (np.abs(XI) >= 31 * UM) & (np.abs(XI) < 70 * UM)
    rough = 0.15 * np.sin(2 * np.pi * XI / (11 * UM)) + 0.1 * np.sin(2 * np.pi * XI / (4.3 * UM))
    z += np.where(floor, (0.35 + rough) * UM, 0.0) + ridges(XI, 70 * UM, 1.5 * UM, 30 * UM)
    z += bump(XI, 55 * UM, 0.8 * UM, 2.5 * UM) + bump(XI, -62 * UM, 0.6 * UM, 2 * UM)
    return z + noise(12, XI.size, 0.02 * UM)


@pytest.mark.parametrize(
    ("track", "band", "groove", "groove_centre"),
    [(rough_band_track, 112.5, 6.0, 29.5), (groove_in_band_track, 85.0, 31.0, 0.0)],
    ids=["rough band, one valley", "groove in a band between ridges"],
)
def test_ambiguous_edges_take_the_band_and_warn_with_both(track, band, groove, groove_centre):
    """The band between the ridges' crests is taken (within 1 µm), never silently the
    groove; the warning gives both half-widths, says which was returned and how to take the
    other; half_width= takes the groove, centred on it."""
    z = track()
    with pytest.warns(ScarProfileWarning, match="ambiguous scar edges") as caught:
        profile = scar_profile(XI, z)
    assert float(profile.half_width) == pytest.approx(band * UM, abs=1 * UM)
    alternative = float(profile.alternative_half_width)
    assert alternative == pytest.approx(groove * UM, abs=1 * UM)
    message = str(caught[0].message)
    taken = float(profile.half_width) * 1e6
    assert (
        f"half-width {taken:.6g} µm for the band between its pile-up ridges' crests "
        "(returned; edges at x = " in message
    )
    assert message.count("µm high)") == 2
    assert (
        f"or {alternative * 1e6:.6g} µm for the groove below the unworn surface's line "
        "(edges at x = " in message
    )
    assert message.endswith(f"; half_width={alternative:.6g} (m) takes the groove")
    assert caught[0].message.alternative == alternative
    chosen = silently(scar_profile, XI, z, half_width=alternative)
    assert float(chosen.centre) == pytest.approx(groove_centre * UM, abs=1 * UM)
    assert np.isnan(float(chosen.alternative_half_width))


def test_debris_beside_one_edge_keeps_the_groove_and_warns_with_the_band():
    """Debris 1.5 µm high just beyond the right ridge (whose flank runs into the groove's
    wall): the band reaches beyond the groove on that side only, to the debris's crest, so
    the groove is taken (within 0.5 %) and the warning offers the band."""
    z = scar("parabola") + ridges(X, W, 2 * UM, 60 * UM) + bump(X, 290 * UM, 1.5 * UM, 4 * UM)
    z += noise(14, X.size)
    with pytest.warns(ScarProfileWarning, match="the disturbed band on its right") as caught:
        profile = scar_profile(X, z)
    assert float(profile.half_width) == pytest.approx(W, rel=5e-3)
    alternative = float(profile.alternative_half_width)
    assert alternative == pytest.approx(0.5 * (290 + 200) * UM, abs=2 * UM)
    message = caught[0].message
    assert (message.alternative, message.alternative_name) == (alternative, "band")
    assert str(message).endswith(f"half_width={alternative:.6g} (m) takes the band")


# --- ridges of any shape (Gaussian, sin², triangular, asymmetric) ---------------------------


def gaussian_ridges(x, crest, height, width):
    """Pile-up ridges H exp(-((|x| - crest)/width)²) with their crests at |x| = crest."""
    return height * np.exp(-(((np.abs(x) - crest) / width) ** 2))


def shaped_ridges(x, shape, crest, height):
    """Ridges 1.5 µm (``height``) high cresting at |x| = crest, of the given shape."""
    d = np.abs(x) - crest
    if shape == "gaussian":
        return gaussian_ridges(x, crest, height, 12 * UM)
    if shape == "sin2":
        return ridges(x, crest - 15 * UM, height, 30 * UM)
    if shape == "triangular":
        return height * np.clip(1 - np.abs(d) / (15 * UM), 0, None)
    # asymmetric: a steep inner flank (6 µm), a long outer one (30 µm)
    return height * np.where(d < 0, np.clip(1 + d / (6 * UM), 0, None),
                             np.clip(1 - d / (30 * UM), 0, None))  # fmt: skip


def groove_between_ridges(shape, floor, sigma, seed, crest=85 * UM):
    """The acceptance track: a groove 31 µm in half-width and 3 µm deep, its floor out to
    the ridges ``floor`` above the surface, ridges 1.5 µm high at ±85 µm, noise ``sigma``."""
    z = np.where(np.abs(XI) < 31 * UM, -3 * UM * (1 - (XI / (31 * UM)) ** 2), 0.0)
    z += np.where((np.abs(XI) >= 31 * UM) & (np.abs(XI) < crest), floor, 0.0)
    return z + shaped_ridges(XI, shape, crest, 1.5 * UM) + noise(seed, XI.size, sigma)


@pytest.mark.parametrize("shape", ["gaussian", "sin2", "triangular", "asymmetric"])
@pytest.mark.parametrize(
    ("floor", "sigma", "tolerance"),
    [(0.0, 0.02, 2.0), (0.15, 0.02, 2.0), (0.35, 0.02, 2.0), (0.35, 0.1, 4.0)],
    ids=["floor 0", "floor 0.15", "floor 0.35", "floor 0.35, noise 0.1"],
)
def test_a_groove_between_ridges_of_any_shape_warns_with_both(shape, floor, sigma, tolerance):
    """Ridges of any shape cresting at ±85 µm beyond a floor (quiet or raised) around a
    groove 31 µm in half-width: never silently the groove. The band between the crests is
    taken, each edge within 2 µm of its crest (4 µm with noise 0.1 µm, where a ridge's top
    is level to within the noise over several µm), and the groove offered within 1 µm."""
    z = groove_between_ridges(shape, floor * UM, sigma * UM, seed=21)
    with pytest.warns(ScarProfileWarning, match="ambiguous scar edges") as caught:
        profile = scar_profile(XI, z)
    np.testing.assert_allclose(profile.edges, [-85 * UM, 85 * UM], rtol=0, atol=tolerance * UM)
    assert float(profile.alternative_half_width) == pytest.approx(31 * UM, abs=1 * UM)
    assert "the band between its pile-up ridges' crests (returned" in str(caught[0].message)


def test_a_wide_band_with_debris_between_gaussian_ridges_warns_with_both():
    """The acceptance track: a band 200 µm wide, wavy (debris) and rough (0.2 µm), Gaussian
    ridges 4 µm high cresting at ±120 µm, a roughness valley inside: read before as a 32.7
    µm half-width, silently. The band between the crests is taken (each edge within 2 µm
    of its crest) and the valley's groove offered."""
    rng = np.random.default_rng(1)
    x = np.arange(-600.0, 600.0, 0.5) * UM
    z = rng.normal(0, 0.2 * UM, x.size) + gaussian_ridges(x, 120 * UM, 4 * UM, 15 * UM)
    inside = np.abs(x) < 100 * UM
    z[inside] += UM * np.sin(x[inside] / (100 * UM) * 7) - 0.5 * UM
    z[np.abs(x - 10 * UM) < 4 * UM] -= 2 * UM
    with pytest.warns(ScarProfileWarning, match="ambiguous scar edges") as caught:
        profile = scar_profile(x, z)
    np.testing.assert_allclose(profile.edges, [-120 * UM, 120 * UM], rtol=0, atol=2 * UM)
    assert float(profile.alternative_half_width) < 50 * UM
    assert "the band between its pile-up ridges' crests" in str(caught[0].message)


@pytest.mark.parametrize(
    "family",
    [
        lambda: ecofmaps.parabolic_profile(D, W),
        lambda: ecofmaps.flat_bottomed_profile(D, W, 0.5),
        lambda: ecofmaps.w_shaped_profile(D, W, 0.3),
        lambda: ecofmaps.ridged_profile(D, W, 2 * UM, 20 * UM),
        lambda: ecofmaps.ridged_profile(10 * UM, 40 * UM, 4 * UM, 30 * UM, extent=3.0),
    ],
    ids=["parabolic", "flat", "w", "ridged", "ridged, high"],
)
@pytest.mark.parametrize("seed", [None, 15])
def test_the_families_read_back_without_a_warning(family, seed):
    """The analytic families, exact or with noise, read back silently with their half-width
    (within 1 %): ridges whose walls run into the groove are not a band."""
    profile = family()
    x, z = np.asarray(profile.position), np.asarray(profile.height)
    z = z + (0.0 if seed is None else noise(seed, x.size, 1e-3 * float(profile.depth)))
    read = silently(scar_profile, x, z)
    assert float(read.half_width) == pytest.approx(float(profile.half_width), rel=0.01)
    assert np.isnan(float(read.alternative_half_width))


def test_two_asperities_beyond_a_quiet_floor_are_not_ridges():
    """Two narrow asperities (1 µm wide, 0.8 and 1 µm high) at -95 and +80 µm beside a
    groove 31 µm in half-width on a quiet surface: not a pair of ridges, no warning, the
    half-width that of the groove without them (to 0.1 %)."""
    plain = np.where(np.abs(XI) < 31 * UM, -3 * UM * (1 - (XI / (31 * UM)) ** 2), 0.0)
    plain += noise(21, XI.size, 0.02 * UM)
    z = plain + bump(XI, 80 * UM, 1.0 * UM, 1 * UM) + bump(XI, -95 * UM, 0.8 * UM, 1 * UM)
    profile = silently(scar_profile, XI, z)
    expected = float(silently(scar_profile, XI, plain).half_width)
    assert float(profile.half_width) == pytest.approx(expected, rel=1e-3)
    assert expected == pytest.approx(31 * UM, abs=1 * UM)


# --- narrow ridges and asperities -------------------------------------------------------


def narrow_ridges(x, shape, width, crest=85 * UM, height=1.5 * UM):
    """Pile-up ridges cresting at |x| = crest, ``width`` wide at half their height, of the
    given shape (the asymmetric one's inner flank a fifth as long as its outer one)."""
    d = np.abs(x) - crest
    if shape == "gaussian":
        return height * np.exp(-4 * np.log(2) * (d / width) ** 2)
    if shape == "sin2":
        v = 0.5 + 0.5 * d / width
        return np.where((v > 0) & (v < 1), height * np.sin(np.pi * v) ** 2, 0.0)
    if shape == "triangular":
        return height * np.clip(1 - np.abs(d) / width, 0, None)
    inner, outer = width / 3, 5 * width / 3
    return height * np.where(d < 0, np.clip(1 + d / inner, 0, None),
                             np.clip(1 - d / outer, 0, None))  # fmt: skip


def groove(x=XI):
    """A groove 31 µm in half-width and 3 µm deep, in a flat surface."""
    return np.where(np.abs(x) < 31 * UM, -3 * UM * (1 - (x / (31 * UM)) ** 2), 0.0)


@pytest.mark.parametrize("shape", ["gaussian", "sin2", "triangular", "asymmetric"])
@pytest.mark.parametrize("fraction", [4, 6, 8, 10])
@pytest.mark.parametrize("sigma", [0.02, 0.1])
def test_narrow_ridges_beyond_a_quiet_floor_are_a_pair(shape, fraction, sigma):
    """Ridges 1.5 µm high cresting at ±85 µm, a quarter down to a tenth of the groove's
    half-width wide (at half their height: 7.8 to 3.1 µm, 16 to 6 samples), beyond a quiet
    floor: recognised as a pair, the band between their crests taken (each edge within 2
    µm of its crest) and the groove offered."""
    z = groove() + narrow_ridges(XI, shape, 31 * UM / fraction) + noise(31, XI.size, sigma * UM)
    with pytest.warns(ScarProfileWarning, match="ambiguous scar edges") as caught:
        profile = scar_profile(XI, z)
    np.testing.assert_allclose(profile.edges, [-85 * UM, 85 * UM], rtol=0, atol=2 * UM)
    assert float(profile.alternative_half_width) == pytest.approx(31 * UM, abs=1.5 * UM)
    assert "the band between its pile-up ridges' crests (returned" in str(caught[0].message)


@pytest.mark.parametrize(
    ("left", "right", "sigma"),
    [
        ((0.0, 3.9), (1.5, 3.9), 0.02),  # one ridge alone
        ((1.5, 3.9), (1.5, 2.0), 0.02),  # not alike: widths 3.9 and 2 µm
        ((1.5, 3.9), (0.8, 3.9), 0.02),  # not alike: heights 1.5 and 0.8 µm
        ((0.4, 3.9), (0.4, 3.9), 0.1),  # not clearly above the noise (0.1 µm)
        ((0.1, 3.9), (0.1, 3.9), 0.002),  # lower than twice 2 % of the groove's depth
    ],
    ids=["one alone", "widths", "heights", "low", "shallow"],
)
def test_narrow_bumps_that_are_not_a_pair_of_ridges_are_not_seen(left, right, sigma):
    """Narrow Gaussian bumps at ±85 µm beyond a quiet floor that are not alike, or one of
    them alone, or not clearly above the shoulders (lower than twice the band's threshold,
    the larger of 5 times the shoulders' noise and 2 % of the depth, or too few samples
    above it): no warning, the groove's half-width (as without them, to 0.1 %)."""
    plain = groove() + noise(33, XI.size, sigma * UM)
    z = plain.copy()
    for (height, width), sign in zip((left, right), (-1, 1), strict=True):
        z += height * UM * np.exp(-4 * np.log(2) * ((XI - sign * 85 * UM) / (width * UM)) ** 2)
    profile = silently(scar_profile, XI, z)
    expected = float(silently(scar_profile, XI, plain).half_width)
    assert float(profile.half_width) == pytest.approx(expected, rel=1e-3)


def test_narrow_ridges_among_asperities_of_their_height_are_not_seen():
    """The narrow pair of an eighth of the groove's half-width, but the shoulders also carry
    asperities as high: the ridges are not the outstanding features of their sides, so no
    pair is seen (no warning)."""
    z = groove() + narrow_ridges(XI, "gaussian", 31 * UM / 8) + noise(34, XI.size)
    z += bump(XI, -240 * UM, 1.2 * UM, 1.5 * UM) + bump(XI, 300 * UM, 1.0 * UM, 1.5 * UM)
    profile = silently(scar_profile, XI, z)
    assert float(profile.half_width) < 40 * UM


def rough_shoulders_with_asperities(seed):
    """The groove in a randomly rough surface (0.05 µm, correlated over about 2 µm) with 1
    to 4 isolated asperities on each side (0.3 to 1.5 µm high, 1.2 to 5.9 µm wide at half
    their height) anywhere from 50 to 380 µm from its centre."""
    rng = np.random.default_rng(seed)
    kernel = np.exp(-0.5 * (np.arange(-20, 21) * 0.5 / 2.0) ** 2)
    rough = np.convolve(rng.normal(size=XI.size), kernel / np.linalg.norm(kernel), "same")
    z = groove() + 0.05 * UM * rough
    for sign in (-1, 1):
        for _ in range(rng.integers(1, 5)):
            at, height, sigma = rng.uniform(50, 380), rng.uniform(0.3, 1.5), rng.uniform(0.5, 2.5)
            z += bump(XI, sign * at * UM, height * UM, sigma * UM)
    return z


def test_isolated_asperities_on_rough_shoulders_are_not_ridges():
    """Rough shoulders with isolated asperities, 60 random surfaces: no pair of ridges is
    seen (no warning names pile-up ridges)."""
    for seed in range(60):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", ScarProfileWarning)
            scar_profile(XI, rough_shoulders_with_asperities(seed))
        assert not [w for w in caught if "pile-up ridge" in str(w.message)], seed


def test_a_groove_in_rough_shoulders_keeps_its_edges():
    """A groove 31 µm in half-width, 3 µm deep, in a surface rough by 0.05 µm (correlated
    over about 2 µm) with asperities, 60 random surfaces: the edges are where the wall
    reaches the unworn surface to within the roughness, the half-width within 1 µm (RMS
    0.3 µm). Read before at the first sample back at or above the line, beyond the valleys
    next to the groove: 110 of 200 surfaces were off by more than 2 µm, up to 21 µm, with
    no warning."""
    widths = []
    for seed in range(60):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", ScarProfileWarning)
            profile = scar_profile(XI, rough_shoulders_with_asperities(seed))
        widths.append(float(profile.half_width) / UM)
    errors = np.array(widths) - 31.0
    assert np.max(np.abs(errors)) < 1.0, widths
    assert np.sqrt(np.mean(errors**2)) < 0.45


def test_correlated_roughness_is_no_outlier_and_a_dropout_in_it_is():
    """A surface rough by 0.02 µm, correlated over about one sample (0.5 µm), 40 random
    surfaces: no sample is an outlier (before, the stretches where a sample's neighbours
    happened to lie close together made 79 of 100 such surfaces warn of outliers). A
    dropout of 0.5 µm in it is still found, and only it."""
    for seed in range(40):
        rng = np.random.default_rng(seed)
        kernel = np.exp(-0.5 * np.arange(-20, 21) ** 2)
        rough = np.convolve(rng.normal(size=XI.size), kernel / np.linalg.norm(kernel), "same")
        z = groove() + 0.02 * UM * rough
        assert not outlying_samples(XI, z).any(), seed
        z[1200] -= 0.5 * UM
        assert np.flatnonzero(outlying_samples(XI, z)).tolist() == [1200], seed


def test_a_stylus_export_of_a_wide_band_with_a_valley_offers_the_band(tmp_path):
    """The acceptance test's export of the band with debris between Gaussian ridges (x in
    mm to 10 nm, heights in mm to 0.1 µm, quoted decimal commas): the groove below the line
    is the roughness valley alone, 4.4 µm in half-width, and its pile-up ridges lie beyond 5
    of its half-widths but within a quarter of the trace's span. The band between the
    crests is returned with a warning (read before as a trace sampled too sparsely: "only
    17 samples across the scar")."""
    rng = np.random.default_rng(1)
    x = np.arange(-0.6, 0.6, 0.0005)  # mm
    z = rng.normal(0, 0.0002, x.size) + 0.004 * np.exp(-(((np.abs(x) - 0.12) / 0.015) ** 2))
    inside = np.abs(x) < 0.1
    z[inside] += 0.001 * np.sin(x[inside] / 0.1 * 7) - 0.0005
    z[np.abs(x - 0.01) < 0.004] -= 0.002
    rows = "".join(f'"{a:.5f}","{b:.4f}"\n'.replace(".", ",") for a, b in zip(x, z, strict=True))
    path = tmp_path / "ridges.csv"
    path.write_text('"Distance","Profile"\n' + rows, encoding="utf-8")
    with pytest.warns(ScarProfileWarning, match="ambiguous scar edges") as caught:
        profile = ecofmaps.read_scar_profile(
            path, x_column="Distance", z_column="Profile", x_unit="mm", z_unit="mm"
        )
    np.testing.assert_allclose(profile.edges, [-120 * UM, 120 * UM], rtol=0, atol=2 * UM)
    assert float(profile.alternative_half_width) < 10 * UM
    assert "the band between its pile-up ridges' crests (returned" in str(caught[-1].message)


def rough_groove(roughness, correlation, seed):
    """The groove of :func:`groove` in a surface rough by ``roughness`` µm (standard
    deviation), correlated over ``correlation`` µm (Gaussian), from ``seed``."""
    rng = np.random.default_rng(seed)
    kernel = np.exp(-0.5 * (np.arange(-20, 21) * 0.5 / correlation) ** 2)
    rough = np.convolve(rng.normal(size=XI.size), kernel / np.linalg.norm(kernel), "same")
    return groove() + roughness * UM * rough


@pytest.mark.parametrize(
    ("roughness", "correlation", "fewest_warned"),
    [(0.05, 0.5, 0), (0.1, 0.5, 30), (0.2, 2.0, 80)],
)
def test_edges_on_rough_surfaces_are_right_or_said_to_be_uncertain(
    roughness, correlation, fewest_warned
):
    """The groove of 31 µm half-width, 3 µm deep, on 100 random surfaces rough by 2 % to 7 %
    of its depth: every half-width returned without a warning is within 10 % (3.1 µm) of the
    truth, each edge within 4.5 µm. Where reading the edges within 3 times the roughness of
    the surface's line moves one by more than 5 % of the half-width, a warning gives both
    half-widths, and ``alternative_half_width`` holds the other. Before, at 7 % roughness,
    31 surfaces were off by more than 2 µm (up to 22 µm) without a warning; at 2 %, a wall
    line fitted over too short a stretch put 2 edges more than 5 µm out."""
    warned = 0
    for seed in range(100):
        profile, findings = scar_profile_and_findings(
            XI, rough_groove(roughness, correlation, seed)
        )
        width = float(profile.half_width) / UM
        edges = float(profile.centre) / UM + np.array([-width, width])
        if not findings:
            assert abs(width - 31.0) < 3.1, (seed, width)
            assert np.all(np.abs(edges - [-31.0, 31.0]) < 4.5), (seed, edges)
            assert np.isnan(float(profile.alternative_half_width))
            continue
        warned += 1
        (finding,) = findings
        other = float(profile.alternative_half_width)
        assert finding.summary.startswith("uncertain groove edges on a rough surface")
        assert finding.alternative == other
        assert f"{width:.6g} µm (returned" in finding.summary
        assert f"or {other / UM:.6g} µm" in finding.summary
    assert warned >= fewest_warned


# --- the errors of a trace that cannot be read, in numbers for people -----------------------


def acceptance_rough_groove():
    """The groove of :func:`groove` in a surface rough by 5 % of its depth, correlated over
    10 µm, whose roughness was read as a scar 227 µm in half-width (an acceptance run)."""
    kernel = np.exp(-0.5 * (np.arange(-80, 81) * 0.5 / 10.0) ** 2)
    rough = np.convolve(np.random.default_rng(53).normal(size=XI.size),
                        kernel / np.linalg.norm(kernel), "same")  # fmt: skip
    return groove() + 0.05 * 3.0 * UM * rough / rough.std()


def test_too_wide_a_scar_is_said_in_micrometres_with_the_remedies():
    """The detected scar leaves too little unworn surface: what was detected, in µm, and
    what to do (give the half-width, or a longer trace)."""
    with pytest.raises(ValueError, match="too short for levelling") as error:
        scar_profile(XI, acceptance_rough_groove())
    message = str(error.value)
    assert "np.float64" not in message and "e-0" not in message
    assert "the detected scar is centred at x = 164.3 µm with a half-width of 226.8 µm" in message
    assert "(57% of the trace, which spans -400 µm to 400 µm)" in message
    assert "half_width= (on the command line --profile-half-width)" in message
    assert message.endswith("else give a longer trace")
    profile = scar_profile(XI, acceptance_rough_groove(), half_width=31 * UM)  # the remedy
    assert float(profile.half_width) == 31 * UM


def test_a_given_half_width_that_leaves_no_unworn_surface_is_said_in_micrometres():
    with pytest.raises(ValueError, match="too short for levelling") as error:
        scar_profile(XI, groove(), half_width=np.float64(395 * UM))
    message = str(error.value)
    assert "np.float64" not in message
    assert "the given scar is centred at x = 0 µm with a half-width of 395 µm" in message
    assert message.endswith(": give a longer trace or a smaller half_width")


def test_a_half_width_beyond_the_trace_is_said_in_micrometres():
    with pytest.raises(ValueError, match=r"half_width = 0\.00045 m does not fit") as error:
        scar_profile(XI, groove(), half_width=np.float64(450 * UM))
    assert str(error.value).endswith(
        "450 µm either side of the scar centre at x = 0 µm reaches beyond the trace, "
        "which spans -400 µm to 400 µm"
    )


def test_no_depression_is_said_in_micrometres():
    flat = 1e-9 * np.random.default_rng(0).normal(size=XI.size)
    with pytest.raises(ValueError, match="z: no depression found") as error:
        scar_profile(XI, flat)
    message = str(error.value)
    assert "np.float64" not in message and " m " not in message
    assert message.count(" µm") == 3  # depth, noise and relief
