"""``ipmc-asym drive`` and the dynamic options of step/freq as a user runs them."""

import csv
import json

import numpy as np
import pytest

from ipmc_asym.cli import main
from ipmc_asym.forward.model import CHECKS


def test_drive_csv_streamed(tmp_path, capsys):
    f = tmp_path / "d.csv"
    assert main(["drive", "--waveform", "dc:0.2V+sine:0.5V@10Hz", "--duration", "0.2s", "--points", "801",
                 "--tol", "none", "--out", str(f)]) == 0
    rows = list(csv.reader(f.read_text().splitlines()))
    meta = json.loads((tmp_path / "d.csv.json").read_text())  # the metadata beside the CSV
    assert meta["waveform"] == "dc:0.2V+sine:0.5V@10Hz" and any("Darcy" in n for n in meta["notes"])
    assert rows[0][:9] == ["t", "phi0", "sigma", "current_density", "layer_voltage", "M_A", "theta", "w", "F_block"]
    assert rows[0][9:] == [f"check_{c}" for c in CHECKS] + ["valid"]
    assert len(rows) == 802 and float(rows[-1][0]) == pytest.approx(0.2)
    assert float(rows[1][1]) == pytest.approx(0.2)
    assert all(r[-1] == "1" for r in rows[1:])  # a small drive: every time point inside the model
    assert not list(tmp_path.glob(".*part"))


def test_drive_flags_time_points_like_estimate(capsys):
    """A 5 V step on the affine strip: the drive's check columns are the forward model's at the
    layer voltage (estimate's checks at the same voltage), and the warnings name the limits."""
    from ipmc_asym.dynamics.drive import drive_response
    from ipmc_asym.forward.model import forward

    r = drive_response("step:5V", 1.0, 20, model="affine", beam="quasi-static")
    f = forward(0.02, 5e-3, 200e-6, r["layer_voltage"], model="affine", fidelity="corrected")
    for c in CHECKS:
        assert np.array_equal(r[f"check_{c}"].astype(bool), np.asarray(getattr(f, c), bool)), c
    assert main(["drive", "--waveform", "step:5V", "--duration", "1s", "--points", "20", "--model", "affine",
                 "--beam", "quasi-static"]) == 0
    err = capsys.readouterr().err
    assert "drive: warning:" in err and "strain" in err and "quarter" in err


