"""The circuit's small-signal impedance against the linearised PNP (the reference)."""

import math

import numpy as np
import pytest

from ipmc_asym.dynamics.circuit import circuit_band, frequency_response
from ipmc_asym.model.params import NAFION_LI, Strip
from ipmc_asym.model.permittivity import get_model

THICK = (20e-6, 200e-6, 1e-3)
MODELS = ("constant", "linear", "affine")


def _exact_z_area(f, strip, model, m=NAFION_LI):
    """Independent derivation: Z_area = [2e + 2 kappa tanh(k e)/(i w eps k)]/(kappa + i w eps), k^2 = 1/lD^2 + i w/D."""
    eps = get_model(model).eps_moy
    kappa = m.phi4 * m.F**2 * m.D * m.C_moy / (m.R * m.T)
    lD = math.sqrt(eps * m.R * m.T / (m.phi4 * m.F**2 * m.C_moy))
    w = 2 * math.pi * np.asarray(f)
    k = np.sqrt(1 / lD**2 + 1j * w / m.D)
    e = strip.e
    return (2 * e + 2 * kappa * np.tanh(k * e) / (1j * w * eps * k)) / (kappa + 1j * w * eps), lD


@pytest.mark.parametrize("thickness", THICK)
@pytest.mark.parametrize("model", MODELS)
def test_pnp_linear_is_the_exact_linear_theory(thickness, model):
    s = Strip(thickness=thickness)
    f = np.geomspace(1e-3, 1e7, 200)
    Zx, _ = _exact_z_area(f, s, model)
    r = frequency_response(f, strip=s, model=model, method="pnp-linear")
    assert np.max(np.abs(r.Z_area / Zx - 1)) < 1e-9


@pytest.mark.parametrize("thickness", THICK)
@pytest.mark.parametrize("model", MODELS)
def test_circuit_error_is_its_stated_error_and_below_lambda_over_2(thickness, model):
    s = Strip(thickness=thickness)
    f = np.geomspace(1e-3, 1e8, 400)
    Zx, lD = _exact_z_area(f, s, model)
    r = frequency_response(f, strip=s, model=model, method="circuit")
    actual = np.abs(r.Z_area - Zx) / np.abs(Zx)
    # the stated per-frequency error is the circuit's actual deviation from the exact theory
    assert np.allclose(r.error, actual, rtol=1e-6, atol=1e-13)
    lam = lD / s.e
    assert r.error_max == pytest.approx(lam / 2)
    assert np.all(actual <= lam / 2)
    # far above the dielectric relaxation frequency both tend to the bulk capacitance (C_g is in the circuit)
    assert actual[-1] < 1e-3 * lam
    # below f_d the error is ~ (f/(2 f_d))/|1 + i omega tau|
    lo = f < 1e-3 * r.f_d
    ratio = actual[lo] / (f[lo] / (2 * r.f_d) / np.abs(1 + 2j * math.pi * f[lo] * r.tau))
    assert np.all(np.abs(ratio - 1) < 0.05)
    # H_w inherits the relative error of Z
    hx = frequency_response(f, strip=s, model=model, method="pnp-linear").H_w
    assert np.all(np.abs(r.H_w / hx - 1) <= actual / (1 - actual) * (1 + 1e-6) + 1e-12)


def test_circuit_band():
    f = np.array([1.0, 2.0, 3.0, 4.0, 5.0])
    assert circuit_band(f, np.array([0.0, 1.0, 0.0, 0.0, 1.0]), 0.5) == [[1.0, 1.0], [3.0, 4.0]]


# --- support and electrode of frequency_response -------------------------------------------------------------------

