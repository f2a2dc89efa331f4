r"""The model on a scar profile in SI units (``profile=`` of the public functions): steady loops
at any broadcast set of points, the tables shared between points of one :math:`\mu` and
stroke; drawn loops and time histories. The method is explained in ``docs/model.md``.
"""

from __future__ import annotations

import math
from functools import partial

import jax
import jax.numpy as jnp
import numpy as np

from ecofmaps._inputs import as_float64, float64, is_concrete
from ecofmaps.model import first_passage
from ecofmaps.model import profile_core as core
from ecofmaps.model.core import checked, compliance_ratio, steady_inputs, valid_geometry
from ecofmaps.model.profiles import ScarProfile
from ecofmaps.model.regimes import GROSS_SLIP, INVALID, NO_GROSS_SLIP

#: How a pad position x maps onto the profile: eq. 11, X = x W/x_o; or X = x.
MAPPINGS = ("scaled", "physical")

# Memory bound of one batch of shared tables (floats), and of the per-point O(N) work.
_TABLE_BUDGET = 2**25
_POINT_BATCH = 256
# Points share tables unless there are more groups than this and than a 16th of the points.
_FEW_GROUPS = 64
# Up to this many points, each builds its own O(N) tables: that costs less than compiling
# the shared sparse tables' kernels for every new shape.
_FEW_POINTS = 256


def as_profile(profile) -> ScarProfile:
    """``profile`` as float64 arrays, checked when concrete; ``ValueError`` if it is not one."""
    if not isinstance(profile, ScarProfile):
        raise ValueError(
            "profile must be a ScarProfile (from ecofmaps.scar_profile, "
            f"ecofmaps.read_scar_profile or a profile family), got {type(profile).__name__}"
        )
    profile = ScarProfile(*(as_float64(leaf) for leaf in profile))
    if is_concrete(*profile):
        position = np.asarray(profile.position)
        if position.ndim != 1 or position.size < 3:
            raise ValueError("profile.position must be 1-D, >= 3 samples (jax.vmap maps a batch)")
        if profile.slope.shape != position.shape:
            raise ValueError("profile.slope must have the shape of profile.position")
        if not (np.all(np.isfinite(position)) and np.all(np.diff(position) > 0.0)):
            raise ValueError("profile.position must be finite and strictly increasing")
        if not np.all(np.isfinite(np.asarray(profile.slope))):
            raise ValueError("profile.slope must be finite")
        width = float(profile.half_width)
        if not (math.isfinite(width) and width > 0.0):
            raise ValueError(f"profile.half_width must be finite and > 0, got {width!r}")
        if not position[0] < 0.0 < position[-1]:
            raise ValueError("profile.position must run from before to after the scar centre 0")
    return profile


def check_mapping(mapping, groove_half_width) -> bool:
    """True for the physical mapping; ``ValueError`` for a bad combination."""
    if mapping not in MAPPINGS:
        raise ValueError(f"mapping must be one of {MAPPINGS}, got {mapping!r}")
    if mapping == "physical" and groove_half_width is not None:
        raise ValueError(
            "groove_half_width sets the scaled mapping X = x W/x_o (eq. 11); "
            "mapping='physical' (X = x) takes none"
        )
    return mapping == "physical"


def _valid(amplitude, load, stiffness, mu, half_width):
    valid = valid_geometry(amplitude, load, stiffness, 0.0, half_width)
    return valid & (mu > 0.0) & jnp.isfinite(mu)


def _stroke(half_width, key, physical: bool):
    """The stroke length A from the grouping key (Δ*/x_o, or Δ* for the physical mapping)."""
    return key if physical else half_width * key


@partial(jax.jit, static_argnames=("physical", "sparse"))
def _shared_tables(position, slope, half_width, mu, key, physical, sparse):
    """One set of tables per group (mu, key), stacked."""
    length = _stroke(half_width, key, physical)
    build = jax.vmap(core.profile_tables, in_axes=(None, None, 0, 0, None))
    return jax.tree.map(lambda leaf: leaf[:, 0], build(position, slope, mu, length, sparse))


@jax.jit
def _shared_loops(tables, group, lam):
    """Steady loops of points in groups with shared sparse tables."""
    return jax.vmap(first_passage.steady_loop, in_axes=(None, 0, 0, None))(tables, group, lam, True)


