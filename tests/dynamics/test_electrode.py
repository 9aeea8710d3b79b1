"""Static electrode charge and capacitance: exact limits, the BVP, the derivation."""

import functools
import math

import mpmath as mp
import numpy as np
import pytest
import sympy as sp

import ipmc_asym
from derivations import charge as DC
from ipmc_asym.dynamics.electrode import charge, charge_scale
from ipmc_asym.kernels import _generated_charge as GC
from ipmc_asym.model.params import NAFION_LI, debye_length
from ipmc_asym.model.permittivity import MODELS

M = NAFION_LI
VT = M.R * M.T / M.F
MODELS3 = ("constant", "linear", "affine")
CLOSED = ("leading", "corrected", "quadrature")


def test_public_functions_are_not_shadowed_by_submodules():
    import importlib
    import pkgutil

    for mod in pkgutil.walk_packages(ipmc_asym.__path__, "ipmc_asym."):
        if not mod.name.endswith("__main__"):
            importlib.import_module(mod.name)
    import ipmc_asym.dynamics.circuit as circuit
    import ipmc_asym.dynamics.electrode as electrode

    assert ipmc_asym.charge is electrode.charge
    assert ipmc_asym.step_response is circuit.step_response
    assert ipmc_asym.frequency_response is circuit.frequency_response
    assert callable(ipmc_asym.charge)


rng = np.random.default_rng(11)


@pytest.mark.parametrize("i", range(8))
def test_layer_capacitance_kernel_matches_sympy(i):
    chat = DC.layer_capacitance().subs({DC.M.exprel(DC.y): DC.M.EXPREL_DEF, DC.M.e2rel(DC.y): DC.M.E2REL_DEF})
    yv = float(rng.uniform(-60, 6))
    r = float(rng.uniform(0, 1))
    ref = complex(chat.subs({DC.y: sp.Float(yv, 40), DC.rho: sp.Float(r, 40)}).evalf(30)).real
    assert GC.layer_capacitance(yv, r) == pytest.approx(ref, rel=1e-12)
    # and the derivative identity it encodes: |dDhat/dY| by a high-precision difference
    Hh = lambda Y: mp.sqrt(2 * ((1 - r) * (mp.e**Y - 1) ** 2 / 2 + r * (mp.e**Y - 1 - Y)))  # noqa: E731
    mp.mp.dps = 40
    d = abs(mp.diff(Hh, mp.mpf(yv)))
    assert GC.layer_capacitance(yv, r) == pytest.approx(float(d), rel=1e-11)


# the affine case (~7 s) with the slow tests: the constant and linear ones run the same comparison
@pytest.mark.parametrize("model", ["constant", "linear", pytest.param("affine", marks=pytest.mark.slow)])
def test_debye_hueckel_limit_exact(model):
    """C_d -> eps_core/(2 lambda_D) and sigma -> the SymPy series in A2 at small voltage."""
    perm = MODELS[model]
    lamD = float(debye_length(200e-6, perm.eps_moy, M)) * 100e-6
    r = charge(200e-6, 1e-7, model, "corrected")
    assert float(r.C_diff) == pytest.approx(perm.eps_moy / (2 * lamD), rel=1e-9)
    assert float(r.eps_app) == pytest.approx(perm.eps_moy / (2 * lamD) * 200e-6, rel=1e-9)
    ser = sp.lambdify(DC.A2, DC.debye_hueckel_series(model, 5))
    for v in (1e-3, 5e-3, 2e-2):
        A2 = v / VT
        s = float(charge(200e-6, v, model).sigma) / charge_scale(perm, M)
        assert s == pytest.approx(ser(A2), rel=3 * A2**6 + 1e-13)


def test_linear_model_exact_solution():
    """sigma = S tanh(A2/2) coth(1/lambda) (exact, any thickness); C_d = (S/V_T) sech^2(A2/2)/2."""
    exact, _ = DC.linear_exact()
    f = sp.lambdify((DC.A2, DC.lam), exact, "mpmath")
    perm = MODELS["linear"]
    S = charge_scale(perm, M)
    for th in (50e-6, 200e-6, 1e-3):
        lam = float(debye_length(th, perm.eps_moy, M))
        for v in (0.01, 0.2, 1.0, -0.7):
            A2 = abs(v) / VT
            ref = math.copysign(S * float(f(mp.mpf(A2), mp.mpf(lam))) / lam, v)
            for fid in CLOSED:
                r = charge(th, v, "linear", fid)
                assert float(r.sigma) == pytest.approx(ref, rel=max(float(r.error), 1e-13))
            cd = S / VT * 0.5 / math.cosh(A2 / 2) ** 2
            assert float(charge(th, v, "linear").C_diff) == pytest.approx(cd, rel=1e-12)


