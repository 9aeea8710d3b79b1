"""The public charge entry: its arguments (the kernels and rungs are tested in tests/kernels and
tests/dynamics/test_electrode.py)."""

from __future__ import annotations

import numpy as np
import pytest

import ipmc_asym as ia


def test_a_strip_supplies_thickness_voltage_and_area():
    s = ia.Strip(thickness="150um", voltage="-0.8V", width="3mm", length="25mm")
    got = ia.charge(s)
    # sigma depends on thickness and voltage only; Q is sigma over the electrode's area 2l L
    ref = ia.charge(150e-6, -0.8, width=1.0, length=1.0)
    assert float(got.sigma) == float(ref.sigma)
    assert float(got.Q) == pytest.approx(float(ref.sigma) * 3e-3 * 25e-3, rel=1e-14)
    # arguments given beside the Strip take precedence
    other = ia.charge(s, 0.4, length=0.05)
    assert float(other.sigma) == float(ia.charge(150e-6, 0.4).sigma)
    assert float(other.Q) == pytest.approx(float(other.sigma) * 3e-3 * 0.05, rel=1e-14)


def test_default_area_is_the_default_strips():
    r = ia.charge(np.array([100e-6, 200e-6]), 1.0)
    np.testing.assert_allclose(r.Q, r.sigma * ia.Strip().width * ia.Strip().length, rtol=1e-14)


def test_voltage_needed_without_a_strip():
    with pytest.raises(ValueError, match="^voltage: needed"):
        ia.charge(200e-6)
