"""The circuit's small-signal impedance against the linearised PNP (the reference)."""

import math

import numpy as np
import pytest

from ipmc_asym.dynamics.circuit import circuit_band, frequency_response
from ipmc_asym.model.params import NAFION_LI, Strip
from ipmc_asym.model.permittivity import get_model

THICK = (20e-6, 200e-6, 1e-3)
MODELS = ("constant", "linear", "affine")


def _exact_z_area(f, strip, model, m=NAFION_LI):
    """Independent derivation: Z_area = [2e + 2 kappa tanh(k e)/(i w eps k)]/(kappa + i w eps), k^2 = 1/lD^2 + i w/D."""
    eps = get_model(model).eps_moy
    kappa = m.phi4 * m.F**2 * m.D * m.C_moy / (m.R * m.T)
    lD = math.sqrt(eps * m.R * m.T / (m.phi4 * m.F**2 * m.C_moy))
    w = 2 * math.pi * np.asarray(f)
    k = np.sqrt(1 / lD**2 + 1j * w / m.D)
    e = strip.e
    return (2 * e + 2 * kappa * np.tanh(k * e) / (1j * w * eps * k)) / (kappa + 1j * w * eps), lD


@pytest.mark.parametrize("thickness", THICK)
@pytest.mark.parametrize("model", MODELS)
def test_pnp_linear_is_the_exact_linear_theory(thickness, model):
    s = Strip(thickness=thickness)
    f = np.geomspace(1e-3, 1e7, 200)
    Zx, _ = _exact_z_area(f, s, model)
    r = frequency_response(f, strip=s, model=model, method="pnp-linear")
    assert np.max(np.abs(r.Z_area / Zx - 1)) < 1e-9


@pytest.mark.parametrize("thickness", THICK)
@pytest.mark.parametrize("model", MODELS)
def test_circuit_error_is_its_stated_error_and_below_lambda_over_2(thickness, model):
    s = Strip(thickness=thickness)
    f = np.geomspace(1e-3, 1e8, 400)
    Zx, lD = _exact_z_area(f, s, model)
    r = frequency_response(f, strip=s, model=model, method="circuit")
    actual = np.abs(r.Z_area - Zx) / np.abs(Zx)
    # the stated per-frequency error is the circuit's actual deviation from the exact theory
    assert np.allclose(r.error, actual, rtol=1e-6, atol=1e-13)
    lam = lD / s.e
    assert r.error_max == pytest.approx(lam / 2)
    assert np.all(actual <= lam / 2)
    # far above the dielectric relaxation frequency both tend to the bulk capacitance (C_g is in the circuit)
    assert actual[-1] < 1e-3 * lam
    # below f_d the error is ~ (f/(2 f_d))/|1 + i omega tau|
    lo = f < 1e-3 * r.f_d
    ratio = actual[lo] / (f[lo] / (2 * r.f_d) / np.abs(1 + 2j * math.pi * f[lo] * r.tau))
    assert np.all(np.abs(ratio - 1) < 0.05)
    # H_w inherits the relative error of Z
    hx = frequency_response(f, strip=s, model=model, method="pnp-linear").H_w
    assert np.all(np.abs(r.H_w / hx - 1) <= actual / (1 - actual) * (1 + 1e-6) + 1e-12)


def test_circuit_band():
    f = np.array([1.0, 2.0, 3.0, 4.0, 5.0])
    assert circuit_band(f, np.array([0.0, 1.0, 0.0, 0.0, 1.0]), 0.5) == [[1.0, 1.0], [3.0, 4.0]]
