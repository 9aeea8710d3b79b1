"""Small voltages, down to 0 and the subnormals: every rung within its own error bound of the
Debye-Hueckel series (``derivations/debye_hueckel.py``), or refused in one line.

References, each independent of the code under test:

* the series ``I0 + A2^2 I2`` evaluated from its SymPy expressions with mpmath at 40 digits
  (not the generated float kernels), with its derived remainder bound;
* the series itself against the BVP at small but representable voltages (slow), and against
  the closed-form kernels (Taylor patches, a different derivation) at ``A2 = 1e-2``.
"""

import math

import mpmath as mp
import numpy as np
import pytest
import sympy as sp

from derivations import debye_hueckel as DH
from ipmc_asym.base.settings import BVP_STATED_ERROR
from ipmc_asym.integral.api import moment, moment_integral
from ipmc_asym.kernels import _generated_dh as G
from ipmc_asym.kernels.debye import DH_A2
from ipmc_asym.model import groups
from ipmc_asym.model.params import NAFION_LI
from ipmc_asym.model.permittivity import MODELS

RUNGS = ("leading", "corrected", "quadrature", "exact")
VOLTS = (0.0, 5e-324, 1e-300, 1e-200, 1e-100, 1e-20, 1e-12, 1e-7, 1e-4)
THICK = (1e-7, 1e-6, 1e-5, 2e-4, 1e-2)


@pytest.fixture(scope="module")
def series():
    """``(I0, I2)`` as mpmath functions of ``(u, rho, A3)``, from the SymPy derivation."""
    pert = DH.perturbation()
    fs = [sp.lambdify((DH.u, DH.E, DH.rho, DH.A3), pert[k], "mpmath") for k in (0, 2)]
    return fs


def reference(series, thickness, voltage, model):
    """``(I, absolute bound)`` of the series for ``|phi0|`` (signed like the voltage)."""
    perm = MODELS[model]
    eps_core = perm.eps0 + perm.deps
    lam = float(groups.debye_length(thickness, eps_core, NAFION_LI))
    A2 = float(groups.A2(voltage, NAFION_LI))
    A3 = float(groups.A3(NAFION_LI))
    r = perm.eps0 / eps_core
    with mp.workdps(40):
        uu = 1 / mp.mpf(lam)
        Eu = mp.exp(uu)
        I = series[0](uu, Eu, r, A3) + mp.mpf(A2) ** 2 * series[1](uu, Eu, r, A3)
        n = mp.coth(uu) / uu - 1 / uu**2
        bound = 2 * (G.DH_K4A + G.DH_K4B * abs(A3)) * n * mp.mpf(A2) ** 4
    if voltage == 0.0:
        return 0.0, 0.0
    return math.copysign(float(I), voltage), float(bound) + 1e-16 * abs(float(I))


@pytest.mark.parametrize("model", tuple(MODELS))
@pytest.mark.parametrize("fidelity", RUNGS)
def test_grid_within_own_bound_or_refused(series, model, fidelity):
    th = np.array(THICK)[:, None]
    v = np.array([-x for x in VOLTS[::-1]] + list(VOLTS))[None, :]
    T, V = np.broadcast_arrays(th, v)
    r = moment(T, V, model, fidelity)
    for idx in np.ndindex(T.shape):
        t, vv = float(T[idx]), float(V[idx])
        if not r.valid[idx]:  # refused: one line naming the rung
            with pytest.raises(ValueError) as exc:
                moment_integral(t, vv, model, fidelity)
            assert "\n" not in str(exc.value) and fidelity in str(exc.value)
            continue
        ref, bref = reference(series, t, vv, model)
        got = float(r.I[idx])
        assert math.isfinite(got) and math.isfinite(float(r.error[idx]))
        assert got == 0.0 if vv == 0.0 else math.copysign(1.0, got) == math.copysign(1.0, vv)
        assert abs(got - ref) <= float(r.error[idx]) * abs(got) + bref, (t, vv, got, ref, float(r.error[idx]))
        assert moment_integral(t, vv, model, fidelity) == got


@pytest.mark.parametrize("model", tuple(MODELS))
def test_exact_refuses_nothing_at_small_voltage(model):
    """``exact`` holds at any thickness: valid on the whole small-voltage grid."""
    T, V = np.meshgrid(THICK, [-1e-4, -5e-324, 5e-324, 1e-200, 1e-7, 1e-4], indexing="ij")
    assert np.all(moment(T, V, model, "exact").valid)


@pytest.mark.parametrize("model", tuple(MODELS))
def test_scalar_path_at_subnormal_voltage(model):
    """The scalar fast path and the array drivers agree, and ``M_A = A5 I`` is tiny, not huge."""
    for v in (5e-324, -5e-324, 1e-300, -1e-200):
        I = moment_integral(200e-6, v, model, "exact")
        assert I == float(moment(200e-6, v, model, "exact").I)
        assert 0.0 < abs(I) < 1.0 and math.copysign(1.0, I) == math.copysign(1.0, v)
        assert abs(groups.A5(5e-3, 200e-6, v, NAFION_LI) * I) < 1e-150


@pytest.mark.parametrize("model", tuple(MODELS))
def test_series_matches_closed_forms(model):
    """The layer limit of the series against the closed forms (Taylor patches) at A2 = 1e-2,
    above the switch: both are accurate there to ~1e-10."""
    v = 1e-2 / float(groups.inverse_thermal_voltage(NAFION_LI))
    assert float(groups.A2(v, NAFION_LI)) > DH_A2
    from ipmc_asym.kernels.debye import dh_layer

    for th in (2e-4, 1e-2):
        c = moment(th, v, model, "corrected")
        perm = MODELS[model]
        lam = float(groups.debye_length(th, perm.eps0 + perm.deps, NAFION_LI))
        I, e, _, _ = dh_layer.py_func(lam, 1e-2, float(groups.A3(NAFION_LI)), perm.eps0 / (perm.eps0 + perm.deps), 2)
        assert abs(I - float(c.I)) <= (e + float(c.error)) * abs(I), (th, I, float(c.I), e)


@pytest.mark.slow
@pytest.mark.parametrize("model", tuple(MODELS))
def test_series_against_bvp(series, model):
    """The series (the reference of the grid) against the BVP at 1e-4 V and -6e-5 V (A2 above
    the switch: a true BVP solve), at a thin strip with overlapping layers and the nominal one."""
    for th in (1e-6, 2e-4):
        for v in (1e-4, -6e-5):
            assert float(groups.A2(v, NAFION_LI)) > DH_A2
            b = moment(th, v, model, "bvp")
            assert bool(b.valid)
            ref, bref = reference(series, th, v, model)
            assert abs(float(b.I) - ref) <= BVP_STATED_ERROR * abs(ref) + bref, (th, v, float(b.I), ref)


@pytest.mark.slow
@pytest.mark.parametrize("model", tuple(MODELS))
def test_bvp_rung_grid(series, model):
    """The ``bvp`` rung on the tiny-voltage grid: its own bound of the series, both signs."""
    for th in (1e-6, 2e-4):
        for v in (5e-324, -1e-300, 1e-100, -1e-12, 1e-7):
            b = moment(th, v, model, "bvp")
            ref, bref = reference(series, th, v, model)
            assert bool(b.valid)
            assert abs(float(b.I) - ref) <= float(b.error) * abs(ref) + bref
