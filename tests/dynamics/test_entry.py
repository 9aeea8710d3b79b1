"""The one dynamic entry (dynamics/entry.py): the solver it picks and its numbers, against the
functions it dispatches to called directly, and against the commands that call it."""

import json

import numpy as np
import pytest

from ipmc_asym.cli import main
from ipmc_asym.dynamics.circuit import frequency_response, step_response, waveform
from ipmc_asym.dynamics.drive import drive_response
from ipmc_asym.dynamics.entry import DEFAULT_BEAM, Drive, spectrum, time_path, time_response
from ipmc_asym.dynamics.line import line_response
from ipmc_asym.dynamics.waveforms import parse_waveform
from ipmc_asym.model.params import Strip


def test_drive_is_a_step_or_a_waveform_checked_when_built():
    d = Drive(1.5)
    assert d.kind == "step" and d.voltage == 1.5 and d.spec == "step"
    assert np.array_equal(d(np.array([0.0, 1.0])), [1.5, 1.5])
    w = Drive("sine:2V@5Hz")
    t = np.linspace(0.0, 0.3, 7)
    assert w.kind == "waveform" and w.spec == "sine:2V@5Hz"
    assert np.allclose(w(t), 2.0 * np.sin(2 * np.pi * 5.0 * t), rtol=0, atol=1e-12)
    assert Drive(w).spec == w.spec and Drive.parse("step:1V").kind == "waveform"
    for bad in (True, None, float("nan"), "sine:1V", object()):
        with pytest.raises(ValueError) as e:
            Drive(bad)
        assert len(str(e.value).splitlines()) == 1
    with pytest.raises(ValueError, match="voltage"):
        Drive.step("1V")


@pytest.mark.parametrize("kw, path", [
    ({}, "memory"),
    ({"stream": True}, "stream"),
    ({"stream": True, "beam": "dynamic"}, "memory"),  # the dynamic beam on its refined grid
    ({"stream": True, "beam": "dynamic", "beam_grid": "output"}, "stream"),
    ({"stream": True, "fidelity": "pnp"}, "memory"),
    ({"stream": True, "tol": 1e-3}, "memory"),
    ({"sheet_resistance": 2.5}, "line"),
    ({"sheet_resistance": 2.5, "stream": True}, "line"),
    ({"support": "clamped-clamped"}, "stream"),
    ({"electrode": (0.0, 0.01)}, "stream"),
    ({"support": "clamped-free", "stream": False}, "memory"),
])
def test_time_path_table(kw, path):
    assert time_path(**kw) == path


@pytest.mark.parametrize("kw, word", [
    ({"sheet_resistance": 2.5, "fidelity": "pnp"}, "fidelity pnp"),
    ({"sheet_resistance": 2.5, "tol": 1e-3}, "tol"),
    ({"support": "clamped-clamped", "tol": 1e-3}, "tol"),
    ({"sheet_resistance": -1.0}, "sheet_resistance"),
    ({"beam": "elastic"}, "beam"),
    ({"beam_grid": "fine"}, "beam_grid"),
])
def test_time_path_refusals_are_one_line(kw, word):
    with pytest.raises(ValueError) as e:
        time_path(**kw)
    assert word in str(e.value) and len(str(e.value).splitlines()) == 1


def test_memory_path_is_step_response_with_the_voltage_once():
    s = Strip(voltage=0.7)
    r = time_response(s, points=9)
    assert r.path == "memory" and r.drive.voltage == 0.7
    ref = step_response(0.7, None, strip=s, points=9)
    for c in ("t", "sigma", "current_density", "M_A", "w", "F_block"):
        assert np.array_equal(getattr(r.result, c), getattr(ref, c)), c
    # an explicit drive wins over the strip's voltage
    r2 = time_response(s, 1.2, points=9)
    assert np.array_equal(r2.result.sigma, step_response(1.2, None, strip=s, points=9).sigma)


def test_stream_and_line_paths_are_the_stepped_circuit():
    s = Strip()
    wave = "sine:1V@20Hz"
    r = time_response(s, wave, duration=0.1, points=21, stream=True)
    assert r.path == "stream" and r.info["beam"] == DEFAULT_BEAM
    chunks = list(r.chunks)
    rows = {k: np.concatenate([c[k] for c in chunks]) for k in ("t", "sigma", "w")}
    ref = drive_response(parse_waveform(wave), 0.1, 21, strip=s, beam="quasi-static")
    for k in rows:
        assert np.array_equal(rows[k], ref[k]), k
    ln = time_response(s, wave, duration=0.1, points=21, sheet_resistance=2.5, line_segments=16)
    assert ln.path == "line" and ln.columns is not None and ln.info["line_segments"] == 32
    lref = drive_response(parse_waveform(wave), 0.1, 21, strip=s, beam="quasi-static", sheet_resistance=2.5,
                          line_segments=16)
    for k in ("sigma", "sigma_error", "w", "w_error"):
        assert np.array_equal(ln.columns[k], lref[k]), k


