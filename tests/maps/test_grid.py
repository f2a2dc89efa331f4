"""Parameter maps: labels, values against the SI API and brute force, collapse, chunking."""

import itertools
import math
import warnings

import jax.numpy as jnp
import numpy as np
import pytest
import xarray as xr
from hypothesis import example, given
from hypothesis import strategies as st

import ecofmaps
from ecofmaps import Regime, compute_loops, compute_map, compute_universal_map
from ecofmaps.maps import tiles
from ecofmaps.maps.tiles import MAX_CHUNK
from tests.brute_force import steady_loop

# A grid that holds every regime: rigid rig (inf), no gross slip (mu*lam >= 1 at small S/P),
# self-locking (rigid, mu * 2 z_o/x_o >= 1 at z_o/x_o = 0.7), and a flat groove.
STIFFNESS_RATIO = np.array([1.3e4, 3e4, 7.7e4, 2e5, np.inf])  # [1/m]
ASPECT_RATIO = np.array([0.0, 0.05, 0.2, 0.4, 0.7])
AMPLITUDE = np.array([25e-6, 50e-6])  # [m]
MU = np.array([0.5, 0.8, 1.2])
LOAD = 450.0  # [N]

# Figure 11: mu = 0.8, amplitude 25 and 50 um, S/P over the range of the paper's maps.
FIG11 = dict(
    stiffness_ratio=np.geomspace(1e4, 3e5, 13),
    aspect_ratio=np.linspace(0.0, 0.3, 7),
    amplitude=AMPLITUDE,
    mu=0.8,
)

VARIABLES = ["slip_amplitude", "slip_ratio", "ecof", "ecof_ratio", "compliance_ratio", "regime"]


@pytest.fixture(scope="module")
def grid():
    return compute_map(STIFFNESS_RATIO, ASPECT_RATIO, AMPLITUDE, MU, LOAD, cache=False)


def assert_close(actual, expected, rtol):
    """Equal NaN patterns, then relative agreement of the finite values."""
    actual, expected = np.asarray(actual, float), np.asarray(expected, float)
    np.testing.assert_array_equal(np.isnan(actual), np.isnan(expected))
    np.testing.assert_allclose(actual, expected, rtol=rtol, atol=0.0, equal_nan=True)


def test_every_variable_and_coordinate_is_labelled(grid):
    datasets = [
        grid,
        compute_universal_map(np.linspace(0.0, 1.0, 3), 0.2, 0.8, cache=False),
        compute_loops(np.array([35e6, np.inf]), 0.2, 50e-6, 450.0, 0.8, num=11),
    ]
    for dataset in datasets:
        for name, variable in dataset.variables.items():
            assert variable.attrs["long_name"], name
            assert variable.attrs["units"], name
        assert "Jin" in dataset.attrs["references"] and "non-Coulomb" in dataset.attrs["references"]
        assert dataset.attrs["ecofmaps_version"] == ecofmaps.__version__
        assert "groove" in dataset.attrs["model"]
    assert grid.stiffness_ratio.attrs["units"] == "m-1"
    assert grid.amplitude.attrs["units"] == "m"
    assert grid.dissipated_energy.attrs["units"] == "J"
    assert grid.max_force.attrs["units"] == "N"
    codes = grid.regime.attrs["flag_values"]
    meanings = grid.regime.attrs["flag_meanings"].split()
    assert {Regime[m.upper()]: int(c) for c, m in zip(codes, meanings, strict=True)} == {
        r: int(r) for r in Regime
    }


def test_dimensions_and_scalar_coordinates(grid):
    assert grid.ecof_ratio.dims == ("stiffness_ratio", "aspect_ratio", "amplitude", "mu")
    assert grid.regime.dtype == np.int32
    assert grid.compliance_ratio.dims == ("stiffness_ratio", "amplitude")  # λ = P/(SΔ*)
    assert all(grid[v].dtype == np.float64 for v in grid.data_vars if v != "regime")
    assert set(grid.data_vars) == {*VARIABLES, "dissipated_energy", "max_force"}
    assert float(grid["load"]) == LOAD and grid["load"].dims == ()
    small = compute_map(STIFFNESS_RATIO, 0.2, AMPLITUDE, 0.8, cache=False)
    assert small.ecof_ratio.dims == ("stiffness_ratio", "amplitude")
    assert float(small.aspect_ratio) == 0.2 and float(small.mu) == 0.8
    assert set(small.data_vars) == set(VARIABLES)  # no load: no energy, no force
    np.testing.assert_array_equal(small.ecof_ratio, grid.ecof_ratio.sel(aspect_ratio=0.2, mu=0.8))


