"""Sensing in the time domain (``ia.sensing_transient``) against independent paths: the relaxed
charge of a step against the static closed forms (``ia.sense``), a slow sine's steady state against
the exact frequency-domain form (``ia.sensing_response``, pnp-linear), linearity, the open circuit's
voltage against the EMF formula, the load's power against I^2 R."""

from __future__ import annotations

import math

import numpy as np
import pytest

import ipmc_asym as ia
from ipmc_asym.dynamics.waveforms import parse_waveform
from ipmc_asym.model import groups
from ipmc_asym.model.params import NAFION_LI
from ipmc_asym.model.permittivity import get_model

MODELS = ("constant", "linear", "affine")


@pytest.mark.parametrize("model", MODELS)
@pytest.mark.parametrize("support", ["free", "tip-force"])
def test_relaxed_step_is_the_static_charge(model, support):
    # 40 tau of the slowest model (tau = 0.48 s linear/affine at 2e = 200 um): the transient is e^-40
    r = ia.sensing_transient("step:1mm", 20.0, 201, model=model, support=support)
    static = ia.sense(tip_displacement=[1e-3], support=support, model=model, fidelity="exact")
    assert r.error_settled < 1e-4  # the relaxed state: DC errors + the linearisation's, small at 1 mm
    assert abs(r.Q[-1] / static.Q[0] - 1.0) <= r.error_settled + static.error[0]
    # and the open circuit reads the static V_oc
    ro = ia.sensing_transient("step:1mm", 20.0, 201, model=model, support=support, load="open")
    assert abs(ro.V[-1] / static.V_oc[0] - 1.0) <= ro.error_settled + static.error_V_oc[0]


@pytest.mark.parametrize("model", MODELS)
def test_slow_sine_steady_state_is_the_frequency_response(model):
    f, w0 = 1e-3, 1e-3
    n_per = 5
    r = ia.sensing_transient(f"sine:1mm@{f}Hz", n_per / f, 5001, model=model)
    fr = ia.sensing_response([f], model=model, method="pnp-linear")
    sel = r.t >= (n_per - 2) / f  # steady (tau <= 0.5 s << 1000 s)
    M = np.c_[np.sin(2 * math.pi * f * r.t[sel]), np.cos(2 * math.pi * f * r.t[sel])]
    a, b = np.linalg.lstsq(M, r.Q[sel], rcond=None)[0]
    # w = Im(w0 e^{i w t}) -> Q = Im(Q/w w0 e^{i w t}) = Re(Q/w) w0 sin + Im(Q/w) w0 cos
    got = complex(a, b)
    want = complex(fr.Q_per_w[0]) * w0
    assert abs(got / want - 1.0) <= r.error
    assert abs(math.remainder(np.angle(got) - np.angle(want), 2 * math.pi)) <= r.error


def test_linear_in_amplitude():
    r1 = ia.sensing_transient("sine:0.5mm@5mHz+step:0.2mm@10s", 300.0, 601, model="linear", load=1e3)
    r2 = ia.sensing_transient("sine:1mm@5mHz+step:0.4mm@10s", 300.0, 601, model="linear", load=1e3)
    for c in ("Q", "I", "V"):
        a, b = getattr(r1, c), getattr(r2, c)
        assert np.max(np.abs(b - 2 * a)) <= 1e-9 * np.max(np.abs(b)), c
    assert np.allclose(r2.power, 4 * r1.power, rtol=1e-8, atol=1e-30)


def test_open_circuit_voltage_is_the_emf_formula():
    # e(t) = (R T/F) 2 [(1 - lam) b + (e^2/(3 D)) db/dt], b = (1 - 2 nu) e kappa_mean/phi4, kappa_mean = 1.5 w/L^2
    s = ia.NOMINAL_STRIP
    f, w0 = 2e-3, 1e-3
    r = ia.sensing_transient(f"sine:1mm@{f}Hz", 1000.0, 1001, model="constant", load="open")
    perm = get_model("constant")
    m = NAFION_LI
    e = s.e
    lam = float(groups.debye_length(s.thickness, perm.eps_moy, m))
    bw = e / m.phi4 * 1.5 / s.length**2
    om = 2 * math.pi * f
    b = bw * w0 * np.sin(om * r.t)
    db = bw * w0 * om * np.cos(om * r.t)
    want = 2 * m.R * m.T / m.F * ((1 - lam) * b + e * e / (3 * m.D) * db)
    assert np.allclose(r.V, want, rtol=1e-12, atol=1e-12 * np.max(np.abs(want)))
    assert np.all(r.Q == 0) and np.all(r.I == 0)


def test_power_into_the_load_is_i2r():
    R = 2.2e3
    # (R + R_load) C_d ~ 230 s for the linear model: 3000 s leaves e^-13 of the start-up
    r = ia.sensing_transient("sine:1mm@3mHz", 3000.0, 6001, model="linear", load=R)
    assert np.allclose(r.power, r.I**2 * R, rtol=1e-12, atol=0)
    assert np.allclose(r.V, r.I * R, rtol=1e-12, atol=0)
    # I = -dQ/dt: against a central difference of the sampled charge (away from t = 0)
    dq = np.gradient(r.Q, r.t)
    i = slice(10, -10)
    assert np.max(np.abs(-dq[i] - r.I[i])) <= 2e-3 * np.max(np.abs(r.I))
    # the mean power over the last period against the exact frequency form |V_load|^2/(2 R)
    fr = ia.sensing_response([3e-3], model="linear", load=R, method="pnp-linear")
    assert abs(r.mean_power / fr.power[0] - 1) <= 2 * r.error + 1e-3  # + the sampled period's quadrature


