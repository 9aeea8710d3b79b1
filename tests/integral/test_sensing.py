"""Static sensing: the closed form and the exact balance against the BVP, linearity, oddness,
the open-circuit voltage against the Donnan law computed from eq (17), and the edges."""

import math

import numpy as np
import pytest

import ipmc_asym as ia
from ipmc_asym.base.registry import MODELS
from ipmc_asym.bvp.sensing import solve_sensing
from ipmc_asym.integral.sensing import debye_length, sense_hat, strain_parameter
from ipmc_asym.kernels.sensing import sense_point
from ipmc_asym.model import groups
from ipmc_asym.model.permittivity import get_model

MAT = ia.NAFION_LI
THICK = (20e-6, 200e-6, 2e-3)
MODEL_NAMES = tuple(MODELS)


def _rho(model):
    p = get_model(model)
    return p.eps0 / p.eps_moy


def _grid():
    for model in MODEL_NAMES:
        for th in THICK:
            # face strains 1e-5 .. 1e-2 (the small-strain limit, Material.strain_limit)
            for strain in (1e-5, 1e-3, 1e-2):
                yield model, th, strain


@pytest.mark.parametrize("model,th,strain", list(_grid()))
def test_rungs_within_their_stated_error_of_the_bvp(model, th, strain):
    lam = float(debye_length(th, get_model(model), MAT))
    kap = strain / (0.5 * th)
    b = float(strain_parameter(kap, th, 0.0, MAT))
    rs = solve_sensing(b, lam, _rho(model), MAT.phi4, load="short")
    ro = solve_sensing(b, lam, _rho(model), MAT.phi4, load="open")
    assert rs.success and ro.success
    for order in (1, 3):
        s, v, es, ev = sense_point(b, lam, _rho(model), MAT.phi4, order)
        # the BVP's own error (1e-8 tolerance on response-scaled unknowns) is added to the bound
        assert abs(s / rs.value - 1.0) <= es + 1e-7, (order, s, rs.value, es)
        assert abs(v / ro.value - 1.0) <= ev + 1e-7, (order, v, ro.value, ev)
    # the exact balance is the better rung wherever the nonlinearity shows
    s1 = sense_point(b, lam, _rho(model), MAT.phi4, 1)
    s3 = sense_point(b, lam, _rho(model), MAT.phi4, 3)
    if strain >= 1e-3:
        assert abs(s3[0] / rs.value - 1.0) < abs(s1[0] / rs.value - 1.0)


@pytest.mark.parametrize("model", MODEL_NAMES)
@pytest.mark.parametrize("fidelity", ("leading", "exact"))
def test_linear_and_odd_at_small_curvature(model, fidelity):
    s = ia.Strip(thickness=200e-6)
    k = np.array([0.1, 0.2, -0.1, -0.2])  # face strains 1e-5, 2e-5
    r = ia.sense(s, curvature=k, model=model, fidelity=fidelity)
    # the departure from linearity is what the linear closed form states as its error
    lin = ia.sense(s, curvature=k, model=model, fidelity="leading", escalate=False)
    assert abs(r.Q[1] / (2.0 * r.Q[0]) - 1.0) <= 2.0 * lin.error.max()
    assert abs(r.V_oc[1] / (2.0 * r.V_oc[0]) - 1.0) <= 2.0 * lin.error_V_oc.max()
    # odd: the mirror z -> -z swaps the short-circuited electrodes (derivations/sensing.py)
    assert r.Q[2] == pytest.approx(-r.Q[0], rel=1e-14)
    assert r.Q[3] == pytest.approx(-r.Q[1], rel=1e-14)
    assert r.V_oc[2] == pytest.approx(-r.V_oc[0], rel=1e-14)
    # bending toward +z compresses the face +e: its fixed charge per solution volume rises, the
    # electrode at -e takes a negative charge
    assert r.Q[0] < 0.0 and r.V_oc[0] > 0.0


def test_nonlinearity_matches_the_cubic_coefficient():
    """Independent of the SymPy series: (sigma/(-b) - 1)/b^2 of the Newton balance -> c3."""
    from ipmc_asym.kernels import _generated_sensing as GS
    from ipmc_asym.kernels.sensing import balance_hat

    for model in MODEL_NAMES:
        rho = _rho(model)
        b = 1e-3
        nc, _ = balance_hat(b, rho, MAT.phi4)
        assert (nc / (-b) - 1.0) / b**2 == pytest.approx(GS.sense_cubic(rho, MAT.phi4), rel=1e-4)


