"""What a closed-form point costs in transcendental calls: the reason the closed forms are
measured against a loop of seven of them (``ipmc-asym bench``) and where their time goes.

The interpreted twin of the closed forms' fused driver runs the compiled driver's own source (bit for bit,
``test_jit.py``); its ``math`` is swapped for a counter, so the count is that of the compiled
code's path through each point (the sweep of the bench's closed-form figures)."""

import collections
import math

import numpy as np
import pytest

import ipmc_asym.integral.api as integral
import ipmc_asym.kernels.jit as _jit
from ipmc_asym.model.params import NAFION_LI
from ipmc_asym.model.permittivity import get_model

TRANSCENDENTAL = ("exp", "expm1", "log", "log1p", "pow", "sinh", "cosh", "tanh", "asinh", "atan", "erf")


class _CountingMath:
    def __init__(self, counts):
        self._counts = counts

    def __getattr__(self, name):
        f = getattr(math, name)
        if not callable(f):
            return f

        def counted(*a):
            self._counts[name] += 1
            return f(*a)
        return counted


@pytest.mark.parametrize("fidelity", ["leading", "corrected"])
@pytest.mark.parametrize("model", ["constant", "linear", "affine"])
def test_closed_forms_spend_about_two_transcendental_calls_a_point(model, fidelity):
    """2.0-2.1 exp/expm1/log calls a point and at most 2.5 square roots on the bench's sweep
    (10 um - 4 mm against 10 V - 1 mV): under a third of the seven-call yardstick, so the closed
    forms' cost beyond it is arithmetic (the patches' polynomials, the choice of piece per point)."""
    n = 600
    th = np.exp(np.linspace(np.log(10e-6), np.log(4e-3), n))
    v = np.exp(np.linspace(np.log(1e-3), np.log(10.0), n))[::-1].copy()
    consts = integral._driver_constants(get_model(model), NAFION_LI, fidelity)
    out = [np.empty(n) for _ in range(6)] + [np.empty(n, bool)]
    twin = _jit.interpreted(integral._fused_blocks)
    twin(th[:2], v[:2], *consts, *[a[:2] for a in out], False)  # every twin module's globals exist now
    counts = collections.Counter()
    saved = {k: g["math"] for k, g in _jit._TWIN_GLOBALS.items() if "math" in g}
    try:
        for k in saved:
            _jit._TWIN_GLOBALS[k]["math"] = _CountingMath(counts)
        twin(th, v, *consts, *out, False)
    finally:
        for k, m in saved.items():
            _jit._TWIN_GLOBALS[k]["math"] = m
    per_point = sum(counts[f] for f in TRANSCENDENTAL) / n
    assert 1.9 <= per_point <= 2.2, dict(counts)
    assert counts["sqrt"] / n <= 2.5, dict(counts)
    # the compiled driver gives the same numbers: the count is that of the compiled path
    ref = [np.empty(n) for _ in range(6)] + [np.empty(n, bool)]
    integral._fused_blocks(th, v, *consts, *ref, False)
    assert np.array_equal(out[0], ref[0], equal_nan=True)
