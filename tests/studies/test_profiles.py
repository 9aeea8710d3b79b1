import math

import numpy as np
import pytest

from ipmc_asym.model.params import Strip
from ipmc_asym.studies.profiles import _crossing, layer_widths, profile_summary


def test_crossing_linear_interp():
    d = np.array([0.0, 1.0, 2.0])
    assert _crossing(d, np.array([0.0, 0.4, 1.0]), 0.5) == pytest.approx(1.0 + 0.1 / 0.6)


def test_layer_widths_on_synthetic_exponential_profile():
    # C = 1 + (B1-1) exp(-(1-z)/lam) near the cathode: 1/e width = lam*e exactly
    class R:
        pass
    r = R()
    r.z = np.linspace(-1, 1, 200001)
    lam, B1 = 0.01, 3.0
    r.C = 1 + (B1 - 1) * np.exp(-(1 - r.z) / lam) - 0.9 * np.exp(-(r.z + 1) / lam)
    w = layer_widths(r, 100e-6)
    assert w["accumulation_um"] == pytest.approx(lam * 100, rel=1e-4)
    assert w["accumulation_half_um"] == pytest.approx(lam * 100 * math.log(2), rel=1e-4)
    # depletion: 1 - 0.9 exp(-d/lam) = 1/2 -> d = lam ln(1.8)
    assert w["depletion_um"] == pytest.approx(lam * 100 * math.log(1.8), rel=1e-3)


def test_profile_summary_constant_vs_closed_facts():
    s = profile_summary("constant")
    # B1 = A2 for the constant model (paper section 5), cathode value is C_bar(1)
    assert s["B1"] == pytest.approx(96487.0 / (8.31 * 300.0), rel=1e-6)
    # depletion width ~ Debye * sqrt(2 (A2 - ln A2 - 1)) (Mott-Schottky estimate), within 30 %
    A2 = s["B1"]
    est = s["debye_um"] * math.sqrt(2 * (A2 - math.log(A2) - 1))
    assert 0.7 < s["depletion_um"] / est < 1.3
    assert 0.1 < s["depletion_um"] < 0.5
    assert s["accumulation_um"] < 0.05
    assert s["D_core"] < 1e-10


def test_linear_accumulation_is_z0():
    # linear model: C-1 = (B1-1) sinh(z/z0)/sinh(1/z0) -> 1/e width = z0 e (paper section 5)
    s = profile_summary("linear", Strip())
    assert s["B1"] == pytest.approx(2.0, rel=1e-6)
    z0_um = s["debye_um"]
    assert s["accumulation_um"] == pytest.approx(z0_um, rel=0.02)


def test_transition_width_of_an_exponential_layer_is_its_length_times_ln_9():
    # exact: f = exp(-x/l) falls from 0.9 to 0.1 of its face value between x = l ln(1/0.9) and l ln 10
    from types import SimpleNamespace

    from ipmc_asym.studies.profiles import transition_width

    z = np.linspace(-1.0, 1.0, 400001)
    lam, e = 0.02, 50e-6
    r = SimpleNamespace(z=z, D=1.0 + np.exp(-(z + 1) / lam) + 3.0 * np.exp(-(1 - z) / (2 * lam)))
    assert transition_width(r, e, "D", "anode") == pytest.approx(lam * math.log(9) * e * 1e6, rel=1e-6)
    assert transition_width(r, e, "D", "cathode") == pytest.approx(2 * lam * math.log(9) * e * 1e6, rel=1e-6)
    with pytest.raises(ValueError, match="face"):
        transition_width(r, e, "D", "middle")


@pytest.mark.parametrize("model, volts", [("constant", 1.0), ("affine", 1.0), ("linear", 1e-9)])
def test_a_negative_voltage_is_the_mirror_image(model, volts, tmp_path):
    """-phi0 is +phi0 mirrored (z_bar -> -z_bar): every face value named by its electrode (the
    anode is the face at the higher potential) is the same; the field, the induction and I change
    sign; the CSV's distances are measured from the right faces."""
    from ipmc_asym.studies.profiles import profile, write_csv

    pos, neg = (profile_summary(model, Strip(voltage=v)) for v in (volts, -volts))
    for k in ("B1", "C_anode", "depletion_um", "devoid_um", "accumulation_um", "accumulation_half_um",
              "cathode_charge", "debye_um"):
        assert neg[k] == pytest.approx(pos[k], rel=1e-9, abs=1e-15, nan_ok=True), k
    for k in ("E_anode", "E_cathode", "D_face", "I"):
        assert neg[k] == pytest.approx(-pos[k], rel=1e-9), k
    for v in (volts, -volts):
        path = tmp_path / f"p{v:+g}.csv"
        write_csv(profile(model, Strip(voltage=v)), path, 100e-6)
        rows = np.genfromtxt(path, delimiter=",", names=True)
        anode = rows["C_bar"][np.argmin(rows["dist_anode_m"])]
        assert anode == pytest.approx(pos["C_anode"], rel=1e-9, abs=1e-15)


@pytest.mark.parametrize("model", ["constant", "linear", "affine"])
@pytest.mark.parametrize("thickness", [200e-6, 1e-6])
@pytest.mark.parametrize("above", [10.0, 100.0])
def test_debye_hueckel_profiles_meet_the_bvp_to_a2(model, thickness, above):
    """Below the BVP's floor the profiles are the Debye-Hueckel solution, whose neglected terms are
    of relative order A2. Just above the floor (10 and 100 times it, where the BVP still resolves
    C - 1) both are computed: every profile, the layer widths and I agree to A2."""
    from ipmc_asym.bvp.solver import min_voltage, solve
    from ipmc_asym.model.params import NAFION_LI
    from ipmc_asym.studies.profiles import debye_hueckel_profile

    strip = Strip(thickness=thickness, voltage=above * min_voltage(NAFION_LI))
    ref, dh = solve(strip, model), debye_hueckel_profile(model, strip)
    A2 = dh.groups.A2
    assert "Debye-Hueckel" in dh.message and ref.success
    for q in ("phi", "E", "D", "rhoZ"):
        a, b = getattr(ref, q), np.interp(ref.z, dh.z, getattr(dh, q))
        assert np.max(np.abs(a - b)) <= A2 * np.max(np.abs(a)), q
    s_ref, s_dh = profile_summary(model, strip, res=ref), profile_summary(model, strip, res=dh)
    for k in ("accumulation_um", "accumulation_half_um", "B1", "I"):
        assert s_dh[k] == pytest.approx(s_ref[k], rel=A2), k


def test_below_the_bvp_floor_the_profiles_are_debye_hueckel():
    """1e-9 V (the BVP resolves from 2.6e-8 V): answered, C_bar - 1 ~ exp(-d/lambda) from the
    cathode (its 1/e width is the Debye length, analytically), anode levels never crossed; below
    A2 = 1e-290 a one-line refusal."""
    from ipmc_asym.studies.profiles import profile

    r = profile("constant", Strip(voltage=1e-9))
    s = profile_summary("constant", Strip(voltage=1e-9), res=r)
    assert "Debye-Hueckel" in r.message
    assert s["accumulation_um"] == pytest.approx(s["debye_um"], rel=1e-4)
    assert math.isnan(s["devoid_um"]) and math.isnan(s["depletion_um"])
    with pytest.raises(ValueError, match="too small for profiles"):
        profile("constant", Strip(voltage=1e-300))
