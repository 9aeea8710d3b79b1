"""The compiled right-hand sides of the transient solver against the scheme written out in NumPy."""

import math

import numpy as np
import pytest

from ipmc_asym.dynamics.transient import _LinearProblem, make_fv_mesh
from ipmc_asym.kernels.pnp import linear_rhs, newton_delta, sg_rhs


def _bernoulli(x):
    # B(x) = x/(e^x - 1) by expm1; the jumps across a face stay well inside |x| < 700 here
    x = np.asarray(x, dtype=float)
    small = np.abs(x) < 1e-6
    return np.where(small, 1.0 - x / 2.0, x / np.expm1(np.where(small, 1.0, x)))


def _sg_reference(S, psi0, X, lam2, rho):
    """``-N`` from the finite-volume scheme's definition (the class notes of ``_Problem``)."""
    h = np.diff(X)
    xc = 0.5 * (X[1:] + X[:-1])
    Sf = np.concatenate(([0.0], S, [0.0]))
    c = 1.0 + np.diff(Sf) / h
    half = 0.5 * h / (rho + (1.0 - rho) * c)
    r = np.concatenate(([half[0]], half[:-1] + half[1:], [half[-1]]))
    d = (lam2 * psi0 - math.fsum(r * Sf)) / math.fsum(r) + Sf
    x = -r[1:-1] * d[1:-1] / lam2
    return -(c[:-1] * _bernoulli(x) - c[1:] * _bernoulli(-x)) / np.diff(xc)


@pytest.mark.parametrize("rho,psi0", [(0.2, 3.0), (1.0, -2.0), (0.05, 0.0), (1.0, 1e-9)])
def test_sg_rhs_is_the_scheme(rho, psi0):
    lam = 0.02
    X = make_fv_mesh(lam, abs(psi0), rho)
    rng = np.random.default_rng(7)
    h = np.diff(X)
    # a charged state: a smooth displacement of the layers' charge, small enough to keep c > 0
    S = 0.3 * np.min(h) * np.sin(np.pi * X[1:-1]) * rng.uniform(0.5, 1.0)
    got = sg_rhs(S, psi0, h, np.diff(0.5 * (X[1:] + X[:-1])), lam * lam, rho)
    ref = _sg_reference(S, psi0, X, lam * lam, rho)
    scale = np.max(np.abs(ref)) + 1e-300
    assert np.max(np.abs(got - ref)) <= 1e-9 * scale


def test_sg_rhs_vanishes_at_rest():
    X = make_fv_mesh(0.01, 0.0, 0.5)
    h = np.diff(X)
    assert np.all(sg_rhs(np.zeros(h.size - 1), 0.0, h, np.diff(0.5 * (X[1:] + X[:-1])), 1e-4, 0.5) == 0.0)


@pytest.mark.parametrize("psi0", [0.7, -4.0, 20.0])
def test_linear_rhs_agrees_with_the_stacked_constraint_solve(psi0):
    """The compiled one-state path against ``solve_d0`` on a stack (its vectorised Newton)."""
    lam = 0.02
    X = make_fv_mesh(lam, abs(psi0), 0.0)
    P = _LinearProblem(X, lam, 0.0, lambda t: psi0, 0.0)
    h = P.h
    S = 0.2 * np.min(h) * np.cos(0.5 * np.pi * X[1:-1]) * np.sign(psi0)
    out, x = linear_rhs(S, psi0, h, P.delta, P.lam2, P.wL, P.wR, P.GL, P.GR, 0.0)
    d0 = P.solve_d0(np.vstack((S, S)), np.array([0.0, 0.0]))[0][0]
    Sf = np.concatenate(([0.0], S, [0.0]))
    c = 1.0 + np.diff(Sf) / h
    ref = -P.flux(c, d0 + Sf)
    assert np.max(np.abs(out - ref)) <= 1e-10 * np.max(np.abs(ref))
    assert math.isfinite(x)


def test_linear_rhs_refuses_a_negative_concentration_with_nan():
    X = make_fv_mesh(0.02, 1.0, 0.0)
    P = _LinearProblem(X, 0.02, 0.0, lambda t: 1.0, 0.0)
    S = np.zeros(P.N - 1)
    S[0] = -2.0 * P.h[0]  # the first cell: c = 1 + (S_1 - 0)/h = -1
    out, x = linear_rhs(S, 1.0, P.h, P.delta, P.lam2, P.wL, P.wR, P.GL, P.GR, 0.25)
    assert np.all(np.isnan(out)) and x == 0.25


def test_newton_delta_finds_the_root():
    # F(delta) = d_0(delta) - (delta + psi0 - I0)/W is decreasing; at the root F = 0
    aL, aR, GL, GR, W, I0, p0 = 1.3, 0.7, 0.4, 0.6, 2.0, 0.1, 5.0
    x = newton_delta(aL, aR, GL, GR, W, I0, p0, 0.0)
    ex = math.exp(-abs(x))
    d0 = (aL * ex - aR) / (GL * ex + GR) if x > 0 else (aL - aR * ex) / (GL + GR * ex)
    assert abs(d0 - (x + p0 - I0) / W) <= 1e-12 * (1 + abs(x))


def test_newton_delta_returns_a_start_that_is_the_root():
    # d_0(0) = (aL - aR)/(GL + GR) = 1 = (0 + p0 - I0)/W, every number exact in binary: delta = 0
    # solves the constraint to the bit, and the iteration must not leave it (its bracket is then
    # empty: a bracketing step would send it 2 away, to come back within the tolerance only)
    assert newton_delta(1.5, 0.5, 0.25, 0.75, 2.0, 0.0, 2.0, 0.0) == 0.0


def test_the_stacked_constraint_solve_keeps_the_state_at_rest():
    # uncharged under 0 V: delta = 0 solves the constraint to the bit; the vectorised Newton must
    # return it, not a value brought back within its tolerance after an empty bracket
    X = make_fv_mesh(0.02, 0.0, 0.0)
    P = _LinearProblem(X, 0.02, 0.0, lambda t: 0.0, 0.0)
    S = np.zeros((3, P.N - 1))
    d0, lnL, lnR = P.solve_d0(S, np.zeros(3))[:3]
    assert not np.any(d0)
    # the face concentrations are 1 to their sums' rounding (one ulp below on an aarch64 machine)
    assert np.all(np.abs(lnL) <= 4e-16) and np.array_equal(lnL, lnR)
