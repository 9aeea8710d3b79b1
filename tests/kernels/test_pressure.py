"""The ``exact`` rung with the pressure term (kernels/pressure.py) against independent references.

* ``beta -> 0``: the paper's ``exact`` rung (kernels/exact.py), a different code path;
* the closed forms ``S``, ``V``, ``P`` against adaptive quadrature of their defining integrands
  (``derivations/pressure.py``);
* the full BVP with the pressure term (bvp/pressure.py, test in tests/bvp/test_pressure.py).
"""

import math

import pytest
from scipy.integrate import quad

from ipmc_asym.kernels.exact import moment_exact
from ipmc_asym.kernels.pressure import _p_of_y, _s_of_y, _v_of_y, moment_pressure, pressure_groups
from ipmc_asym.model.params import NAFION_LI, Strip
from ipmc_asym.model.permittivity import get_model

A3 = 0.3027


def _args(model, th, v):
    g = get_model(model).groups(Strip(thickness=th, voltage=v), NAFION_LI)
    return math.sqrt((g.A0 + g.A1) / g.A2), g.A2, g.A3, g.A1 / (g.A0 + g.A1)


@pytest.mark.parametrize("rho", [1.0, 0.0, 5 / 1005])
@pytest.mark.parametrize("beta", [-0.0242, 0.02, -1e-7])
def test_closed_forms_against_quadrature(rho, beta):
    g0, b0 = pressure_groups(beta, A3)
    for y in (-30.0, -3.0, -0.7, -0.3, -1e-3, 2e-4, 0.2, 0.6, 2.0, 5.0, 13.0):
        if 1.0 - b0 * math.expm1(y) <= 0.0:
            continue

        def integ(f):
            return quad(f, 0.0, y, epsabs=0.0, epsrel=1e-13, limit=400)[0]

        S = integ(lambda u: 2 * (1 + (1 - rho) * math.expm1(u)) * math.expm1(u) / (1 - b0 * math.expm1(u)))
        V = integ(lambda u: 1 / (g0 * (1 - b0 * math.expm1(u))))
        P = integ(lambda u: (math.exp(u) + A3) / (g0 * (1 - b0 * math.expm1(u))))
        assert _s_of_y(y, rho, b0) == pytest.approx(S, rel=1e-12)
        assert _v_of_y(y, b0, g0) - _v_of_y(0.0, b0, g0) == pytest.approx(V, rel=1e-12)
        assert _p_of_y(y, A3, b0, g0) == pytest.approx(P, rel=1e-12)


@pytest.mark.parametrize("model", ["constant", "linear", "affine"])
@pytest.mark.parametrize("th,v", [(200e-6, 1.0), (2e-6, 0.3), (1e-6, 20.0), (200e-6, 1e-3)])
def test_beta_to_zero_reproduces_the_paper_model(model, th, v):
    a = _args(model, th, v)
    I0 = moment_exact(*a)[0]
    r0 = moment_pressure(*a, 0.0)
    assert r0[4] > 0
    assert r0[0] == pytest.approx(I0, rel=1e-11)
    # and the limit is approached linearly: the change is O(beta)
    d1 = moment_pressure(*a, 1e-6)[0] / I0 - 1.0
    d2 = moment_pressure(*a, 2e-6)[0] / I0 - 1.0
    assert abs(d1) < 1e-5
    assert d2 == pytest.approx(2.0 * d1, rel=1e-3, abs=1e-12)


@pytest.mark.parametrize("th,v", [(200e-6, 10.0), (1e-6, 20.0), (10e-6, 5.0), (1e-2, 20.0)])
def test_panel_refinement_where_the_bvp_does_not_converge(th, v):
    """Constant model, beta < 0, >= 5 V: C(1)/C_moy reaches 1e3-1e9 and the BVP with the pressure
    term does not converge from the paper's solution; a different discretisation (panels split in
    two, 14 instead of 10 Gauss-Legendre nodes) must agree within the stated 1e-11."""
    import numpy as np

    from ipmc_asym.kernels.pressure import _S, _W, _X, moment_pressure_nodes
    from ipmc_asym.kernels.special import gauss_legendre

    X2, W2, S2 = (np.ascontiguousarray(a) for a in gauss_legendre(14))
    a = _args("constant", th, v) + (-0.0241,)
    r1 = moment_pressure_nodes(*a, _X, _W, _S, 1)
    r2 = moment_pressure_nodes(*a, X2, W2, S2, 2)
    assert r1[4] > 0 and r2[4] > 0
    assert r2[0] == pytest.approx(r1[0], rel=1e-11)
