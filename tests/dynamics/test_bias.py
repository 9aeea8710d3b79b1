"""The PNP linearised about a biased static state (dynamics/bias.py) and the biased circuit's error.

Independent checks: at 0 V the closed form ``pnp-linear``; at low frequency the exact static
differential capacitance ``dsigma/dphi0`` (``charge``, rung ``exact``); the stated error of the
biased circuit against the reference recomputed on finer meshes."""

import math

import numpy as np
import pytest

import ipmc_asym as ia
from ipmc_asym.dynamics import bias as B
from ipmc_asym.dynamics import circuit as C
from ipmc_asym.dynamics.bias import bias_reference
from ipmc_asym.dynamics.circuit import frequency_response
from ipmc_asym.model.params import Strip

F = np.geomspace(1e-3, 1e5, 7)


@pytest.mark.parametrize("th", [20e-6, 200e-6, 1e-3])
@pytest.mark.parametrize("model", ["constant", "linear", "affine"])
def test_zero_volt_is_pnp_linear(th, model):
    s = Strip(thickness=th)
    r = bias_reference(F, 0.0, s, model)
    p = frequency_response(F, strip=s, model=model)
    dev = np.abs(r.Z_area / p.Z_area - 1.0)
    assert np.all(dev <= r.error) and dev.max() < 3e-8
    assert r.error.max() < 2e-7


@pytest.mark.parametrize("th", [20e-6, 1e-3])
@pytest.mark.parametrize("model", ["constant", "affine"])
def test_small_bias_tends_to_zero_volt(th, model):
    """Z is even in the bias: at 1 uV (A2 ~ 4e-5) it is the 0 V closed form to ~A2^2."""
    s = Strip(thickness=th)
    r = bias_reference(F[:4], 1e-6, s, model)
    p = frequency_response(F[:4], strip=s, model=model)
    assert np.all(np.abs(r.Z_area / p.Z_area - 1.0) <= r.error + 1e-8)


@pytest.mark.parametrize("th", [20e-6, 1e-3])
@pytest.mark.parametrize("model,V", [("constant", 0.05), ("constant", -1.0), ("constant", 5.0),
                                     ("affine", 0.05), ("affine", -1.0), ("affine", 3.0), ("linear", 0.05),
                                     ("linear", -0.05)])
def test_low_frequency_is_the_static_differential_capacitance(th, model, V):
    s = Strip(thickness=th)
    r = bias_reference([1e-7], V, s, model)
    Cd = float(ia.charge(th, V, model, "exact").C_diff)
    assert abs(r.charge_transfer[0] / Cd - 1.0) <= r.error[0]
    assert r.error[0] < 2e-5


# past ~0.6 V the static state is the closed form, down to 1 um (layers filling the strip)
@pytest.mark.parametrize("th,V", [(th, V) for th in (20e-6, 1e-3) for V in (0.3, -0.5, 0.7)]
                         + [(th, V) for th in (1e-6, 5e-6, 20e-6, 1e-3) for V in (1.0, -2.0)])
def test_linear_model_depleted_anode(th, V, monkeypatch):
    """The linear model past 0.2 V (its anode depleted to ~2 e^{-v} of C_moy, dsigma/dphi0 down to 7e-9
    F/m^2 at 0.7 V, 6e-14 at 1 V, 1e-30 at 2 V): the low-frequency limit is the exact static
    differential capacitance within the stated error, and (up to 0.5 V, and on the closed-form static
    state past ~0.6 V) the stated error bounds the reference on meshes split 4 times finer."""
    s = Strip(thickness=th)
    f = np.array([1e-7, 1e-1, 1e2])
    r = bias_reference(f, V, s, "linear")
    Cd = float(ia.charge(th, V, "linear", "exact").C_diff)
    assert abs(r.charge_transfer[0] / Cd - 1.0) <= r.error[0]
    assert r.error.max() <= B.BIAS_REFERENCE_CEILING
    if 0.5 < abs(V) < 0.8:
        # at 0.7 V, 1 mm the finer reference itself refuses: its mesh error (7e-5) falls below the
        # static state's (1.9e-4, the miss the low-frequency check measures and adds to the error)
        return
    mesh = B._graded_mesh
    monkeypatch.setattr(B, "MAX_NODES", 10**7)
    monkeypatch.setattr(B, "_graded_mesh", lambda ell, extra, refine=1, lo=-1.0: mesh(ell, extra, 4 * refine, lo))
    fine = bias_reference(f, V, s, "linear")
    actual = np.abs(r.Z_area / fine.Z_area - 1.0)
    assert np.all(actual <= r.error)