@pytest.mark.parametrize("model", MODELS3)
def test_large_voltage_asymptotics(model):
    """Dhat^2 -> (1 - 3 rho) + 2 rho (A2 - ln B1) (the paper's table D(+-1)) when e^{-A2} -> 0."""
    expr, dexpr = DC.large_voltage_sigma(model)
    f = sp.lambdify(DC.A2, expr, "mpmath")
    df = sp.lambdify(DC.A2, dexpr, "mpmath")
    perm = MODELS[model]
    S = charge_scale(perm, M)
    for v in (2.0, 5.0, 10.0):
        A2 = v / VT
        r = charge(200e-6, v, model, "corrected")
        assert float(r.sigma) / S == pytest.approx(float(f(mp.mpf(A2))), rel=1e-12)
        if model != "linear":  # linear: C_d ~ 2 e^{-A2}, beyond the e^{-A2} -> 0 limit
            assert float(r.C_diff) / (S / VT) == pytest.approx(float(df(mp.mpf(A2))), rel=1e-10)
    if model == "constant":  # sigma ~ S sqrt(2 A2): the depletion zone, sigma ~ phi0^{1/2}
        A2 = 1e4
        s = float(charge(200e-6, A2 * VT, model).sigma) / S
        assert s / math.sqrt(2 * A2) == pytest.approx(1 - (1 + math.log(A2)) / (2 * A2), rel=1e-5)


@pytest.mark.parametrize("model", MODELS3)
def test_every_fidelity_against_the_bvp_at_nominal(model):
    ref = charge(200e-6, 1.0, model, "bvp")
    for fid in CLOSED:
        r = charge(200e-6, 1.0, model, fid)
        assert abs(float(r.sigma) / float(ref.sigma) - 1) <= 1e-8
        assert abs(float(r.sigma) / float(ref.sigma) - 1) <= float(r.error) + float(ref.error)
        assert bool(r.valid)
        if bool(ref.valid):  # linear at 1 V: C_d ~ 1e-13 F/m^2, below the BVP difference quotient
            assert abs(float(r.C_diff) / float(ref.C_diff) - 1) <= float(ref.error_C_diff) + 1e-13


@pytest.mark.parametrize("th,v", [(50e-6, 0.05), (1e-3, -3.0)])
def test_sigma_within_stated_error_of_the_bvp(th, v):
    for model in MODELS3:
        ref = charge(th, v, model, "bvp")
        for fid in CLOSED:
            r = charge(th, v, model, fid)
            rel = abs(float(r.sigma) / float(ref.sigma) - 1)
            assert rel <= float(r.error) + float(ref.error)


def test_odd_even_and_zero_volts():
    v = np.array([-2.0, -0.3, 0.0, 0.3, 2.0])
    for model in MODELS3:
        r = charge(200e-6, v, model)
        assert np.allclose(r.sigma, -r.sigma[::-1], rtol=1e-15, atol=0)
        assert np.allclose(r.C_diff, r.C_diff[::-1], rtol=1e-15, atol=0)
        assert r.sigma[2] == 0.0
        assert r.Q[3] == pytest.approx(r.sigma[3] * 5e-3 * 0.02, rel=1e-15)


def test_closed_form_is_the_layer_integral_on_a_grid():
    """The quadrature rung (int_0^Yc chat dy, generic rho) reproduces Dhat(ln B1) closed forms."""
    v = np.geomspace(1e-3, 10, 40)
    for model in MODELS3:
        a = charge(200e-6, v, model, "corrected").sigma
        b = charge(200e-6, v, model, "quadrature").sigma
        assert np.max(np.abs(a / b - 1)) < 1e-12


def test_capacitance_is_the_derivative_of_the_charge():
    """Analytic C_d against a Richardson difference quotient of the closed-form sigma."""
    for model in MODELS3:
        for v in (0.02, 0.3, 1.0):
            h = 1e-4
            s = {k: float(charge(200e-6, v + k * h, model).sigma) for k in (-2, -1, 1, 2)}
            d = (8 * (s[1] - s[-1]) - (s[2] - s[-2])) / (12 * h)
            # the quotient's own rounding: ~eps |sigma|/h (dominant where C_d ~ 0, linear model)
            noise = 100 * 2.2e-16 * abs(s[1]) / h
            assert float(charge(200e-6, v, model).C_diff) == pytest.approx(d, rel=1e-7, abs=noise)


