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
    ax = r.plot().axes[0]
    assert "[m]" in ax.get_xlabel() and "[m]" in ax.get_ylabel()
    (line,) = ax.lines
    x, y = line.get_data()
    assert (x[0], y[0]) == (0.0, 0.0) and y[-1] == pytest.approx(r["y_tip"], rel=1e-12)