def test_linear_static_state_keeps_its_slope_inside_the_anode_sublayer():
    """The generated closed form at distances from the anode below the spacing of the doubles at 2
    (the depleted sublayer, ~u_f lambda: 3e-17 at 1 V): u against the exact solution at 50 digits,
    on a strip whose layers fill it (lambda ~ 1, where the cathode term's share of the slope
    is e^{-2/lambda} ~ 12 %: a form with e^{(xi - 2)/lambda} - e^{-2/lambda} loses it, and the 1 um
    reference then misses dsigma/dphi0 by 5-10 %)."""
    import mpmath as mp

    from ipmc_asym.kernels._generated_charge import linear_static_concentration

    lam, uf = 0.9563441728864065, 3.1e-17
    xi = np.array([1e-20, 3e-18, 1e-16, 1e-9])
    got = linear_static_concentration(xi, lam, uf)
    with mp.workdps(50):
        L, U = mp.mpf(lam), mp.mpf(uf)

        def exact(x):  # u = u_f + (1 - u_f)(1 - e^{-x/L} + e^{(x - 2)/L} - e^{-2/L})/(1 - e^{-2/L})
            x = mp.mpf(x)
            return U + (1 - U) * (1 - mp.exp(-x / L) + mp.exp((x - 2) / L) - mp.exp(-2 / L)) / (1 - mp.exp(-2 / L))

        want = np.array([float(exact(x)) for x in xi])
    np.testing.assert_allclose(got, want, rtol=1e-13)


def test_reference_refuses_where_the_static_state_is_not_resolved():
    """Past 3.4 V (the anode at ~1e-59 of C_moy) the reference refuses before any solve."""
    with pytest.raises(RuntimeError, match="below what the mesh resolves"):
        bias_reference([1.0], 3.5, Strip(thickness=200e-6), "linear")


@pytest.mark.parametrize("th", [1e-6, 5e-6, 20e-6, 200e-6])
def test_linear_closed_form_static_state_is_the_bvp(th):
    """The linear model's static state in closed form (``u'' = (u - 1)/lambda^2``, ``u_f = 2/(1 + e^v)``)
    against the BVP's profiles at 0.3 V, where the BVP's anode is still resolved (u_f = 1.8e-5): u and
    D_bar agree across the thickness to the BVP's accuracy, from layers filling the strip (1 um) to a
    neutral core (200 um); its face induction is the exact rung's charge at 0.3 and 2 V."""
    from ipmc_asym.bvp.solver import solve
    from ipmc_asym.model import groups
    from ipmc_asym.model.params import NAFION_LI as m
    from ipmc_asym.model.permittivity import get_model

    s = Strip(thickness=th, voltage=0.3)
    perm = get_model("linear")
    lam = float(groups.debye_length(s.thickness, perm.eps_moy, m))
    _, prof = B._linear_profile(lam, 0.3 * groups.inverse_thermal_voltage(m))
    r = solve(s, perm, m)
    x = np.concatenate([[-1.0], -1.0 + np.geomspace(1e-6, 1.0, 200), 1.0 - np.geomspace(1e-6, 1.0, 200)])
    sb, Db = r.sol(x)[:2]
    u, D = prof(x + 1.0)
    assert np.max(np.abs(u - sb / float(r.groups.A0))) < 1e-9
    assert np.max(np.abs(D - Db)) < 1e-9 * lam
    for V in (0.3, 2.0):
        _, prof = B._linear_profile(lam, V * groups.inverse_thermal_voltage(m))
        sigma = m.phi4 * m.F * m.C_moy * 0.5 * th * float(prof(np.array([0.0]))[1][0])
        assert sigma == pytest.approx(float(ia.charge(th, V, "linear", "exact").sigma), rel=1e-13)