def test_every_regime_is_present(grid):
    codes = set(np.unique(grid.regime.values))
    assert codes == {int(Regime.GROSS_SLIP), int(Regime.NO_GROSS_SLIP), int(Regime.SELF_LOCKING)}


def test_map_equals_the_si_api(grid):
    """Every point against ecofmaps.slip_amplitude & co. with S = (S/P) P (rtol 1e-12)."""
    s, r, a, m = xr.broadcast(grid.stiffness_ratio, grid.aspect_ratio, grid.amplitude, grid.mu)
    point = dict(amplitude=a.values, load=LOAD, stiffness=s.values * LOAD, mu=m.values)
    point["aspect_ratio"] = r.values
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ecofmaps.RegimeWarning)  # NaN where no gross slip
        expected = {
            "slip_amplitude": ecofmaps.slip_amplitude(**point),
            "ecof": ecofmaps.energy_cof(**point),
            "dissipated_energy": ecofmaps.dissipated_energy(**point),
            "max_force": ecofmaps.max_force(**point),
            "regime": ecofmaps.slip_regime(**point),
        }
    for name, values in expected.items():
        assert grid[name].shape == values.shape
        assert_close(grid[name], values, rtol=1e-12)
    assert_close(grid.slip_ratio, expected["slip_amplitude"] / point["amplitude"], rtol=1e-12)
    assert_close(grid.ecof_ratio, expected["ecof"] / point["mu"], rtol=1e-12)
    compliance_ratio = grid.compliance_ratio.broadcast_like(grid.ecof_ratio)
    assert_close(compliance_ratio, LOAD / (point["stiffness"] * point["amplitude"]), 1e-15)


@given(
    stiffness_ratio=st.one_of(st.floats(1e3, 1e7), st.just(math.inf)),
    aspect_ratio=st.floats(0.0, 1.0),
    amplitude=st.floats(1e-6, 2e-4),
    mu=st.floats(0.05, 2.0),
)
@example(math.inf, 0.99999, 6.78e-5, 0.5)
@example(math.inf, 0.999999, 3.3e-5, 0.5)
def test_single_points_equal_the_si_api(stiffness_ratio, aspect_ratio, amplitude, mu):
    """Over the whole valid domain; load 1 N so that S = S/P exactly (same λ bits). The two
    paths round differently where 1 - z_o/x_o cancels (about ε/(1 - z_o/x_o) apart at
    z_o/x_o = 0.99999): 1e-12 plus four times that."""
    point = compute_map(stiffness_ratio, aspect_ratio, amplitude, mu, 1.0, cache=False)
    si = dict(amplitude=amplitude, load=1.0, stiffness=stiffness_ratio, mu=mu)
    si["aspect_ratio"] = aspect_ratio
    eps = np.finfo(np.float64).eps
    rtol = 1e-12 + 4.0 * eps / max(1.0 - aspect_ratio, eps)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ecofmaps.RegimeWarning)
        assert int(point.regime) == int(ecofmaps.slip_regime(**si))
        assert_close(point.slip_amplitude, ecofmaps.slip_amplitude(**si), rtol=rtol)
        assert_close(point.ecof, ecofmaps.energy_cof(**si), rtol=rtol)
        assert_close(point.dissipated_energy, ecofmaps.dissipated_energy(**si), rtol=rtol)
        assert_close(point.max_force, ecofmaps.max_force(**si), rtol=rtol)