def test_frequency_response_defaults_and_the_full_electrode_clamped_clamped_strip():
    """``electrode=(0, L)`` and ``support`` clamped-free/pinned are the defaults exactly; with a full electrode
    the clamped-clamped strip does not move and both clamps take the moment per volt (any frequency)."""
    strip = Strip()
    f = np.array([0.5, 20.0, 150.0, 2e3])
    base = frequency_response(f, strip=strip, beam="dynamic")
    for kw in ({"electrode": (0.0, strip.length)}, {"support": "clamped-free"}, {"support": "clamped-clamped"}):
        r = frequency_response(f, strip=strip, beam="dynamic", **kw)
        for k in ("Z", "H_w", "H_theta", "H_F"):
            assert np.array_equal(getattr(r, k), getattr(base, k)), (kw, k)
    cc = r.H_clamped
    # the moment per volt, independently: the quasi-static free tip's deflection over -L^2/(2 E I_p)
    qs = frequency_response(f, strip=strip, beam="quasi-static")
    HM = qs.H_w / (-strip.length**2 / (2 * NAFION_LI.E * strip.I_p))
    assert np.allclose(cc["M_root"], HM, rtol=1e-13, atol=0) and np.allclose(cc["M_tip"], HM, rtol=1e-13, atol=0)
    assert np.all(cc["F_root"] == 0) and np.all(cc["F_tip"] == 0) and np.all(cc["w_mid"] == 0)
    # the clamped-clamped resonances: cos(b) cosh(b) = 1, b1 = 4.730040745 (textbook root)
    b = frequency_response(f[:1], strip=strip, support="clamped-clamped").resonances["clamped-clamped"][0]
    A = strip.width * strip.thickness
    rho = (1 - NAFION_LI.phi4) * NAFION_LI.rho3 + NAFION_LI.phi4 * NAFION_LI.rho2
    f1 = 4.730040745**2 / (2 * math.pi * strip.length**2) * math.sqrt(NAFION_LI.E * strip.I_p / (rho * A))
    assert b == pytest.approx(f1, rel=1e-9)


@pytest.mark.parametrize("electrode", [(0.002, 0.012), (0.0, 0.006), (0.015, 0.02)])
def test_frequency_response_partial_electrode_quasi_static_limit_is_the_closed_form_statics(electrode):
    """f -> 0 (dynamic beam at 0.1 mHz, first mode ~20 Hz) and the quasi-static beam at every frequency: each
    output per volt is the hand-derived small-displacement statics (tests/references.py) times the moment
    per volt of the full-electrode strip."""
    from references import partial_electrode_statics

    strip = Strip()
    st = partial_electrode_statics(strip.length, NAFION_LI.E * strip.I_p, *electrode)
    f = np.array([1e-4, 1.0, 30.0])  # the dynamic correction at 0.1 mHz: (f/f1)^2 ~ 2e-11
    qs = frequency_response(f, strip=strip, beam="quasi-static")
    HM = qs.H_w / (-strip.length**2 / (2 * NAFION_LI.E * strip.I_p))
    for beam in ("quasi-static", "dynamic"):
        r = frequency_response(f, strip=strip, beam=beam, support="clamped-clamped", electrode=electrode)
        got = {"w": r.H_w, "theta": r.H_theta, "F": r.H_F, **r.H_clamped}
        n = f.size if beam == "quasi-static" else 1
        for k, v in st.items():
            scale = np.abs(HM[:n]) * max(abs(v), abs(st["M_root"]) / strip.length if k.startswith("F") else 0.0,
                                         abs(st["M_root"]) if k.startswith("M") else 0.0, 1e-300)
            assert np.all(np.abs(got[k][:n] - HM[:n] * v) <= 1e-9 * scale), (beam, k)
        assert r.electrode == tuple(electrode) and "partial electrode" in " ".join(r.notes)


def test_frequency_response_partial_electrode_resonance():
    """A damped clamped-clamped strip, electrode on its first fifth: the midspan deflection per volt peaks at
    the first clamped-clamped resonance, ~1/(2 zeta) above its static value."""
    from ipmc_asym.beam.dynamics import viscous_modulus_from_damping_ratio

    strip = Strip()
    f1 = frequency_response([1.0], strip=strip, support="clamped-clamped").resonances["clamped-clamped"][0]
    eta = viscous_modulus_from_damping_ratio(0.05, f1, NAFION_LI.E)
    f = np.linspace(0.9, 1.1, 401) * f1
    kw = dict(strip=strip, support="clamped-clamped", electrode=(0.0, 0.004), viscous_modulus=eta)
    r = frequency_response(f, beam="dynamic", **kw)
    q = frequency_response(f, beam="quasi-static", **kw)
    gain = np.abs(r.H_clamped["w_mid"] / q.H_clamped["w_mid"])
    assert f[np.argmax(gain)] == pytest.approx(f1, rel=5e-3)
    assert 7.0 < gain.max() < 13.0  # one mode dominates: Q = 1/(2 zeta) = 10 times its modal share


@pytest.mark.parametrize("kw, word", [({"support": "pinned"}, "support"), ({"electrode": (0.01, 0.005)}, "electrode"),
                                      ({"electrode": (0.0, 0.03)}, "electrode"), ({"electrode": 0.01}, "electrode")])
