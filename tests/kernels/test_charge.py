"""The charge's compiled drivers: one per rung, so a first closed-form call compiles no exact code."""

import numpy as np
from references import jitted_reach as _reach

import ipmc_asym as ia
from ipmc_asym.kernels import charge as K
from ipmc_asym.kernels.charge_exact import charge_exact_point


def test_closed_driver_reaches_no_exact_code():
    assert charge_exact_point not in _reach(K.closed_sweep)
    # the walk finds the exact kernel where it is called: the two other drivers
    assert charge_exact_point in _reach(K.near_sweep)
    assert charge_exact_point in _reach(K.exact_sweep)


def test_overlapping_layers_error_bounds_the_difference_from_exact():
    """1 um at 20 V (constant model): the layers overlap, the closed forms' error is measured against
    the exact rung, and the stated error covers the actual difference from that independent rung."""
    th = np.array([1e-6, 2e-4])
    for fid in ("leading", "corrected", "quadrature"):
        r = ia.charge(th, 20.0, "constant", fid)
        x = ia.charge(th, 20.0, "constant", "exact")
        rel = np.abs(r.sigma / x.sigma - 1.0)
        assert np.all(rel <= r.error + x.error), (fid, rel, r.error)
        # the thin strip is the overlap case: its error is far above the neutral-core estimate's rounding
        assert r.error[0] > K.NEAR_LIMIT > r.error[1]