def test_figure_11_against_brute_force():
    """Sample points of the Figure 11 grid against brentq on eq. 16 + quad of eq. 12 (1e-10)."""
    fig11 = compute_map(**FIG11, load=LOAD, cache=False)
    rng = np.random.default_rng(11)
    shape = fig11.ecof_ratio.shape
    samples = [np.unravel_index(i, shape) for i in rng.choice(math.prod(shape), 24, False)]
    samples.append((shape[0] - 1, shape[1] - 1, 1))  # the extreme corner: stiff, deep, 50 um
    checked = 0
    for index in samples:
        point = fig11.isel(dict(zip(fig11.ecof_ratio.dims, index, strict=True)))
        reference = steady_loop(
            amplitude=float(point.amplitude),
            load=LOAD,
            stiffness=float(point.stiffness_ratio) * LOAD,
            mu=0.8,
            aspect_ratio=float(point.aspect_ratio),
        )
        for name, value in reference.items():
            if math.isnan(value):
                assert np.isnan(point[name])
            else:
                assert float(point[name]) == pytest.approx(value, rel=1e-10, abs=0.0), name
        checked += reference["slip_amplitude"] > 0
    assert checked >= 12  # most samples are in gross slip, some stick (small S/P, 25 um)
    # The paper: up to about 13 % at the extreme of the maps (S/P, z_o/x_o, Δ* largest).
    assert 1.10 < float(fig11.ecof_ratio.max()) < 1.16


def test_maps_collapse_onto_the_compliance_ratio():
    """Δ* = 25 µm at S/P equals Δ* = 50 µm at S/P / 2: λ = P/(SΔ*) is the same (eq. 16)."""
    stiffness_ratio = FIG11["stiffness_ratio"]
    at_25 = compute_map(stiffness_ratio, FIG11["aspect_ratio"], 25e-6, 0.8, cache=False)
    at_50 = compute_map(stiffness_ratio / 2, FIG11["aspect_ratio"], 50e-6, 0.8, cache=False)
    for name in ("slip_ratio", "ecof_ratio", "ecof", "compliance_ratio", "regime"):
        np.testing.assert_array_equal(at_25[name].values, at_50[name].values, err_msg=name)
    np.testing.assert_array_equal(2.0 * at_25.slip_amplitude.values, at_50.slip_amplitude.values)
    # ... and the universal map holds both at λ = 1/((S/P) Δ*).
    universal = compute_universal_map(
        at_25.compliance_ratio.values, FIG11["aspect_ratio"], 0.8, cache=False
    )
    for name in ("slip_ratio", "ecof_ratio", "regime"):
        np.testing.assert_array_equal(universal[name].values, at_25[name].values, err_msg=name)


def test_universal_map_regimes():
    universal = compute_universal_map(
        np.array([0.0, 0.5, 1.25, 2.0]), np.array([0.0, 0.3, 0.7]), 0.8, cache=False
    )
    assert universal.ecof_ratio.dims == ("compliance_ratio", "aspect_ratio")
    regime = universal.regime.values
    assert regime[0, 2] == Regime.SELF_LOCKING  # rigid, mu * kappa = 0.8 * 1.4 >= 1
    assert (regime[2:] == Regime.NO_GROSS_SLIP).all()  # mu * lam >= 1
    np.testing.assert_array_equal(universal.ecof_ratio.values[:2, 0], 1.0)  # flat groove
    np.testing.assert_array_equal(universal.slip_ratio.values[0, :2], 1.0)  # rigid rig
    assert np.isnan(universal.ecof_ratio.values[0, 2]) and np.isnan(universal.slip_ratio[0, 2])
    np.testing.assert_array_equal(universal.slip_ratio.values[2:], 0.0)


@pytest.mark.parametrize("max_chunk", [1, 7, 64, 150, 10**6])
def test_chunked_equals_unchunked(grid, max_chunk):
    chunked = compute_map(
        STIFFNESS_RATIO, ASPECT_RATIO, AMPLITUDE, MU, LOAD, cache=False, max_chunk=max_chunk
    )
    xr.testing.assert_allclose(chunked, grid, rtol=1e-15, atol=0.0)
    np.testing.assert_array_equal(chunked.regime, grid.regime)


def test_one_call_per_point_equals_one_call_for_the_grid(grid):
    rng = np.random.default_rng(3)
    for index in rng.choice(grid.regime.size, 12, replace=False):
        i, j, k, m = np.unravel_index(index, grid.regime.shape)
        point = compute_map(
            STIFFNESS_RATIO[i], ASPECT_RATIO[j], AMPLITUDE[k], MU[m], LOAD, cache=False
        )
        expected = grid.isel(stiffness_ratio=i, aspect_ratio=j, amplitude=k, mu=m)
        xr.testing.assert_allclose(point, expected, rtol=1e-15, atol=0.0)
        assert int(point.regime) == int(expected.regime)


