"""Scar profiles: the analytic families, measured traces (edges, levelling, smoothing), errors."""

import subprocess
import sys

import jax
import jax.numpy as jnp
import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

import ecofmaps
from ecofmaps.model.profiles import local_quadratic

D, W = 10e-6, 50e-6  # the paper's groove at D/W = 0.2 (Figure 5)


def parabola_trace(samples, extent=1.5, depth=D, half_width=W):
    """A parabolic scar cut into a flat surface, as arrays (no sample at the edges)."""
    x = np.linspace(-extent * half_width, extent * half_width, samples)
    z = np.where(np.abs(x) < half_width, depth * ((x / half_width) ** 2 - 1.0), 0.0)
    return x, z


# --- analytic families ------------------------------------------------------------------


@pytest.mark.parametrize(
    "profile",
    [
        ecofmaps.parabolic_profile(D, W),
        ecofmaps.flat_bottomed_profile(D, W, 0.5),
        ecofmaps.w_shaped_profile(D, W, 0.3),
        ecofmaps.ridged_profile(D, W, 2e-6, 20e-6),
    ],
    ids=["parabolic", "flat", "w", "ridged"],
)
def test_families_have_the_depth_and_half_width_they_are_built_with(profile):
    """D and W as given, the deepest point at depth D, edges at ±W, slopes = dz/dX."""
    assert float(profile.depth) == D and float(profile.half_width) == W
    assert float(profile.aspect_ratio) == pytest.approx(0.2, rel=1e-15)
    x, z, g = (np.asarray(a) for a in (profile.position, profile.height, profile.slope))
    assert x.size == 2001 and np.all(np.diff(x) > 0)
    assert np.min(z) == pytest.approx(-D, rel=1e-12)
    inside = np.abs(x) < W
    assert np.all(z[inside] < 0) and np.all(z[~inside] >= 0)
    assert set(np.round(np.asarray(profile.edges) / W, 12)) == {-1.0, 1.0}
    # the slope is the derivative of the height: the trapezoid rule on g gives the height
    # steps to O(h^3) away from the kinks (the edges, where the slope jumps)
    step = np.diff(x)
    smooth = np.abs(np.diff(g)) < 0.05
    trapezoid = step * 0.5 * (g[:-1] + g[1:])
    np.testing.assert_allclose(np.diff(z)[smooth], trapezoid[smooth], rtol=0, atol=1e-6 * D)


def test_family_worn_areas():
    """Worn area: 4DW/3 for the parabola, D(2a + 4(W - a)/3) for the flat bottom."""
    assert float(ecofmaps.parabolic_profile(D, W).worn_area) == pytest.approx(
        4 * D * W / 3, rel=1e-5
    )
    a = 0.5 * W
    flat = ecofmaps.flat_bottomed_profile(D, W, 0.5)
    assert float(flat.worn_area) == pytest.approx(D * (2 * a + 4 * (W - a) / 3), rel=1e-5)


def test_w_shape_hump_and_ridges():
    """The W shape's hump is h*D above its troughs; the ridges are H high at W + w/2."""
    w = ecofmaps.w_shaped_profile(D, W, 0.25)
    z, x = np.asarray(w.height), np.asarray(w.position)
    assert z[np.argmin(np.abs(x))] == pytest.approx(-D + 0.25 * D, rel=1e-12)
    r = ecofmaps.ridged_profile(D, W, 2e-6, 20e-6)
    crest = np.argmin(np.abs(np.asarray(r.position) - (W + 10e-6)))
    assert float(r.height[crest]) == pytest.approx(2e-6, rel=1e-12)


def test_tilt_adds_to_slopes_and_heights_only():
    """A tilted family: slope + t, height + tX, the same D, W and area; reference tilt t."""
    flat, tilted = ecofmaps.parabolic_profile(D, W), ecofmaps.parabolic_profile(D, W, tilt=0.05)
    np.testing.assert_allclose(tilted.slope, flat.slope + 0.05, rtol=0, atol=1e-16)
    np.testing.assert_allclose(tilted.height, flat.height + 0.05 * flat.position, atol=1e-20)
    assert float(tilted.depth) == D and float(tilted.reference_slope) == 0.05


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda: ecofmaps.parabolic_profile(-1e-6, W), "depth must be finite and > 0"),
        (lambda: ecofmaps.parabolic_profile(D, np.nan), "half_width must be finite"),
        (lambda: ecofmaps.parabolic_profile(D, W, samples=10), "samples must be an integer"),
        (lambda: ecofmaps.parabolic_profile(D, W, extent=1.0), "extent must be finite and > 1"),
        (lambda: ecofmaps.parabolic_profile(D, W, tilt=np.inf), "tilt must be finite"),
        (lambda: ecofmaps.flat_bottomed_profile(D, W, 1.0), "flat_fraction must satisfy"),
        (lambda: ecofmaps.w_shaped_profile(D, W, -0.1), "hump must satisfy"),
        (lambda: ecofmaps.ridged_profile(D, W, 0.0, 1e-6), "ridge_height must be finite"),
        (lambda: ecofmaps.ridged_profile(D, W, 1e-6, 60e-6), "extent must be finite and > 2.2"),
    ],
)
def test_family_bad_parameters(call, message):
    with pytest.raises(ValueError, match=message):
        call()


