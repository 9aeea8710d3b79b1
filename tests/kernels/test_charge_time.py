"""The reduced circuit's time stepper at the limits of its drive: zero and subnormal voltages."""

import numpy as np
import pytest

from ipmc_asym.integral.api import paper_model_id
from ipmc_asym.kernels.charge import GL_W, GL_X
from ipmc_asym.kernels.charge_time import integrate_circuit
from ipmc_asym.model.permittivity import get_model


def _run(psi0, model="constant"):
    """Layer voltage A and charge s of a step of ``psi0`` (R T/F) over 5 tau on a graded grid."""
    perm = get_model(model)
    tt = np.concatenate(([0.0], np.geomspace(1e-4, 5.0, 400)))
    A, s = np.empty(tt.size), np.empty(tt.size)
    integrate_circuit(tt, np.full(tt.size, psi0), perm.eps0 / perm.eps_moy, paper_model_id(perm), GL_X, GL_W,
                      A, s, np.zeros(5))
    return A, s


@pytest.mark.parametrize("model", ["constant", "affine"])
def test_a_zero_drive_leaves_the_strip_uncharged_exactly(model):
    # the root of every implicit step is 0 itself: nothing may be made of rounding
    A, s = _run(0.0, model)
    assert not A.any() and not s.any()


@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_a_subnormal_step_is_the_small_signal_step_scaled(sign):
    # far below the thermal voltage the circuit is linear: a subnormal step is a normal small step
    # scaled, up to the subnormals' few significant bits (4e-319 carries ~16 of them; each of the
    # few hundred steps rounds its increments to them: measured 1.7e-3 of the final charge)
    small = sign * 4e-319
    A_ref, s_ref = _run(sign * 4e-9)
    A, s = _run(small)
    scale = small / (sign * 4e-9)
    for got, ref in ((s, s_ref * scale), (A, A_ref * scale)):
        assert np.max(np.abs(got - ref)) <= 1e-2 * np.max(np.abs(ref))
    assert np.all(np.diff(sign * s) >= 0.0) and sign * s[-1] > 0.0  # the step's charge grows, with its sign
