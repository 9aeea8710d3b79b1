"""The checks of model/params that every entry shares: the voltage cap."""

import numpy as np
import pytest

from ipmc_asym.base.settings import MAX_VOLTAGE
from ipmc_asym.model.params import Strip, check_voltages


def test_a_strip_refuses_a_voltage_past_the_cap_in_one_line_and_takes_it_at_the_cap():
    for bad in (2 * MAX_VOLTAGE, -1e308, "2kV"):
        with pytest.raises(ValueError, match=r"^voltage: \|phi0\| up to 1000 V allowed") as ei:
            Strip(voltage=bad)
        assert "\n" not in str(ei.value)
    for ok in (MAX_VOLTAGE, -MAX_VOLTAGE, "1kV", 0.0, 5e-324):
        Strip(voltage=ok)


def test_check_voltages_says_which_of_not_finite_and_past_the_cap():
    check_voltages(np.array([-MAX_VOLTAGE, 0.0, MAX_VOLTAGE]))
    with pytest.raises(ValueError, match="voltage must be finite"):
        check_voltages([1.0, np.nan])
    with pytest.raises(ValueError, match="must be finite"):
        check_voltages(np.inf, "bias")  # inf is not finite, though also past the cap
    with pytest.raises(ValueError, match=r"bias: \|phi0\| up to"):
        check_voltages([1.0, -1.5 * MAX_VOLTAGE], "bias")


def test_a_strip_refuses_a_dimension_past_the_cap_in_one_line_naming_it():
    import ipmc_asym as ia
    from ipmc_asym.base.settings import MAX_DIMENSION

    for name, kw in (("length", {"length": 1e308}), ("width", {"width": 2 * MAX_DIMENSION}),
                     ("thickness", {"thickness": 1e308})):
        with pytest.raises(ValueError, match=rf"^{name}.* must be at most 1000 m") as ei:
            Strip(**kw)
        assert "\n" not in str(ei.value)
    with pytest.raises(ValueError, match=r"^width \(total, 2l\) must be at most"):
        ia.charge(200e-6, 1.0, width=1e308)  # Q = 2l L sigma would be inf
    # at the cap the products stay finite
    Strip(length=MAX_DIMENSION, width=MAX_DIMENSION, thickness=MAX_DIMENSION)
    c = ia.charge(200e-6, 1.0, width=MAX_DIMENSION, length=MAX_DIMENSION)
    assert np.isfinite(float(c.Q)) and float(c.Q) > 0


def test_a_strip_refuses_a_subnormal_length_or_width_by_name():
    # a subnormal length divides the beam's formulas by zero ("float division by zero" in sense)
    for name, kw in (("length", {"length": 1e-320}), ("width", {"width": 5e-324})):
        with pytest.raises(ValueError, match=rf"^{name}.* must be at least 1e-09 m"):
            Strip(**kw)
    with pytest.raises(ValueError, match="MIN_THICKNESS"):  # the thickness keeps its own, stricter floor
        Strip(thickness=1e-320)
