"""Reciprocity of the linear two-port: dQ/dw at V = 0 (sensing) against dF/dV at w = 0 (actuation).

A two-port derived from a free energy has ``dQ/dw|_V = dF/dV|_w`` (``Q`` the charge of the
electrode where ``V = phi(-e) - phi(e)`` is applied, ``F`` the strip's force on the blocker along
``w``).  Derived in ``derivations/sensing.py:reciprocity_ratio``: the paper's model gives the
ratio ``(1 - 2 nu)/(3 (1 + A3))`` at every thickness, with or without the pressure term, so it
does NOT derive from one free energy.  Here both sides come from the shipped code (the sensing
closed form; the actuation's blocking force by a central difference at +-0.1 mV, where the
moment is linear up to relative O(A2^2) ~ 1e-5) and their ratio is compared with that prediction.
"""

import pytest

import ipmc_asym as ia
from ipmc_asym.model import groups

MAT = ia.NAFION_LI
V = 1e-4  # A2 = 3.9e-3: the central difference's error is O(A2^2) ~ 1e-5 relative


def _ratio(model, thickness, nu, pressure_term, fidelity):
    s = ia.Strip(thickness=thickness)
    fp = ia.evaluate(s.with_(voltage=V), model, fidelity, pressure_term=pressure_term)
    fm = ia.evaluate(s.with_(voltage=-V), model, fidelity, pressure_term=pressure_term)
    # the actuator bends toward -z (w_small < 0 at V > 0): its force on the blocker is along -z
    assert fp["w_small"] < 0.0
    dFdV = -(fp["F_block_small"] - fm["F_block_small"]) / (2.0 * V)
    r = ia.sense(s, tip_displacement=0.0, support="tip-force", model=model, nu=nu, pressure_term=pressure_term)
    return float(r.Q_per_w[0]) / dFdV


@pytest.mark.parametrize("model", ("constant", "linear", "affine"))
@pytest.mark.parametrize("thickness", (20e-6, 200e-6))
@pytest.mark.parametrize("nu", (0.0, 0.3))
def test_ratio_is_the_derived_mismatch(model, thickness, nu):
    pred = (1.0 - 2.0 * nu) / (3.0 * (1.0 + float(groups.A3(MAT))))
    got = _ratio(model, thickness, nu, False, "corrected")
    # the sign agrees (both negative); the magnitude does not: 0.256 at nu = 0
    assert got == pytest.approx(pred, rel=2e-5)
    assert abs(got - 1.0) > 0.5


@pytest.mark.slow
@pytest.mark.parametrize("model", ("constant", "linear", "affine"))
def test_ratio_with_the_pressure_term(model):
    pred = 1.0 / (3.0 * (1.0 + float(groups.A3(MAT))))
    assert _ratio(model, 200e-6, 0.0, True, "exact") == pytest.approx(pred, rel=2e-5)
