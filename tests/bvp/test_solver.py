"""Full BVP (ipmc_asym.bvp.solver) against independent computations written here.

* linear model: exact solution ``C = 1 + (B1 - 1) sinh(z/z0)/sinh(1/z0)``;
* constant / affine: first integral + layer quadratures (core neutral, exponentially
  small error), with scipy.integrate.quad at tight tolerances.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from references import I_layer_quadrature, I_linear_exact

import ipmc_asym.bvp.solver as bvp
from ipmc_asym.bvp.solver import BVPResult, moment_integral_bvp, solve
from ipmc_asym.model.params import NAFION_LI, Strip
from ipmc_asym.model.permittivity import get_model

NOMINAL = Strip(thickness=200e-6, voltage=1.0)


def groups(model, strip=NOMINAL):
    return get_model(model).groups(strip, NAFION_LI)


# ---------------------------------------------------------------------------------------
# independent references
# ---------------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def nominal():
    return {m: solve(NOMINAL, m) for m in ("constant", "linear", "affine")}


# ---------------------------------------------------------------------------------------
# accuracy at the nominal point
# ---------------------------------------------------------------------------------------
def test_linear_against_exact_solution(nominal):
    r = nominal["linear"]
    assert r.success and r.status == 0
    ref = I_linear_exact(r.groups)
    assert abs(r.I - ref) <= 1e-8 * abs(ref), (r.I, ref)
    assert r.B1 == pytest.approx(2.0 / (1.0 + math.exp(-r.groups.A2)), rel=1e-12)


@pytest.mark.parametrize("model", ["constant", "affine"])
def test_layer_quadrature_reference(nominal, model):
    r = nominal[model]
    assert r.success and r.status == 0
    ref, B1 = I_layer_quadrature(r.groups)
    assert abs(r.I - ref) <= 1e-8 * abs(ref), (r.I, ref)
    assert r.B1 == pytest.approx(B1, rel=1e-10)


def test_profiles_consistent(nominal):
    for r in nominal.values():
        g = r.groups
        assert r.z[0] == -1.0 and r.z[-1] == 1.0 and np.all(np.diff(r.z) > 0)
        assert r.phi[0] == pytest.approx(1.0, abs=1e-12)
        assert r.phi[-1] == pytest.approx(0.0, abs=1e-12)
        assert r.D[0] == pytest.approx(r.D[-1], abs=1e-12)
        np.testing.assert_allclose(r.C, r.B1 * np.exp(-g.A2 * r.phi), rtol=1e-9, atol=1e-300)
        np.testing.assert_allclose(r.p, r.C / g.A2 - g.A3 * r.phi)
        # electroneutrality, by the trapezoid rule on the (fine) mesh
        assert abs(np.trapezoid(r.rhoZ, r.z)) < 1e-5
        # D' = C - 1
        np.testing.assert_allclose(np.gradient(r.D, r.z)[2:-2], r.rhoZ[2:-2], atol=2e-2 * r.B1)
        assert r.n_nodes == r.z.size and r.max_rms_residual <= 1.01e-10
        assert r.bc_residual < 1e-10


@pytest.mark.slow
def test_self_convergence():
    for model in ("constant", "linear", "affine"):
        a = solve(NOMINAL, model, tol=1e-10)
        b = solve(NOMINAL, model, tol=2.5e-11)
        assert b.success
        assert abs(a.I - b.I) < 1e-9 * abs(b.I), (model, a.I, b.I)


# ---------------------------------------------------------------------------------------
# range, symmetry, API
# ---------------------------------------------------------------------------------------
CORNERS = [(10e-6, 1e-3), (10e-6, 10.0), (4e-3, 1e-3), (4e-3, 10.0), (200e-6, 0.1)]


@pytest.mark.slow
@pytest.mark.parametrize("model", ["constant", "affine", "linear"])
@pytest.mark.parametrize("thickness,voltage", CORNERS)
def test_corners_converge(model, thickness, voltage):
    """Corners and geometric centre of 10 um - 4 mm x 1 mV - 10 V, checked against the
    independent references (the layer quadrature neglects the layers' overlap, ~exp(-2/lam))."""
    r = solve(Strip(thickness=thickness, voltage=voltage), model)
    assert r.success and r.status == 0, r.message
    assert np.isfinite(r.I) and r.I > 0
    assert r.max_rms_residual <= 1.01e-10 and r.bc_residual < 1e-10
    if model == "linear":
        ref, rtol = I_linear_exact(r.groups), 1e-8
    else:
        ref = I_layer_quadrature(r.groups)[0]
        rtol = 1e-8 + 10.0 * math.exp(-2.0 / r.groups.debye)
    assert abs(r.I - ref) <= rtol * abs(ref), (r.I, ref)


@pytest.mark.parametrize("thickness,voltage", [(1e-6, 5.0), (2e-6, 1.0)])
def test_overlapping_layers_linear_exact(thickness, voltage):
    """Where the layers fill the strip (lambda ~ 1) the closed forms and the quadrature give up;
    the BVP must still converge to the exact solution of the linear model (any thickness)."""
    from ipmc_asym.integral.api import moment

    assert not bool(moment(thickness, voltage, "linear", "quadrature").valid)
    r = solve(Strip(thickness=thickness, voltage=voltage), "linear")
    assert r.success, r.message
    assert r.I == pytest.approx(I_linear_exact(r.groups), rel=1e-8)


def test_mirror_symmetry():
    for model in ("constant", "linear"):
        rp = solve(NOMINAL, model)
        rm = solve(NOMINAL.with_(voltage=-1.0), model)
        assert rm.success
        assert rm.I == pytest.approx(-rp.I, rel=1e-13)
        np.testing.assert_array_equal(rm.z, -rp.z[::-1])
        np.testing.assert_allclose(rm.C, rp.C[::-1])
        np.testing.assert_allclose(rm.D, -rp.D[::-1])
        np.testing.assert_allclose(rm.phi, rp.phi[::-1] - 1.0)
        assert rm.phi[0] == pytest.approx(-1.0) and rm.phi[-1] == pytest.approx(0.0, abs=1e-12)
        assert moment_integral_bvp(200e-6, -1.0, model) == pytest.approx(-rp.I, rel=1e-13)


def test_zero_voltage():
    r = solve(NOMINAL.with_(voltage=0.0), "affine")
    assert r.success and r.I == 0.0 and "zero voltage" in r.message
    assert np.all(r.C == 1.0) and np.all(r.E == 0.0)
    assert moment_integral_bvp(200e-6, 0.0) == 0.0


def test_helper_and_errors(monkeypatch, nominal):
    assert moment_integral_bvp(200e-6, 1.0, "constant") == pytest.approx(
        nominal["constant"].I, rel=1e-13)
    for bad in ((0.0, 1.0), (-1e-4, 1.0), (float("nan"), 1.0), (2e-4, float("inf")),
                ("x", 1.0)):
        with pytest.raises(ValueError):
            moment_integral_bvp(*bad)
    with pytest.raises(ValueError):
        moment_integral_bvp(2e-4, 1.0, "quadratic")

    def failed(*a, **k):
        r = nominal["constant"]
        return BVPResult(**{**r.__dict__, "success": False, "status": 1,
                            "message": "The maximum number of mesh nodes is exceeded."})

    monkeypatch.setattr(bvp, "solve", failed)
    with pytest.raises(RuntimeError, match="did not converge.*maximum number"):
        moment_integral_bvp(200e-6, 1.0)


def test_continuation_path_agrees(nominal):
    res, prob, g = bvp._continuation(NOMINAL, get_model("constant"), NAFION_LI, 1e-10, 300000)
    assert res.status == 0
    assert float(res.y[2, -1]) == pytest.approx(nominal["constant"].I, rel=1e-9)


def test_custom_eps_matches_affine(nominal):
    r = solve(NOMINAL, lambda C: 5e-6 + 1e-3 * C / NAFION_LI.C_moy)
    assert r.success, r.message
    assert r.I == pytest.approx(nominal["affine"].I, rel=1e-8)
    with pytest.raises(ValueError, match="> 0"):
        solve(NOMINAL, lambda C: 5e-6 - 1e-3 * C / NAFION_LI.C_moy)
    with pytest.raises(ValueError, match="too small at the anode"):
        solve(NOMINAL, lambda C: 1e-3 * C / NAFION_LI.C_moy)  # eps(0) = 0: use "linear"


def test_extreme_voltage_no_fp_errors():
    """Above ~18 V, exp(-A2) underflows: still finite, odd, converged (seterr=raise)."""
    for model in ("linear", "constant"):
        r = solve(NOMINAL.with_(voltage=-20.0), model)
        assert r.success and np.isfinite(r.I) and r.I < 0
        assert np.all(np.isfinite(r.E)) and np.all(np.isfinite(r.y))


def test_b1_guess_limits():
    A2 = 38.7
    assert bvp.b1_guess(0.0, 1e-6, A2) == pytest.approx(A2 / -math.expm1(-A2), rel=1e-14)
    assert bvp.b1_guess(1e-3, 0.0, A2) == pytest.approx(2 / (1 + math.exp(-A2)), rel=1e-14)
    B = bvp.b1_guess(8.8e-4, 4.4e-6, A2)
    assert 8.8e-4 / 2 * B * B + (4.4e-6 - 8.8e-4) * B - 4.4e-6 * A2 == pytest.approx(0, abs=1e-15)


def test_a_diverged_solve_is_a_failure_without_overflow():
    # 0.012 Debye lengths thick: the affine solve's last iterate has b = ln B1 ~ 1e10, past exp's range
    # (NumPy's default floating-point handling, as the CLI runs it: solve_bvp then iterates that far)
    mat = NAFION_LI.with_(c_moy=10.0)
    with np.errstate(all="warn", under="ignore"):
        r = solve(Strip(thickness=1e-7, voltage=1.0), "affine", mat)
        with pytest.raises(RuntimeError, match="did not converge"):
            moment_integral_bvp(1e-7, 1.0, "affine", mat)
    assert not r.success
    assert r.B1 == math.inf and math.isnan(r.I) and np.all(np.isfinite(r.C))
