"""The fidelity contract, for every fidelity of the registry, on a grid of strips.

Each fidelity states an error bound with every result (``MomentResult.error``) and calls a
result ``valid`` only if that bound is within its advertised ceiling
(``registry.FIDELITIES[f].ceiling``).  Checked here:

* a valid result is within its stated error of the reference -- the full BVP (plus the
  BVP's own stated error); for the BVP itself, the independent references of
  tests/bvp/test_solver.py (the exact solution of the linear model; first integral + layer
  quadratures for constant/affine, exact up to the layers' overlap ~exp(-2/lambda));
* a valid result's stated error is within the fidelity's ceiling;
* the nominal strip is valid at every fidelity (the contract is not vacuous).

Negative voltages are the mirror image in every rung (tests/bvp/test_solver.py::test_mirror_symmetry).
"""

import math

import numpy as np
import pytest
from references import I_layer_quadrature, I_linear_exact

from ipmc_asym.base.registry import FIDELITIES, fidelity_names, model_names
from ipmc_asym.base.settings import BVP_STATED_ERROR
from ipmc_asym.integral.api import moment
from ipmc_asym.model.params import NAFION_LI, Strip
from ipmc_asym.model.permittivity import get_model

TH = np.array([20e-6, 200e-6, 1e-3])
V = np.array([0.05, 1.0, 5.0])
T, VV = np.meshgrid(TH, V, indexing="ij")
NOMINAL = (1, 1)  # 200 um, 1 V

@pytest.fixture(scope="module", params=model_names())
def bvp(request):
    """The BVP rung on the grid, and independent references with their own error."""
    model = request.param
    b = moment(T, VV, model, "bvp", progress=False)
    ref, ref_err = np.empty(T.shape), np.empty(T.shape)
    for idx in np.ndindex(T.shape):
        g = get_model(model).groups(Strip(thickness=float(T[idx]), voltage=float(VV[idx])), NAFION_LI)
        if model == "linear":
            ref[idx], ref_err[idx] = I_linear_exact(g), 1e-12
        else:
            ref[idx], ref_err[idx] = I_layer_quadrature(g)[0], 1e-12 + 10.0 * math.exp(-2.0 / g.debye)
    return model, b, ref, ref_err


@pytest.mark.slow
@pytest.mark.parametrize("fidelity", fidelity_names())
def test_fidelity_contract(bvp, fidelity):
    model, b, exact, exact_err = bvp
    if fidelity == "bvp":
        r, ref, ref_err = b, exact, exact_err
    else:
        r, ref, ref_err = moment(T, VV, model, fidelity), b.I, BVP_STATED_ERROR
    ceiling = FIDELITIES[fidelity].ceiling
    ok = np.asarray(r.valid, bool)
    assert ok[NOMINAL], (model, fidelity, "nominal strip not valid")
    rel = np.abs(r.I - ref) / np.abs(ref)
    stated = np.asarray(r.error, float)
    # 1. within its own stated error of the reference
    bad = ok & (rel > stated + ref_err)
    assert not bad.any(), (model, fidelity, T[bad], VV[bad], rel[bad], stated[bad])
    # 2. the stated error of a valid result is within the advertised ceiling
    assert np.all(stated[ok] <= ceiling), (model, fidelity, stated[ok].max(), ceiling)