def test_loops():
    stiffness = np.array([35e6, np.inf])
    aspect_ratio = np.array([0.0, 0.2, 0.7])
    loops = compute_loops(stiffness, aspect_ratio, 50e-6, 450.0, 0.8, num=4001)
    assert loops.displacement.dims == ("stiffness", "aspect_ratio", "point")
    assert loops.sizes["point"] == 2 * 4001 + 1
    assert loops.stiffness.attrs["units"] == "N m-1"
    x, q = loops.displacement.values, loops.force.values
    area = np.sum(0.5 * (q[..., 1:] + q[..., :-1]) * np.diff(x), axis=-1)  # ∮ Q dΔ by trapezoids
    energy = loops.dissipated_energy.values
    ok = np.isfinite(energy)
    assert ok.sum() == 5  # the rigid rig self-locks in the deep groove
    np.testing.assert_allclose(area[ok], energy[ok], rtol=1e-6)  # polygon area: O(1/num^2)
    np.testing.assert_allclose(q[ok].max(axis=-1), loops.max_force.values[ok], rtol=1e-14)
    np.testing.assert_allclose(x[..., 0][ok], -50e-6, rtol=1e-15)
    assert loops.regime.values[1, 2] == Regime.SELF_LOCKING and np.isnan(x[1, 2]).all()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ecofmaps.RegimeWarning)
        expected = ecofmaps.slip_amplitude(50e-6, 450.0, stiffness[:, None], 0.8, aspect_ratio)
    assert_close(loops.slip_amplitude, expected, rtol=1e-14)


@pytest.mark.parametrize(
    ("arguments", "message"),
    [
        (dict(stiffness_ratio=-1.0), "stiffness_ratio must satisfy 0 < stiffness_ratio <= inf"),
        (dict(stiffness_ratio=np.array([1e4, np.nan])), "stiffness_ratio"),
        (dict(aspect_ratio=-0.1), "aspect_ratio must satisfy 0 <= aspect_ratio < inf"),
        (dict(aspect_ratio=np.inf), "aspect_ratio"),
        (dict(amplitude=0.0), "amplitude must satisfy 0 < amplitude < inf"),
        (dict(amplitude=np.ones((2, 2)) * 1e-5), "amplitude must be a single value or a 1-D"),
        (dict(mu=np.array([])), "mu must hold at least one value"),
        (dict(mu="x"), "mu must be a real number"),
        (dict(load=-450.0), "load must satisfy 0 < load < inf"),
        (dict(load=np.array([1.0, 2.0])), "load must be a single value"),
        (dict(max_chunk=0), "max_chunk must be an integer >= 1"),
        (
            dict(aspect_ratio=[0.1, 1e308]),
            "aspect_ratio must satisfy 0 <= aspect_ratio <= 1e",
        ),
        (dict(stiffness_ratio=1e-300), "stiffness_ratio must satisfy 1e-12 <= stiffness_ratio <="),
    ],
)
def test_bad_input_is_named(arguments, message):
    call = dict(stiffness_ratio=1e5, aspect_ratio=0.2, amplitude=50e-6, mu=0.8, cache=False)
    with pytest.raises(ValueError, match=message.replace("(", r"\(").replace("*", r"\*")):
        compute_map(**{**call, **arguments})


def test_bad_input_of_the_other_maps_is_named():
    with pytest.raises(ValueError, match="compliance_ratio must satisfy 0 <= compliance_ratio"):
        compute_universal_map(-0.5, 0.2, 0.8, cache=False)
    with pytest.raises(ValueError, match="stiffness must satisfy 0 < stiffness <= inf"):
        compute_loops(0.0, 0.2, 50e-6, 450.0, 0.8)
    with pytest.raises(ValueError, match="num must be an integer >= 2"):
        compute_loops(35e6, 0.2, 50e-6, 450.0, 0.8, num=1)


# --- chunked maps (dask) ----------------------------------------------------------------------

# Small axes with every regime; each is given as an array or as its first value alone.
AXES = dict(
    stiffness_ratio=np.array([1.3e4, 3e4, 2e5, np.inf, 7.7e4]),
    aspect_ratio=np.array([0.0, 0.2, 0.7, 0.05]),
    amplitude=np.array([25e-6, 50e-6, 10e-6]),
    mu=np.array([0.8, 0.5]),
)


