"""The ``pressure_term`` option through the one forward model."""

import numpy as np
import pytest

from ipmc_asym.forward.model import forward
from ipmc_asym.model.params import NAFION_LI


def test_default_is_the_paper_model():
    a = forward(0.02, 5e-3, 200e-6, 1.0, model="affine", fidelity="exact")
    b = forward(0.02, 5e-3, 200e-6, 1.0, model="affine", fidelity="exact", pressure_term=False)
    assert float(a.I) == float(b.I)


@pytest.mark.parametrize("model", ["constant", "affine"])
def test_beta_zero_reproduces_default(model):
    # v1 = M1 v2/M2 makes beta = 0: the option must give the paper's exact rung
    mat = NAFION_LI.with_(v1=NAFION_LI.M1 * NAFION_LI.v2 / NAFION_LI.M2)
    th, v = np.array([200e-6, 5e-6, 200e-6]), np.array([1.0, 0.5, -2.0])
    ref = forward(0.02, 5e-3, th, v, model=model, fidelity="exact", escalate=False)
    got = forward(0.02, 5e-3, th, v, model=model, material=mat, pressure_term=True)
    assert np.all(got.fidelity_used == "exact")
    np.testing.assert_allclose(got.I, ref.I, rtol=1e-11)
    np.testing.assert_allclose(got.M_A, ref.M_A, rtol=1e-11)


def test_exact_and_bvp_rungs_agree():
    th, v = np.array([200e-6, 20e-6]), np.array([1.0, -0.3])
    e = forward(0.02, 5e-3, th, v, model="constant", fidelity="exact", pressure_term=True, escalate=False)
    b = forward(0.02, 5e-3, th, v, model="constant", fidelity="bvp", pressure_term=True, escalate=False)
    assert np.all(e.fidelity_used == "exact") and np.all(b.fidelity_used == "bvp")
    np.testing.assert_allclose(e.I, b.I, rtol=1e-10)


def test_refusals():
    with pytest.raises(ValueError, match="pressure term"):
        forward(0.02, 5e-3, 200e-6, 1.0, fidelity="leading", escalate=False, pressure_term=True)
    with pytest.raises(ValueError, match="c_moy"):
        forward(0.02, 5e-3, 200e-6, 1.0, c_moy=3000.0, pressure_term=True)
