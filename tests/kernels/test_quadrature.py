"""The doubling-panel quadrature shared by the layer integrals, against closed forms."""

import ast
import math
import subprocess
import sys

import numpy as np
import pytest

from ipmc_asym.kernels.jit import jit
from ipmc_asym.kernels.quadrature import doubling_panels
from ipmc_asym.kernels.special import gauss_legendre


@jit
def _lorentz(u, sgn, a, wt):
    """``wt / (1 + (sgn u/a)^2)``: a pole at distance ``a`` from the real axis."""
    y = sgn * u / a
    return wt / (1.0 + y * y)


@jit
def _exp(u, sgn, a, wt):
    return wt * math.exp(sgn * a * u)


_panels_lorentz = doubling_panels(_lorentz)
_panels_exp = doubling_panels(_exp)
_X, _W, _ = (np.ascontiguousarray(v) for v in gauss_legendre(20))


@pytest.mark.parametrize("T", [1e-3, 0.3, 0.5, 0.7, 1.0, 5.0, 37.0, 1e3])
@pytest.mark.parametrize("sgn", [1.0, -1.0])
def test_doubling_panels_against_closed_forms(T, sgn):
    # a pole at distance 1 (the layer integrands' kind of singularity) at every T; an exponential
    # where it changes by less than e^9 over a panel (the doubling panels are not made for more)
    assert _panels_lorentz(T, sgn, 1.0, _X, _W) == pytest.approx(math.atan(T), rel=1e-13)
    a = 0.5
    if T > 40.0:
        return
    ref = sgn * math.expm1(sgn * a * T) / a  # int_0^T e^{sgn a u} du
    assert _panels_exp(T, sgn, a, _X, _W) == pytest.approx(ref, rel=1e-13)


def test_doubling_panels_end_on_a_limit_that_is_not_finite():
    """A NaN upper limit never met the loop's end test (the charge at A2 ~ 1e308 spun forever,
    deaf to SIGTERM): NaN out, at once, for NaN and inf; in a child process so that a regression
    fails here instead of hanging the suite."""
    code = ("import math; from ipmc_asym.kernels.charge import _chat_panels; "
            "from ipmc_asym.kernels.quadrature import _X, _W; "
            "print([_chat_panels(t, 1.0, 0.5, _X, _W) for t in (2.0, math.inf, math.nan)])")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    finite, inf, nan = ast.literal_eval(out.stdout.strip().replace("nan", "None"))
    assert finite > 0 and inf is None and nan is None
