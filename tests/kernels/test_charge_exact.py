"""The exact charge kernels: small-voltage series, exact solution, analytic C_d, neutral-core asymptotics."""

import math

import mpmath as mp
import numpy as np
import pytest

from ipmc_asym.kernels import _generated_charge as GC
from ipmc_asym.kernels.charge_exact import (
    SMALL_A2,
    _w_cheap_bound,
    _w_side,
    charge_exact_point,
    kappa_neutral_log,
    layer_potentials,
)

RHOS = (0.0, 1.0 / 201.0, 1.0 / 3.0, 0.5, 1.0)


def _yc_mp(A2, rho):
    """ln B1 from the exact quadratic of electroneutrality (derivations.model:b1_quadratic_rho), 60 digits."""
    mp.mp.dps = 60
    A2 = mp.mpf(A2)
    q = -mp.expm1(-A2)
    a = (1 - rho) * q * (2 - q) / 2
    b = (2 * rho - 1) * q
    c = -rho * A2
    root = -c / b if a == 0 else (-b + mp.sqrt(b * b - 4 * a * c)) / (2 * a)
    return mp.log(root)


@pytest.mark.parametrize("rho", RHOS)
def test_small_voltage_series_within_its_bound(rho):
    for A2 in (1e-12, 1e-6, 1e-3, 0.05, 0.2, SMALL_A2):
        r, bound = GC.yc_small(A2, rho)
        ref = _yc_mp(A2, mp.mpf(rho)) / A2
        assert abs(r / float(ref) - 1) <= bound + 4e-16
        Yc, Ya, b = layer_potentials(A2, rho, -1)
        assert Yc == pytest.approx(float(_yc_mp(A2, mp.mpf(rho))), rel=1e-15)
        assert Ya == pytest.approx(float(_yc_mp(A2, mp.mpf(rho)) - A2), rel=1e-15)
    # just above the switch the closed root takes over without a jump
    for A2 in (SMALL_A2 * (1 + 1e-12), 0.3, 2.0, 40.0):
        Yc, _, b = layer_potentials(A2, rho, -1)
        assert b == 0.0 and Yc == pytest.approx(float(_yc_mp(A2, mp.mpf(rho))), rel=2e-15)


@pytest.mark.parametrize("lam", [1e-4, 0.02, 0.1, 0.5, 1.2, 5.0])
def test_linear_model_exact_solution(lam):
    """rho = 0: D(1) = lam tanh(A2/2) coth(1/lam) exactly (derivations.charge:linear_exact), and its derivative."""
    for A2 in (1e-25, 1e-9, 1e-3, 0.1, 1.0, 10.0, 200.0):
        Yc, Ya, _ = layer_potentials(A2, 0.0, -1)
        g, cd, t, niter = charge_exact_point(lam, A2, 0.0, Yc, Ya)
        assert niter > 0
        coth = 1.0 / math.tanh(1.0 / lam)
        assert g == pytest.approx(math.tanh(A2 / 2) / A2 * coth, rel=2e-13)
        assert cd == pytest.approx(0.5 / math.cosh(A2 / 2) ** 2 * coth, rel=2e-13, abs=1e-300)
        # kappa/Dc = 1/sinh(1/lam) (derivations.exact:linear_check)
        if 1.0 / lam < 700:
            assert t == pytest.approx(1.0 / math.sinh(1.0 / lam), rel=2e-13)


@pytest.mark.parametrize("rho", [1.0, 1.0 / 201.0, 0.5])
@pytest.mark.parametrize("lam", [0.03, 0.4, 1.2])
def test_capacitance_is_the_derivative_of_the_exact_charge(rho, lam):
    """The implicit derivative against a 6th-order difference quotient of the exact sigma_hat."""
    for A2 in (0.02, 1.0, 9.0, 60.0):
        def sh(a):
            Yc, Ya, _ = layer_potentials(a, rho, -1)
            return charge_exact_point(lam, a, rho, Yc, Ya)[0] * a

        h = 1e-3 * max(1.0, A2)
        d = (45 * (sh(A2 + h) - sh(A2 - h)) - 9 * (sh(A2 + 2 * h) - sh(A2 - 2 * h)) + (sh(A2 + 3 * h) - sh(A2 - 3 * h))) / (60 * h)
        Yc, Ya, _ = layer_potentials(A2, rho, -1)
        cd = charge_exact_point(lam, A2, rho, Yc, Ya)[1]
        assert cd == pytest.approx(d, rel=1e-9)


def test_neutral_core_asymptotics_of_kappa():
    """ln kappa of thick strips against the exact solver (t = kappa/Dc), and the exact linear kappa."""
    for rho in RHOS:
        for A2 in (1e-6, 0.5, 5.0, 80.0):
            Yc, Ya, _ = layer_potentials(A2, rho, -1)
            lam = 0.05
            t = charge_exact_point(lam, A2, rho, Yc, Ya)[2]
            Dc = t  # t = kappa/Dc: compare ln kappa - ln Dc
            from ipmc_asym.kernels import _generated as G
            ln_t = kappa_neutral_log(lam, Yc, Ya, rho) - math.log(G.dhat(Yc, rho))
            assert math.log(Dc) == pytest.approx(ln_t, abs=2e-3)
    # linear model: W(Yc) + W(Ya) = 2 ln(B1 - 1) exactly
    for A2 in (1e-4, 1.0, 30.0):
        Yc, Ya, _ = layer_potentials(A2, 0.0, -1)
        assert _w_side(Yc, 0.0) + _w_side(Ya, 0.0) == pytest.approx(2 * math.log(math.expm1(Yc)), abs=1e-9)


def test_cheap_bound_of_w():
    """The cheap bound that skips the neutral-core quadrature is an upper bound of W(Yc) + W(Ya)."""
    for rho in np.linspace(0.0, 1.0, 11):
        for A2 in np.geomspace(1e-29, 3000.0, 60):
            Yc, Ya, _ = layer_potentials(A2, rho, -1)
            assert _w_side(Yc, rho) + _w_side(Ya, rho) <= _w_cheap_bound(Yc, Ya, rho)