@pytest.mark.parametrize("model", MODEL_NAMES)
def test_open_circuit_voltage_is_the_donnan_difference(model):
    """V_oc against (RT/F) ln(C_moy(+e)/C_moy(-e)) from eq (17) at each face's solution fraction."""
    th, kap = 2e-3, 5.0  # face strain 5e-3
    e = 0.5 * th
    r = ia.sense(ia.Strip(thickness=th), curvature=kap, support="free", model=model, fidelity="exact")  # uniform kappa
    # solid incompressible: (1 - phi4)(1 + tr eps) = 1 - phi4_0, tr eps = -kappa z (nu = 0)
    faces = {}
    for zf in (-e, e):
        tr = -kap * zf
        p4 = 1.0 - (1.0 - MAT.phi4) / (1.0 + tr)
        faces[zf] = MAT.with_(phi4=p4, c_moy="formula").C_moy
    donnan = groups.thermal_voltage(MAT) * math.log(faces[e] / faces[-e])
    lam = float(debye_length(th, get_model(model), MAT))
    # the finite-thickness factor 1 - lam tanh(1/lam) of derivations.sensing:linear_solution
    assert r.V_oc[0] / (1.0 - lam * math.tanh(1.0 / lam)) == pytest.approx(donnan, rel=r.error_V_oc[0] + 1e-12)
    assert r.V_oc[0] == pytest.approx(donnan, rel=2.0 * lam)


def test_zero_curvature_is_exactly_zero_and_finite():
    for fid in ("leading", "exact", "bvp"):
        r = ia.sense(ia.Strip(), curvature=[0.0], fidelity=fid, support="tip-force")
        assert r.Q[0] == 0.0 and r.V_oc[0] == 0.0 and r.sigma[0] == 0.0 and r.error[0] <= 1e-7
        assert np.isfinite(r.Q_per_w[0]) and r.Q_per_w[0] < 0.0
        assert bool(r.valid[0])


def test_beyond_small_strain_keeps_the_number_and_flags():
    s = ia.Strip(thickness=200e-6)
    kap = 3.0 * MAT.strain_limit / s.e  # three times the small-strain limit
    r = ia.sense(s, curvature=[1.0, kap], fidelity="exact")
    assert np.all(np.isfinite(r.Q)) and np.all(np.isfinite(r.V_oc))
    assert list(r.check_strain) == [True, False]
    assert list(r.valid) == [True, False]
    assert r.max_strain[1] == pytest.approx(3.0 * MAT.strain_limit)


def test_no_state_past_a_dry_face_is_refused_by_name():
    s = ia.Strip(thickness=200e-6)
    with pytest.raises(ValueError, match="^curvature: .* must be < 1"):
        ia.sense(s, curvature=MAT.phi4 / s.e * 1.01)
    with pytest.raises(ValueError, match="^tip_displacement: "):
        ia.sense(s, tip_displacement=1.0)


def test_ladder_escalates_to_meet_tol():
    b = np.array([1e-4, 0.05])
    p = get_model("linear")
    lam = float(debye_length(200e-6, p, MAT))
    h = sense_hat(b, lam, p, MAT, "leading", tol=1e-4)
    assert list(h.used) == ["leading", "exact"]
    assert np.all(h.valid) and np.all(h.error <= 1e-4)
    h = sense_hat(b, lam, p, MAT, "leading", tol=1e-6)
    assert list(h.used) == ["leading", "bvp"]
    h = sense_hat(b, lam, p, MAT, "leading", tol=1e-6, escalate=False)
    assert list(h.valid) == [True, False] and np.all(np.isfinite(h.sigma_hat))
    assert "no valid fidelity at b = 0.05" in h.message


def test_underflowing_response_is_flagged_not_silent():
    r = ia.sense(ia.Strip(thickness=1e-6), curvature=[5e-324, 1e-300], model="linear")
    assert r.Q[0] == 0.0 and r.error[0] == 1.0 and not bool(r.valid[0])
    assert r.Q[1] < 0.0 and r.error[1] < 1e-12 and bool(r.valid[1])
