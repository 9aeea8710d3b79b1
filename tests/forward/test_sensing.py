"""``ia.sense``: the support cases against each other, the inputs checked once with the
parameter named, the pressure-term variant, and the drained Poisson ratio's scaling."""

import numpy as np
import pytest

import ipmc_asym as ia

S = ia.Strip(thickness=200e-6)


def test_tip_force_is_three_quarters_of_the_free_strip_at_linear_order():
    """Free: kappa = 2w/L^2 uniform; tip force: kappa0 = 3w/L^2, mean kappa0/2 -> Q ratio 3/4."""
    w = np.array([1e-5, 2e-5])
    free = ia.sense(S, tip_displacement=w, support="free", fidelity="leading", escalate=False)
    tip = ia.sense(S, tip_displacement=w, support="tip-force", fidelity="leading", escalate=False)
    np.testing.assert_allclose(tip.Q / free.Q, 0.75, rtol=1e-13)
    np.testing.assert_allclose(tip.V_oc / free.V_oc, 0.75, rtol=1e-13)
    np.testing.assert_allclose(tip.curvature, 1.5 * free.curvature, rtol=1e-15)
    # and the nonlinear rung's length integral against a fine trapezoid of the same sigma(kappa)
    big = ia.sense(S, tip_displacement=[5e-3], support="tip-force", fidelity="exact")
    x = np.linspace(0.0, S.length, 2001)
    loc = ia.sense(S, curvature=big.curvature[0] * (1 - x / S.length), support="free", fidelity="exact")
    q_trap = S.width * np.trapezoid(loc.sigma, x)
    assert big.Q[0] == pytest.approx(q_trap, rel=1e-6)


def test_nu_scales_the_linear_response():
    a = ia.sense(S, curvature=0.1, nu=0.0)
    b = ia.sense(S, curvature=0.1, nu=0.3)
    assert b.Q[0] / a.Q[0] == pytest.approx(0.4, rel=1e-8)
    z = ia.sense(S, curvature=0.1, nu=0.5)
    assert z.Q[0] == 0.0 and z.V_oc[0] == 0.0


def test_pressure_term_is_linear_order_whatever_the_rung():
    r = ia.sense(S, curvature=[1.0], fidelity="exact", pressure_term=True, model="linear")
    assert list(r.fidelity_used) == ["leading"] and np.isfinite(r.Q[0]) and bool(r.valid[0])
    p = ia.sense(S, curvature=[1.0], model="linear")
    assert r.Q[0] != p.Q[0] and abs(r.Q[0] / p.Q[0] - 1.0) < 0.05


@pytest.mark.parametrize("kw,needle", [
    ({"curvature": 1.0, "tip_displacement": 1e-3}, "exactly one of curvature"),
    ({}, "exactly one of curvature"),
    ({"curvature": float("nan")}, "curvature must be finite"),
    ({"curvature": [[1.0]]}, "curvature must be a number or a 1-D list"),
    ({"curvature": 1.0, "nu": 0.6}, "nu (drained Poisson ratio)"),
    ({"curvature": 1.0, "support": "pinned"}, "support"),
    ({"curvature": 1.0, "load": "100"}, "load"),
    ({"curvature": 1.0, "model": "nope"}, "model"),
    ({"curvature": 1.0, "fidelity": "nope"}, "fidelity"),
    ({"curvature": 1.0, "tol": 2.0}, "tol"),
    ({"curvature": 1.0, "model": lambda c: 1e-3 + 0 * c}, "model: sensing needs"),
])
def test_bad_input_names_the_parameter(kw, needle):
    with pytest.raises(ValueError) as ex:
        ia.sense(S, **kw)
    assert needle in str(ex.value) and "\n" not in str(ex.value)


def test_strip_must_be_a_strip():
    with pytest.raises(ValueError, match="strip must be"):
        ia.sense({"thickness": 1e-4}, curvature=1.0)


def test_an_underflowing_response_is_flagged_with_its_reason():
    # at a subnormal tip displacement every rung meets its bound, but Q rounds to a few units of
    # 4.9e-324: the row is kept and flagged, and a flagged row carries its reason
    w = np.array([1e-3, 1e-320])
    r = ia.sense(ia.Strip(), tip_displacement=w)
    assert r.valid.tolist() == [True, False]
    assert r.error[1] >= 1e-2 and abs(r.Q[1]) < 1e-320
    assert "subnormal" in r.message and "1 of 2 points" in r.message
    assert ia.sense(ia.Strip(), tip_displacement=1e-3).message == ""


def test_an_incompressible_drained_matrix_senses_nothing_exactly():
    """nu = 1/2: the bend leaves the solution's volume, so C_moy and the response, unchanged: Q and
    V_oc are 0 exactly, with no error and valid (an exact 0 is no rounded subnormal); any
    other nu is proportional to 1 - 2 nu at linear order."""
    r = ia.sense(ia.Strip(), curvature=np.array([0.0, 2.0, -3.0]), nu=0.5)
    assert r.Q.tolist() == [0.0, 0.0, 0.0] and r.V_oc.tolist() == [0.0, 0.0, 0.0]
    assert r.valid.all() and np.all(r.error == 0.0) and r.message == ""
    small = [ia.sense(ia.Strip(), curvature=1e-3, nu=nu).Q[0] for nu in (0.0, 0.25)]
    assert small[1] == pytest.approx(0.5 * small[0], rel=1e-6)