def test_frequency_response_support_refusals(kw, word):
    with pytest.raises(ValueError, match=word):
        frequency_response([1.0], **kw)


@pytest.mark.parametrize("model, voltage", [("affine", 2.0), ("linear", 0.5)])
def test_default_window_resolves_the_nonlinear_rise(model, voltage):
    # independent: the 50 % and 90 % times of sigma from a dense explicit grid over 0.5 tau (4001 times);
    # the default window must put outputs inside the rise, and still end at 5 tau
    from ipmc_asym.dynamics.circuit import step_response
    from ipmc_asym.model.params import Strip

    s = Strip(voltage=voltage)
    r = step_response(voltage, strip=s, model=model)
    dense = step_response(voltage, strip=s, model=model, t=np.linspace(0.0, 0.5 * r.tau, 4001))
    sig, final = np.abs(dense.sigma), abs(float(r.sigma[-1]))
    t50, t90 = (float(dense.t[np.argmax(sig >= q * final)]) for q in (0.5, 0.9))
    assert 0.0 < t50 < t90 < 0.25 * r.tau  # the case: charged before an equally spaced grid's early rows
    assert np.count_nonzero((r.t > t50) & (r.t < t90)) >= 20
    assert np.count_nonzero((r.t > 0) & (r.t < t50)) >= 20  # the start of the rise too
    assert r.t[0] == 0.0 and r.t[-1] == pytest.approx(5 * r.tau, rel=1e-12)
    # and the printed table (11 rows evenly spread over the outputs) shows it: rows inside the rise
    idx = np.unique(np.linspace(0, r.t.size - 1, 11).astype(int))
    assert np.count_nonzero(r.t[idx] < t90) >= 3


@pytest.mark.parametrize("h_max", [5e-3, 2.5e-4])
def test_the_substep_refusal_states_the_longest_chunk_where_it_is(h_max):
    # the refusal's figure in seconds is the boundary itself: 1 % below it the grid is laid,
    # 1 % above it refused
    import re

    from ipmc_asym.dynamics.circuit import substep_grid

    tau = 0.0338
    with pytest.raises(ValueError, match="the reduced model's fixed substeps") as ex:
        substep_grid(np.array([0.0, 1e30]), tau, h_max, 2, ("the reduced model's", "use fewer time constants"))
    span = float(re.search(r"= (\S+) s here", str(ex.value)).group(1))
    assert math.isclose(span, 5e6 * h_max * tau, rel_tol=1e-2)
    grid, idx = substep_grid(np.array([0.0, 0.99 * span]), tau, h_max, 2, ("x", "y"))
    assert grid[idx[-1]] * tau == pytest.approx(0.99 * span)
    with pytest.raises(ValueError, match="use fewer time constants"):
        substep_grid(np.array([0.0, 1.01 * span]), tau, h_max, 2, ("the reduced model's", "use fewer time constants"))


def test_the_frequency_range_ends_are_the_exact_theory_and_beyond_them_one_line():
    # settings.FREQUENCY_RANGE: the closed forms hold at its ends (against the independent exact
    # impedance above), every output finite for each model, method and beam, with the electrode line too;
    # past them, one line (no NumPy warning before it)
    import warnings

    from ipmc_asym.base.settings import FREQUENCY_RANGE
    from ipmc_asym.dynamics.line import line_response

    f = np.array(FREQUENCY_RANGE)
    s = Strip()
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for m in MODELS:
            ref, _ = _exact_z_area(f, s, m)
            r = frequency_response(f, strip=s, model=m)
            assert np.allclose(r.Z_area, ref, rtol=1e-9, atol=0.0), m
            for method in ("pnp-linear", "circuit"):
                for beam in ("quasi-static", "dynamic"):
                    for res in (frequency_response(f, model=m, method=method, beam=beam),
                                line_response(f, model=m, method=method, beam=beam, sheet_resistance=2.5)):
                        assert all(np.all(np.isfinite(x)) for x in (res.Z, res.H_w, res.H_theta, res.H_F)), (m, method)
        for bad in ([0.5 * f[0]], [2.0 * f[1]], [np.nan]):
            with pytest.raises(ValueError, match=r"^frequencies must be finite and within") as ei:
                frequency_response(bad)
            assert "\n" not in str(ei.value)
        for D in (1e308, 1e-320):  # the material refuses a D whose time constant leaves the doubles
            with pytest.raises(ValueError, match=r"^cation diffusion coefficient D must be a finite number within"):
                frequency_response([1.0], material=NAFION_LI.with_(D=D))


