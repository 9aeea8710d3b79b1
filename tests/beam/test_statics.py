"""Tests of ipmc_asym.beam.statics against independent references.

References: direct integration of the beam ODE (scipy solve_ivp), adaptive quadrature of the
paper's blocking condition (scipy quad), an independent continuation of the blocking-force
branch (brentq on quad), and series expansions derived here with SymPy.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
import sympy as sp
from scipy.integrate import IntegrationWarning, quad, solve_ivp
from scipy.optimize import brentq

import ipmc_asym.beam.statics as beam

L = 0.02
EI = 1.3e8 * 4 * 2.5e-3 * (1e-4) ** 3 / 3  # E * 4 l e^3 / 3, ~4.33e-7 N m^2


def M_of(kL):
    return np.asarray(kL, dtype=float) * EI / L


# ---------------------------------------------------------------------------- series
@pytest.fixture(scope="module")
def deflection_series():
    """w/w_small = 2(1 - cos m)/m^2 expanded in m = kappa L, from the paper's formulas."""
    m = sp.symbols("m")
    w = (sp.cos(m) - 1) / m  # w / L with kappa L = m   (paper eq. (w))
    ws = -m / 2  # w_p / L
    ser = sp.series(w / ws, m, 0, 6).removeO()
    return float(ser.coeff(m, 2)), float(ser.coeff(m, 4))


@pytest.fixture(scope="module")
def blocking_series():
    """F = psi M/L; psi = 3/2 + c2 m^2 + c4 m^4 from the blocking integral expanded in m."""
    t, m, c2, c4 = sp.symbols("t m c2 c4")
    psi = sp.Rational(3, 2) + c2 * m**2 + c4 * m**4
    theta = m * (psi * (t - t**2 / 2) - t)  # theta(x = L t) / 1 with F = psi M / L
    G = sp.integrate(sp.expand(sp.series(sp.sin(theta), m, 0, 8).removeO()), (t, 0, 1))
    G = sp.expand(G / m)
    assert sp.simplify(G.coeff(m, 0)) == 0  # psi(0) = 3/2 is the small-displacement value
    s2 = sp.solve(G.coeff(m, 2), c2)[0]
    s4 = sp.solve(G.coeff(m, 4).subs(c2, s2), c4)[0]
    return s2, s4


def test_small_moment_limit_order_two(deflection_series):
    c2, _ = deflection_series
    assert c2 == pytest.approx(-1 / 12)
    ms = 0.2 / 2.0 ** np.arange(5)
    w = beam.tip_deflection(M_of(ms), L, EI)
    ws = beam.tip_deflection_small(M_of(ms), L, EI)
    dev = w / ws - 1.0
    order = np.log2(dev[:-1] / dev[1:])
    assert np.allclose(order, 2.0, atol=0.01)
    assert np.allclose(dev / ms**2, c2, rtol=1e-2)
    # small_displacement_error = |w_s - w|/|w| = -c2 m^2 + ...
    err = beam.small_displacement_error(M_of(ms), L, EI)
    assert np.allclose(err, np.abs(ws - w) / np.abs(w), rtol=1e-9)
    assert np.allclose(err / ms**2, 1 / 12, rtol=1e-2)


def test_small_error_closed_form_vs_direct():
    ms = np.array([1e-6, 1e-3, 0.05, 0.19, 0.21, 0.5, 1.0, 3.0, 6.0, -2.5])
    w = beam.tip_deflection(M_of(ms), L, EI)
    ws = beam.tip_deflection_small(M_of(ms), L, EI)
    direct = np.abs(ws - w) / np.abs(w)
    got = beam.small_displacement_error(M_of(ms), L, EI)
    ok = ms > 1e-3  # direct loses digits to cancellation below
    assert np.allclose(got[ok], direct[ok], rtol=1e-8)
    assert got[0] == pytest.approx(1e-12 / 12, rel=1e-6)
    # w = 0 at kappa L = 2 pi: infinite relative error, no FP exception
    assert np.isinf(beam.small_displacement_error(M_of(2 * np.pi), L, EI)) or (
        beam.small_displacement_error(M_of(2 * np.pi), L, EI) > 1e12
    )


