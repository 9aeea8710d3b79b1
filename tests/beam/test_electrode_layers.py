"""Metal electrode layers in the beam: the composite section against independent mechanics.

The composite stiffness is checked against the parallel-axis theorem layer by layer (not the
closed form the code uses), the statics against ``w_p = -M_A L^2/(2 EI)`` with the moment of
the bare membrane (the symmetric section keeps the neutral axis, so ``M_A`` is unchanged), and
the resonances against the exact cantilever eigenvalue ``b1 = 1.875104068711961``.
"""

import math

import numpy as np
import pytest

from ipmc_asym.beam.dynamics import Beam, first_resonance, hydrated_density, natural_frequencies
from ipmc_asym.forward.model import forward
from ipmc_asym.model.electrode import METALS, NO_ELECTRODE, Electrode, electrode_from_spec
from ipmc_asym.model.params import NAFION_LI, material_from_spec

B1 = 1.875104068711961  # first root of 1 + cos b cosh b = 0 (clamped-free)


def _parallel_axis_EI(Ep, Em, w, h, t):
    """E I of the membrane plus two layers, each ``w t^3/12 + w t d^2`` about the mid-plane."""
    d = 0.5 * h + 0.5 * t  # distance of a layer's centroid from the neutral axis
    layer = w * t**3 / 12.0 + w * t * d * d
    return Ep * w * h**3 / 12.0 + 2.0 * Em * layer


def _platinum(t):
    return NAFION_LI.with_(electrode=electrode_from_spec({"thickness": t, "metal": "platinum"}))


@pytest.mark.parametrize("t", [1e-6, 5e-6, 20e-6])
def test_small_deflection_equals_moment_over_composite_stiffness(t):
    L, w, h, V = 0.02, 5e-3, 200e-6, 1.0
    mat = _platinum(t)
    bare = forward(L, w, h, V, material=NAFION_LI, model="constant", fidelity="quadrature")
    lay = forward(L, w, h, V, material=mat, model="constant", fidelity="quadrature")
    Em = METALS["platinum"][0]
    EI = _parallel_axis_EI(NAFION_LI.E, Em, w, h, t)
    M = float(bare.M_A)
    assert float(lay.M_A) == M  # the electrochemistry keeps the membrane thickness
    assert float(lay.w_small) == pytest.approx(-M * L * L / (2.0 * EI), rel=1e-13)
    assert float(lay.theta) == pytest.approx(-M * L / EI, rel=1e-13)
    # the polymer's face strain e |kappa| (the membrane's face, not the metal's outer face)
    assert float(lay.max_strain) == pytest.approx(0.5 * h * abs(M) / EI, rel=1e-13)
    # the stiffer beam bends less
    assert abs(float(lay.w)) < abs(float(bare.w))


def test_no_layer_is_the_bare_membrane_bit_for_bit():
    L, w = np.array([0.01, 0.02, 0.03]), 5e-3
    h, V = np.array([100e-6, 200e-6, 300e-6]), np.array([0.5, 1.0, 2.0])
    zero = material_from_spec({"electrode_thickness": 0.0, "electrode_metal": "gold"})
    assert zero == NAFION_LI and zero.electrode is NO_ELECTRODE
    a = forward(L, w, h, V, material=NAFION_LI, model="affine", fidelity="quadrature")
    b = forward(L, w, h, V, material=zero, model="affine", fidelity="quadrature")
    for k in ("M_A", "theta", "w", "w_small", "F_block", "F_block_small", "max_strain"):
        assert np.array_equal(getattr(a, k), getattr(b, k)), k
    ba = Beam.from_strip(0.02, 5e-3, 200e-6, NAFION_LI, viscous_modulus=1e5)
    bb = Beam.from_strip(0.02, 5e-3, 200e-6, zero, viscous_modulus=1e5)
    assert ba == bb


@pytest.mark.parametrize("metal,t", [("platinum", 3e-6), ("gold", 10e-6)])
def test_resonances_scale_with_composite_section(metal, t):
    L, w, h = 0.03, 5e-3, 183e-6
    mat = NAFION_LI.with_(electrode=electrode_from_spec({"thickness": t, "metal": metal}))
    Em, rho_m, _ = METALS[metal]
    EI = _parallel_axis_EI(NAFION_LI.E, Em, w, h, t)
    rhoA = hydrated_density(NAFION_LI) * w * h + 2.0 * rho_m * w * t
    f1 = B1**2 * math.sqrt(EI / (rhoA * L**4)) / (2.0 * math.pi)
    b = Beam.from_strip(L, w, h, mat)
    assert float(natural_frequencies("clamped-free", b, 1)[0]) == pytest.approx(f1, rel=1e-12)
    assert float(first_resonance(L, w, h, mat)) == pytest.approx(f1, rel=1e-12)
    # clamped-clamped: first root of cos b cosh b = 1, 4.730040744862704
    fcc = 4.730040744862704**2 * math.sqrt(EI / (rhoA * L**4)) / (2.0 * math.pi)
    assert float(natural_frequencies("clamped-clamped", b, 1)[0]) == pytest.approx(fcc, rel=1e-10)


def test_viscous_time_acts_on_the_membrane_share():
    """Kelvin-Voigt on the membrane only: EI_total tau_eff = E_p I_p tau_v."""
    L, w, h, t, eta = 0.02, 5e-3, 200e-6, 5e-6, 2e6
    mat = _platinum(t)
    b = Beam.from_strip(L, w, h, mat, viscous_modulus=eta)
    EIp = NAFION_LI.E * w * h**3 / 12.0
    assert b.EI * b.tau_v == pytest.approx(EIp * eta / NAFION_LI.E, rel=1e-13)


def test_layer_needs_modulus_and_names_the_option():
    with pytest.raises(ValueError, match="--electrode-metal"):
        electrode_from_spec({"thickness": 5e-6}, {"thickness": "--electrode-thickness", "metal": "--electrode-metal",
                                                  "modulus": "--electrode-modulus"})
    with pytest.raises(ValueError, match="electrode.metal must be one of"):
        electrode_from_spec({"thickness": 5e-6, "metal": "copper"})
    with pytest.raises(ValueError, match="electrode thickness"):
        Electrode(-1e-6, 1e11, 1e4)
    given = electrode_from_spec({"thickness": 5e-6, "metal": "gold", "modulus": 50e9})
    assert given.modulus == 50e9 and given.density == METALS["gold"][1] and "given by the user" in given.source