def test_linear_closed_form_reference_is_the_bvp_reference(monkeypatch):
    """At 0.5 V both static states serve: the reference on the closed form (used from ~0.6 V) and on the
    BVP agree within the sum of their stated errors."""
    f = np.array([1e-3, 1.0, 1e2, 1e4])
    s = Strip(thickness=200e-6)
    b = bias_reference(f, 0.5, s, "linear")
    monkeypatch.setattr(B, "CLOSED_FORM_BELOW", 1.0)  # the closed form at any bias
    a = bias_reference(f, 0.5, s, "linear")
    assert not np.array_equal(a.Z_area, b.Z_area)  # two computations
    assert np.all(np.abs(a.Z_area / b.Z_area - 1.0) <= a.error + b.error)


def test_sign_of_the_bias_is_a_mirror_image():
    s = Strip(thickness=200e-6)
    a = bias_reference([1.0, 100.0], 0.7, s, "affine")
    b = bias_reference([1.0, 100.0], -0.7, s, "affine")
    assert np.array_equal(a.Z_area, b.Z_area)


@pytest.mark.slow
@pytest.mark.parametrize("th", [20e-6, 1e-3])
@pytest.mark.parametrize("model,V", [("constant", 0.3), ("constant", -2.0), ("affine", 0.05),
                                     ("affine", -1.0), ("linear", 0.05), ("linear", 0.5)])
def test_biased_circuit_error_bounds_a_finer_reference(th, model, V, monkeypatch):
    """The stated error bounds the circuit's deviation from the reference on a finer mesh (every
    interval split in 4 more): ratio actual/stated <= 1, and the bound is not loose by more than 2x
    plus the reference's own stated error."""
    f = np.geomspace(1e-2, 1e4, 5)
    s = Strip(thickness=th)
    # the reference the circuit's error is stated against: the one frequency_response solves, kept
    refs = []

    def kept(*a, **k):
        refs.append(bias_reference(*a, **k))
        return refs[-1]

    monkeypatch.setattr(C, "bias_reference", kept)
    r = frequency_response(f, strip=s, model=model, method="circuit", voltage=V)
    assert r.error is not None
    assert len(refs) == 1 and np.array_equal(refs[0].f, f) and refs[0].voltage == V
    ref = refs[0]
    mesh = B._graded_mesh
    monkeypatch.setattr(B, "MAX_NODES", 10**7)
    monkeypatch.setattr(B, "_graded_mesh", lambda ell, extra, refine=1, lo=-1.0: mesh(ell, extra, 4 * refine, lo))
    fine = bias_reference(f, V, s, model)
    actual = np.abs(r.Z_area - fine.Z_area) / np.abs(fine.Z_area)
    assert np.all(actual <= r.error)
    # not loose by more than 2x beyond the reference's own error (which the stated error carries:
    # ~4e-4 for the linear model's depleted anode at 0.5 V, below 2e-5 elsewhere)
    assert np.all(r.error <= 2.0 * actual + ref.error + 1e-6)


@pytest.mark.parametrize("bad", [2.5, -1, "12", True])
def test_reference_points_must_be_a_count(bad):
    with pytest.raises(ValueError, match="reference_points must be an integer >= 0"):
        frequency_response([1.0], method="circuit", voltage=0.5, reference_points=bad)


@pytest.mark.parametrize("model,V", [("linear", -1e-9)] + [
    pytest.param(m, v, marks=pytest.mark.slow) for m in ("constant", "linear", "affine") for v in (1e-9, -1e-9, 1e-320)
    if (m, v) != ("linear", -1e-9)])
def test_a_bias_below_the_static_solvers_floor_has_a_reference(model, V):
    """Below the floor of the static BVP (A2 = 1e-6, 2.6e-8 V) the reference is the one at rest, its
    error raised by its change up to the floor: it holds against the references at two biases above
    the floor, extrapolated linearly to V (their own errors added), and the charge per volt's static
    limit is the exact differential capacitance at V."""
    s = Strip()
    f = F[1:3]
    r = bias_reference(f, V, s, model)
    a = math.copysign(4e-8, V)
    ra, r2a = bias_reference(f, a, s, model), bias_reference(f, 2.0 * a, s, model)
    z = ra.Z_area + (r2a.Z_area - ra.Z_area) * (V - a) / a
    assert np.all(np.abs(z - r.Z_area) <= (r.error + 3.0 * np.maximum(ra.error, r2a.error)) * np.abs(r.Z_area))
    assert r.voltage == V and r.error.max() < 1e-6
    cd = ia.charge(s.thickness, V, model, "exact").C_diff
    assert r.C_diff == pytest.approx(float(cd), rel=1e-12)