@pytest.mark.slow
@pytest.mark.parametrize("given", list(itertools.product([False, True], repeat=4)))
def test_chunked_equals_in_memory_to_the_bit(given):
    """Every combination of scalar and 1-D axes, awkward blocks and tiles: identical."""
    arguments = {n: a if array else a[0] for (n, a), array in zip(AXES.items(), given, strict=True)}
    dims = [name for name, array in zip(AXES, given, strict=True) if array]
    awkward = [1, 7, "auto"]
    if dims:
        awkward += [{dims[0]: 2}, {dims[-1]: 1, dims[0]: None}]
    for max_chunk in (7, MAX_CHUNK):  # the grid in tiles of at most 7 points, or at once
        expected = compute_map(**arguments, load=LOAD, cache=False, max_chunk=max_chunk)
        for chunks in awkward:
            chunked = compute_map(**arguments, load=LOAD, chunks=chunks, max_chunk=max_chunk)
            lazy = [v for v in chunked.data_vars if chunked[v].chunks is not None]
            assert sorted(lazy) == sorted(set(chunked.data_vars) - {"compliance_ratio"})
            xr.testing.assert_identical(chunked.compute(), expected)


@pytest.mark.parametrize("given", list(itertools.product([False, True], repeat=3)))
def test_chunked_universal_map_equals_in_memory_to_the_bit(given):
    axes = dict(
        compliance_ratio=np.array([0.0, 0.5, 1.25, 0.1]),
        aspect_ratio=np.array([0.3, 0.0, 0.7]),
        mu=np.array([0.8, 1.2]),
    )
    arguments = {n: a if array else a[0] for (n, a), array in zip(axes.items(), given, strict=True)}
    for max_chunk in (3, MAX_CHUNK):
        expected = compute_universal_map(**arguments, cache=False, max_chunk=max_chunk)
        for chunks in (1, 5, "auto"):
            chunked = compute_universal_map(**arguments, chunks=chunks, max_chunk=max_chunk)
            xr.testing.assert_identical(chunked.compute(), expected)


def test_chunked_map_is_lazy_and_evaluates_each_block_once(monkeypatch, grid):
    calls = []
    block = tiles._block

    def counted(*args):
        calls.append(args[4])  # the block's region
        return block(*args)

    monkeypatch.setattr(tiles, "_block", counted)
    chunked = compute_map(STIFFNESS_RATIO, ASPECT_RATIO, AMPLITUDE, MU, LOAD, chunks=60)
    assert calls == []  # lazy
    assert chunked.ecof_ratio.chunks == ((2, 2, 1), (5,), (2,), (3,))  # 2 x 5 x 2 x 3 = 60
    xr.testing.assert_identical(chunked.compute(), grid)  # all variables at once
    assert len(calls) == len(set(calls)) == 3


def test_blocks_take_whole_tiles():
    """chunks=N: the blocks of the split axis hold whole tiles, so no tile is evaluated twice."""
    chunked = compute_map(np.geomspace(1e4, 1e5, 100), np.linspace(0, 0.3, 30), 50e-6, 0.8,
                          chunks=1000, max_chunk=120)  # fmt: skip
    # Tiles of 4 rows (120 points), 25 of them; blocks of at most 25 rows (balanced: 4 blocks
    # of at most 33 rows, 990 points) hold 6 whole tiles: 5 blocks of 5 tiles (20 rows).
    assert chunked.ecof_ratio.chunks == ((20, 20, 20, 20, 20), (30,))


@pytest.mark.parametrize(
    ("chunks", "message"),
    [
        (0, r"chunks must be 'auto', an integer >= 1 \(grid points per block\) or a dict"),
        (-5, "chunks must be 'auto', an integer >= 1"),
        (True, "chunks must be 'auto', an integer >= 1"),
        (2.5, "chunks must be 'auto', an integer >= 1"),
        ("big", "chunks must be 'auto', an integer >= 1.* got 'big'"),
        ({"load": 2}, "chunks names 'load', which is not a dimension of this map"),
        ({"mu": 2}, "chunks names 'mu', which is not a dimension of this map .its dimensions: "
                    "stiffness_ratio, aspect_ratio."),
        ({"aspect_ratio": 0}, r"chunks\['aspect_ratio'\] must be an integer >= 1, or -1 or None"),
        ({"aspect_ratio": "x"}, r"chunks\['aspect_ratio'\] must be an integer >= 1"),
    ],
)  # fmt: skip
def test_bad_chunks_are_named(chunks, message):
    with pytest.raises(ValueError, match=message):
        compute_map(np.array([1e4, 1e5]), np.array([0.0, 0.2]), 50e-6, 0.8, chunks=chunks)


