"""``ipmc-asym step --tol``: the rung that meets the tolerance, its error estimate, refusals."""

import csv
import json

import numpy as np
import pytest

from ipmc_asym.cli import main
from ipmc_asym.dynamics.circuit import time_constant, waveform
from ipmc_asym.dynamics.transient import solve_transient
from ipmc_asym.model.params import NAFION_LI, Strip


def test_step_tol_json_carries_the_error_estimate(capsys):
    assert main(["step", "--voltage", "1V", "--points", "6", "--tol", "1%", "--json"]) == 0
    cap = capsys.readouterr()
    out = json.loads(cap.out)
    assert out["fidelity"] == "circuit" and out["tol"] == 0.01 and out["valid_from"] == 0.0
    # the long part is said once, as it starts
    assert cap.err.count("a reference PNP run (tol 0.01)") == 1, cap.err
    sig, err = np.array(out["sigma"]), np.array(out["sigma_error"])
    assert np.all(err <= 0.01 * np.max(np.abs(sig)))
    # independent check: the PNP solver at its default tolerance
    ref = solve_transient(np.array(out["t"]), waveform("step", 1.0), Strip(), "constant", NAFION_LI, moment=False)
    assert np.all(np.abs(sig - ref.sigma) <= err + ref.sigma_error)


def test_step_tol_escalates_on_a_thin_affine_strip(tmp_path, capsys):
    f = tmp_path / "s.csv"
    tau = float(time_constant(20e-6, "affine"))
    assert main(["step", "--voltage", "2V", "--thickness", "20um", "--model", "affine", "--tol", "1e-2",
                 "--duration", f"{0.04 * tau}s", "--points", "5", "--out", str(f)]) == 0
    rows = list(csv.reader(f.read_text().splitlines()))
    meta = json.loads((tmp_path / "s.csv.json").read_text())
    assert meta["fidelity"] == "pnp" and "sigma_error" in rows[0]


@pytest.mark.parametrize("argv", [["--tol", "0"], ["--tol", "2"], ["--tol", "1e-9"]])
def test_step_tol_refusals_are_one_line(argv, capsys):
    try:
        rc = main(["step", "--points", "3", *argv])
    except SystemExit as ex:  # argparse's own refusal of a malformed value
        rc = ex.code
    assert rc == 2
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert "tol" in err and "Traceback" not in err


@pytest.mark.parametrize("argv", [["step", "--duration", "1e30"],
                                  ["drive", "--waveform", "sine:1V@1Hz", "--duration", "1e30"]])
def test_a_duration_past_the_substeps_is_refused_before_anything_is_said(argv, capsys):
    """The circuit's substep limit (2.5e4 tau) refuses 1e30 s: the refusal is the only line on
    stderr (the line saying that a reference PNP run starts is printed when it starts)."""
    assert main(argv) == 2
    err = capsys.readouterr().err
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert len(lines) == 1 and "fixed substeps" in lines[0], err


def test_step_csv_is_streamed_and_equals_the_in_memory_run(tmp_path):
    """step --out --tol none (circuit, quasi-static beam) is written chunk by chunk through drive_chunks:
    the same rows as the in-memory step_response (same circuit, same forward model and checks)."""
    from ipmc_asym.dynamics.circuit import step_response
    from ipmc_asym.model.params import Strip

    f = tmp_path / "s.csv"
    assert main(["step", "--voltage", "2V", "--points", "301", "--model", "affine", "--tol", "none", "--out", str(f)]) == 0
    rows = list(csv.reader(f.read_text().splitlines()))
    head, body = rows[0], rows[1:]
    r = step_response(2.0, strip=Strip(voltage=2.0), model="affine", points=301)
    for name, want in (("t", r.t), ("sigma", r.sigma), ("M_A", r.M_A), ("w", r.w), ("current_density", r.current_density)):
        got = np.array([float(x[head.index(name)]) for x in body])
        np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-12 * np.max(np.abs(want)), err_msg=name)
    got_valid = np.array([x[head.index("valid")] == "True" for x in body])
    assert np.array_equal(got_valid, r.valid)
    assert json.loads((tmp_path / "s.csv.json").read_text())["fidelity"] == "circuit"


def test_step_pnp_linear_model_reaches_the_exact_static_charge(capsys):
    """--fidelity pnp --model linear: the relaxed charge is the exact static one within the stated estimate."""
    from ipmc_asym.dynamics.electrode import charge

    assert main(["step", "--voltage=-1V", "--fidelity", "pnp", "--model", "linear", "--tol", "1e-6", "--points", "6",
                 "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["fidelity"] == "pnp" and out["model"] == "linear"
    sig, err = np.array(out["sigma"]), np.array(out["sigma_error"])
    ref = float(charge(Strip().thickness, -1.0, "linear", "exact").sigma)
    assert abs(sig[-1] - ref) <= err[-1] <= 1e-6 * abs(ref)


def test_step_pnp_all_models(capsys):
    assert main(["step", "--fidelity", "pnp", "--model", "all", "--points", "4", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert sorted(out["models"]) == ["affine", "constant", "linear"]
    for m, r in out["models"].items():
        assert r["fidelity"] == "pnp" and len(r["sigma"]) == 4 and all(np.isfinite(r["sigma"])), m


def test_step_tol_bounds_the_circuit_for_the_linear_model(capsys):
    assert main(["step", "--voltage", "0.5V", "--model", "linear", "--points", "6", "--tol", "1%", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    sig, err = np.array(out["sigma"]), np.array(out["sigma_error"])
    ref = solve_transient(np.array(out["t"]), waveform("step", 0.5), Strip(), "linear", NAFION_LI, moment=False)
    assert np.all(np.abs(sig - ref.sigma) <= err + ref.sigma_error)


def test_step_pnp_json_states_its_default_tolerance_and_errors(capsys):
    """Without --tol the pnp runs at its default tolerance: the JSON says which and carries the
    per-time errors of sigma and J; the errors bound the difference from an independent run at a
    tolerance ten times tighter."""
    tau = float(time_constant(Strip().thickness))
    assert main(["step", "--voltage", "0.5V", "--fidelity", "pnp", "--points", "6", "--duration", f"{2 * tau}s",
                 "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["tol"] == 1e-6
    sig, err = np.array(out["sigma"]), np.array(out["sigma_error"])
    J, jerr = np.array(out["current_density"]), np.array(out["current_error"])
    ref = solve_transient(np.array(out["t"]), waveform("step", 0.5), Strip(), "constant", NAFION_LI, moment=False,
                          tol=1e-7)
    assert np.all(np.abs(sig - ref.sigma) <= err + ref.sigma_error)
    assert np.all(np.abs(J - ref.current_density) <= jerr + ref.current_error)
    assert np.all(err <= 1e-6 * np.max(np.abs(sig)))


@pytest.mark.parametrize("extra, said", [
    (["--waveform", "sine:1V@10Hz", "--voltage", "3V"], 1),
    (["--waveform", "sine:1V@10Hz", "--voltage", "1V"], 1),  # given, though equal to the default
    (["--waveform", "sine:1V@10Hz"], 0),
    (["--voltage", "3V"], 0),
])
def test_a_voltage_the_waveform_overrides_is_said(capsys, extra, said):
    assert main(["step", "--duration", "0.01", "--points", "3", "--tol", "none", *extra]) == 0
    err = capsys.readouterr().err
    assert err.count("--voltage") == said and err.count("is not used: --waveform sets the voltage") == said