def test_spectrum_picks_the_line_with_a_sheet_resistance():
    f = np.geomspace(0.1, 100.0, 5)
    r = spectrum(f, Strip())
    ref = frequency_response(f, strip=Strip(), beam="quasi-static")
    assert np.array_equal(r.Z, ref.Z) and np.array_equal(r.w_amp, ref.w_amp)
    rl = spectrum(f, Strip(), sheet_resistance=2.5)
    lref = line_response(f, strip=Strip(), sheet_resistance=2.5, beam="quasi-static")
    assert np.array_equal(rl.Z, lref.Z) and np.array_equal(rl.w_amp, lref.w_amp)
    # a bias without a method: the method that supports it (the circuit), as freq --voltage does
    rb = spectrum(f, Strip(), voltage=0.5)
    bref = frequency_response(f, strip=Strip(), beam="quasi-static", method="circuit", voltage=0.5)
    assert rb.method == "circuit" and np.array_equal(rb.Z, bref.Z)
    with pytest.raises(ValueError, match="circuit"):
        spectrum(f, Strip(), voltage=0.5, method="pnp-linear")
    with pytest.raises(ValueError, match="sheet_resistance"):
        spectrum(f, Strip(), sheet_resistance=1.0, support="clamped-clamped")


def test_the_commands_make_the_entry_s_choice(tmp_path, capsys):
    """step/drive/freq print what the entry (and the functions it calls) return for the same options."""
    assert main(["step", "--points", "9", "--voltage", "0.7V", "--tol", "none", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    ref = step_response(0.7, None, strip=Strip(voltage=0.7), points=9)
    assert out["beam"] == DEFAULT_BEAM and np.allclose(out["sigma"], ref.sigma, rtol=1e-15, atol=0)
    # step --out streams (the circuit on the output grid, no error stated): the rows of drive_chunks
    f = tmp_path / "s.csv"
    assert main(["step", "--points", "9", "--voltage", "0.7V", "--duration", "0.2s", "--tol", "none", "--out", str(f)]) == 0
    assert "streamed" in capsys.readouterr().err
    rows = [ln.split(",") for ln in f.read_text().splitlines()]
    sig = np.array([float(x[rows[0].index("sigma")]) for x in rows[1:]])
    dref = drive_response(waveform("step", 0.7), 0.2, 9, strip=Strip(voltage=0.7), beam="quasi-static")
    assert np.allclose(sig, dref["sigma"], rtol=1e-15, atol=0)
    assert main(["drive", "--waveform", "step:0.7V", "--duration", "0.2s", "--points", "9", "--json"]) == 0
    dout = json.loads(capsys.readouterr().out)
    assert dout["beam"] == DEFAULT_BEAM and np.allclose(dout["sigma"], dref["sigma"], rtol=1e-15, atol=0)
    assert main(["freq", "--from", "0.1Hz", "--to", "100Hz", "--points", "5", "--json"]) == 0
    fout = json.loads(capsys.readouterr().out)
    fref = frequency_response(np.geomspace(0.1, 100.0, 5), strip=Strip(), beam="quasi-static")
    assert fout["beam"] == DEFAULT_BEAM and np.allclose(fout["Z_re"], fref.Z.real, rtol=1e-15, atol=0)


def test_time_response_is_a_result_object_of_its_rows():
    from ipmc_asym.base.quantities import BY_NAME

    s = Strip(thickness=200e-6, voltage=0.5)
    ref = step_response(0.5, strip=s, points=40)
    for kw in ({}, {"stream": False, "sheet_resistance": 2.5}):
        r = time_response(s, points=40, **kw)
        ds = r.to_xarray()
        t = ref.t if r.result is not None else r.columns["t"]
        np.testing.assert_array_equal(ds["t"].values, t)
        sigma = ref.sigma if r.result is not None else r.columns["sigma"]
        np.testing.assert_array_equal(ds["sigma"].values, sigma)
        for name, var in ds.data_vars.items():  # units and long names of the vocabulary
            assert var.attrs["units"] == BY_NAME[name].unit and var.attrs["long_name"] == BY_NAME[name].long_name
        fig = r.plot()
        assert all("[" in ax.get_ylabel() for ax in fig.axes)
    streamed = time_response(s, points=40, stream=True, sheet_resistance=2.5)
    with pytest.raises(ValueError, match="streamed"):
        streamed.to_xarray()


def test_tol_auto_states_the_circuit_error_where_a_reference_can_run():
    """tol="auto" (step's default): the in-memory circuit bounded at AUTO_TOL; where no reference PNP
    run applies it states none instead of refusing, and says why (an explicit tol is refused there)."""
    from ipmc_asym.dynamics.drive import MAX_STATED_POINTS
    from ipmc_asym.dynamics.entry import AUTO_TOL, stated_tol

    s = Strip(voltage=0.3)
    # the electrode line: no refusal (its own discretisation error is stated), while tol=1e-2 is refused
    r = time_response(s, points=20, tol="auto", sheet_resistance=2.5)
    assert r.path == "line" and np.all(np.isfinite(r.columns["sigma_error"]))
    with pytest.raises(ValueError, match="drop tol"):
        time_response(s, points=20, tol=1e-2, sheet_resistance=2.5)
    # a clamped-clamped support: stepped by the circuit only, said in the notes
    r = time_response(s, points=20, tol="auto", support="clamped-clamped", stream=True)
    assert r.path == "stream" and any("clamped-clamped" in n and "no error stated" in n for n in r.info["notes"])
    # the reference PNP run refuses the strip (layers that fill 1 um at 20 V): auto keeps the circuit
    # and says so; an explicit tolerance is refused
    thin = Strip(thickness=1e-6, voltage=20.0)
    r = time_response(thin, points=5, model="linear", tol="auto")
    assert r.result.fidelity == "circuit" and np.all(np.isnan(r.result.sigma_error)) and r.info["tol"] is None
    assert any("reference PNP run refuses" in n for n in r.info["notes"])
    with pytest.raises(ValueError, match="neutral core"):
        time_response(thin, points=5, model="linear", tol=1e-2)
    assert stated_tol("auto", points=MAX_STATED_POINTS) == (AUTO_TOL, None)
    assert stated_tol("auto", fidelity="pnp") == (None, None)  # the PNP states its own at 1e-6
    assert stated_tol(3e-3, points=10**6) == (3e-3, None)  # an explicit tolerance is the caller's


def test_tol_auto_gives_up_a_reference_past_its_cost_cap_or_that_fails_and_says_so():
    """tol="auto" caps the reference PNP run's work (AUTO_WORK; here a small cap through pnp_options):
    past it, or where the reference fails (too few cells allowed), the circuit's rows come back
    without an error, bit for bit the bare circuit's, with a note that says which; an explicit
    tolerance raises the failure instead (no silent downgrade)."""
    from ipmc_asym.dynamics.circuit import ReferenceFailed
    from ipmc_asym.dynamics.entry import AUTO_WORK

    s = Strip(voltage=0.5)
    bare = time_response(s, "sine:0.5V@20Hz", duration=0.1, points=41, tol=None).result
    assert np.all(np.isnan(bare.sigma_error))
    for opts, words in (({"max_work": 1e5}, "would cost more than tol='auto' allows"),
                        ({"max_cells": 60}, "reference PNP run fails in this case")):
        r = time_response(s, "sine:0.5V@20Hz", duration=0.1, points=41, tol="auto", pnp_options=opts)
        assert r.info["tol"] is None and r.result.fidelity == "circuit"
        assert np.all(np.isnan(r.result.sigma_error)) and np.array_equal(r.result.sigma, bare.sigma)
        assert sum(words in n for n in r.info["notes"]) == 1, r.info["notes"]
        assert sum("no error stated" in n for n in r.info["notes"]) == 1  # one line says it, with its reason
        with pytest.raises(ReferenceFailed):
            time_response(s, "sine:0.5V@20Hz", duration=0.1, points=41, tol=1e-2, pnp_options=opts)
    # within the cap (the default one), the same drive states its error
    r = time_response(s, "sine:0.5V@20Hz", duration=0.1, points=41, tol="auto")
    assert r.info["tol"] == 1e-2 and np.all(np.isfinite(r.result.sigma_error)) and AUTO_WORK >= 1e7
