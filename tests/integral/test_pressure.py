"""integral/pressure.py: the two rungs with the pressure term agree; zero volts; refusals."""

import numpy as np
import pytest

from ipmc_asym.integral.pressure import moment_pressure_term
from ipmc_asym.model.params import NAFION_LI


def test_rungs_agree_and_zero_voltage():
    th, v = np.array([200e-6, 200e-6, 10e-6]), np.array([1.0, 0.0, -0.5])
    e = moment_pressure_term(th, v, "affine", "exact", NAFION_LI)
    b = moment_pressure_term(th, v, "affine", "bvp", NAFION_LI)
    assert np.all(e.success) and np.all(b.success)
    assert e.I[1] == 0.0 and b.I[1] == 0.0
    np.testing.assert_allclose(e.I, b.I, rtol=1e-10)
    np.testing.assert_allclose(e.B1, b.B1, rtol=1e-10)
    assert np.sign(e.I[2]) == -1.0
    assert e.beta == pytest.approx((NAFION_LI.v1 - NAFION_LI.M1 * NAFION_LI.v2 / NAFION_LI.M2) * NAFION_LI.C_moy)


def test_refusals():
    with pytest.raises(ValueError, match="fidelity"):
        moment_pressure_term(200e-6, 1.0, "constant", "quadrature")
    with pytest.raises(ValueError, match="paper's permittivity"):
        moment_pressure_term(200e-6, 1.0, lambda C: 1e-5 + 0 * C, "exact")
