r"""Fretting loops from the model: :func:`fretting_loop` draws the steady loop in closed form
(Figures 5 and 6 of the paper); :func:`simulate` runs the stick/slip return map over any
displacement history, exactly at each step (``docs/model.md``).
"""

from __future__ import annotations

from functools import partial

import jax
import jax.numpy as jnp

from ecofmaps._inputs import check, float64, is_concrete
from ecofmaps.model import core
from ecofmaps.model.on_profile import broadcast_history, profile_loop, profile_simulation
from ecofmaps.model.regimes import GROSS_SLIP, INVALID, NO_GROSS_SLIP
from ecofmaps.model.steady_state import dimensionless, one_geometry


@partial(jax.jit, static_argnames="num")
def _steady_loop(amplitude, load, stiffness, mu, aspect_ratio, groove_half_width, num):
    mu, kappa, lam, code = dimensionless(
        amplitude, load, stiffness, mu, aspect_ratio, groove_half_width
    )
    mu, kappa, lam, code = (x[..., None] for x in (mu, kappa, lam, code))
    d = core.slip_ratio(mu, kappa, lam)
    t = jnp.linspace(-1.0, 1.0, num)
    # Forward-slip branch from -d to d (eq. 9, 10), sampled as docs/model.md explains: the
    # margin w = 1 - mu*kappa*xi falls geometrically on a deep groove (u = mu*kappa*d >= 1/2).
    a = mu * kappa
    u = a * d
    shallow = u < 0.5
    w_end = jnp.where(shallow, 0.5, core.locking_margin(1.0, mu, kappa, lam))
    w_deep = (1.0 + u) * jnp.exp((t + 1.0) / 2.0 * jnp.log(w_end / (1.0 + u)))
    xi = jnp.where(shallow, t * d, (1.0 - w_deep) / jnp.where(shallow, 1.0, a))
    w = jnp.where(shallow, 1.0 - a * xi, w_deep)
    xi = xi.at[..., 0].set(-d[..., 0]).at[..., -1].set(d[..., 0])
    q_slip = (mu + kappa * xi) / w  # eq. 9
    # No gross slip: the contact sticks at the centre and the loop is the line Q = S*Delta.
    stick = code == int(NO_GROSS_SLIP)
    ok = (code == int(GROSS_SLIP)) | stick
    target = jnp.where(ok, jnp.where(stick, t, xi + lam * q_slip), jnp.nan)
    q = jnp.where(ok, jnp.where(stick, t / jnp.where(stick, lam, 1.0), q_slip), jnp.nan)
    # The loop starts at the reversal point (-1, -q*); the backward branch is the forward
    # one turned through 180 degrees, and it ends where the loop began.
    start_target = jnp.where(ok[..., :1], -1.0, jnp.nan)
    targets = jnp.concatenate([start_target, target, -target], axis=-1)
    forces = jnp.concatenate([-q[..., -1:], q, -q], axis=-1)
    return targets * amplitude[..., None], forces * load[..., None]


@float64
def fretting_loop(
    amplitude,
    load,
    stiffness,
    mu,
    aspect_ratio=None,
    groove_half_width=None,
    num=201,
    *,
    profile=None,
    mapping="scaled",
):
    r"""The steady fretting loop: displacement and tangential force around one cycle, its slip
    branches :math:`\Delta = x + Q_\pm(x)/S` (eq. 9, 10) sampled as ``docs/model.md`` explains.

    Parameters
    ----------
    amplitude, load, stiffness, mu, aspect_ratio, groove_half_width, profile, mapping
        As for :func:`ecofmaps.slip_amplitude`: :math:`\Delta^*` [m], :math:`P` [N], :math:`S`
        [N/m], :math:`\mu` [1], :math:`z_o/x_o` [1] or a scar ``profile``, :math:`x_o` [m]
        (default ``amplitude``) and the mapping onto the profile.
    num : int
        Points on each slip branch (>= 2). [1]

    Returns
    -------
    displacement, force : jax.Array of float64
        Shape ``broadcast(inputs).shape + (2 * num + 1,)``: from the reversal
        :math:`(-\Delta^*, -Q^*)` stick, slip to :math:`(\Delta^*, Q^*)`, stick, slip back to
        the first point, clockwise (the shoelace sum :math:`\oint Q\,d\Delta` is
        :math:`E_d > 0`); NaN when self-locking or off a profile's trace. [m], [N]

    Raises
    ------
    ValueError
        For a concrete input out of range (see :func:`ecofmaps.slip_amplitude`), or
        ``num < 2``.

    References
    ----------
    X. Jin, W. Sun, P.H. Shipway (2016), Derivation of a wear scar geometry-independent coefficient
    of friction from fretting loops exhibiting non-Coulomb frictional behaviour: eq. 9, 10, 11.
    """
    if not isinstance(num, int) or num < 2:
        raise ValueError(f"num must be an integer >= 2, got {num!r}")
    one_geometry(aspect_ratio, profile, mapping)
    if profile is not None:
        return profile_loop(
            profile, amplitude, load, stiffness, mu, groove_half_width, mapping, num
        )
    values = core.steady_inputs(amplitude, load, stiffness, mu, aspect_ratio, groove_half_width)
    return _steady_loop(*jnp.broadcast_arrays(*values), num=num)


