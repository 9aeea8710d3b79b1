"""Leading order at nominal, convergence orders, API behaviour (the fidelity contract on a grid:
tests/integration/test_fidelity_contract.py)."""

import math

import numpy as np
import pytest

from ipmc_asym import moment_integral
from ipmc_asym.bvp.solver import moment_integral_bvp
from ipmc_asym.integral.api import moment

MODELS = ("constant", "linear", "affine")


@pytest.mark.parametrize("model", MODELS)
def test_leading_at_nominal(model):
    ref = moment_integral_bvp(200e-6, 1.0, model)
    r = moment(200e-6, 1.0, model, "leading")
    err = abs(float(r.I) / ref - 1)
    assert err <= 5e-2
    # the estimate (next term) is the right size: within a factor 2 of the true error
    assert 0.5 * err <= float(r.error) <= 2 * err + 1e-10


@pytest.mark.parametrize("model", MODELS)
def test_leading_converges_first_order_in_lambda(model):
    """Doubling the thickness halves lambda: leading's error must halve (order 1)."""
    th = 200e-6 * 2.0 ** np.arange(4)
    ref = moment(th, 1.0, model, "quadrature").I
    lead = moment(th, 1.0, model, "leading").I
    err = np.abs(lead / ref - 1)
    orders = np.log2(err[:-1] / err[1:])
    assert np.all(np.abs(orders - 1.0) < 0.05), orders


@pytest.mark.parametrize("model", MODELS)
def test_corrected_exact_in_lambda(model):
    """The lambda expansion stops at two terms: corrected's error does not grow with lambda."""
    th = 20e-6 * 2.0 ** np.arange(6)
    ref = moment(th, 1.0, model, "quadrature").I
    cor = moment(th, 1.0, model, "corrected").I
    assert np.max(np.abs(cor / ref - 1)) < 1e-10


def test_quadrature_error_is_exponentially_small_in_core_over_lambda():
    """Affine model at 10 um: overlap effect ~exp(-2/lambda) is visible and bounded."""
    ref = moment_integral_bvp(10e-6, 1.0, "affine")
    q = moment(10e-6, 1.0, "affine", "quadrature")
    err = abs(float(q.I) / ref - 1)
    assert 1e-12 < err <= float(q.error)


def test_broadcast_sign_and_zero():
    th = np.array([[100e-6], [200e-6]])
    v = np.array([-2.0, -0.5, 0.0, 0.5, 2.0])
    I = moment_integral(th, v, "constant", "corrected")
    assert I.shape == (2, 5)
    assert np.all(I[:, 2] == 0.0)
    assert np.all(np.sign(I) == np.sign(v))
    assert isinstance(moment_integral(200e-6, 1.0), float)


@pytest.mark.parametrize("bad", [dict(thickness=-1e-4), dict(thickness=float("nan")), dict(voltage=float("inf"))])
def test_bad_input_raises_valueerror(bad):
    kw = dict(thickness=200e-6, voltage=1.0)
    kw.update(bad)
    with pytest.raises(ValueError, match="thickness|voltage"):
        moment_integral(kw["thickness"], kw["voltage"])


def test_unknown_model_and_fidelity_list_valid_ones():
    with pytest.raises(ValueError, match="constant, linear, affine"):
        moment_integral(200e-6, 1.0, "quadratic")
    with pytest.raises(ValueError, match="leading, corrected, quadrature, exact, bvp"):
        moment_integral(200e-6, 1.0, "constant", "exactly")
    with pytest.raises(ValueError, match="phi4"):
        moment_integral(200e-6, 1.0, phi4=1.2)


def test_custom_eps_needs_bvp():
    with pytest.raises(ValueError, match="bvp"):
        moment_integral(200e-6, 1.0, lambda C: 5e-6 + 0 * C, "quadrature")
    I = moment_integral(200e-6, 1.0, lambda C: 5e-6 + 0 * C, "bvp")
    assert I == pytest.approx(moment_integral(200e-6, 1.0, "constant", "quadrature"), rel=1e-7)


def test_c_moy_choice_changes_result():
    a = moment_integral(200e-6, 1.0, c_moy="paper")
    b = moment_integral(200e-6, 1.0, c_moy="formula")
    assert a != b and math.isfinite(b)


def test_outside_validity_is_never_silent():
    """1 um total thickness at 20 V: the layers fill the strip; leading must say so."""
    with pytest.raises(ValueError, match="outside its validity"):
        moment_integral(1e-6, 20.0, "linear", "leading")  # default: raise, never a number
    with pytest.warns(RuntimeWarning, match="outside its validity"):
        assert math.isnan(moment_integral(1e-6, 20.0, "linear", "leading", on_invalid="warn"))
    I = moment_integral([1e-6, 200e-6], 20.0, "linear", "leading", on_invalid="nan")
    assert math.isnan(I[0]) and math.isfinite(I[1])
    with pytest.raises(ValueError, match="on_invalid"):
        moment_integral(200e-6, 1.0, on_invalid="maybe")
    r = moment(1e-6, 20.0, "linear", "leading")
    assert not bool(r.valid) and float(r.error) > 1e-2
