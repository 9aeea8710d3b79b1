"""The BVP below the voltage it resolves: a one-line refusal, never a number past its stated
error.  Reference: the Debye-Hueckel series (``derivations/debye_hueckel.py``) via ``exact``."""

import pytest

from ipmc_asym.base.settings import BVP_STATED_ERROR
from ipmc_asym.bvp.solver import BVP_MIN_A2, solve
from ipmc_asym.integral.api import moment
from ipmc_asym.model import groups
from ipmc_asym.model.params import NAFION_LI, Strip


@pytest.mark.parametrize("v", [5e-324, -1e-200, 1e-12, -1e-9])
def test_refused_in_one_line(v):
    with pytest.raises(ValueError) as exc:
        solve(Strip(thickness=200e-6, voltage=v), "constant")
    assert "\n" not in str(exc.value) and "voltage" in str(exc.value)


# the affine model's solve takes ~9 s: run in CI, the dev loop keeps the constant model
@pytest.mark.parametrize("model", ["constant", pytest.param("affine", marks=pytest.mark.slow)])
def test_just_above_the_floor_within_stated_error(model):
    v = -1.5 * BVP_MIN_A2 / float(groups.inverse_thermal_voltage(NAFION_LI))
    r = solve(Strip(thickness=200e-6, voltage=v), model)
    assert r.success
    ref = float(moment(200e-6, v, model, "exact").I)
    assert abs(r.I - ref) <= BVP_STATED_ERROR * abs(ref)
