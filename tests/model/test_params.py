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


def test_a_material_refuses_a_diffusion_coefficient_outside_its_range_in_one_line():
    from ipmc_asym.base.settings import DIFFUSION_RANGE
    from ipmc_asym.model.params import NAFION_LI

    for bad in (1e308, 1e-320, 0.5 * DIFFUSION_RANGE[0], 2.0 * DIFFUSION_RANGE[1]):
        with pytest.raises(ValueError, match=r"^cation diffusion coefficient D must be a finite number within "
                                             r"1e-30\.\.1e\+10 m\^2/s") as ei:
            NAFION_LI.with_(D=bad)
        assert "\n" not in str(ei.value)


def test_a_material_refuses_a_mean_concentration_outside_its_range_in_one_line():
    from ipmc_asym.base.settings import C_MOY_RANGE
    from ipmc_asym.model.params import NAFION_LI, material_from_spec

    for bad in (1e-320, 0.5 * C_MOY_RANGE[0], 2.0 * C_MOY_RANGE[1]):
        with pytest.raises(ValueError, match=r"^c_moy must be a finite number within 0\.001\.\.1e\+08 mol/m\^3"):
            NAFION_LI.with_(c_moy=bad)
        with pytest.raises(ValueError, match=r"^--c-moy must be a finite number within"):
            material_from_spec({"c_moy": bad}, {"c_moy": "--c-moy"})
    # eq. (17) from data each accepted on its own
    with pytest.raises(ValueError, match=r"^C_moy \(formula, eq\. \(17\) from phi4, rho3 and Z3\) must be"):
        NAFION_LI.with_(c_moy="formula", rho3=1e-300)


@pytest.mark.parametrize("end", [0, 1])
def test_the_ends_of_the_diffusion_range_give_finite_dynamics(end):
    from ipmc_asym.base.settings import DIFFUSION_RANGE
    from ipmc_asym.dynamics.circuit import frequency_response, step_response
    from ipmc_asym.model.params import NAFION_LI

    m = NAFION_LI.with_(D=DIFFUSION_RANGE[end])
    for th in (200e-9, 200e-6, 1.0):
        s = Strip(thickness=th)
        r = step_response(1.0, strip=s, material=m, points=5)
        assert np.all(np.isfinite(r.t)) and np.all(np.isfinite(r.sigma)) and np.all(np.isfinite(r.current_density))
        f = frequency_response([1e-9, 1.0, 1e12], strip=s, material=m)
        assert np.all(np.isfinite(f.Z)) and np.all(np.isfinite(f.H_w))


@pytest.mark.parametrize("end", [0, 1])
def test_the_ends_of_the_concentration_range_give_answers(end):
    import ipmc_asym as ia
    from ipmc_asym.base.settings import C_MOY_RANGE
    from ipmc_asym.model.params import NAFION_LI

    m = NAFION_LI.with_(c_moy=C_MOY_RANGE[end])
    for th in (200e-9, 200e-6, 1.0):
        c = ia.charge(th, 1.0, material=m)
        assert np.isfinite(float(c.Q)) and float(c.Q) > 0
        assert np.isfinite(float(ia.moment(th, 1.0, material=m).I))
