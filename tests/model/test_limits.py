"""Plausible ranges and slender-beam limits: the rules both the command line and scene files read."""

import numpy as np
import pytest

from ipmc_asym.model.limits import (
    PLAUSIBLE,
    SLENDER_LIMITS,
    bare_number_warning,
    material_warnings,
    range_warning,
    slender_ok,
    slender_warnings,
)
from ipmc_asym.model.params import NAFION_LI


def test_slender_limits_by_hand():
    # nominal strip: L/2e = 100, 2l/2e = 25, 2l/L = 0.25 -> slender
    assert bool(slender_ok(0.02, 5e-3, 200e-6)) and slender_warnings(0.02, 5e-3, 200e-6) == []
    # thicker than long (L/2e = 0.5) and wider than long (2l/L = 50)
    assert not bool(slender_ok(100e-6, 5e-3, 200e-6))
    lines = slender_warnings(100e-6, 5e-3, 200e-6)
    assert len(lines) == 2 and "L/2e = 0.5" in lines[0] and ">= 10" in lines[0] and "2l/L = 50" in lines[1]
    # each ratio at its limit passes, just beyond it fails (vectorised; exact binary ratios)
    L = np.array([10.0, 10.0, 20.0, 20.0, 20.0, 20.0])
    w = np.array([10.0, 10.0, 10.0, 10.0 - 1e-8, 20.0, 20.0 + 1e-8])
    t = np.array([1.0, 1.0 + 1e-9, 1.0, 1.0, 1.0, 1.0])
    assert list(slender_ok(L, w, t)) == [True, False, True, False, True, False]
    assert set(SLENDER_LIMITS) == {"L/2e", "2l/2e", "2l/L"} and all(v[2] for v in SLENDER_LIMITS.values())


@pytest.mark.parametrize("name, text, value, hint", [
    ("thickness", "200", 200.0, "200um"),
    ("length", "2", 2.0, "2cm"),
    ("width", "5", 5.0, "5mm"),
])
def test_bare_number_implausible_in_si_suggests_units(name, text, value, hint):
    line = bare_number_warning(name, text, value, f"--{name}")
    assert line and f"--{name} {text}" in line and hint in line and "\n" not in line


def test_bare_number_plausible_or_with_units_is_silent():
    assert bare_number_warning("thickness", "200e-6", 200e-6) is None
    assert bare_number_warning("thickness", "200m", 200.0) is None  # a unit was written: meant
    assert bare_number_warning("length", "0.02", 0.02) is None


def test_every_material_parameter_has_a_range_with_a_reason():
    for k in ("E", "c_moy", "phi4", "Z3", "rho3", "rho2", "T", "D", "strain_limit"):
        lo, hi, _unit, why = PLAUSIBLE[k]
        assert lo < hi and why
    assert material_warnings(NAFION_LI) == []  # the preset is plausible
    lines = material_warnings(NAFION_LI.with_(E=1.0, T=1000.0))
    assert len(lines) == 2 and "material E = 1" in lines[0] and "material T = 1000" in lines[1]
    assert "1e-13" in range_warning("D", 1e10) and range_warning("D", 1e-10) is None
    assert range_warning("D", 1e-30) is not None