# -------------------------------------------------------------------------------- arc
def _ode_tip(M, F=0.0):
    def rhs(s, y):
        th = y[0]
        return [(F * (L - s) - M) / EI, math.cos(th), math.sin(th)]

    sol = solve_ivp(rhs, (0, L), [0.0, 0.0, 0.0], rtol=1e-12, atol=1e-15, method="DOP853")
    return sol.y[:, -1]


@pytest.mark.parametrize("kL", [1e-3, 0.3, 0.92, 2.0, -2.0, 4.0, 7.0, 13.0])
def test_arc_matches_ode(kL):
    M = float(M_of(kL))
    th, x, z = _ode_tip(M)
    assert beam.rotation(M, L, EI) == pytest.approx(th, rel=1e-10, abs=1e-14)
    xt, yt = beam.tip_position(M, L, EI)
    assert xt == pytest.approx(x, abs=1e-11 * L)
    assert yt == pytest.approx(z, abs=1e-11 * L)
    assert beam.tip_deflection(M, L, EI) == pytest.approx(z, abs=1e-11 * L)
    # the paper's own formula (where it is not 0/0)
    k = M / EI
    assert beam.tip_deflection(M, L, EI) == pytest.approx((math.cos(k * L) - 1) / k, rel=1e-6)


def test_tiny_moment_no_cancellation():
    M = float(M_of(1e-9))
    w = beam.tip_deflection(M, L, EI)
    assert w == pytest.approx(-M * L**2 / (2 * EI), rel=1e-15)
    x, _ = beam.tip_position(M, L, EI)
    assert x == pytest.approx(L, rel=1e-15)


# -------------------------------------------------------------------- blocking force
def _quad_residual(F, M):
    f = lambda x: math.sin(F * x * (2 * L - x) / (2 * EI) - M * x / EI)  # noqa: E731
    with warnings.catch_warnings():  # the integral is ~0 at the root: roundoff notices
        warnings.simplefilter("ignore", IntegrationWarning)
        return quad(f, 0, L, limit=1000, epsabs=1e-16 * L, epsrel=1e-13)[0]


@pytest.mark.parametrize("kL", [0.01, 0.3, 0.92, 3.0, -3.0, 10.0, 25.0, 60.0])
def test_blocking_large_is_root(kL):
    M = float(M_of(kL))
    F = beam.blocking_force_large(M, L, EI)
    assert np.isfinite(F) and np.sign(F) == np.sign(M)
    res = _quad_residual(F, M)
    assert abs(res) < 1e-12 * L
    # the small-displacement force is NOT a root (the check can fail)
    if abs(kL) > 0.2:
        assert abs(_quad_residual(1.5 * M / L, M)) > 1e3 * abs(res)
    # Fresnel closed form of the residual agrees with quad at arbitrary F
    for Fx in (0.0, 0.3 * F, F, 2.0 * F, -F):
        assert beam.blocking_residual(Fx, M, L, EI) == pytest.approx(
            _quad_residual(Fx, M), abs=1e-12 * L
        )


def test_blocking_paper_claim_and_scaling(blocking_series):
    c2, c4 = blocking_series
    assert c2 == sp.Rational(-1, 2240)
    # relative difference |F_s - F|/|F| = |3/2 - psi|/psi = -c2 m^2 / (3/2) + O(m^4)
    coef = float(-c2 / sp.Rational(3, 2))
    assert coef == pytest.approx(1 / 3360)
    M = float(M_of(0.92))
    Fl = beam.blocking_force_large(M, L, EI)
    Fs = beam.blocking_force_small(M, L)
    rel = abs(Fs - Fl) / abs(Fl)
    assert rel < 0.01  # paper: < 1 %
    assert rel == pytest.approx(coef * 0.92**2, rel=0.01)
    ms = np.array([0.4, 0.2, 0.1, 0.05])
    err = beam.blocking_force_error(M_of(ms), L, EI)
    order = np.log2(err[:-1] / err[1:])
    assert np.allclose(order, 2.0, atol=0.01)
    assert np.allclose(err / ms**2, coef, rtol=2e-3)
    # psi(m) against the SymPy series (both orders)
    ms = np.array([0.05, 0.2, 0.3, 0.5, 0.7])  # series branch and Newton branch
    psi = beam.blocking_force_ratio(ms)
    series = 1.5 + float(c2) * ms**2 + float(c4) * ms**4
    assert np.all(np.abs(psi - series) < 1e-8 * ms**6 + 1e-14)  # next term: m^6 (~4e-9)


