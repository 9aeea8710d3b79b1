"""The sensing BVP against the exact linear (Debye-Hueckel) solution, evaluated independently in mpmath."""

import mpmath as mp
import pytest

from ipmc_asym.bvp.sensing import solve_sensing


@pytest.mark.parametrize("lam", [0.3, 0.05, 3e-3, 3e-5])
@pytest.mark.parametrize("rho", [0.0, 1.0])
def test_small_b_is_the_linear_solution(lam, rho):
    b = 1e-7  # nonlinear corrections ~ b^2 ~ 1e-14
    L = mp.mpf(lam)
    sig = -b * (mp.coth(1 / L) - L)  # derivations.sensing:linear_solution
    voc = 2 * b * (1 - L * mp.tanh(1 / L))
    rs = solve_sensing(b, lam, rho, 0.38, load="short")
    ro = solve_sensing(b, lam, rho, 0.38, load="open")
    assert rs.success and ro.success
    assert rs.value == pytest.approx(float(sig), rel=1e-8)
    assert ro.value == pytest.approx(float(voc), rel=1e-8)