@jax.jit
def _shared_jumps(tables, group, lam, ends):
    one = partial(first_passage.jump_areas, tables)
    return jax.lax.map(lambda point: one(*point), (group, lam, ends), batch_size=_POINT_BATCH)


def _own_loop(position, slope, half_width, physical, point, num=0):
    """One point with its own O(N) tables, jumps included; with ``num``, its loop drawn too."""
    mu, key, lam = point
    tables = core.profile_tables(position, slope, mu, _stroke(half_width, key, physical), False)
    loop = first_passage.steady_loop(tables, 0, lam, False)
    jumps = first_passage.jump_areas(tables, 0, lam, loop.ends)
    if not num:
        return loop, jumps
    return loop, jumps, first_passage.draw_loop(tables, 0, lam, loop, num)


@partial(jax.jit, static_argnames=("physical", "num", "batch"))
def _own_loops(position, slope, half_width, mu, key, lam, physical, num=0, batch=_POINT_BATCH):
    one = partial(_own_loop, position, slope, half_width, physical, num=num)
    return jax.lax.map(one, (mu, key, lam), batch_size=batch)


def _pad(indices: np.ndarray) -> np.ndarray:
    """Indices padded (with the last one) to a power of two: few shapes to compile."""
    return np.pad(indices, (0, _bucket(indices.size) - indices.size), mode="edge")


def _bucket(size: int) -> int:
    """``size`` rounded up to a power of two (at least 8)."""
    return max(8, 1 << (size - 1).bit_length())