def test_blocking_branch_continuation():
    """Independent continuation in kappa L with brentq on quad; must match the module."""
    ms = np.arange(0.2, 30.0 + 1e-9, 0.2)
    psi_prev = 1.5
    ref = []
    for m in ms:
        M = float(M_of(m))
        g = lambda p: _quad_residual(p * M / L, M)  # noqa: E731
        lo, hi = psi_prev - 0.03, psi_prev + 0.03
        assert g(lo) < 0 < g(hi)  # a single sign change near the previous root
        psi_prev = brentq(g, lo, hi, xtol=1e-14)
        ref.append(psi_prev)
    got = beam.blocking_force_ratio(ms)
    assert np.allclose(got, ref, rtol=0, atol=1e-10)
    assert np.all(np.abs(np.diff(got)) < 0.02)


def test_blocking_beyond_branch_is_withheld_with_warning():
    M = float(M_of(beam.KL_BLOCK_MAX * 1.5))
    assert np.isnan(beam.blocking_force_large(M, L, EI))
    r = beam.solve_beam(M, L, EI)
    assert r.F_block is None  # scalar inputs: None, as evaluate gives
    assert np.isnan(beam.solve_beam(np.array([M]), L, EI).F_block[0])  # arrays: NaN
    assert any("F_block withheld" in w for w in r.warnings)
    assert r.regime == "multi-turn"


# ----------------------------------------------------------------- regimes, symmetry
def test_regimes():
    assert beam.regime(M_of(0.1), L, EI) == "small"
    assert beam.regime(M_of(0.92), L, EI) == "large"  # error ~ 7 % > 1 %
    assert beam.regime(M_of(2.0), L, EI) == "past-quarter-turn"
    assert beam.regime(M_of(7.0), L, EI) == "multi-turn"
    assert beam.regime(M_of(0.92), L, EI, tol=0.1) == "small"
    # boundaries: |theta| = pi/2, 2 pi; "small" iff the directly computed error <= tol
    d = 1e-6
    assert beam.regime(M_of(np.pi / 2 - d), L, EI) == "large"
    assert beam.regime(M_of(np.pi / 2 + d), L, EI) == "past-quarter-turn"
    assert beam.regime(M_of(2 * np.pi - d), L, EI) == "past-quarter-turn"
    assert beam.regime(M_of(2 * np.pi + d), L, EI) == "multi-turn"
    kLs = np.linspace(0.2, 0.4, 201)
    w, ws = beam.tip_deflection(M_of(kLs), L, EI), -kLs * L / 2
    direct = np.abs(ws - w) / np.abs(w)
    for tol in (0.01, 0.005):
        labs = beam.regime(M_of(kLs), L, EI, tol=tol)
        assert np.array_equal(labs == "small", direct <= tol)
        assert 0 < np.count_nonzero(labs == "small") < kLs.size
    labs = beam.regime(M_of([0.1, -2.0, -7.0, 0.0]), L, EI)
    assert list(labs) == ["small", "past-quarter-turn", "multi-turn", "small"]
    r = beam.solve_beam(M_of(2.0), L, EI)
    assert any("pi/2" in w for w in r.warnings)
    r = beam.solve_beam(M_of(7.0), L, EI)
    assert any("2 pi" in w for w in r.warnings)
    assert beam.solve_beam(M_of(0.1), L, EI).warnings == []
    # past a quarter turn, w is no longer monotone in M
    w = beam.tip_deflection(M_of(np.linspace(0, 4, 401)), L, EI)
    assert np.all(np.diff(w[:100]) < 0) and np.any(np.diff(w[250:]) > 0)


@pytest.mark.parametrize("kL", [1e-7, 0.5, 2.0, 7.0, 40.0])
def test_sign_symmetry(kL):
    a = beam.solve_beam(M_of(kL), L, EI)
    b = beam.solve_beam(M_of(-kL), L, EI)
    for f in ("theta", "w", "w_small", "y_tip", "F_block", "F_block_small"):
        if getattr(a, f) is None:  # withheld (past a full turn): on both sides
            assert getattr(b, f) is None and kL > 2 * np.pi, f
            continue
        assert getattr(b, f) == pytest.approx(-getattr(a, f), rel=1e-13)
    for f in ("x_tip", "small_error", "block_error"):
        if getattr(a, f) is None:
            assert getattr(b, f) is None and kL > 2 * np.pi, f
            continue
        assert getattr(b, f) == pytest.approx(getattr(a, f), rel=1e-13)
    assert a.regime == b.regime
    assert (a.w is None or a.w < 0) and a.theta < 0 and a.F_block > 0  # M > 0 bends towards z < 0


