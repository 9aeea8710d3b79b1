"""The charge/step/freq commands as a user runs them."""

import csv
import json

import numpy as np
import pytest

from ipmc_asym.cli import main
from ipmc_asym.dynamics.electrode import charge
from ipmc_asym.forward.model import CHECKS


def test_charge_json_keys_and_values(capsys):
    assert main(["charge", "--json", "--voltage", "500mV", "--thickness", "150um"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["inputs"]["thickness_total"] == 150e-6 and out["inputs"]["half_thickness_e"] == 75e-6
    assert [r["model"] for r in out["results"]] == ["constant", "linear", "affine"]
    for r in out["results"]:
        assert {"sigma", "Q", "C_diff", "eps_app"} <= set(r)
        ref = charge(150e-6, 0.5, r["model"], "corrected")
        assert r["sigma"] == pytest.approx(float(ref.sigma), rel=1e-14)
        assert r["Q"] == pytest.approx(float(ref.sigma) * 5e-3 * 0.02, rel=1e-14)
        assert r["eps_app"] == pytest.approx(float(ref.C_diff) * 150e-6, rel=1e-14)


def test_step_json_and_csv(tmp_path, capsys):
    assert main(["step", "--voltage", "0.5V", "--points", "50", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    for k in ("t", "phi0", "sigma", "current_density", "M_A", "theta", "w", "tau"):
        assert k in out
    assert len(out["t"]) == 50 and out["t"][-1] == pytest.approx(5 * out["tau"])
    assert any("Darcy" in n for n in out["notes"]) and any("D = " in n for n in out["notes"])
    f = tmp_path / "s.csv"
    assert main(["step", "--voltage", "1V", "--duration", "20ms", "--points", "30", "--tol", "none",
                 "--out", str(f)]) == 0
    rows = list(csv.reader(f.read_text().splitlines()))
    assert rows[0][:7] == ["t", "phi0", "sigma", "current_density", "M_A", "theta", "w"]
    assert rows[0][7:] == [f"check_{c}" for c in CHECKS] + ["valid"]
    assert len(rows) == 31 and float(rows[-1][0]) == pytest.approx(0.02)
    meta = json.loads((tmp_path / "s.csv.json").read_text())
    assert meta["tau"] > 0 and meta["thickness_total"] == pytest.approx(200e-6) and meta["units"]["w"] == "m"
    pd = pytest.importorskip("pandas")
    df = pd.read_csv(f)  # the header row is the first line: no comment= needed
    assert list(df.columns) == rows[0] and len(df) == 30


def test_freq_json(capsys):
    assert main(["freq", "--from", "0.1Hz", "--to", "1kHz", "--points", "5", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    for k in ("f", "Z_re", "Z_im", "w_amp", "w_phase"):
        assert len(out[k]) == 5
    assert out["f"][0] == pytest.approx(0.1) and out["f"][-1] == pytest.approx(1e3)


def test_freq_bias_without_method_picks_the_method_that_supports_it(capsys):
    """--voltage without --method runs the method that supports a bias (circuit) instead of refusing;
    an explicit --method pnp-linear with a bias is still refused in one line."""
    base = ["freq", "--from", "1Hz", "--to", "100Hz", "--points", "4", "--voltage", "0.5V", "--beam", "quasi-static",
            "--json"]
    assert main(base) == 0
    a = json.loads(capsys.readouterr().out)
    assert main(base + ["--method", "circuit"]) == 0
    b = json.loads(capsys.readouterr().out)
    assert a["method"] == "circuit" and a == b
    # its error against the PNP linearised about the bias (the keys of the 0 V case)
    assert len(a["error"]) == 4 and all(e is not None and 0.0 < e < 0.1 for e in a["error"])
    assert a["error_max"] == max(a["error"]) and "0.5 V" in a["reference"]
    assert main(base + ["--method", "pnp-linear"]) == 2
    err = capsys.readouterr().err  # the library's one refusal, named by the parameter
    assert len(err.strip().splitlines()) == 1 and "voltage" in err and "circuit" in err


@pytest.mark.parametrize("args,word", [
    (["charge", "--thickness", "0"], "thickness"),
    (["charge", "--fidelity", "exact-ish"], "fidelity"),
    (["step", "--duration", "-1s"], "duration"),
    (["step", "--out", "/nonexistent-dir/x.csv"], "--out"),
    (["freq", "--from", "10Hz", "--to", "1Hz"], "--to"),
    (["freq", "--from", "0", "--to", "1Hz"], "--from"),
    (["freq", "--to", "1Hz"], "--from"),
])
def test_bad_input_exit_2_one_line(args, word, capsys):
    with pytest.raises(SystemExit) as ei:
        rc = main(args)
        raise SystemExit(rc)
    assert ei.value.code == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and word in err


def test_charge_escalates_like_estimate(capsys):
    assert main(["charge", "--json", "--thickness", "1um", "--voltage", "20V"]) == 0
    out = json.loads(capsys.readouterr().out)
    for r in out["results"]:
        ref = charge(1e-6, 20.0, r["model"], r["fidelity_used"])
        assert bool(ref.valid) and r["sigma"] == float(ref.sigma)
        assert r["fidelity"] == "corrected" and r["escalated"] == (r["fidelity_used"] != "corrected")
        # the cheapest valid rung: every rung below it, from the requested one, is not valid
        assert r["fidelity_used"] in ("quadrature", "exact")
        if r["fidelity_used"] == "exact":
            assert not bool(charge(1e-6, 20.0, r["model"], "quadrature").valid)
    assert main(["charge", "--thickness", "10um", "--model", "linear"]) == 0
    assert "corrected" in capsys.readouterr().out


def test_charge_below_min_thickness_names_the_limit(capsys):
    assert main(["charge", "--thickness", "50nm"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "MIN_THICKNESS" in err and "thickness" in err


def test_charge_tiny_voltages(capsys):
    """sigma -> C_d(0) phi0 (not 0, not a constant); a Q below the double range is answered with its
    rounding as the error estimate, flagged not valid, with one warning line."""
    for v in ("1e-300", "-1e-100", "1e-20"):
        assert main(["charge", "--json", "--model", "affine", f"--voltage={v}"]) == 0
        r = json.loads(capsys.readouterr().out)["results"][0]
        assert r["sigma"] / float(v) == pytest.approx(float(charge(200e-6, 0.0, "affine").C_diff), rel=1e-12)
    assert main(["charge", "--json", "--model", "constant", "--voltage=5e-324"]) == 0
    cap = capsys.readouterr()
    r = json.loads(cap.out)["results"][0]
    assert r["valid"] is False and r["error_estimate"] >= 0.01
    err = [ln for ln in cap.err.splitlines() if "warning" in ln]
    assert len(err) == 1 and "subnormal" in err[0]


def test_freq_z_abs_phase_read_by_fit(capsys, tmp_path):
    """freq's Z_abs (Ohm) and Z_phase (deg) written as a spectrum file are what the dynamic fit reads,
    and its model at the same strip predicts them (the fit's forward model is the line, freq's the
    uniform strip: equal with ideal electrodes)."""
    from ipmc_asym.model.params import NAFION_LI, Strip
    from ipmc_asym.studies.calibrate_dynamic import _impedance_columns, predict_impedance, read_file

    assert main(["freq", "--from", "0.1Hz", "--to", "10kHz", "--points", "7", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["units"]["Z_abs"] == "Ohm" and out["units"]["Z_phase"] == "deg"
    path = tmp_path / "spectrum.csv"
    path.write_text("f,Z_abs,Z_phase\n" + "".join(f"{f!r},{a!r},{p!r}\n" for f, a, p in
                                                    zip(out["f"], out["Z_abs"], out["Z_phase"])), encoding="utf-8")
    data = read_file(path)
    pred = _impedance_columns(predict_impedance({}, data, Strip(), "constant", NAFION_LI), data)
    np.testing.assert_allclose(data.measured["Z_abs"], pred["Z_abs"], rtol=1e-9)
    np.testing.assert_allclose(data.measured["Z_phase"], pred["Z_phase"], atol=1e-9)
    # and they are |Z| and arg Z of the Z_re, Z_im columns
    Z = np.array(out["Z_re"]) + 1j * np.array(out["Z_im"])
    np.testing.assert_allclose(out["Z_phase"], np.degrees(np.angle(Z)), atol=1e-12)


def test_freq_bias_beyond_the_validated_range_is_flagged_and_capped(capsys):
    """A bias past settings.VALIDATED_VOLTAGE is a model assumption: the spectrum is kept, finite, with
    check_voltage false and a warning naming the limit; past MAX_DRIVE_VOLTAGE (where the kernels are
    not checked finite) it is refused in one line, exit 2, as a drive's voltage is."""
    from ipmc_asym.base.settings import MAX_DRIVE_VOLTAGE, VALIDATED_VOLTAGE

    assert main(["freq", "--from", "1Hz", "--to", "10Hz", "--points", "2", f"--voltage={-MAX_DRIVE_VOLTAGE}V",
                 "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["check_voltage"] is False
    assert any("VALIDATED_VOLTAGE" in n for n in doc["notes"])
    assert np.all(np.isfinite(doc["Z_re"])) and np.all(np.isfinite(doc["w_amp"]))
    assert main(["freq", "--from", "1Hz", "--to", "10Hz", "--points", "2", f"--voltage={VALIDATED_VOLTAGE}V",
                 "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["check_voltage"] is True
    assert main(["freq", "--from", "1Hz", "--to", "10Hz", "--points", "2", "--voltage=1e5V"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    # refused where the strip is built, by the cap every entry holds (the option's name leads the line)
    assert len(err) == 1 and "error: voltage" in err[0] and "|phi0| up to" in err[0]