# --- measured traces ----------------------------------------------------------------------


def test_parabola_from_arrays_exact_without_smoothing():
    """No smoothing: edges from the wall's straight extension (second order), slopes exact."""
    x, z = parabola_trace(4000)
    p = ecofmaps.scar_profile(x, z, smoothing=0)
    assert float(p.half_width) == pytest.approx(W, rel=1e-6)
    assert float(p.depth) == pytest.approx(D, rel=1e-6)
    assert float(p.centre) == pytest.approx(0.0, abs=1e-12)
    inside = np.abs(x) < 0.99 * W
    np.testing.assert_allclose(np.asarray(p.slope)[inside], 2 * D * x[inside] / W**2, atol=1e-12)


def test_parabola_from_arrays_default_smoothing():
    """The default smoothing (2 % of W) keeps a parabola's slope (quadratics are exact)."""
    x, z = parabola_trace(4000)
    p = ecofmaps.scar_profile(x, z)
    assert float(p.half_width) == pytest.approx(W, rel=5e-4)  # the edge kink, lightly smoothed
    inside = np.abs(x) < 0.9 * W
    np.testing.assert_allclose(np.asarray(p.slope)[inside], 2 * D * x[inside] / W**2, atol=1e-11)


@pytest.mark.parametrize("level", [True, False])
def test_noisy_tilted_offset_trace(level):
    """Noise, tilt and offset: the edges, depth and tilt are found; levelling removes the line."""
    rng = np.random.default_rng(1)
    x, z = parabola_trace(3001, extent=2.0)
    x = x + 300e-6  # a profilometer's own coordinates
    raw = z + 0.02 * x + 5e-6 + 20e-9 * rng.normal(size=x.size)
    p = ecofmaps.scar_profile(x, raw, level=level)
    assert float(p.centre) == pytest.approx(300e-6, abs=0.2e-6)
    assert float(p.half_width) == pytest.approx(W, rel=3e-3)
    assert float(p.depth) == pytest.approx(D, rel=3e-3)
    tilt = 0.0 if level else 0.02
    assert float(p.reference_slope) == pytest.approx(tilt, abs=1e-4)
    position = np.asarray(p.position) + float(p.centre) - 300e-6  # the scar's own frame
    inside = np.abs(position) < 0.8 * W
    error = np.asarray(p.slope)[inside] - (2 * D * position[inside] / W**2 + tilt)
    # 20 nm of noise on samples 67 nm apart, smoothed over 1 um: slopes to about 0.5 % of
    # the largest (0.4), without bias
    assert np.sqrt(np.mean(error**2)) < 2e-3 and np.max(np.abs(error)) < 1e-2
    assert abs(np.mean(error)) < 3e-4
    if level:
        assert (
            abs(np.median(np.asarray(p.height)[~(np.abs(np.asarray(p.position)) < 1.5 * W)])) < 1e-8
        )


def test_half_width_override():
    x, z = parabola_trace(2000)
    p = ecofmaps.scar_profile(x, z, half_width=45e-6, smoothing=0)
    assert float(p.half_width) == 45e-6 and float(p.centre) == pytest.approx(0.0, abs=1e-12)


def test_local_quadratic_reproduces_quadratics_on_uneven_samples():
    """The smoothing's local fits are exact for quadratics, whatever the spacing."""
    rng = np.random.default_rng(3)
    x = np.sort(rng.uniform(0, 1e-3, 500))
    z = 3.0 * x**2 - 2e-3 * x + 1e-6
    height, slope = local_quadratic(x, z, 2e-5)
    np.testing.assert_allclose(height, z, rtol=0, atol=1e-15)
    np.testing.assert_allclose(slope, 6.0 * x - 2e-3, rtol=0, atol=1e-11)


@given(
    depth=st.floats(1e-7, 1e-4),
    half_width=st.floats(1e-5, 2e-3),
    tilt=st.floats(-0.05, 0.05),
    offset=st.floats(-1e-4, 1e-4),
    fraction=st.floats(0.0, 0.8),
)
def test_levelled_family_recovered_from_its_trace(depth, half_width, tilt, offset, fraction):
    """Any flat-bottomed scar, tilted and offset: scar_profile(level=True) finds D and W."""
    family = ecofmaps.flat_bottomed_profile(depth, half_width, fraction, samples=1001)
    x = np.asarray(family.position)
    z = np.asarray(family.height) + tilt * x + offset
    p = ecofmaps.scar_profile(x, z, smoothing=0, level=True)
    assert float(p.half_width) == pytest.approx(half_width, rel=1e-6)
    assert float(p.depth) == pytest.approx(depth, rel=1e-6)
    assert float(p.reference_slope) == 0.0
    np.testing.assert_allclose(p.height, family.height, rtol=0, atol=1e-9 * depth + 1e-18)