@pytest.mark.parametrize("model", ["constant", "linear"])
@pytest.mark.parametrize("load", ["short", 10.0, 2.2e3])
def test_integrator_is_the_circuits_frequency_form(model, load):
    # the same reduced model (circuit Z, leading-order EMF) in the frequency domain: the time stepping
    # alone is compared, to its interpolation error (1e-6) and the start-up's remainder
    f = 1e-3
    r = ia.sensing_transient(f"sine:1mm@{f}Hz", 20 / f, 20001, model=model, load=load)
    fc = ia.sensing_response([f], model=model, method="circuit", load=load)
    ph = np.exp(2j * math.pi * f * r.t)
    sel = r.t > r.t[-1] - 2 / f
    if load == "short":
        got, want = r.Q[sel], (fc.Q_per_w[0] * 1e-3 * ph).imag[sel]
        scale = abs(fc.Q_per_w[0] * 1e-3)
    else:
        got, want = r.V[sel], (fc.V_load[0] * ph).imag[sel]
        scale = abs(fc.V_load[0])
    assert np.max(np.abs(got - want)) <= 2e-6 * scale


def test_short_circuit_current_is_minus_dq_dt():
    r = ia.sensing_transient("sine:1mm@3mHz", 700.0, 2801, model="constant")
    dq = np.gradient(r.Q, r.t)
    i = slice(10, -10)
    assert np.max(np.abs(-dq[i] - r.I[i])) <= 2e-3 * np.max(np.abs(r.I))
    assert np.all(r.V == 0)


def test_past_the_strain_limit_is_kept_and_flagged():
    r = ia.sensing_transient("sine:20mm@1mHz", 1000.0, 101, model="constant")
    assert np.all(np.isfinite(r.Q))
    assert not r.check_strain.all() and r.check_strain.any()
    assert np.array_equal(r.valid, r.check_strain & r.check_beam_regime & r.check_one_way)


@pytest.mark.parametrize("kw,needle", [
    ({"waveform": "step:1V", "duration": 1.0}, "unknown unit"),
    ({"waveform": "step:1mm", "duration": -1.0}, "duration must be > 0"),
    ({"waveform": "step:1mm", "duration": 1.0, "points": 1}, "points must be an integer"),
    ({"waveform": "step:5m", "duration": 1.0}, "a face would lose all its water"),
    ({"waveform": "sine:1mm@100Hz", "duration": 1e4, "points": 10001}, "steps over the duration"),
    ({"waveform": "step:1mm", "duration": 1.0, "load": -3.0}, "finite resistance > 0"),
])
def test_refusals(kw, needle):
    with pytest.raises(ValueError) as exc:
        ia.sensing_transient(**kw)
    assert needle in str(exc.value) and "\n" not in str(exc.value)


def test_length_waveform_grammar():
    w = parse_waveform("dc:0.5mm+sine:1mm@2Hz,90+step:-200um@1s", quantity="length")
    assert w(np.array([0.0]))[0] == pytest.approx(1.5e-3)
    assert w(np.array([1.0]))[0] == pytest.approx(0.5e-3 + 1e-3 - 0.2e-3)
    assert w.derivative(np.array([0.125]))[0] == pytest.approx(-1e-3 * 4 * math.pi)
    t, d = w.jumps(0.0, 2.0)
    assert t.tolist() == [1.0] and d.tolist() == pytest.approx([-0.2e-3])
    sq = parse_waveform("square:1mm@1Hz", quantity="length")
    t, d = sq.jumps(0.0, 1.0)
    assert t.tolist() == pytest.approx([0.5, 1.0]) and d.tolist() == pytest.approx([-2e-3, 2e-3])
    with pytest.raises(ValueError, match="waveform term"):
        parse_waveform("step:1V", quantity="length")
    # the voltage grammar is unchanged
    assert parse_waveform("step:1V")(np.array([0.0]))[0] == 1.0


def test_square_wave_relaxes_between_flips():
    # flips every 50 s, tau = 34 ms: each half period ends relaxed at -/+ the static charge
    r = ia.sensing_transient("square:1mm@10mHz", 100.0, 2001, model="constant")
    static = ia.sense(tip_displacement=[1e-3], support="tip-force", model="constant", fidelity="exact").Q[0]
    i_half = np.searchsorted(r.t, 49.95)
    assert abs(r.Q[i_half] / static - 1) <= r.error_settled + 1e-9
    assert abs(r.Q[-2] / -static - 1) <= r.error_settled + 1e-9


def test_result_object():
    r = ia.sensing_transient("sine:1mm@5mHz", 400.0, 201, model="constant", load=1e3)
    text = repr(r)
    assert "SensingTransient" in text and "[C]" in text and "[W]" in text
    pytest.importorskip("xarray")
    ds = r.to_xarray()
    assert ds["Q"].attrs["units"] == "C" and ds["V_load"].attrs["units"] == "V"
    pytest.importorskip("matplotlib")
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib.figure import Figure

    assert isinstance(r.plot(), Figure)


def test_step_streaming_charge_is_flagged_then_relaxes():
    # at t = 0+ the streaming EMF's delta has pushed a charge through the core (ohmic drop >> the static
    # EMF): the one-way coupling fails there; many tau later the rows are valid again
    r = ia.sensing_transient("step:1mm", 20.0, 201, model="constant")
    assert not r.check_one_way[0] and r.valid[-1]
    assert np.all(np.diff(r.valid.astype(int)) >= 0)  # once relaxed, stays valid
    # a sine at the frequency where sensing_response flags the one-way bound is flagged here too
    for f in (1e-3, 1e-2):
        rs = ia.sensing_transient(f"sine:1mm@{f}Hz", 5 / f, 2001, model="linear")
        fr = ia.sensing_response([f], model="linear")
        assert bool(rs.check_one_way[rs.t > 1 / f].all()) == bool(fr.check_one_way[0])
