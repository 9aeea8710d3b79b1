"""Chunked drive runs against one-pass runs, the step API, the static limit and the small-signal circuit."""

import math

import numpy as np
import pytest

from ipmc_asym.beam.dynamics import natural_frequencies, viscous_modulus_from_damping_ratio
from ipmc_asym.dynamics.circuit import circuit_response, frequency_response, quasi_static_mechanics, step_response, strip_beam
from ipmc_asym.dynamics.drive import drive_chunks, drive_response
from ipmc_asym.dynamics.waveforms import parse_waveform
from ipmc_asym.model.params import NAFION_LI, Strip
from ipmc_asym.model.permittivity import MODELS

SPEC = "step:1V+square:0.2V@30Hz"


def test_chunks_are_one_run_and_equal_the_step_api():
    a = drive_response(SPEC, 0.3, 3001, chunk=10**6, beam="dynamic")
    b = drive_response(SPEC, 0.3, 3001, chunk=37, beam="dynamic")
    for k in a:
        assert np.array_equal(a[k], b[k]) or np.max(np.abs(a[k] - b[k])) <= 1e-12 * np.max(np.abs(a[k]))
    s = step_response(t=np.linspace(0, 0.3, 3001), waveform_kind=parse_waveform(SPEC), beam="dynamic")
    for k in ("sigma", "current_density", "M_A", "theta", "w", "F_block"):
        assert np.max(np.abs(a[k] - getattr(s, k))) <= 1e-12 * np.max(np.abs(a[k]))
    # memory: the chunks hold at most `chunk` rows
    assert max(c["t"].size for c in drive_chunks(SPEC, 0.3, 3001, chunk=500, beam="dynamic")) <= 501


def test_damped_slow_drive_ends_at_the_quasi_static_forward_model():
    strip = Strip()
    b = strip_beam(strip, NAFION_LI)
    f1 = natural_frequencies("clamped-free", b, 1)[0]
    eta = viscous_modulus_from_damping_ratio(0.2, f1, NAFION_LI.E)
    r = drive_response("ramp:0.8V/0.2s", 1.0, 4001, beam="dynamic", viscous_modulus=eta)
    M, th, w, F = quasi_static_mechanics(r["layer_voltage"][-1:], strip, MODELS["constant"], NAFION_LI)
    assert r["w"][-1] == pytest.approx(w[0], rel=1e-8)
    assert r["theta"][-1] == pytest.approx(th[0], rel=1e-8)
    assert r["F_block"][-1] == pytest.approx(F[0], rel=1e-6)
    q = drive_response("ramp:0.8V/0.2s", 1.0, 4001, beam="quasi-static")
    assert np.array_equal(q["M_A"], r["M_A"])  # the beam does not feed back on the electrochemistry


def test_beam_grid_too_coarse_is_refused():
    with pytest.raises(ValueError, match="points"):
        drive_response("sine:1V@1Hz", 10.0, 100, beam="dynamic")


def test_small_signal_about_a_bias_matches_a_small_sine_in_the_circuit():
    """Drive the reduced circuit with 1 mV about 0.5 V; fit the periodic current; compare Z and H_w."""
    s = Strip()
    V, amp = 0.5, 1e-3
    fr0 = frequency_response([1.0], method="circuit", voltage=V, beam="quasi-static")
    f = 1 / (2 * math.pi * fr0.tau)
    per = 1 / f
    t = np.linspace(0, 30 * per, 30 * 64 + 1)
    fun = parse_waveform(f"dc:{V}V+sine:{amp}V@{f}Hz")
    sig, u, J = circuit_response(t, fun, s, MODELS["constant"], NAFION_LI)
    M, _, w, _ = quasi_static_mechanics(u, s, MODELS["constant"], NAFION_LI)
    sel = t >= 26 * per
    A = np.column_stack([np.sin(2 * math.pi * f * t[sel]), np.cos(2 * math.pi * f * t[sel]), np.ones(sel.sum())])
    a, b, _ = np.linalg.lstsq(A, J[sel], rcond=None)[0]
    Z_t = amp / (a + 1j * b) / (s.width * s.length)
    fr = frequency_response([f], method="circuit", voltage=V, beam="quasi-static")
    assert abs(Z_t / fr.Z[0] - 1) < 5e-3
    # the moment: M = M(V) + dM/dV u~, the small-displacement deflection slope
    a, b, _ = np.linalg.lstsq(A, M[sel], rcond=None)[0]
    H_M = (a + 1j * b) / amp
    w_per_M = -s.length**2 / (2 * NAFION_LI.E * s.I_p)
    assert abs(H_M * w_per_M / fr.H_w[0] - 1) < 5e-3


def test_frequency_response_dynamic_over_quasi_static_is_the_beam_transfer():
    from ipmc_asym.beam.dynamics import transfer

    f = np.array([0.5, 5.0, 21.0, 24.0, 60.0])
    d = frequency_response(f, beam="dynamic")
    q = frequency_response(f, beam="quasi-static")
    b = strip_beam(Strip(), NAFION_LI)
    tr = transfer(f, b, "clamped-free")
    assert np.allclose(d.H_w / q.H_w, tr["dynamic_factor"]["w"], rtol=1e-12)
    assert np.allclose(d.H_F / q.H_F, transfer(f, b, "clamped-pinned")["dynamic_factor"]["F"], rtol=1e-12)
    assert d.resonances["clamped-free"][0] == pytest.approx(natural_frequencies("clamped-free", b, 1)[0])
    assert any("Darcy" in n for n in d.notes) and any("inertia" in n for n in d.notes)
    # the resonance of the free strip shows in |H_w|
    assert d.w_amp[2] > 5 * q.w_amp[2] and d.w_amp[3] > 5 * q.w_amp[3]


