"""The per-sample moment drivers (the uq path): one per rung, so a first closed-form call compiles
neither the quadrature nor the exact rung."""

import numpy as np
from references import jitted_reach

from ipmc_asym.forward.model import forward
from ipmc_asym.integral import samples
from ipmc_asym.kernels.exact import moment_exact
from ipmc_asym.kernels.quadrature import moment_quadrature


def test_closed_driver_reaches_no_other_rung():
    closed = jitted_reach(samples._closed_samples)
    assert moment_quadrature not in closed and moment_exact not in closed
    assert moment_quadrature in jitted_reach(samples._point_samples)  # the walk finds them where called


def test_per_sample_closed_forms_are_the_per_material_moment():
    """A per-sample ``c_moy`` equal at every point gives the one-material forward's numbers (a different
    driver: the fused one with ``A3`` a scalar)."""
    th = np.geomspace(2e-5, 2e-3, 7)
    v = np.linspace(-3.0, 3.0, 7)
    for fid in ("leading", "corrected", "quadrature"):
        one = forward(0.02, 5e-3, th, v, c_moy=3082.0, fidelity=fid)
        per = forward(0.02, 5e-3, th, v, c_moy=np.full(th.size, 3082.0), fidelity=fid)
        np.testing.assert_allclose(per.I, one.I, rtol=1e-13, atol=0.0)
