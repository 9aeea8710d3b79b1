"""`ipmc-asym laws`: printed exponents against fits of BVP values in each regime."""

import json

import numpy as np
import pytest

from ipmc_asym.bvp.solver import moment_integral_bvp
from ipmc_asym.cli import main


@pytest.fixture(scope="module")
def laws(tmp_path_factory):
    import io
    from contextlib import redirect_stdout

    buf = io.StringIO()
    with redirect_stdout(buf):
        assert main(["laws", "--json"]) == 0
    return json.loads(buf.getvalue())


def _exp(laws, model, regime, q="I"):
    for r in laws["models"][model]["laws"]:
        if r["regime"] == regime and r["quantity"] == q:
            return {k: float(eval(v)) for k, v in r["exponents"].items()}  # "1/2" -> 0.5
    raise KeyError((model, regime, q))


def _fit(xs, ys):
    return np.polyfit(np.log(xs), np.log(np.abs(ys)), 1)[0]


@pytest.mark.slow
@pytest.mark.parametrize("model,regime,volts,tol", [
    ("constant", "small voltage", (1e-3, 2e-3), 0.02),
    ("constant", "large voltage", (8.0, 10.0), 0.05),
    ("linear", "small voltage", (1e-3, 2e-3), 0.02),
    ("linear", "large voltage", (2.0, 4.0), 0.02),
])
def test_voltage_exponents_against_bvp(laws, model, regime, volts, tol):
    I = [moment_integral_bvp(200e-6, v, model) for v in volts]
    assert _fit(volts, I) == pytest.approx(_exp(laws, model, regime)["phi0"], abs=tol)


@pytest.mark.parametrize("model", ["constant", "linear", "affine"])
def test_thickness_exponent_against_bvp(laws, model):
    th = (1e-3, 2e-3)  # total thickness; e = half
    I = [moment_integral_bvp(t, 1.0, model) for t in th]
    assert _fit(th, I) == pytest.approx(_exp(laws, model, "small voltage")["e"], abs=0.01)


def test_moment_exponents_follow(laws):
    e = _exp(laws, "linear", "large voltage", "M_A")
    assert e["phi0"] == 0 and e["l"] == 1 and e["e"] == 1
    assert laws["factor_sections_3_4_over_6_2"] == {"theta": "3", "w_small": "3", "F_block": "3"}
