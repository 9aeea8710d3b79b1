"""The time-domain electrode line (a ladder of reduced circuits) against the inverse Laplace transform
of the exact line, a finer ladder, the uniform strip at 0 Ohm/sq, and its refusals."""

import mpmath as mp
import numpy as np
import pytest

from ipmc_asym.dynamics.circuit import quasi_static_forward, waveform
from ipmc_asym.dynamics.drive import drive_response
from ipmc_asym.dynamics.electrode import capacitance_scale, core_resistance
from ipmc_asym.dynamics.line_time import LineStepper
from ipmc_asym.model import groups
from ipmc_asym.model.params import NAFION_LI, Strip
from ipmc_asym.model.permittivity import get_model

S = Strip()
PERM = get_model("constant")
R = float(core_resistance(S.thickness, NAFION_LI))
C = 0.5 * capacitance_scale(PERM, NAFION_LI)
TAU = R * C
CG = float(groups.geometric_capacitance(S.thickness, PERM.eps_moy))


def _exact(F, t):
    mp.mp.dps = 30
    return np.array([float(mp.invertlaplace(F, float(x), method="talbot")) for x in t])


def _g(p, Rs):
    return S.length * mp.sqrt(2 * Rs / (R + 1 / (p * C)))


@pytest.mark.parametrize("Rs", [2.5, 25.0])
def test_small_signal_step_against_the_inverse_laplace_transform_of_the_exact_line(Rs):
    # 1 uV: the layers are linear to (V/(R T/F))^2 ~ 1e-9.  The exact line (derivations/line.py) with
    # the time model's shunt, conduction R in series with C_d(0), and the bulk's displacement charge
    # C_g (v - u) added to sigma: sigma_mean(s) = (V0/s) (tanh g/g) (1 + s R C_g)/(s (R + 1/(s C)))
    V0 = 1e-6
    t = np.linspace(0.0, 5 * TAU, 51)
    o = LineStepper(waveform("step", V0), S, PERM, NAFION_LI, Rs, segments=16).advance(t)

    def F(p):
        g = _g(p, Rs)
        return V0 / p * mp.tanh(g) / g * (1 + p * R * CG) / (p * (R + 1 / (p * C)))

    idx = [2, 5, 10, 20, 50]
    ref = _exact(F, t[idx])
    assert np.all(np.abs(o["sigma_mean"][idx] - ref) <= o["sigma_error"][idx])
    # and the estimate is not vacuous: the 32-segment line is within a few 1e-3 of the exact one
    assert np.max(o["sigma_error"]) < 5e-3 * np.max(np.abs(ref))


def test_current_and_charge_at_a_jump_against_the_exact_line():
    # a 1 uV step at t0 > 0, on an output time: the row at t0 is the state just after the jump (as the
    # circuit's).  Exact line as above: the electrode charge jumps at once by the bulk's displacement
    # charge, sigma(t0+) = lim s sigma(s) = V0 C_g tanh(g_inf)/g_inf, g_inf = L sqrt(2 R_s/R) (the
    # uncharged layers are shorts, the line purely resistive), and J = dsigma/dt after it is the inverse
    # transform of s sigma(s) - sigma(t0+).  A difference over the output rows would straddle the jump.
    V0, Rs = 1e-6, 2.5
    t = np.linspace(0.0, 2 * TAU, 81)
    k0 = 20
    r = drive_response(f"step:{V0}V@{float(t[k0])!r}", float(t[-1]), t.size, beam="quasi-static", sheet_resistance=Rs,
                       line_segments=16)
    mp.mp.dps = 30
    g_inf = S.length * mp.sqrt(2 * Rs / R)
    jump = V0 * CG * mp.tanh(g_inf) / g_inf

    def F(p):
        g = _g(p, Rs)
        return V0 * mp.tanh(g) / g * (1 + p * R * CG) * C / (1 + p * R * C) - jump

    assert np.all(r["current_density"][:k0] == 0.0) and np.all(r["sigma"][:k0] == 0.0)
    assert abs(r["sigma"][k0] - float(jump)) <= r["sigma_error"][k0]
    idx = [k0, k0 + 1, k0 + 2, k0 + 5, k0 + 20, t.size - 1]
    ref = _exact(F, np.maximum(t[idx] - t[k0], 1e-9 * TAU))
    # the 32-segment line's own error, as its charge's above (a few 1e-3)
    assert np.all(np.abs(r["current_density"][idx] - ref) <= 5e-3 * np.abs(ref))