def test_a_viscous_modulus_the_quasi_static_beam_does_not_use_is_said():
    f = np.array([1.0, 10.0])
    r0 = frequency_response(f, method="circuit")
    r1 = frequency_response(f, method="circuit", viscous_modulus=1e4)
    np.testing.assert_array_equal(r1.H_w, r0.H_w)  # indeed unused
    said = [n for n in r1.notes if "viscous modulus 10000 Pa s given is not used" in n]
    assert len(said) == 1 and not any("not used" in n for n in r0.notes)
    rd = frequency_response(f, method="circuit", beam="dynamic", viscous_modulus=1e4)
    assert not any("not used" in n for n in rd.notes)


@pytest.mark.parametrize("stream", [False, True])
def test_a_drive_faster_than_the_output_grid_is_resolved(stream):
    """The substeps follow the waveform's fastest component, not only tau/200: an 11-row grid
    over ten periods of a 1 kHz sine gives the rows a 10001-row grid gives at the same times (a
    different discretisation); before, its middle row had the wrong sign (0.18 against -0.022)."""
    import ipmc_asym as ia

    said = {}

    def rows(points):
        r = ia.time_response(Strip(), ia.Drive("sine:1V@1010Hz"), duration=0.01, points=points, tol=None,
                             stream=stream)
        said[points] = [n for n in r.info["notes"] if n.startswith("output rows every")]
        if stream:
            return np.concatenate([np.asarray(c["sigma"]) for c in r.iter_chunks()])
        assert [n for n in r.result.notes if n.startswith("output rows every")] == said[points]
        return np.asarray(r.result.sigma)

    fine, coarse = rows(10001), rows(11)
    # the rows' spacing said where it is wider than half a period (0.1 rows a period here)
    assert said[10001] == [] and len(said[11]) == 1 and "1010 Hz" in said[11][0]
    scale = np.max(np.abs(fine))
    np.testing.assert_allclose(coarse, fine[::1000], rtol=0, atol=2e-4 * scale)


def test_drive_substep_follows_the_fastest_component():
    from ipmc_asym.dynamics.circuit import STEPS_PER_PERIOD, drive_substep
    from ipmc_asym.dynamics.waveforms import parse_waveform

    tau = 0.03
    assert drive_substep(parse_waveform("step:1V"), tau, 5e-3) == 5e-3
    assert drive_substep(parse_waveform("sine:1V@1Hz"), tau, 5e-3) == 5e-3
    w = parse_waveform("step:1V+square:0.1V@5kHz")
    assert drive_substep(w, tau, 5e-3) == pytest.approx(1.0 / (STEPS_PER_PERIOD * 5e3 * tau), rel=1e-15)
    assert drive_substep(lambda t: 0.0 * t, tau, 5e-3) == 5e-3  # a bare callable states no frequency


@pytest.mark.parametrize("creep_time", [8.0, 1e3])
def test_a_heavily_damped_beam_creeps_as_the_kelvin_voigt_law_says(creep_time):
    """Far past critical damping every mode creeps at 1/tau_v: w follows tau_v w' + w = w_qs (the
    quasi-static deflection), integrated here on its own (implicit Euler). The modal step's slow
    root, written mu - a, cancelled there (the upper modes never crept: x120 at tau_v = 8e3 s)."""
    import ipmc_asym as ia

    s = Strip()
    qs = ia.time_response(s, 1.0, duration=0.17, points=2001, tol=None).result
    t, wq = np.asarray(qs.t), np.asarray(qs.w)
    w = np.zeros_like(t)
    for i in range(1, t.size):
        h = t[i] - t[i - 1]
        w[i] = (w[i - 1] + h / creep_time * wq[i]) / (1.0 + h / creep_time)
    eta = creep_time * NAFION_LI.E
    r = ia.time_response(s, 1.0, duration=0.17, points=2001, tol=None, beam="dynamic", viscous_modulus=eta).result
    assert np.asarray(r.w)[-1] == pytest.approx(w[-1], rel=1e-3)
    with pytest.raises(ValueError, match="settings.MAX_CREEP_TIME"):
        ia.time_response(s, 1.0, duration=0.17, points=11, tol=None, beam="dynamic", viscous_modulus=eta * 1.01
                         if creep_time == 1e3 else 1e308)
