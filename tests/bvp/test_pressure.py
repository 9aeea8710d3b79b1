"""The BVP with the pressure term against the ``exact`` rung with it (an independent path: the
BVP integrates the ODEs on a collocation mesh, the kernel uses the first integral and panels)."""

import math

import pytest

from ipmc_asym.bvp.pressure import solve_pressure
from ipmc_asym.kernels.pressure import moment_pressure
from ipmc_asym.model.params import NAFION_LI, Strip
from ipmc_asym.model.permittivity import get_model


@pytest.mark.parametrize("model", ["constant", "linear", "affine"])
@pytest.mark.parametrize("th,v", [(200e-6, 1.0), (2e-6, 0.3), (200e-6, -3.0), (20e-6, 0.01)])
def test_bvp_matches_exact_with_pressure_term(model, th, v):
    beta = -0.0242
    st = Strip(thickness=th, voltage=v)
    r = solve_pressure(st, model, NAFION_LI, beta=beta)
    assert r.success, r.message
    g = get_model(model).groups(st, NAFION_LI)
    k = moment_pressure(math.sqrt((g.A0 + g.A1) / g.A2), g.A2, g.A3, g.A1 / (g.A0 + g.A1), beta)
    assert k[4] > 0
    assert r.I == pytest.approx(math.copysign(k[0], v), rel=1e-10)
    assert r.B1 == pytest.approx(k[1], rel=1e-10)
    assert r.D1 == pytest.approx(k[5], rel=1e-10)
