"""compute_map on a scar profile: the closed-form map on a parabola, chunks, cache, errors."""

import warnings

import numpy as np
import pytest
import xarray as xr

import ecofmaps
from ecofmaps import Regime, compute_map

GRID = dict(stiffness_ratio=np.geomspace(1e4, 3e5, 12), amplitude=np.array([25e-6, 50e-6]))
PARABOLA = ecofmaps.parabolic_profile(10e-6, 50e-6)


@pytest.mark.slow
def test_parabolic_profile_gives_the_closed_form_map():
    """On a parabola the map is Figure 11's (closed forms, aspect_ratio = D/W): 1e-12."""
    mu = np.array([0.3, 0.8])
    on_profile = compute_map(**GRID, mu=mu, load=450.0, profile=PARABOLA, cache=False)
    closed = compute_map(**GRID, aspect_ratio=0.2, mu=mu, load=450.0, cache=False)
    assert on_profile.ecof.dims == ("stiffness_ratio", "amplitude", "mu")
    for name in ("slip_amplitude", "ecof", "ecof_ratio", "dissipated_energy", "max_force"):
        expected = closed[name].drop_vars("aspect_ratio")
        xr.testing.assert_allclose(on_profile[name], expected, rtol=1e-12, atol=0)
    xr.testing.assert_equal(on_profile.regime, closed.regime.drop_vars("aspect_ratio"))
    xr.testing.assert_equal(
        on_profile.compliance_ratio, closed.compliance_ratio.drop_vars("aspect_ratio")
    )
    assert set(np.unique(on_profile.regime)) == {Regime.GROSS_SLIP, Regime.NO_GROSS_SLIP}
    assert on_profile.attrs["scar_aspect_ratio"] == pytest.approx(0.2)
    assert on_profile.attrs["mapping"] == "scaled"
    for name in on_profile.variables:
        assert {"long_name", "units"} <= set(on_profile[name].attrs), name


@pytest.mark.slow
def test_chunks_cache_and_netcdf(tmp_path):
    """Blocks of max_chunk points give the same map; the cache returns it identical, and a
    different profile (same D and W) is a different entry."""
    profile = ecofmaps.w_shaped_profile(10e-6, 50e-6, 0.3)
    whole = compute_map(**GRID, mu=0.8, profile=profile, cache=False)
    chunked = compute_map(**GRID, mu=0.8, profile=profile, cache=False, max_chunk=5)
    xr.testing.assert_identical(whole, chunked)
    first = compute_map(**GRID, mu=0.8, profile=profile, cache_dir=tmp_path)
    again = compute_map(**GRID, mu=0.8, profile=profile, cache_dir=tmp_path)
    xr.testing.assert_identical(first, again)
    xr.testing.assert_identical(first, whole)
    other = ecofmaps.w_shaped_profile(10e-6, 50e-6, 0.5)
    different = compute_map(**GRID, mu=0.8, profile=other, cache_dir=tmp_path)
    assert len(list(tmp_path.glob("compute_profile_map-*.nc"))) == 2
    assert not np.allclose(different.ecof, first.ecof, equal_nan=True)


def test_map_depends_on_lambda_only():
    """Scaled mapping (x_o = Δ*): the map depends on S/P and Δ* through P/(S Δ*) only."""
    profile = ecofmaps.flat_bottomed_profile(10e-6, 50e-6)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ecofmaps.RegimeWarning)
        m = compute_map([4e4, 8e4], amplitude=[50e-6, 25e-6], mu=0.8, profile=profile,
                        cache=False)  # fmt: skip
    assert float(m.ecof[0, 0]) == pytest.approx(float(m.ecof[1, 1]), rel=1e-14)


@pytest.mark.slow
def test_physical_mapping_runs_off_short_traces():
    profile = ecofmaps.parabolic_profile(10e-6, 50e-6, extent=1.2)
    m = compute_map(1e6, amplitude=[40e-6, 80e-6], mu=0.8, profile=profile, mapping="physical",
                    cache=False)  # fmt: skip
    assert list(m.regime.values) == [Regime.GROSS_SLIP, Regime.BEYOND_PROFILE]
    assert np.isnan(float(m.ecof[1]))


@pytest.mark.parametrize(
    ("arguments", "message"),
    [
        (dict(aspect_ratio=0.2, profile=PARABOLA), "not both"),
        (dict(), "needs aspect_ratio or profile"),
        (dict(profile=PARABOLA, mapping="flat"), "mapping must be one of"),
        (dict(aspect_ratio=0.2, mapping="physical"), "mapping applies to a profile only"),
        (dict(profile=PARABOLA, stiffness_ratio=-1.0), "stiffness_ratio must satisfy"),
        (dict(profile=PARABOLA, max_chunk=0), "max_chunk must be an integer"),
        (dict(profile="parabola"), "profile must be a ScarProfile"),
    ],
)
def test_bad_input(arguments, message):
    grid = {**GRID, "mu": 0.8, "cache": False, **arguments}
    with pytest.raises(ValueError, match=message):
        compute_map(**grid)
