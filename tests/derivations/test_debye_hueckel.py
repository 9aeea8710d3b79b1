"""The small-voltage series: its SymPy derivation and the generated kernels agree; the series
meets two independent limits (the linear solution; the exact ``B1`` root)."""

import math

import mpmath as mp
import numpy as np
import pytest
import sympy as sp

from derivations import debye_hueckel as DH
from ipmc_asym.kernels import _generated_dh as G
from ipmc_asym.kernels.closed import b1_model


@pytest.fixture(scope="module")
def pert():
    return DH.perturbation()


def test_leading_order_is_the_linear_solution():
    assert DH.check_leading()


def test_series_is_even_and_layer_limit(pert):
    """``I2`` has the layer limit ``lam j1 + lam^2 j2`` of the generated ``dh_layer_j``."""
    j = DH.layer_limit(pert[2])
    for A2, A3, r in ((1e-3, 0.3, 1.0), (2e-3, -0.2, 0.0), (1.5e-3, 0.7, 0.4)):
        J1, J2 = G.dh_layer_j.py_func(A2, A3, r)
        sub = {DH.A3: A3, DH.rho: r}
        assert J1 == pytest.approx((1 + A3) + A2**2 * float(j[0].subs(sub)), rel=1e-14)
        assert J2 == pytest.approx(-(1 + A3) + A2**2 * float(j[1].subs(sub)), rel=1e-14)


@pytest.mark.parametrize("seed", range(3))
def test_dh_moment_kernel_matches_sympy(pert, seed):
    rng = np.random.default_rng(seed)
    f = [sp.lambdify((DH.u, DH.E, DH.rho, DH.A3), pert[k], "mpmath") for k in (0, 2)]
    with mp.workdps(40):
        for _ in range(20):
            uu = float(10 ** rng.uniform(-1.5, 5))
            A2, A3, r = float(rng.uniform(0, 2e-3)), float(rng.uniform(-0.5, 1)), float(rng.uniform(0, 1))
            ref = f[0](mp.mpf(uu), mp.exp(uu), r, A3) + mp.mpf(A2) ** 2 * f[1](mp.mpf(uu), mp.exp(uu), r, A3)
            got = G.dh_moment.py_func(uu, A2, A3, r)
            assert abs(got - float(ref)) <= 2e-13 * abs(float(ref)), (uu, A2, A3, r)
            n = mp.coth(uu) / uu - 1 / uu**2
            assert G.dh_norm.py_func(uu) == pytest.approx(float(n), rel=2e-13)


@pytest.mark.parametrize("rho", [0.0, 5 / 1005, 0.5, 1.0])
def test_b1_series_against_exact_root(rho):
    """``dh_b1`` against the exact root of the electroneutrality quadratic at A2 = 2e-3
    (where the root's own rounding is ~1e-16 absolute): agreement to O(A2^5)."""
    for A2 in (1e-3, 2e-3):
        assert abs(G.dh_b1.py_func(A2, rho) - b1_model.py_func(A2, rho, -1)) < 1e-14


@pytest.mark.slow
def test_remainder_constants_bound_the_next_term():
    """Spot values of the order-4 term within the bound the kernels use (``MARGIN`` included)."""
    # the order-4 term as ``derive`` gets it (``order_four``), evaluated with its common
    # subexpressions shared; the spot points are not the grid the constants come from
    I4 = sp.lambdify((DH.u, DH.E, DH.rho, DH.A3), DH.order_four(), "mpmath", cse=True)
    with mp.workdps(60):
        for uu in (0.05, 0.7, 3.0, 40.0, 3000.0):
            n = mp.coth(uu) / uu - 1 / uu**2
            for r in (0.1, 5 / 1005, 0.9):
                for A3 in (-0.4, 0.3, 2.0):
                    v = I4(mp.mpf(uu), mp.exp(uu), r, A3)
                    assert abs(v) <= (G.DH_K4A + G.DH_K4B * abs(A3)) * n, (uu, r, A3)
    assert math.isclose(G.DH_A2, DH.DH_A2)