def test_drive_json_and_step_model_all(capsys):
    assert main(["drive", "--waveform", "triangle:1V@5Hz", "--duration", "0.1s", "--points", "201", "--beam", "dynamic",
                 "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert len(out["w"]) == 201 and out["resonances"]["clamped-free"][0] == pytest.approx(22.55, rel=1e-3)
    assert any("Darcy" in n for n in out["notes"])
    assert main(["step", "--model", "all", "--points", "5", "--tol", "none", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert set(out["models"]) == {"constant", "linear", "affine"}
    assert all(len(v["w"]) == 5 for v in out["models"].values())
    assert any("Darcy" in n for n in out["notes"])


def test_freq_bias_and_beam(capsys):
    assert main(["freq", "--from", "10Hz", "--to", "40Hz", "--points", "3", "--method", "circuit", "--voltage", "0.5V",
                 "--beam", "dynamic", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["voltage"] == 0.5 and out["beam"] == "dynamic" and len(out["F_amp"]) == 3
    assert any("Darcy" in n for n in out["notes"])


@pytest.mark.parametrize("args,word", [
    (["drive", "--waveform", "sin:1V@1Hz", "--duration", "1s"], "--waveform"),
    (["drive", "--waveform", "sine:1V@1Hz", "--duration", "10s", "--points", "100", "--beam", "dynamic", "--tol", "none"],
     "points"),
    (["drive", "--waveform", "sine:1V@1Hz", "--duration", "1s", "--points", "2e6", "--json"], "--json"),
    (["drive", "--waveform", "sine:1V@1Hz", "--duration", "1s", "--viscous-modulus", "-1"], "viscous"),
    (["freq", "--from", "1Hz", "--to", "10Hz", "--voltage", "0.5V", "--method", "pnp-linear"], "circuit"),
])
def test_bad_input_exit_2_one_line(args, word, capsys):
    with pytest.raises(SystemExit) as ei:
        raise SystemExit(main(args))
    assert ei.value.code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and word in err[0]


def test_drive_and_step_with_a_sheet_resistance(tmp_path, capsys):
    from ipmc_asym.dynamics.drive import drive_response

    # 0 Ohm/sq is today's uniform strip, bit for bit
    base = ["drive", "--waveform", "step:0.5V", "--duration", "20ms", "--points", "41", "--beam", "quasi-static",
            "--tol", "none", "--json"]
    assert main(base) == 0
    a = json.loads(capsys.readouterr().out)
    assert main(base + ["--sheet-resistance", "0"]) == 0
    b = json.loads(capsys.readouterr().out)
    assert a == b and "sigma_error" not in b
    # the line: the library's rows, with their stated errors, in the CSV streamed by drive and by step --out
    f = tmp_path / "d.csv"
    assert main(base[:-1] + ["--sheet-resistance", "2.5ohm/sq", "--line-segments", "8", "--out", str(f)]) == 0
    capsys.readouterr()
    rows = list(csv.reader(f.read_text().splitlines()))
    r = drive_response("step:0.5V", 0.02, 41, beam="quasi-static", sheet_resistance=2.5, line_segments=8)
    assert rows[0][-2:] == ["sigma_error", "w_error"]
    assert np.allclose([float(x[rows[0].index("w")]) for x in rows[1:]], r["w"], rtol=1e-15, atol=0)
    g = tmp_path / "s.csv"
    step = ["step", "--voltage", "0.5V", "--duration", "20ms", "--points", "41", "--sheet-resistance", "2.5",
            "--line-segments", "8"]
    assert main(step + ["--out", str(g)]) == 0
    srows = list(csv.reader(g.read_text().splitlines()))
    assert np.allclose([float(x[srows[0].index("sigma")]) for x in srows[1:]], r["sigma"], rtol=1e-15, atol=0)
    assert json.loads((tmp_path / "s.csv.json").read_text())["sheet_resistance"] == 2.5
    assert main(step + ["--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert np.allclose(out["sigma_error"], r["sigma_error"], rtol=1e-15, atol=0)
    # step at 0 Ohm/sq: the same as without the option
    assert main(["step", "--points", "11", "--json"]) == 0
    s0 = json.loads(capsys.readouterr().out)
    assert main(["step", "--points", "11", "--json", "--sheet-resistance", "0"]) == 0
    s1 = json.loads(capsys.readouterr().out)
    assert {k: v for k, v in s0.items() if k != "seconds"} == {k: v for k, v in s1.items() if k != "seconds"}


@pytest.mark.parametrize("args, word", [
    (["drive", "--waveform", "step:1V", "--duration", "1s", "--points", "11", "--sheet-resistance", "2.5", "--beam",
      "dynamic"], "--points"),
    (["step", "--sheet-resistance", "2.5", "--fidelity", "pnp"], "fidelity pnp"),
    (["step", "--sheet-resistance", "2.5", "--tol", "1e-3"], "tol"),
    (["step", "--sheet-resistance", "-2ohm/sq"], "--sheet-resistance"),
    (["step", "--line-segments", "1000"], "--line-segments"),
])
def test_sheet_resistance_refusals_one_line(args, word, capsys):
    try:
        code = main(args)  # a refusal after parsing returns 2
    except SystemExit as e:  # the argument's own type check exits 2
        code = e.code
    assert code == 2
    err = capsys.readouterr().err.strip()
    assert word in err and len(err.splitlines()) == 1


def test_freq_and_drive_support_and_electrode(tmp_path, capsys):
    """--support clamped-clamped and --electrode add columns/keys (the default ones kept, in order); the
    quasi-static clamped-clamped reactions are the hand-derived statics (tests/references.py)."""
    from references import partial_electrode_statics

    from ipmc_asym.dynamics.drive import drive_response
    from ipmc_asym.model.params import NAFION_LI, Strip

    base = ["freq", "--from", "1Hz", "--to", "100Hz", "--points", "3", "--beam", "quasi-static", "--json"]
    assert main(base) == 0
    a = json.loads(capsys.readouterr().out)
    assert main(base + ["--support", "clamped-clamped", "--electrode", "2mm:12mm"]) == 0
    b = json.loads(capsys.readouterr().out)
    assert set(a) < set(b) and b["electrode"] == pytest.approx([0.002, 0.012]) and "clamped-clamped" in b["resonances"]
    assert b["Z_re"] == a["Z_re"]
    s = Strip()
    st = partial_electrode_statics(s.length, NAFION_LI.E * s.I_p, 0.002, 0.012)
    full = partial_electrode_statics(s.length, NAFION_LI.E * s.I_p, 0.0, s.length)
    HM = np.array(a["w_amp"]) / abs(full["w"])  # the moment per volt of the full strip
    for k in ("M_root", "M_tip", "F_root", "F_tip", "w_mid", "w", "theta", "F"):
        col = {"w": "w_amp", "theta": "theta_amp", "F": "F_amp"}.get(k, f"{k}_amp")
        assert np.allclose(b[col], HM * abs(st[k]), rtol=1e-10, atol=0), k
    # drive: the CSV's header keeps the default columns and appends the new ones; rows = the library's
    f = tmp_path / "d.csv"
    assert main(["drive", "--waveform", "step:0.5V", "--duration", "50ms", "--points", "201", "--support",
                 "clamped-clamped", "--electrode", "2mm:12mm", "--beam", "dynamic", "--out", str(f)]) == 0
    capsys.readouterr()
    rows = list(csv.reader(f.read_text().splitlines()))
    default = ["drive", "--waveform", "step:0.5V", "--duration", "50ms", "--points", "201", "--json"]
    assert main(default) == 0
    d = json.loads(capsys.readouterr().out)
    assert rows[0][-5:] == ["M_root", "M_tip", "F_root", "F_tip", "w_mid"] and all(c in rows[0] for c in d if
                                                                                     c in ("t", "w", "valid"))
    r = drive_response("step:0.5V", 0.05, 201, support="clamped-clamped", electrode=(0.002, 0.012), beam="dynamic")
    for c in ("w", "M_root", "F_tip", "w_mid"):
        assert np.allclose([float(x[rows[0].index(c)]) for x in rows[1:]], r[c], rtol=1e-15, atol=0), c
    side = json.loads((tmp_path / "d.csv.json").read_text())
    assert side["support"] == "clamped-clamped" and "M_root" in side["units"]


@pytest.mark.parametrize("args, word", [
    (["freq", "--from", "1Hz", "--to", "2Hz", "--electrode", "12mm:2mm"], "--electrode"),
    (["freq", "--from", "1Hz", "--to", "2Hz", "--electrode", "2mm:3cm"], "--electrode"),
    (["freq", "--from", "1Hz", "--to", "2Hz", "--electrode", "2mm"], "--electrode"),
    (["freq", "--from", "1Hz", "--to", "2Hz", "--support", "pinned"], "--support"),
    (["freq", "--from", "1Hz", "--to", "2Hz", "--support", "clamped-clamped", "--sheet-resistance", "2"],
     "--sheet-resistance"),
    (["freq", "--from", "1Hz", "--to", "2Hz", "--electrode", "0:1cm", "--export", "x.json"], "--export"),
    (["drive", "--waveform", "step:1V", "--duration", "1s", "--electrode", "0:1cm", "--sheet-resistance", "2.5"],
     "--sheet-resistance"),
    (["drive", "--waveform", "step:1V", "--duration", "1s", "--electrode", "-1mm:1cm"], "--electrode"),
])
def test_support_and_electrode_refusals_one_line(args, word, capsys):
    try:
        code = main(args)
    except SystemExit as e:
        code = e.code
    assert code == 2
    err = capsys.readouterr().err.strip()
    assert word in err and len(err.splitlines()) == 1


def test_drive_says_in_one_line_that_its_rows_state_no_error(capsys):
    """drive --tol none: the rows carry no circuit error (an arbitrary waveform is not bounded): one
    note line says so and where an error is stated (freq's small signal, --tol), in the text and in
    --json.  By default (--tol auto) the rows state it and no such note is printed."""
    from ipmc_asym.dynamics.drive import DRIVE_ERROR_NOTE

    base = ["drive", "--waveform", "sine:0.1V@5Hz", "--duration", "0.1s", "--points", "21", "--beam", "quasi-static"]
    assert main(base + ["--tol", "none"]) == 0
    lines = [ln for ln in capsys.readouterr().out.splitlines() if "no error of the reduced circuit" in ln]
    assert lines == [f"note: {DRIVE_ERROR_NOTE}"] and "--tol" in lines[0] and "freq" in lines[0]
    assert main(base + ["--tol", "none", "--json"]) == 0
    assert DRIVE_ERROR_NOTE in json.loads(capsys.readouterr().out)["notes"]
    assert main(base + ["--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["tol"] == 1e-2 and DRIVE_ERROR_NOTE not in d["notes"]
    assert all(np.all(np.isfinite(np.asarray(d[c], float))) for c in ("sigma_error", "w_error"))


def test_drive_with_a_tolerance_states_errors_that_hold_against_a_finer_pnp(capsys):
    """drive --tol: the circuit's rows with a stated error (against a PNP run over the same waveform);
    the error holds against an independent PNP run at a tolerance 100 times tighter (its own error
    added), and the circuit's rows are those of the streamed run (the same circuit) within it."""
    base = ["drive", "--waveform", "dc:0.2V+sine:1V@10Hz", "--duration", "0.1s", "--points", "21",
            "--beam", "quasi-static", "--json"]
    assert main(base + ["--tol", "1e-2"]) == 0
    c = json.loads(capsys.readouterr().out)
    assert c["fidelity"] == "circuit" and c["tol"] == 1e-2
    assert not any("no error of the reduced circuit" in n for n in c["notes"])
    assert main(base + ["--solver", "pnp", "--tol", "1e-4"]) == 0
    ref = json.loads(capsys.readouterr().out)
    assert ref["fidelity"] == "pnp"
    for k in ("sigma", "w"):
        v, e, r, re = (np.asarray(x, float) for x in (c[k], c[f"{k}_error"], ref[k], ref[f"{k}_error"]))
        assert np.all(np.isfinite(e)) and np.all(np.abs(v - r) <= e + re), k
        assert np.max(e) <= 1e-2 * np.max(np.abs(v)) or k == "w"  # sigma's bound meets the tolerance
    assert main(base + ["--tol", "none"]) == 0
    streamed = json.loads(capsys.readouterr().out)
    assert "sigma_error" not in streamed
    s, v, e = (np.asarray(x, float) for x in (streamed["sigma"], c["sigma"], c["sigma_error"]))
    assert np.all(np.abs(s - v) <= e)


@pytest.mark.parametrize("args,word", [
    (["--tol", "1e-2", "--points", "20002"], "--points"),
    (["--solver", "pnp", "--sheet-resistance", "2.5"], "sheet_resistance"),
    (["--tol", "1e-2", "--support", "clamped-clamped"], "tol"),
])
def test_drive_tolerance_refusals_before_the_work(args, word, capsys):
    try:
        code = main(["drive", "--waveform", "sine:1V@10Hz", "--duration", "0.1s"] + args)
    except SystemExit as e:
        code = e.code
    assert code == 2
    err = capsys.readouterr().err.strip()
    assert word in err and len(err.splitlines()) == 1


def test_drive_tol_auto_keeps_the_circuit_where_the_reference_refuses(capsys):
    """--tol auto as step's default: where the reference PNP run refuses the strip (layers filling 1 um
    at 20 V) the circuit's rows are printed without error columns and a note says why."""
    assert main(["drive", "--waveform", "sine:20V@10Hz", "--thickness", "1um", "--model", "linear",
                 "--duration", "2ms", "--points", "21", "--tol", "auto", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert "sigma_error" not in out and len(out["sigma"]) == 21
    assert any("reference PNP run refuses" in n for n in out["notes"])