def test_small_signal_deflection_against_the_exact_line():
    # w(s) = (V0/s) k_w F_w(g)/(1 + s R C): the layers' moment follows u = sigma_L/C_d(0), the line's
    # deflection factor F_w (derivations/line.py item 3), k_w the static deflection per volt
    V0, Rs = 1e-6, 2.5
    t = np.linspace(0.0, 4 * TAU, 41)
    r = drive_response(f"step:{V0}V", float(t[-1]), t.size, beam="quasi-static", sheet_resistance=Rs, line_segments=16)
    kw = float(np.asarray(quasi_static_forward(np.array([V0]), S, PERM, NAFION_LI).w)[0]) / V0

    def F(p):
        g = _g(p, Rs)
        fw = 2 * (g * mp.sinh(g) - mp.cosh(g) + 1) / (g**2 * mp.cosh(g))
        return V0 / p * kw * fw / (1 + p * R * C)

    idx = [4, 10, 20, 40]
    ref = _exact(F, t[idx])
    assert np.all(np.abs(r["w"][idx] - ref) <= r["w_error"][idx] + 1e-12 * np.max(np.abs(ref)))
    assert np.max(r["w_error"]) < 2e-3 * np.max(np.abs(ref))


def test_large_signal_against_a_finer_ladder_within_the_stated_errors():
    # 1 V step (nonlinear layers): 64 reported segments against 256, each with its own stated error
    kw = dict(beam="quasi-static", sheet_resistance=25.0)
    a = drive_response("step:1V", 5 * TAU, 201, line_segments=32, **kw)
    b = drive_response("step:1V", 5 * TAU, 201, line_segments=128, **kw)
    for k, e in (("sigma", "sigma_error"), ("w", "w_error")):
        assert np.all(np.abs(a[k] - b[k]) <= a[e] + b[e] + 1e-14 * np.max(np.abs(b[k])))
        assert np.max(b[e]) < np.max(a[e]) / 8  # second order: 4x per halving of h, twice halved
    # the line is slower than the uniform strip; the uniform strip is 0 Ohm/sq exactly
    u = drive_response("step:1V", 5 * TAU, 201, beam="quasi-static")
    assert np.all(np.abs(b["sigma"][1:50]) < np.abs(u["sigma"][1:50]))
    z = drive_response("step:1V", 5 * TAU, 201, beam="quasi-static", sheet_resistance=0.0)
    assert all(np.array_equal(z[k], u[k]) for k in u) and "sigma_error" not in z


def test_line_chunks_are_one_run():
    kw = dict(beam="quasi-static", sheet_resistance=2.5, line_segments=8)
    a = drive_response("sine:0.5V@20Hz", 0.05, 301, **kw)
    b = drive_response("sine:0.5V@20Hz", 0.05, 301, chunk=37, **kw)
    for k in a:
        assert np.allclose(a[k], b[k], rtol=1e-12, atol=1e-15 * np.max(np.abs(a[k]) + 1e-300)), k


def test_refusals():
    with pytest.raises(ValueError, match="sheet_resistance"):
        drive_response("step:1V", 0.01, 11, beam="quasi-static", sheet_resistance=-1.0)
    with pytest.raises(ValueError, match=r"line_segments must be an integer in \[2, 512\] \(--line-segments"):
        drive_response("step:1V", 0.01, 11, beam="quasi-static", sheet_resistance=1.0, line_segments=10**6)
    with pytest.raises(ValueError, match="sheet_resistance"):
        LineStepper(waveform("step", 1.0), S, PERM, NAFION_LI, 0.0)


def test_an_underresolved_line_is_refused_not_printed(tmp_path):
    # 1000 Ohm/sq at a 20 Hz square wave: the line's decay length is a few segments of 8
    with pytest.raises(ValueError, match="raise line_segments"):
        drive_response("square:2V@20Hz", 0.05, 201, beam="quasi-static", sheet_resistance=1e3, line_segments=4)
    with pytest.raises(ValueError, match="raise line_segments"):  # ~1 % at 25 Ohm/sq with 16 segments
        drive_response("step:1V", 5 * TAU, 201, beam="quasi-static", sheet_resistance=25.0, line_segments=8)
    from ipmc_asym.cli import main

    out = tmp_path / "d.csv"
    assert main(["drive", "--waveform", "square:2V@20Hz", "--duration", "50ms", "--points", "201", "--beam",
                 "quasi-static", "--sheet-resistance", "1000", "--line-segments", "4", "--out", str(out)]) == 2
    assert not out.exists()  # written atomically: nothing of the refused run is left