def test_a_batch_of_profiles_stacks_and_vmaps():
    """Profiles of one sample count stack into a pytree batch that jax.vmap maps over."""
    profiles = [ecofmaps.parabolic_profile(d, W, samples=1000) for d in (5e-6, 10e-6)]
    batch = jax.tree.map(lambda *leaves: jnp.stack(leaves), *profiles)
    assert batch.position.shape == (2, 1000)
    np.testing.assert_allclose(jax.vmap(lambda p: p.aspect_ratio)(batch), [0.1, 0.2])


# --- bad measured traces --------------------------------------------------------------------


def _trace():
    return parabola_trace(400)


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (lambda x, z: (x[::-1], z), r"x must be strictly increasing; x\[1\].*\(decreasing\)"),
        (lambda x, z: (np.r_[x[:5], x[4], x[6:]], z), r"x\[5\] = .* \(repeated\)"),
        (lambda x, z: (x, np.r_[z[:3], np.nan, z[4:]]), r"z must be finite; z\[3\] = nan"),
        (lambda x, z: (x[:-1], z), "x and z must have the same length"),
        (lambda x, z: (x[:30], z[:30]), "x: a trace needs at least 40 samples"),
        (lambda x, z: (x, np.zeros_like(z)), "z: no depression found"),
        (lambda x, z: (x, -z), "z: no depression found"),
        (
            lambda x, z: (x[100:], z[100:]),
            "reaches the left end of the trace|too short for levelling",
        ),
        (lambda x, z: (x.reshape(20, 20), z), "x must be a 1-D array"),
    ],
    ids=["unsorted", "repeated", "nan", "length", "short", "flat", "upside-down", "cut", "2d"],
)
def test_bad_traces(change, message):
    x, z = change(*_trace())
    with pytest.raises(ValueError, match=message):
        ecofmaps.scar_profile(x, z)


def test_bad_trace_parameters():
    x, z = _trace()
    with pytest.raises(ValueError, match=r"half_width = 0\.0001 m does not fit the trace"):
        ecofmaps.scar_profile(x, z, half_width=100e-6)
    with pytest.raises(ValueError, match="half_width must be > 0"):
        ecofmaps.scar_profile(x, z, half_width=-1.0)
    with pytest.raises(ValueError, match="smoothing must be >= 0"):
        ecofmaps.scar_profile(x, z, smoothing=-1e-6)
    with pytest.raises(ValueError, match=r"smoothing = .* more than a fifth of the scar's half"):
        ecofmaps.scar_profile(x, z, smoothing=20e-6)
    coarse_x = np.linspace(-300e-6, 300e-6, 60)
    coarse_z = np.where(np.abs(coarse_x) < W, D * ((coarse_x / W) ** 2 - 1), 0.0)
    with pytest.raises(ValueError, match=r"x: only \d+ samples across the scar"):
        ecofmaps.scar_profile(coarse_x, coarse_z)


@pytest.mark.slow
def test_profiles_are_float64_without_jax_64_bit_mode():
    """A fresh process (JAX's 64-bit mode off, as in a script or the command line) still
    gets float64 profiles: the file's positions are not truncated to float32."""
    script = (
        "import warnings; warnings.simplefilter('error')\n"
        "import ecofmaps\n"
        "from ecofmaps.measured.synthetic import scar_example_path\n"
        "p = ecofmaps.read_scar_profile(scar_example_path())\n"
        "q = ecofmaps.w_shaped_profile(10e-6, 50e-6)\n"
        "print(*{str(leaf.dtype) for leaf in (*p, *q, p.aspect_ratio, p.edges)})\n"
    )
    run = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    assert run.stdout.split() == ["float64"]


@pytest.mark.slow
def test_a_profile_s_numbers_stay_float64_in_a_user_s_arithmetic():
    """In a process of its own (JAX's 64-bit mode off, as in a user's script), arithmetic on
    a read profile's fields stays float64, with no JAX warning: JAX would truncate a
    float64 JAX array times a Python float to float32."""
    import subprocess
    import sys

    script = (
        "import warnings; warnings.simplefilter('error')\n"
        "import ecofmaps\n"
        "profile = ecofmaps.read_scar_profile(ecofmaps.scar_example_path())\n"
        "width = profile.half_width * 1e6\n"
        "edges = profile.edges * 1e6\n"
        "assert width.dtype == 'float64' and edges.dtype == 'float64', (width, edges)\n"
        "assert abs(width - float(profile.half_width) * 1e6) < 1e-9 * width\n"
        "print(repr(float(width)))\n"
    )
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                          timeout=300, check=False)  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert done.stderr == ""