@pytest.mark.parametrize("kw,msg", [(dict(thickness=-1.0), "thickness"), (dict(fidelity="exactly"), "fidelity"),
                                    (dict(width=0.0), "width"), (dict(voltage=float("nan")), "voltage")])
def test_bad_input_one_line(kw, msg):
    args = dict(thickness=200e-6, voltage=1.0)
    args.update(kw)
    th, v = args.pop("thickness"), args.pop("voltage")
    with pytest.raises(ValueError, match=msg) as ei:
        charge(th, v, **args)
    assert "\n" not in str(ei.value)


# ---- the exact rung, the closed forms' estimates, tiny voltages ------------------------------
RUNGS = ("leading", "corrected", "quadrature", "exact")


def _dh_exact(th, model):
    """C_d(0) of the exact solution: eps coth(e/lambda_D)/(2 lambda_D) (linearised Poisson-Boltzmann)."""
    eps = MODELS[model].eps_moy
    lamD = float(debye_length(th, eps, M)) * th / 2
    return eps / (2 * lamD * math.tanh(th / 2 / lamD))


def test_small_voltage_capacitance_of_a_1um_strip():
    """At 1 um the exact C_d(0) is eps coth(e/lambda_D)/(2 lambda_D), ~28 % above the thick-strip value."""
    for model, ref in (("linear", 1340.0), ("affine", 1346.0)):
        r = charge(1e-6, 1e-4, model, "exact")
        assert bool(r.valid)
        assert float(r.C_diff) == pytest.approx(_dh_exact(1e-6, model), rel=1e-5)  # relative O(A2^2) ~ 4e-6
        assert round(float(r.C_diff)) == pytest.approx(ref, abs=1.0)
        thick = float(charge(1e-6, 1e-4, model, "corrected").C_diff)
        assert float(r.C_diff) / thick == pytest.approx(1.28, abs=0.01)
        assert not bool(charge(1e-6, 1e-4, model, "corrected").valid)


def _closed_against_exact(th, v, model):
    T, V = np.meshgrid(th, v, indexing="ij")
    ex = charge(T, V, model, "exact")
    assert np.all(ex.valid)
    for fid in ("leading", "corrected", "quadrature"):
        r = charge(T, V, model, fid)
        for q, est, ref in ((r.sigma, r.error, ex.sigma), (r.C_diff, r.error_C_diff, ex.C_diff)):
            with np.errstate(all="ignore"):
                act = np.where(q == ref, 0.0, np.abs(q - ref) / np.abs(ref))
            # the exact rung is itself within EXACT_STATED_ERROR (1e-11) of the truth
            assert np.all(~r.valid | (act <= est + 1e-11)), (model, fid)
            assert np.all((act <= 1e-14) | (est <= 10 * act)), (model, fid, np.max(est / np.maximum(act, 1e-300)))


@pytest.mark.parametrize("model", MODELS3)
def test_closed_form_estimates_bound_and_tight_subset(model):
    """Representative subset of the extremes grid: estimates bound the error and are within 10x of it."""
    th = np.array([1e-6, 2.6e-6, 10e-6, 15.8e-6, 200e-6, 1e-2])
    v = np.array([-20.0, -1.0, -1e-2, 1e-4, 0.3, 5.9, 20.0])
    _closed_against_exact(th, v, model)


@pytest.mark.slow
@pytest.mark.parametrize("model", MODELS3)
def test_closed_form_estimates_bound_and_tight_extremes_grid(model):
    th = np.geomspace(1e-6, 1e-2, 61)
    v = np.geomspace(1e-4, 20.0, 61)
    _closed_against_exact(th, np.concatenate([-v, v]), model)


def test_closed_forms_valid_where_their_error_is_small():
    """10 um linear: error 1.65e-9 (valid); 1 um constant at 1 V: error 2e-11 with a tight estimate."""
    r = charge(10e-6, 1.0, "linear", "corrected")
    assert bool(r.valid) and float(r.error) < 1e-8
    r = charge(1e-6, 1.0, "constant", "corrected")
    assert bool(r.valid) and float(r.error) < 1e-10
    assert not bool(charge(2e-6, 1.0, "linear", "corrected").valid)


# one BVP solve a point: the two signs of a mirrored pair (below) share it
@functools.lru_cache(maxsize=None)
def _bvp_charge(t, u, model):
    return charge(t, u, model, "bvp")


