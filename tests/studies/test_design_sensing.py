"""The design objectives of the sensing mode: ``sensitivity`` (C/m, static) and ``harvested_power``
(W at a load and frequency), against ``ia.sense`` and ``ia.sensing_response`` at the optimum."""

import pytest

import ipmc_asym as ia

BASE = {"model": "linear", "strip": {"width": "5mm", "voltage": "1V"},
        "vary": {"length": ["1cm", "4cm"], "thickness": ["100um", "400um"]}}


def _strip(d):
    x = d["optimum"]["inputs"]
    return ia.Strip(length=x["length"], width=x["width"], thickness=x["thickness"])


def test_sensitivity_is_the_static_charge_per_tip_displacement():
    d = ia.design({**BASE, "objective": {"maximize": "sensitivity"}, "sensing": {"support": "free", "nu": 0.2}}).as_dict()
    s = _strip(d)
    r = ia.sense(s, tip_displacement=[1e-3], support="free", model="linear", nu=0.2)
    assert d["optimum"]["outputs"]["sensitivity"] == pytest.approx(abs(float(r.Q_per_w[0])), rel=1e-12)
    # Q/w grows as e/L: the optimum sits on the thick, short corner
    assert s.length == pytest.approx(0.01) and s.thickness == pytest.approx(400e-6)


def test_harvested_power_is_the_sensing_response_at_the_optimum():
    spec = {**BASE, "objective": {"maximize": "harvested_power"},
            "sensing": {"frequency": "2mHz", "load": "1kOhm", "amplitude": "0.5mm"},
            "constraints": {"harvested_power": {"min": "1pW"}}}
    d = ia.design(spec).as_dict()
    s = _strip(d)
    r = ia.sensing_response([2e-3], s, model="linear", load=1e3, amplitude=0.5e-3)
    assert bool(r.valid[0])
    assert d["optimum"]["outputs"]["harvested_power"] == pytest.approx(float(r.power[0]), rel=1e-12)


def test_power_past_the_one_way_bound_is_no_design():
    # at 1 Hz every candidate's streaming potential is past the one-way bound: no power to design on
    spec = {**BASE, "objective": {"maximize": "harvested_power"}, "sensing": {"frequency": "1Hz", "load": "10ohm"}}
    with pytest.raises(ValueError, match="no design within the bounds"):
        ia.design(spec)


@pytest.mark.parametrize("sensing, needle", [
    ({}, "harvested_power needs [sensing] frequency"),
    ({"frequency": "2mHz"}, "harvested_power needs [sensing] frequency"),
    ({"frequency": "2mHz", "load": "-1ohm"}, "sensing.load must be a resistance > 0"),
    ({"frequency": "2mHz", "load": "1kOhm", "nu": 0.7}, "sensing.nu"),
    ({"frequency": "2mHz", "load": "1kOhm", "support": "pinned"}, "sensing.support"),
    ({"frequency": "2mHz", "load": "1kOhm", "colour": 1}, "unknown key 'colour' in [sensing]"),
])
def test_refusals_name_the_key(sensing, needle):
    with pytest.raises(ValueError, match=needle.replace("[", r"\[").replace("]", r"\]")):
        ia.design({**BASE, "objective": {"maximize": "harvested_power"}, "sensing": sensing})
