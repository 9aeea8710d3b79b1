"""The waveform grammar against the formulas it names."""

import math

import numpy as np
import pytest

from ipmc_asym.dynamics.waveforms import parse_waveform

T = np.linspace(0.0, 0.37, 1001)


def test_each_kind_and_sums():
    f = 7.0
    assert np.allclose(parse_waveform("dc:0.2V")(T), 0.2)
    assert np.array_equal(parse_waveform("step:1V@50ms")(T), np.where(T >= 0.05, 1.0, 0.0))
    assert np.allclose(parse_waveform("ramp:2V/100ms@10ms")(T), 2 * np.clip((T - 0.01) / 0.1, 0, 1))
    assert np.allclose(parse_waveform("sine:0.5V@7Hz,90")(T), 0.5 * np.cos(2 * math.pi * f * T), atol=1e-15)
    sq = parse_waveform("square:300mV@7Hz")(T)
    s = np.sin(2 * math.pi * f * T)
    ok = np.abs(s) > 1e-9
    assert np.array_equal(sq[ok], 0.3 * np.sign(s[ok]))
    tri = parse_waveform("triangle:1V@7Hz")(T)
    assert np.allclose(tri, (2 / math.pi) * np.arcsin(np.sin(2 * math.pi * f * T)), atol=1e-12)
    total = parse_waveform("dc:0.2V+sine:0.5V@7Hz + square:0.1V@3Hz")(T)
    parts = parse_waveform("dc:0.2V")(T) + parse_waveform("sine:0.5V@7Hz")(T) + parse_waveform("square:0.1V@3Hz")(T)
    assert np.array_equal(total, parts)
    assert parse_waveform("step:-1.5e+0V")(np.array([1.0]))[0] == -1.5  # a '+' inside a number is not a sum


def test_measured_csv(tmp_path):
    p = tmp_path / "v.csv"
    p.write_text("t,V\n0,0\n10ms,1V\n0.03,-0.5\n")
    w = parse_waveform(f"csv:{p}+dc:0.1V")
    assert np.allclose(w(np.array([0.0, 0.005, 0.02, 1.0])), [0.1, 0.6, 0.35, -0.4])


@pytest.mark.parametrize("spec,word", [
    ("", "SPEC"), ("sin:1V@1Hz", "kind"), ("sine:1V", "V@F"), ("ramp:1V", "TR"), ("sine:1V@-2Hz", "> 0"),
    ("csv:/nonexistent.csv", "no such file"), ("square:1V@1Hz,30", "phase"), ("step:1Q", "unit"),
])
def test_bad_specs_one_line(spec, word):
    with pytest.raises(ValueError, match=word) as ei:
        parse_waveform(spec)
    assert "\n" not in str(ei.value)


def test_drive_voltage_cap_refuses_by_name_and_is_finite_at_the_cap():
    """Beyond MAX_DRIVE_VOLTAGE a drive is refused in one line naming it; at the cap (both signs)
    the step's charge and moment are finite (the guard's claim)."""
    import ipmc_asym as ia
    from ipmc_asym.base.settings import MAX_DRIVE_VOLTAGE

    for bad in (1e300, -2 * MAX_DRIVE_VOLTAGE):
        with pytest.raises(ValueError, match=r"drive: \|phi0\| up to"):
            ia.Drive(bad)
    with pytest.raises(ValueError, match=r"waveform: \|phi0\| up to"):
        parse_waveform(f"dc:{0.6 * MAX_DRIVE_VOLTAGE}V+sine:{0.6 * MAX_DRIVE_VOLTAGE}V@1Hz")
    # the library's own waveforms and the DC bias go through the same check as a Drive
    from ipmc_asym.dynamics.circuit import waveform

    with pytest.raises(ValueError, match=r"voltage: \|phi0\| up to"):
        waveform("step", 2 * MAX_DRIVE_VOLTAGE)
    for bad in (float("nan"), "x"):
        with pytest.raises(ValueError, match="voltage must be a finite number of volts"):
            waveform("ramp", bad, ramp_time=1.0)
    with pytest.raises(ValueError, match=r"DC bias\)?: \|phi0\| up to"):
        ia.spectrum([1.0], ia.Strip(), voltage=2 * MAX_DRIVE_VOLTAGE)
    for v in (MAX_DRIVE_VOLTAGE, -MAX_DRIVE_VOLTAGE):
        r = ia.time_response(ia.Strip(), ia.Drive(v), duration=0.1, points=3)
        rows = r.result if r.result is not None else r.columns
        sigma, M = np.asarray(rows["sigma"] if isinstance(rows, dict) else rows.sigma), \
            np.asarray(rows["M_A"] if isinstance(rows, dict) else rows.M_A)
        assert np.all(np.isfinite(sigma)) and np.all(np.isfinite(M)), (v, sigma, M)


def test_voltage_rate_of_a_plain_callable_is_one_sided_at_a_jump():
    """A jump's impulse is no current density: at the jump the rate just after it, just before it
    the rate before; a smooth function's rate is its derivative (central difference, ~1e-14)."""
    from ipmc_asym.dynamics.waveforms import voltage_rate

    def square(t):
        return np.where(np.asarray(t) >= 0.5, -1.0, 1.0) + 0.1 * np.asarray(t)

    r = voltage_rate(square, np.array([0.0, 0.25, 0.5, np.nextafter(0.5, 0.0)]), 1e-5)
    assert r[0] == 0.0 and r[1:] == pytest.approx([0.1, 0.1, 0.1], rel=1e-6)
    t = np.linspace(0.01, 1.0, 7)
    assert voltage_rate(lambda x: np.sin(3.0 * x), t, 1e-5) == pytest.approx(3.0 * np.cos(3.0 * t), rel=1e-7,
                                                                            abs=1e-7)
    # a parsed waveform: the regular part of its own derivative (its jumps left out)
    w = parse_waveform("sine:1V@2Hz+square:0.5V@1Hz")
    assert voltage_rate(w, t, 1e-5) == pytest.approx(2.0 * math.pi * 2.0 * np.cos(2.0 * math.pi * 2.0 * t))


def test_a_ramp_time_or_period_past_the_numerical_guard_is_refused_naming_the_term():
    from ipmc_asym.base.settings import FREQUENCY_RANGE, MIN_TIME

    for spec, what in (("ramp:1V/1e-320s", "the ramp time TR must be at least 1e-12 s"),
                       ("ramp:1V/5e-324s", "the ramp time TR must be at least"),
                       ("ramp:1V/1e-13s", "the ramp time TR must be at least"),
                       ("sine:1V@1e300Hz", "the frequency must be within 1e-09..1e+12 Hz"),
                       ("square:1V@1e-320Hz", "the frequency must be within"),
                       ("dc:0.1V+triangle:1V@2e12Hz", "the frequency must be within")):
        with pytest.raises(ValueError) as ei:
            parse_waveform(spec)
        msg = str(ei.value)
        assert msg.startswith("waveform term '") and what in msg and "\n" not in msg, msg
    # the ends themselves are taken, and give finite values and slopes
    w = parse_waveform(f"ramp:1V/{MIN_TIME}s+sine:0.1V@{FREQUENCY_RANGE[1]}Hz+sine:0.1V@{FREQUENCY_RANGE[0]}Hz")
    t = np.linspace(0.0, 10 * MIN_TIME, 11)
    assert np.all(np.isfinite(w(t))) and np.all(np.isfinite(w.derivative(t)))