def _bvp_points(th, v, model, bvp_error=False, mirror=False):
    """Exact rung against the BVP's face induction: within the exact rung's estimate (+1e-13 for the
    BVP's own rounding), or within both estimates (``bvp_error``: tiny voltages, where the BVP's
    collocation residual is ~1e-11 relative).  ``mirror``: a negative voltage is held against the BVP
    at ``|voltage|``, sigma's sign flipped (sigma odd, C_d even: the strip's mirror image, which the
    BVP solves at ``|voltage|`` itself), so that both signs share one solve."""
    for t in th:
        for u in v:
            ex = charge(t, u, model, "exact")
            ref = _bvp_charge(t, abs(u) if mirror else u, model)
            sign = math.copysign(1.0, u) if mirror else 1.0
            assert bool(ex.valid)
            slack = float(ref.error) if bvp_error else 1e-13
            assert abs(float(ex.sigma) / (sign * float(ref.sigma)) - 1) <= float(ex.error) + slack
            if bool(ref.valid) and float(ref.error_C_diff) < 1e-3:
                assert abs(float(ex.C_diff) / float(ref.C_diff) - 1) <= float(ref.error_C_diff) + float(ex.error_C_diff)


@pytest.mark.parametrize("model", MODELS3)
def test_exact_rung_against_the_bvp_subset(model):
    """sigma of the exact rung against the BVP's face induction (thin strips, where the core is not neutral)."""
    _bvp_points((1e-6, 4e-6), (-1e-4, 1.0), model)


@pytest.mark.slow
@pytest.mark.parametrize("model", MODELS3)
def test_exact_rung_against_the_bvp_extremes(model):
    # 1 um - 10 mm at 1 mV and 1 V, and the corners at 20 V: the thinnest strip (its layers overlap
    # there) and the thickest (a neutral core, as 100 um's is: the same case again, at 5-24 s a BVP charge).
    # -20 V against the mirror image of the 20 V solve: the BVP's own sign handling is held at
    # -0.1 mV by the subset test above and at -0.1 uV by the tiny-voltage grid below
    _bvp_points(np.geomspace(1e-6, 1e-2, 3), (1e-3, 1.0), model)
    _bvp_points((1e-6, 1e-2), (20.0, -20.0), model, mirror=True)


TINY = (0.0, 5e-324, 1e-300, 1e-100, 1e-20, 1e-12, 1e-7)


def _tiny_grid(ths):
    for model in MODELS3:
        for th in ths:
            cd0 = _dh_exact(th, model)
            for u in TINY:
                for v in (u, -u):
                    A2 = abs(v) / VT
                    for fid in RUNGS:
                        r = charge(th, v, model, fid)
                        if v == 0.0:
                            assert float(r.sigma) == 0.0 and math.isfinite(float(r.C_diff))
                        if not bool(r.valid):
                            continue
                        if model == "linear":  # exact at every voltage
                            coth = 1 / math.tanh(th / 2 / (float(debye_length(th, MODELS[model].eps_moy, M)) * th / 2))
                            s_ref = charge_scale(MODELS[model], M) / VT * coth * (math.tanh(A2 / 2) / A2 if A2 else 0.5) * v
                            c_ref = charge_scale(MODELS[model], M) / VT * coth * 0.5 / math.cosh(A2 / 2) ** 2
                            slack = 0.0
                        else:  # Debye-Hueckel: relative O(A2^2) (sigma is odd), coefficient <= 0.25 measured
                            s_ref, c_ref, slack = cd0 * v, cd0, A2 * A2
                        es = abs(float(r.sigma) - s_ref) / abs(s_ref) if s_ref else abs(float(r.sigma))
                        assert es <= float(r.error) + slack, (model, th, v, fid)
                        assert abs(float(r.C_diff) / c_ref - 1) <= float(r.error_C_diff) + slack, (model, th, v, fid)
                        if u >= 1e-300:  # sigma ~ C_d(0) phi0, not 0 and not a constant
                            assert float(r.sigma) / v == pytest.approx(cd0, rel=0.3)


def test_tiny_voltages_subset():
    """sigma -> C_d(0) phi0 for every rung down to subnormal voltages, both signs, and 0 V."""
    _tiny_grid((1e-6, 200e-6))
    # the 1e-300 V affine strip of the reproducer
    r = charge(200e-6, 1e-300, "affine")
    assert float(r.sigma) == pytest.approx(float(charge(200e-6, 0.0, "affine").C_diff) * 1e-300, rel=1e-12)


@pytest.mark.slow
def test_tiny_voltages_grid():
    _tiny_grid(np.geomspace(1e-6, 1e-2, 9))
    for model in ("constant", "affine"):
        _bvp_points((1e-6, 200e-6), (1e-7, -1e-7), model, bvp_error=True)


def test_below_min_thickness_refused():
    with pytest.raises(ValueError, match="MIN_THICKNESS"):
        charge(50e-9, 1.0)
