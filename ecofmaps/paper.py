r"""The paper ecofmaps implements: its citation, its worked examples and its figures' parameters.

Jin, Sun and Shipway (2016) add the rig's compliance to the wear-scar interaction model of
Mulvihill et al. Every value here is the paper's, in SI units, and every other module reads
it from here (``docs/model.md``)."""

import numpy as np

__all__ = [
    "AMPLITUDE",
    "ASPECT_RATIO",
    "CITATION",
    "EXAMPLE_1",
    "EXAMPLE_2",
    "EXAMPLE_2_FIT",
    "FIGURE_7_STIFFNESSES",
    "FIGURE_10_FITS",
    "FIGURE_11_AMPLITUDES",
    "FIGURE_11_STIFFNESS_RATIOS",
    "LOAD",
    "MODEL",
    "MU",
    "STIFFNESS",
]

#: How to cite the paper (also the ``references`` attribute of every map).
CITATION = (
    "X. Jin, W. Sun, P.H. Shipway (2016), Derivation of a wear scar geometry-independent "
    "coefficient of friction from fretting loops exhibiting non-Coulomb frictional behaviour"
)

#: One-line description of the model (the ``model`` attribute of every map).
MODEL = (
    "compliant wear-scar interaction model: a rigid round-ended pad with Coulomb friction in a "
    "parabolic groove z = z_o (x/x_o)^2, driven through a spring of stiffness S (the rig); "
    "steady loops of displacement amplitude Delta*, groove half-width x_o = Delta*"
)

# --- the test conditions of Sections 3 and 4 (cylinder-on-flat, Figure 3) ----------------

#: Displacement amplitude :math:`\Delta^*`, also the groove half-width :math:`x_o`. [m]
AMPLITUDE = 50e-6
#: Normal load :math:`P`. [N]
LOAD = 450.0
#: Rig stiffness :math:`S` of Example 2 and of Figures 5, 6 and 8. [N/m]
STIFFNESS = 35e6
#: Contact coefficient of friction :math:`\mu` of Section 3. [1]
MU = 0.8
#: Groove aspect ratio :math:`z_o/x_o` of Section 3's Example 2 and Figure 5. [1]
ASPECT_RATIO = 0.2

#: Example 2 as Section 3 states it (Figures 5 and 8): :math:`\mu_E` is about 4 % above
#: :math:`\mu`. Keyword arguments of :func:`ecofmaps.energy_cof` and friends.
EXAMPLE_2 = dict(
    amplitude=AMPLITUDE, load=LOAD, stiffness=STIFFNESS, mu=MU, aspect_ratio=ASPECT_RATIO
)

#: The two tests whose final loops Figure 10 fits (Section 4.2): :math:`\mu` = GICoF = 0.825,
#: :math:`S` = 45 and 35 MN/m, :math:`z_o` = 1.8 and 8.0 µm with :math:`x_o = \Delta^*`.
EXAMPLE_1 = {**EXAMPLE_2, "stiffness": 45e6, "mu": 0.825, "aspect_ratio": 1.8e-6 / AMPLITUDE}
EXAMPLE_2_FIT = {**EXAMPLE_1, "stiffness": 35e6, "aspect_ratio": 8.0e-6 / AMPLITUDE}

#: Figure 10's fits by name, and Section 3's Example 2: the points marked on the maps.
FIGURE_10_FITS = {
    "Example 1": EXAMPLE_1,
    "Example 2": EXAMPLE_2_FIT,
    "Example 2 (Section 3)": EXAMPLE_2,
}

# --- the grids of the figures ----------------------------------------------------------------

#: Rig stiffnesses of Figures 7 and 8, rigid included. [N/m]
FIGURE_7_STIFFNESSES = (20e6, 35e6, 50e6, 100e6, np.inf)
#: Displacement amplitudes of Figures 11a and 11b. [m]
FIGURE_11_AMPLITUDES = {"11a": 25e-6, "11b": 50e-6}
#: S/P of Figure 11's axis: 20 to 200 (MN/m)/kN. [1/m]
FIGURE_11_STIFFNESS_RATIOS = np.linspace(20e3, 200e3, 91)