def test_dynamic_beam_sine_steady_state_against_the_frequency_domain_line():
    # 1 uV at 30 Hz (above the first resonance), 10 % damping at the first mode, 3 s: every transient
    # (the line's slowest, ~4 tau; the modes) has decayed.  Reference: the exact line with the time
    # model's shunt R + 1/(s C_d(0)) (the bulk capacitance instantaneous), the moment per volt
    # M'(0)/(1 + s R C_d(0)) of the forward model, the distributed moment through the modal transfer
    from ipmc_asym.beam.dynamics import distributed_transfer, viscous_modulus_from_damping_ratio
    from ipmc_asym.dynamics.circuit import strip_beam
    from ipmc_asym.dynamics.line import ProfileQuadrature

    eta = viscous_modulus_from_damping_ratio(0.1, 22.55, NAFION_LI.E)
    V0, f0, Rs = 1e-6, 30.0, 2.5
    r = drive_response(f"sine:{V0}V@{f0}Hz", 3.0, 12001, beam="dynamic", viscous_modulus=eta, sheet_resistance=Rs,
                       line_segments=16)
    sel = r["t"] >= 3.0 - 2.0 / f0
    A = np.column_stack([np.sin(2 * np.pi * f0 * r["t"][sel]), np.cos(2 * np.pi * f0 * r["t"][sel])])

    def phasor(k):  # x(t) = Im(X e^{i w t}) = Re X sin + Im X cos
        a, b = np.linalg.lstsq(A, r[k][sel], rcond=None)[0]
        return a + 1j * b

    s = 2j * np.pi * np.array([f0])
    Mp = float(np.asarray(quasi_static_forward(np.array([V0]), S, PERM, NAFION_LI).M_A)[0]) / V0
    HM = Mp / (1 + s * R * C)
    q = ProfileQuadrature(S.length * np.sqrt(2 * Rs / (R + 1 / (s * C))), S.length, uniform_panels=10)
    b = strip_beam(S, NAFION_LI, eta)
    cf = distributed_transfer(np.array([f0]), b, "clamped-free", lambda c: HM[:, None] * q(c))
    cp = distributed_transfer(np.array([f0]), b, "clamped-pinned", lambda c: HM[:, None] * q(c))
    wstated = np.max(r["w_error"][sel]) / np.max(np.abs(r["w"][sel]))
    for k, H in (("w", cf["w"]), ("theta", cf["theta"]), ("F_block", cp["F"])):
        # the line's stated error (6e-4 here) plus the time stepping's, measured 3e-4 at 400 points a period
        # (the circuit's BDF2 substeps and the modes' first-order hold; halved from 200 points a period)
        assert abs(phasor(k) - V0 * H[0]) <= (wstated + 1e-3) * abs(V0 * H[0]), k
    # the line matters here: the uniform strip's deflection is far off
    u = drive_response(f"sine:{V0}V@{f0}Hz", 3.0, 12001, beam="dynamic", viscous_modulus=eta)
    assert abs(phasor("w") - V0 * cf["w"][0]) < 0.01 * abs(u["w"][sel]).max()
    np.testing.assert_array_less(0.1 * abs(V0 * cf["w"][0]), abs(np.max(np.abs(u["w"][sel])) - abs(V0 * cf["w"][0])))


def test_line_beam_dynamics_of_a_uniform_moment_is_the_modal_beam_and_chunks_are_one_run():
    from ipmc_asym.dynamics.circuit import BeamDynamics
    from ipmc_asym.dynamics.line_time import LineBeamDynamics, line_weights

    x, _ = line_weights(32, S.length)
    t = np.linspace(0.0, 0.2, 2001)
    Mt = 1e-6 * np.sin(2 * np.pi * 30 * t) * (1 - np.exp(-t / 0.01))
    EI, L = NAFION_LI.E * S.I_p, S.length
    th, w, F = -Mt * L / EI, -Mt * L * L / (2 * EI), 1.5 * Mt / L
    a = BeamDynamics(S, NAFION_LI, 2e3, 20).advance(t, Mt, th, w, F)
    Mn = np.repeat(Mt[:, None], x.size, axis=1)
    b = LineBeamDynamics(S, NAFION_LI, 2e3, 20, x).advance(t, Mn, (th, w), F)
    for p, q in zip(a, b):
        assert np.max(np.abs(p - q)) <= 1e-12 * np.max(np.abs(p))
    d = LineBeamDynamics(S, NAFION_LI, 2e3, 20, x)
    parts = [d.advance(t[i:j + 1], Mn[i:j + 1], (th[i:j + 1], w[i:j + 1]), F[i:j + 1]) for i, j in ((0, 700), (700, 2000))]
    for k in range(3):
        c = np.concatenate([parts[0][k], parts[1][k][1:]])
        assert np.max(np.abs(c - b[k])) <= 1e-13 * np.max(np.abs(b[k]))
