"""The row of ``evaluate`` as a result object (its numbers are tested against the BVP and the paper
in tests/forward/test_model.py and tests/integration)."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import ipmc_asym as ia
from ipmc_asym.forward.estimate import arc


@pytest.mark.parametrize("voltage", [1.0, -2.0])
def test_the_arc_ends_at_the_tip_the_beam_computes(voltage):
    """The figure's arc (uniform curvature from theta) against the beam's own tip position."""
    s = ia.Strip(voltage=voltage)
    r = ia.evaluate(s)
    x, y = arc(r.theta, s.length)
    assert x[-1] == pytest.approx(r["x_tip"], rel=1e-12) and y[-1] == pytest.approx(r["y_tip"], rel=1e-12)
    # arc length: the strip does not stretch
    assert float(np.sum(np.hypot(np.diff(x), np.diff(y)))) == pytest.approx(s.length, rel=1e-4)


def test_arc_straight_and_tiny_rotation():
    x, y = arc(0.0, 0.02)
    assert np.all(y == 0.0) and x[-1] == 0.02
    x, y = arc(1e-12, 0.02)  # the small-displacement deflection theta L/2
    assert y[-1] == pytest.approx(0.5e-12 * 0.02, rel=1e-9) and math.isfinite(x[-1])


def test_row_is_the_json_dict_with_a_face():
    r = ia.evaluate(ia.Strip(), model="linear")
    plain = json.loads(json.dumps(r))
    assert plain == {k: v for k, v in r.items()} and r.theta == r["theta"]
    with pytest.raises(AttributeError):
        r.no_such_key
    text = repr(r)
    assert "EstimateRow(model=linear" in text and "[N m]" in text and len(text.splitlines()) < 40
    ds = r.to_xarray()
    assert float(ds["M_A"]) == r["M_A"] and ds["M_A"].attrs["units"] == "N m"
    # the strip evaluated travels with the row (not as keys: the JSON row is as before)
    s = ia.Strip()
    assert [float(ds[k]) for k in ("length", "width", "thickness", "voltage")] == [s.length, s.width, s.thickness,
                                                                                  s.voltage]
    assert "thickness" not in r and "thickness (total 2e)" in text and "2e = 200 um" in text
    ax = r.plot().axes[0]
    assert "[m]" in ax.get_xlabel() and "[m]" in ax.get_ylabel()
    (line,) = ax.lines
    x, y = line.get_data()
    assert (x[0], y[0]) == (0.0, 0.0) and y[-1] == pytest.approx(r["y_tip"], rel=1e-12)


def test_model_notes_say_what_the_numbers_show():
    """The linear model's saturation note is true where it is said (an independent evaluation:
    M_A at twice the voltage within 0.2 %), and the electrolysis note appears above 1.23 V only."""
    from ipmc_asym.forward.estimate import estimate_document
    from ipmc_asym.forward.model import LINEAR_SATURATION_A2
    from ipmc_asym.model import groups

    v_sat = LINEAR_SATURATION_A2 / float(groups.A2(1.0, ia.NAFION_LI))  # volts where A2 reaches the threshold
    for v in (v_sat * 1.01, 1.0, 3.0):
        doc = estimate_document(ia.Strip(voltage=v), ia.NAFION_LI, "linear", "quadrature", None)
        assert sum("saturated" in n for n in doc["notes"]) == 1
        m1 = doc["results"][0]["M_A"]
        m2 = ia.evaluate(ia.Strip(voltage=2 * v), "linear")["M_A"]
        assert abs(m2 / m1 - 1.0) < 2e-3
        assert any("decomposition potential" in n for n in doc["notes"]) == (v > 1.23)
    for th in (1e-6, 2e-3):  # thin and thick strips saturate from the same A2
        m1, m2 = (ia.evaluate(ia.Strip(thickness=th, voltage=k * v_sat * 1.01), "linear")["M_A"] for k in (1, 2))
        assert abs(m2 / m1 - 1.0) < 2e-3
    below = estimate_document(ia.Strip(voltage=0.5 * v_sat), ia.NAFION_LI, "all", "quadrature", None)
    assert below["notes"] == []
    # not said for the models that do not saturate
    assert estimate_document(ia.Strip(voltage=1.0), ia.NAFION_LI, "constant", "quadrature", None)["notes"] == []