def test_zero_moment():
    r = beam.solve_beam(0.0, L, EI, e=1e-4)
    assert (r.theta, r.w, r.w_small, r.y_tip, r.F_block, r.F_block_small) == (0, 0, 0, 0, 0, 0)
    assert r.x_tip == L
    assert r.small_error == 0 and r.block_error == 0 and r.max_strain == 0
    assert r.regime == "small" and r.warnings == []
    assert isinstance(r.w, float) and isinstance(r.F_block, float)


def test_arrays_broadcast():
    kL = np.array([[0.0], [0.5], [-3.0]])
    Ls = np.array([0.01, 0.02, 0.04])
    M = kL * EI / 0.02
    r = beam.solve_beam(M, Ls, EI)
    assert r.w.shape == r.F_block.shape == r.regime.shape == r.x_tip.shape == (3, 3)
    for i in range(3):
        for j in range(3):
            s = beam.solve_beam(float(M[i, 0]), float(Ls[j]), EI)
            assert r.w[i, j] == pytest.approx(s.w, rel=1e-14, abs=0)
            assert r.F_block[i, j] == pytest.approx(s.F_block, rel=1e-12, abs=0)
            assert r.x_tip[i, j] == pytest.approx(s.x_tip, rel=1e-14)
            assert r.regime[i, j] == s.regime
    assert np.shape(beam.blocking_force_small(M, Ls)) == (3, 3)
    x, y = beam.tip_position(np.zeros(4), L, EI)
    assert x.shape == y.shape == (4,)


def test_max_strain_and_bad_input():
    assert beam.max_strain(2e-5, EI, 1e-4) == pytest.approx(1e-4 * 2e-5 / EI)
    r = beam.solve_beam(M_of(2.0), L, EI, e=L)  # absurdly thick: strain warning
    assert any("strain" in w for w in r.warnings)
    with pytest.raises(ValueError, match="L"):
        beam.tip_deflection(1.0, -1.0, EI)
    with pytest.raises(ValueError, match="EI"):
        beam.solve_beam(1.0, L, 0.0)


def test_branch_integrals_quadrature_equals_fresnel_form():
    """The two implementations of G, dG/dpsi (Gauss-Legendre for small inputs, Fresnel
    integrals for large ones) agree on and around the blocking-force branch."""
    ms, ps = beam._branch_table()
    m = np.concatenate([ms[20::50], ms[20::50]])
    p = np.concatenate([ps[20::50], ps[20::50] * 1.3])
    g1, d1 = beam._G_and_dG(p, m)
    g2, d2 = beam._G_and_dG_fresnel(p, m)
    assert np.allclose(g1, g2, rtol=0, atol=1e-14)
    assert np.allclose(d1, d2, rtol=1e-12, atol=1e-14)
    assert np.max(np.abs(g2[: m.size // 2])) < 1e-13  # the table sits on G = 0


def test_blocking_ratio_interpolation_is_at_rounding_level():
    """Between the table's nodes psi comes from an 8-point interpolation, no Newton polish:
    it must sit on the root of the Fresnel form of the blocking condition (Newton-converged
    here, from the interpolated value) to <= 5e-15 relative, edges of the table included."""
    rng = np.random.default_rng(7)
    m = np.concatenate([rng.uniform(beam._SERIES_KL, beam.KL_BLOCK_MAX, 4000),
                        [beam._SERIES_KL, beam._SERIES_KL + 1e-3, beam.KL_BLOCK_MAX - 1e-3, beam.KL_BLOCK_MAX]])
    psi = beam.blocking_force_ratio(m)
    root = psi.copy()
    for _ in range(4):
        g, dg = beam._G_and_dG_fresnel(root, m)
        root = root - g / dg
    assert np.max(np.abs(psi - root) / np.abs(root)) <= 5e-15
