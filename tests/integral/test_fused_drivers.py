"""The fused array path and the scalar fast path of the moment API against the bare driver
on groups computed separately (params.debye_length), point by point."""

import math

import numpy as np
import pytest

from ipmc_asym.integral.api import (
    _ORDER,
    _sweep,
    closed_model_id,
    groups_arrays,
    moment,
    moment_integral,
)
from ipmc_asym.model.params import NAFION_LI
from ipmc_asym.model.permittivity import get_model


def _bare(th, v, model, fidelity):
    perm = get_model(model)
    lam, A2, A3, rho, sign = groups_arrays(th, v, perm, NAFION_LI)
    lam, A2, sign = (np.ascontiguousarray(a, dtype=float).reshape(-1) for a in (lam, A2, sign))
    outs = [np.empty(lam.size) for _ in range(4)]
    _sweep(lam, A2, A3, rho, closed_model_id(perm, fidelity), _ORDER[fidelity], sign, *outs)
    return outs[0].reshape(np.broadcast_shapes(np.shape(th), np.shape(v)))


@pytest.mark.parametrize("fidelity", ["leading", "corrected", "quadrature", "exact"])
def test_fused_broadcasts_like_the_bare_driver(fidelity):
    th = np.logspace(-5, -2.5, 6)
    v = np.array([-3.0, -1e-3, 0.0, 0.2, 7.0])
    cases = [(th[:, None], v[None, :]),             # outer product: materialised broadcast
             (th, 1.0), (2e-4, v),                   # size-1 side: no copy
             (th[::2], v[1:4]),                      # non-contiguous input
             (np.asfortranarray(np.outer(th, np.ones(5))), np.outer(np.ones(6), v))]
    for a, b in cases:
        r = moment(a, b, "affine", fidelity)
        ref = _bare(a, b, "affine", fidelity)
        assert r.I.shape == ref.shape
        assert np.allclose(r.I, ref, rtol=1e-14, atol=0)


def test_fused_groups_match_debye_length():
    th = np.logspace(-6, -2, 101)
    v = np.linspace(-20, 20, 101)
    r = moment(th, v, "linear", "corrected")
    lam, A2, *_ = groups_arrays(th, v, get_model("linear"), NAFION_LI)
    assert np.allclose(r.lam, lam, rtol=1e-15) and np.allclose(r.A2, A2, rtol=1e-15)


@pytest.mark.parametrize("model", ["constant", "linear", "affine"])
@pytest.mark.parametrize("fidelity", ["leading", "corrected", "quadrature", "exact"])
def test_scalar_fast_path_equals_array_path(model, fidelity):
    for th, v in [(2e-4, 1.0), (2e-4, -1.0), (1e-5, 0.0), (3e-3, 12.0), (np.float64(5e-5), 2)]:
        got = moment_integral(th, v, model, fidelity, on_invalid="nan")
        r = moment(np.array([th]), np.array([v]), model, fidelity)
        ref = float(r.I[0]) if bool(r.valid[0]) else math.nan  # never a number that failed its check
        assert isinstance(got, float)
        assert got == pytest.approx(ref, rel=1e-15, abs=0, nan_ok=True)


def test_scalar_path_still_warns_and_refuses():
    with pytest.warns(RuntimeWarning, match="outside its validity"):
        assert math.isnan(moment_integral(1e-6, 20.0, "constant", "quadrature", on_invalid="warn"))
    with pytest.raises(ValueError, match="outside its validity"):
        moment_integral(1e-6, 20.0, "constant", "quadrature")
    with pytest.raises(ValueError, match="thickness"):
        moment_integral(-1e-4, 1.0, fidelity="leading")
    with pytest.raises(ValueError, match="voltage"):
        moment_integral(1e-4, math.nan, fidelity="leading")
    with pytest.raises(ValueError, match="on_invalid"):
        moment_integral(1e-4, 1.0, fidelity="leading", on_invalid="maybe")


def test_bad_array_inputs_refused_in_one_line():
    with pytest.raises(ValueError, match="thickness"):
        moment(np.array([1e-4, 0.0]), 1.0, "constant", "leading")
    with pytest.raises(ValueError, match="voltage"):
        moment(1e-4, np.array([1.0, np.inf]), "constant", "exact")


@pytest.mark.parametrize("fidelity", ["leading", "corrected"])
@pytest.mark.parametrize("model", ["constant", "linear", "affine"])
def test_block_driver_is_the_point_driver_bit_for_bit(fidelity, model):
    """The closed forms run stage by stage over blocks of points (latency hidden); the results
    are those of the point-by-point driver, bit for bit, with every output, in both the full
    (moment) and the lean (moment_integral) modes -- zero volts and bad inputs included."""
    import ipmc_asym.integral.api as integral
    from ipmc_asym.model.params import NAFION_LI
    from ipmc_asym.model.permittivity import get_model

    rng = np.random.default_rng(5)
    n = 3 * integral.BLOCK + 17  # several blocks and a partial one
    th = np.exp(rng.uniform(np.log(1e-6), np.log(1e-2), n))
    v = np.exp(rng.uniform(np.log(1e-4), np.log(20.0), n)) * rng.choice([-1.0, 1.0], n)
    v[:3] = 0.0
    th[5], v[6], th[7] = np.nan, np.inf, -1.0
    consts = integral._driver_constants(get_model(model), NAFION_LI, fidelity)
    for full in (True, False):
        outs = []
        for driver in (integral._fused_blocks, integral._fused_points):
            o = [np.empty(n) for _ in range(6)] + [np.empty(n, bool)]
            if not full:
                o[1:6] = [np.empty(0)] * 5
            counts = driver(th, v, *consts, *o, not full)
            outs.append((counts, o))
        (ca, a), (cb, b) = outs
        assert tuple(ca) == tuple(cb) and ca[0] == 2 and ca[1] == 1
        for x, y in zip(a, b):
            assert np.array_equal(x, y, equal_nan=True)
