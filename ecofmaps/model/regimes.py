"""The regimes of a fretting contact, as integer codes that maps and results store."""

from __future__ import annotations

from ecofmaps._codes import Code

__all__ = ["GROSS_SLIP", "INVALID", "NO_GROSS_SLIP", "SELF_LOCKING", "Regime"]


class Regime(Code):
    """Regime codes returned by :func:`regime` and stored in maps.

    Attributes
    ----------
    GROSS_SLIP
        :math:`\\mu\\lambda < 1`: the contact slips over part of every cycle.
    NO_GROSS_SLIP
        :math:`\\mu\\lambda \\ge 1`: the rig's deflection takes all of the amplitude;
        the contact sticks, :math:`\\delta^* = 0`, :math:`E_d = 0`, :math:`\\mu_E` undefined.
    SELF_LOCKING
        Rigid rig (:math:`\\lambda = 0`) and :math:`\\mu\\kappa \\ge 1`: the pad jams on the
        groove flank before the end of the stroke; no solution.
    INVALID
        An input outside its valid range (or NaN).
    """

    GROSS_SLIP = 0, "gross slip"
    NO_GROSS_SLIP = (
        1,
        "no gross slip",
        "no gross slip (mu * load / (stiffness * amplitude) >= 1), so the energy coefficient "
        "of friction is undefined",
    )
    SELF_LOCKING = (
        2,
        "self-locking",
        "self-locking (rigid rig with mu * curvature number >= 1: the pad jams on the groove "
        "flank)",
    )
    INVALID = 3, "invalid", "invalid input"


GROSS_SLIP = Regime.GROSS_SLIP
NO_GROSS_SLIP = Regime.NO_GROSS_SLIP
SELF_LOCKING = Regime.SELF_LOCKING
INVALID = Regime.INVALID
