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