# --- support and electrode of drive_response ------------------------------------------------------------------------

CC_KEYS = ("M_root", "M_tip", "F_root", "F_tip", "w_mid")


@pytest.mark.parametrize("beam", ["dynamic", "quasi-static"])
def test_drive_clamped_clamped_full_electrode_gives_the_moment_to_the_clamps(beam):
    """Columns are only added: the default ones are unchanged; with a full electrode the clamped-clamped
    strip does not move and both reaction moments are M_A(t) (the beam docstring's limit), at every time."""
    base = drive_response(SPEC, 0.1, 1001, beam=beam)
    r = drive_response(SPEC, 0.1, 1001, beam=beam, support="clamped-clamped")
    assert all(np.array_equal(base[k], r[k]) for k in base)
    assert np.array_equal(r["M_root"], r["M_A"]) and np.array_equal(r["M_tip"], r["M_A"])
    assert all(np.all(r[k] == 0.0) for k in ("F_root", "F_tip", "w_mid"))
    assert not set(CC_KEYS) & set(drive_response(SPEC, 0.1, 1001, beam=beam, support="clamped-free"))


def test_drive_partial_electrode_static_limit_is_the_closed_form_statics():
    """Quasi-static beam: every row is the hand-derived small-displacement statics (tests/references.py) times
    M_A(t); dynamic, damped, after the transient: the same at the end (the clamped-clamped reactions, the
    free tip's w and theta, the blocked tip's force)."""
    from references import partial_electrode_statics

    strip = Strip()
    x1, x2 = 0.002, 0.012
    st = partial_electrode_statics(strip.length, NAFION_LI.E * strip.I_p, x1, x2)
    cols = {"w": "w", "theta": "theta", "F": "F_block", **{k: k for k in CC_KEYS}}
    q = drive_response("step:0.5V", 0.3, 601, beam="quasi-static", support="clamped-clamped", electrode=(x1, x2))
    for k, c in cols.items():
        assert np.allclose(q[c], st[k] * q["M_A"], rtol=1e-12, atol=1e-15 * abs(st[k] * q["M_A"][-1])), k
    f1 = natural_frequencies("clamped-free", strip_beam(strip, NAFION_LI), 1)[0]
    eta = viscous_modulus_from_damping_ratio(0.2, f1, NAFION_LI.E)
    r = drive_response("step:0.5V", 1.0, 4001, beam="dynamic", viscous_modulus=eta, support="clamped-clamped",
                       electrode=(x1, x2))
    assert np.array_equal(r["M_A"], drive_response("step:0.5V", 1.0, 4001, beam="quasi-static")["M_A"])
    for k, c in cols.items():
        assert r[c][-1] == pytest.approx(st[k] * r["M_A"][-1], rel=1e-7), k


@pytest.mark.parametrize("kw, word", [
    ({"support": "clamped-clamped", "sheet_resistance": 2.5}, "sheet_resistance"),
    ({"electrode": (0.0, 0.01), "sheet_resistance": 2.5}, "sheet_resistance"),
    ({"electrode": (0.01, 0.03)}, "electrode"),
    ({"support": "free"}, "support"),
])
def test_drive_support_refusals(kw, word):
    with pytest.raises(ValueError, match=word):
        drive_response("step:0.5V", 0.1, 1001, **kw)


@pytest.mark.parametrize("solver", ["circuit", "pnp"])
def test_a_later_step_is_the_step_at_zero_shifted(solver, capsys):
    """Nothing happens before a step at 0.1 s: from 0.1 s the response is the step response at 0
    (time invariance; independent of how either run treats the jump). At the jump the output is
    the state just after it: the core's displacement charge C_g V, the current V/R; the current is
    not a difference across the jump (that would be ~dV C_g/dt, hundreds of times V/R)."""
    import json

    from ipmc_asym.cli import main

    tol = ["--tol", "none"] if solver == "circuit" else []
    assert main(["drive", "--waveform", "step:1V@0.1s", "--duration", "0.2s", "--points", "3", "--solver", solver,
                 "--json", *tol]) == 0
    late = json.loads(capsys.readouterr().out)
    assert main(["drive", "--waveform", "step:1V", "--duration", "0.1s", "--points", "2", "--solver", solver,
                 "--json", *tol]) == 0
    now = json.loads(capsys.readouterr().out)
    # (the tail's current, 1e-5 of its peak, differs by the time steps' history: to 1e-6 of the peak)
    for k, rel, peak in (("sigma", 1e-6, 0.0), ("current_density", 0.0, 1e-6)):
        assert late[k][0] == 0.0
        assert late[k][1:] == pytest.approx(now[k], rel=rel, abs=peak * max(map(abs, now[k]))), k