def _groups(mu: np.ndarray, key: np.ndarray):
    """The distinct (mu, key) pairs, as a (2, U) array, and each point's pair."""
    if mu.size and np.all(mu == mu[0]) and np.all(key == key[0]):
        return np.array([[mu[0]], [key[0]]]), np.zeros(mu.size, dtype=np.int64)
    mus, mu_index = np.unique(mu, return_inverse=True)
    keys, key_index = np.unique(key, return_inverse=True)
    pairs, group = np.unique(mu_index * keys.size + key_index, return_inverse=True)
    unique = np.stack([mus[pairs // keys.size], keys[pairs % keys.size]])
    return unique, group.reshape(-1)


def _shared(profile, unique, group, lam, physical):
    """Loops and jump areas of points in groups ``unique[:, group]`` with shared tables."""
    count = unique.shape[1]
    n = profile.position.shape[-1]
    per_group = 8 * n * (core.table_levels(n) + 1)
    batch = min(_bucket(count), max(1, 1 << (_TABLE_BUDGET // per_group).bit_length() - 1))
    arguments = (profile.position, profile.slope, profile.half_width)
    unique = np.pad(unique, ((0, 0), (0, -count % batch)), mode="edge")
    lam = np.asarray(lam)
    parts = []
    starts = range(0, count, batch)
    members_of = [np.flatnonzero((group >= f) & (group < f + batch)) for f in starts]
    width = _bucket(max(m.size for m in members_of))
    for first, members in zip(starts, members_of, strict=True):  # every batch of one shape
        padded = np.pad(members, (0, width - members.size), mode="edge")
        tables = _shared_tables(*arguments, *unique[:, first : first + batch], physical, True)
        part = _shared_loops(tables, group[padded] - first, lam[padded])
        parts.append(jax.tree.map(lambda leaf, m=members.size: leaf[:m], part))
    inverse = np.argsort(np.concatenate(members_of))  # the points back in their order
    loops = jax.tree.map(lambda *leaves: jnp.concatenate(leaves)[inverse], *parts)
    dense = _shared_tables(*arguments, *unique[:, :count], physical, False)
    jumps = np.zeros(lam.size)
    where = np.flatnonzero(~np.asarray(loops.monotone))
    if where.size:
        padded = _pad(where)
        ends = jax.tree.map(lambda leaf: leaf[padded], loops.ends)
        values = _shared_jumps(dense, group[padded], lam[padded], ends)
        jumps[where] = np.asarray(values)[: where.size]
    return loops, jumps


@partial(jax.jit, static_argnames="physical")
def _prepare(amplitude, load, stiffness, mu, half_width, profile_half_width, physical):
    """Flat (mu, key, lam, valid) with harmless stand-ins at invalid points."""
    valid = _valid(amplitude, load, stiffness, mu, half_width)
    lam = jnp.where(valid, compliance_ratio(amplitude, load, stiffness), 0.1)
    key = amplitude if physical else amplitude / half_width
    key = jnp.where(valid, key, profile_half_width if physical else 1.0)
    return tuple(v.reshape(-1) for v in (jnp.where(valid, mu, 0.5), key, lam, valid))


@jax.jit
def _finish(loops, jumps, mu, lam, valid) -> dict:
    """The steady-loop numbers from the loops and the jumps' areas (``docs/model.md``)."""
    loops, jumps = jax.tree.map(lambda leaf: leaf[: mu.shape[0]], (loops, jumps))
    slip = 0.5 * (loops.plus - loops.minus)
    scale = 4.0 * mu * jnp.where(lam > 0.0, lam, 1.0) * jnp.where(slip > 0.0, slip, 1.0)
    ratio = loops.ecof_ratio + jnp.where(jumps > 0.0, jumps / scale, 0.0)
    regime = jnp.where(valid, loops.regime, int(INVALID)).astype(jnp.int32)
    gross = regime == int(GROSS_SLIP)
    settled = gross | (regime == int(NO_GROSS_SLIP))
    energy = jnp.where(gross, 4.0 * slip * mu * ratio, jnp.where(settled, 0.0, jnp.nan))
    return {
        "slip_ratio": jnp.where(settled, slip, jnp.nan),
        "ecof_ratio": jnp.where(gross, ratio, jnp.nan),
        "normalized_energy": energy,
        "normalized_max_force": jnp.where(settled, loops.peak_force, jnp.nan),
        "regime": regime,
        "minus": jnp.where(settled, loops.minus, jnp.nan),
        "plus": jnp.where(settled, loops.plus, jnp.nan),
    }


def steady_values(numbers, amplitude, load, mu) -> dict:
    """:func:`steady_numbers` in SI units, broadcast: ``slip_amplitude`` [m], ``ecof`` [1] and,
    with a ``load``, ``dissipated_energy`` [J] and ``max_force`` [N]."""
    values = {
        "slip_amplitude": amplitude * numbers["slip_ratio"],
        "ecof": mu * numbers["ecof_ratio"],
    }
    if load is not None:
        values["dissipated_energy"] = load * amplitude * numbers["normalized_energy"]
        values["max_force"] = load * numbers["normalized_max_force"]
    return values


def _points(profile, amplitude, load, stiffness, mu, groove_half_width, mapping):
    """The checked profile, the SI inputs broadcast, the mapping and :func:`_prepare`'s values."""
    physical = check_mapping(mapping, groove_half_width)
    profile = as_profile(profile)
    values = jnp.broadcast_arrays(
        *steady_inputs(amplitude, load, stiffness, mu, None, groove_half_width)
    )
    return profile, values, physical, _prepare(*values, profile.half_width, physical)


def _each_own(profile, physical, mu, key, lam, num=0):
    """:func:`_own_loops` of the points padded to a power of two."""
    padded = _pad(np.arange(lam.size))
    arguments = (profile.position, profile.slope, profile.half_width)
    # With loops drawn (a figure's few points) one point at a time: it compiles faster.
    batch = None if num else _POINT_BATCH
    return _own_loops(*arguments, mu[padded], key[padded], lam[padded], physical, num, batch)


def _scaled(curve, ok, scale, shape):
    """A drawn curve per point, NaN where not ``ok``, times ``scale`` [SI], in ``shape``."""
    curve = jnp.where(ok[:, None], curve[: ok.size], jnp.nan) * scale.reshape(-1, 1)
    return curve.reshape(*shape, -1)


def steady_numbers(
    profile, amplitude, load, stiffness, mu, groove_half_width=None, mapping="scaled"
) -> dict:
    r"""The steady loop on ``profile`` at every point, in the units of the core."""
    profile, values, physical, (mu, key, lam, valid) = _points(
        profile, amplitude, load, stiffness, mu, groove_half_width, mapping
    )
    own = not is_concrete(mu, key, lam) or lam.size <= _FEW_POINTS
    if not own:
        unique, group = _groups(np.asarray(mu), np.asarray(key))
        own = unique.shape[1] > max(_FEW_GROUPS, lam.size // 16)
    if own:  # each point its own O(N) tables
        loops, jumps = _each_own(profile, physical, mu, key, lam)
    else:
        loops, jumps = _shared(profile, unique, group, lam, physical)
    numbers = _finish(loops._replace(ends=()), jumps, mu, lam, valid)
    return {name: value.reshape(values[0].shape) for name, value in numbers.items()}


@float64
def steady_numbers_and_loops(
    profile, amplitude, load, stiffness, mu, num=201, groove_half_width=None, mapping="scaled"
) -> dict:
    r""":func:`steady_numbers` and each point's steady loop drawn, by one compiled kernel."""
    profile, values, physical, (mu, key, lam, valid) = _points(
        profile, amplitude, load, stiffness, mu, groove_half_width, mapping
    )
    loops, jumps, (actuator, force) = _each_own(profile, physical, mu, key, lam, num)
    numbers = _finish(loops._replace(ends=()), jumps, mu, lam, valid)
    settled = (numbers["regime"] == int(GROSS_SLIP)) | (numbers["regime"] == int(NO_GROSS_SLIP))
    shape = values[0].shape
    numbers = {name: value.reshape(shape) for name, value in numbers.items()}
    numbers["displacement"] = _scaled(actuator, settled, values[0], shape)
    numbers["force"] = _scaled(force, settled, values[1], shape)
    return numbers


def profile_loop(profile, amplitude, load, stiffness, mu, groove_half_width, mapping, num):
    """Displacement and force around the steady loop on ``profile`` (see fretting_loop)."""
    profile, values, physical, (mu, key, lam, valid) = _points(
        profile, amplitude, load, stiffness, mu, groove_half_width, mapping
    )
    arguments = (profile.position, profile.slope, profile.half_width)
    loops, _, (actuator, force) = _own_loops(*arguments, mu, key, lam, physical, num)
    ok = valid & ((loops.regime == int(GROSS_SLIP)) | (loops.regime == int(NO_GROSS_SLIP)))
    shape = values[0].shape
    return _scaled(actuator, ok, values[0], shape), _scaled(force, ok, values[1], shape)


def _history(position, slope, history):
    """Q/P over a history of D for one (mu, lam): the return map from rest at the centre."""
    mu, lam, targets = history
    tables = first_passage.simulation_tables(position, slope, mu, lam)
    start = (tables.start_segment[0], tables.start_fraction[0], jnp.zeros(()), jnp.array(False))
    _, q = jax.lax.scan(partial(first_passage.simulation_step, tables, lam), start, targets)
    return q


@jax.jit
def _histories(position, slope, mu, lam, targets):
    return jax.lax.map(partial(_history, position, slope), (mu, lam, targets))


def broadcast_history(displacement, *values):
    """``displacement`` (time last) as float64 and ``values`` broadcast to one batch shape."""
    displacement = as_float64(displacement)
    batch = jnp.broadcast_shapes(displacement.shape[:-1], *(jnp.shape(v) for v in values))
    values = [jnp.broadcast_to(v, batch) for v in values]
    return jnp.broadcast_to(displacement, batch + displacement.shape[-1:]), values


def profile_simulation(profile, displacement, load, stiffness, mu, groove_half_width, mapping):
    """Tangential force history on ``profile`` (see simulate); displacement has time last."""
    physical = check_mapping(mapping, groove_half_width)
    profile = as_profile(profile)
    if not physical and groove_half_width is None:
        raise ValueError(
            "simulate on a profile with the scaled mapping X = x W/x_o (eq. 11) needs "
            "groove_half_width = x_o (the steady loop uses x_o = amplitude); or give "
            "mapping='physical'"
        )
    load, stiffness, mu, *x_o = checked(
        load=load, stiffness=stiffness, mu=mu, groove_half_width=groove_half_width
    )
    x_o = profile.half_width if physical else x_o[0]
    displacement, (load, stiffness, mu, x_o) = broadcast_history(
        displacement, load, stiffness, mu, x_o
    )
    batch, steps = load.shape, displacement.shape[-1]
    valid = _valid(jnp.ones(batch), load, stiffness, mu, x_o)
    # Units of the scar's half-width W: X/W = x/x_o, D = Δ/x_o, λ = P/(S x_o).
    lam = jnp.where(valid, compliance_ratio(x_o, load, stiffness), 0.1).reshape(-1)
    targets = (displacement / x_o[..., None]).reshape(-1, steps)
    mu_flat = jnp.where(valid, mu, 0.5).reshape(-1)
    position = profile.position / profile.half_width
    q = _histories(position, profile.slope, mu_flat, lam, targets)
    force = q.reshape(*batch, steps) * load[..., None]
    return jnp.where(valid[..., None], force, jnp.nan)