def test_a_chunked_map_is_not_cached(tmp_path):
    with pytest.raises(ValueError, match="cache=True with chunks: a chunked map is not cached"):
        compute_map(1e5, 0.2, 50e-6, 0.8, chunks="auto", cache=True)
    with pytest.raises(ValueError, match="cache must be True, False or None"):
        compute_universal_map(0.5, 0.2, 0.8, cache="yes")
    with pytest.raises(ValueError, match="max_chunk must be an integer >= 1"):
        compute_map(1e5, 0.2, 50e-6, 0.8, chunks="auto", max_chunk=0)
    compute_map(np.array([1e4, 1e5]), 0.2, 50e-6, 0.8, chunks=1, cache_dir=tmp_path).compute()
    assert list(tmp_path.iterdir()) == []


def test_memory_refusal_names_the_chunked_way_out(monkeypatch):
    monkeypatch.setattr(tiles, "available_memory", lambda: 10_000)  # 10 kB free
    axes = (np.geomspace(1e4, 1e5, 100), np.linspace(0, 0.3, 30), 50e-6, 0.8)
    message = (
        r"the grid of 3e\+03 points needs about 0.000\d+ GB of memory for its results, more "
        r"than the 1e-05 GB available: use a smaller grid, or compute it block by block with "
        r"chunks='auto' and write it with ecofmaps.maps.write_map"
    )
    with pytest.raises(ValueError, match=message):
        compute_map(*axes, cache=False)
    chunked = compute_map(*axes, chunks=1000).compute()  # not refused: a block at a time
    monkeypatch.undo()
    xr.testing.assert_identical(chunked, compute_map(*axes, cache=False))


def test_a_failing_tile_stops_the_map():
    """An error in one tile's evaluation is raised; the threads stop at their next tile."""
    calls = []

    def kernel(x, y):
        calls.append(x.size)
        if len(calls) == 3:
            raise FloatingPointError("tile 3")
        return {"ecof_ratio": jnp.add.outer(x, y)}

    axes = [np.arange(40.0), np.arange(5.0)]
    with pytest.raises(FloatingPointError, match="tile 3"):
        tiles._evaluate_grid(kernel, axes, (), max_chunk=10)
    assert len(calls) < 20  # 20 tiles of 2 rows


@given(
    shape=st.lists(st.integers(1, 6), min_size=1, max_size=4),
    points=st.integers(1, 200),
    data=st.data(),
)
def test_tiles_cover_any_region_once(shape, points, data):
    """The tiles that overlap a region cover each of its points exactly once."""
    split = tiles._split(tuple(shape), points)
    k, rows = split
    assert rows * math.prod(shape[k + 1 :]) <= max(points, math.prod(shape[k + 1 :]))
    count = -(-shape[k] // rows)  # tiles along the split axis: as even as can be
    assert count * rows - shape[k] < count
    region = []
    for size in shape:
        start = data.draw(st.integers(0, size - 1))
        region.append((start, data.draw(st.integers(start + 1, size))))
    covered = np.zeros(shape, int)
    for index, start in tiles._tiles(split, region):
        assert start % rows == 0
        covered[(*index, slice(start, start + rows))] += 1
    inside = tuple(slice(a, b) for a, b in region)
    assert (covered[inside] == 1).all()


def test_dataset_is_what_xarray_would_build(grid):
    """The map's Dataset, built directly, is the one xarray.Dataset(...) builds from its parts."""
    loops = compute_loops(np.array([35e6, np.inf]), 0.2, 50e-6, 450.0, 0.8, num=5)
    for dataset in (grid, loops, compute_map(1e5, 0.2, 50e-6, 0.8, cache=False)):
        rebuilt = xr.Dataset(dataset.data_vars, coords=dataset.coords, attrs=dataset.attrs)
        xr.testing.assert_identical(dataset, rebuilt)
        assert dict(dataset.xindexes).keys() == dict(rebuilt.xindexes).keys()
        assert list(dataset.variables) == list(rebuilt.variables)