@jax.jit
def _return_map(displacement, mu, kappa, lam, length):
    """Stick/slip history in the units of ``length``: contact position and Q/P."""
    target = jnp.moveaxis(displacement / length[..., None], -1, 0)

    def step(state, d):
        xi, q = state
        gap = d - xi
        forward = gap > lam * core.traction_ratio(xi, mu, kappa)
        backward = gap < lam * core.traction_ratio(xi, mu, kappa, -1.0)
        xi_forward, w_forward = core.slip_roots(d, mu, kappa, lam)
        xi_backward, w_backward = core.slip_roots(-d, mu, kappa, lam)
        q_forward = (mu + kappa * xi_forward) / w_forward  # eq. 9, digits kept near locking
        q_backward = -(mu + kappa * xi_backward) / w_backward
        q_stick = jnp.where(lam > 0.0, gap / jnp.where(lam > 0.0, lam, 1.0), q)
        xi_new = jnp.where(forward, xi_forward, jnp.where(backward, -xi_backward, xi))
        q_new = jnp.where(forward, q_forward, jnp.where(backward, q_backward, q_stick))
        q_new = jnp.where(jnp.isfinite(q_new), q_new, jnp.nan)
        return (xi_new, q_new), q_new

    _, q = jax.lax.scan(step, (jnp.zeros(target.shape[1:]),) * 2, target)
    return jnp.moveaxis(q, 0, -1)


@float64
def simulate(
    displacement,
    load,
    stiffness,
    mu,
    aspect_ratio=None,
    groove_half_width=None,
    *,
    profile=None,
    mapping="scaled",
):
    r"""Tangential force history for any actuator displacement history :math:`\Delta(t)`: from
    rest at the groove centre, the pad sticks or slips to the exact equilibrium at each step
    (eq. 9, 10, 16; ``docs/model.md``).

    Parameters
    ----------
    displacement : array_like
        Actuator displacement :math:`\Delta` at successive instants, time along the last
        axis; any leading axes broadcast against the other parameters. [m]
    load, stiffness, mu, aspect_ratio, profile, mapping
        As for :func:`ecofmaps.slip_amplitude`: :math:`P` [N], :math:`S` [N/m], :math:`\mu`
        [1], and :math:`z_o/x_o` [1] or a scar ``profile`` and its mapping.
    groove_half_width : array_like
        Groove half-width :math:`x_o`, required except in the physical mapping (the amplitude
        matches the steady loop of :func:`ecofmaps.fretting_loop`). [m]

    Returns
    -------
    force : jax.Array of float64
        Tangential force :math:`Q` at each instant, shape of ``displacement`` broadcast
        with the parameters' shape plus the time axis. NaN once a rigid rig drives the pad
        into the locking point, or the pad runs off a profile's trace. [N]

    Raises
    ------
    ValueError
        For a concrete input out of range; ``displacement`` must be finite.

    References
    ----------
    X. Jin, W. Sun, P.H. Shipway (2016), Derivation of a wear scar geometry-independent coefficient
    of friction from fretting loops exhibiting non-Coulomb frictional behaviour: eq. 9, 10, 11, 16.
    """
    check("displacement", displacement, "finite", "m")
    if is_concrete(displacement) and jnp.ndim(displacement) == 0:
        raise ValueError("displacement must have a time axis (at least one dimension)")
    one_geometry(aspect_ratio, profile, mapping)
    if profile is not None:
        return profile_simulation(
            profile, displacement, load, stiffness, mu, groove_half_width, mapping
        )
    if groove_half_width is None:
        raise ValueError("simulate with aspect_ratio needs groove_half_width (x_o) [m]")
    load, stiffness, mu, aspect_ratio, length = core.steady_inputs(
        None, load, stiffness, mu, aspect_ratio, groove_half_width
    )
    mu, kappa, lam, code = dimensionless(length, load, stiffness, mu, aspect_ratio, length)
    displacement, (mu, kappa, lam, length, load, code) = broadcast_history(
        displacement, mu, kappa, lam, length, load, code
    )
    force = _return_map(displacement, mu, kappa, lam, length) * load[..., None]
    return jnp.where(code[..., None] == int(INVALID), jnp.nan, force)
