"""One validity rule on the command line: the shared options' checks, and every command's
checks against the forward model's (numerical checks withhold, model assumptions flag).

References are independent of the code under test: the face strain ``e |M_A| / (E I_p)`` and
the rotation ``|M_A| L/(E I_p)`` from the printed moment, the documented limits.
"""

import json
import math
import textwrap

import numpy as np
import pytest

from ipmc_asym.base.settings import MIN_THICKNESS, STRAIN_LIMIT, VALIDATED_VOLTAGE
from ipmc_asym.cli import main
from ipmc_asym.forward.model import CHECKS
from ipmc_asym.model.params import NAFION_LI, Strip


def _one_line(err):
    lines = [ln for ln in err.strip().splitlines() if ln.strip()]
    assert len(lines) == 1 and "Traceback" not in err, err
    return lines[0]


@pytest.mark.parametrize("argv", [
    ["estimate"], ["charge"], ["step", "--points", "3"], ["profiles"], ["freq", "--from", "1Hz", "--to", "10Hz"],
])
def test_every_command_refuses_below_the_thickness_floor(argv, capsys):
    assert main(argv + ["--thickness", "50nm"]) == 2
    line = _one_line(capsys.readouterr().err)
    assert "thickness" in line and "MIN_THICKNESS" in line and f"{MIN_THICKNESS:g}" in line


def test_sweep_keeps_the_papers_blocking_force_flagged_by_strain(capsys):
    assert main(["sweep", "--vary", "voltage=0.5V:5V:10", "--model", "constant", "--json"]) == 0
    rows = json.loads(capsys.readouterr().out)["rows"]
    assert len(rows) == 10
    s = Strip()
    EI = NAFION_LI.E * s.I_p
    for r in rows:
        assert r["F_block"] is not None and r["F_block"] > 0 and r["I"] is not None
        strain = s.e * abs(r["M_A"]) / EI  # independent of the code's max_strain
        assert r["check_strain"] == (strain <= STRAIN_LIMIT)
        assert r["check_beam_regime"] == (abs(r["M_A"]) * s.length / EI <= math.pi / 2)
        assert r["valid"] == all(r["check_" + c] for c in CHECKS)
        # theta kept past a quarter turn; the tip position withheld past a full turn only
        assert r["theta"] is not None
        assert (r["w"] is None) == (abs(r["M_A"]) * s.length / EI > 2 * math.pi)
    assert sum(not r["check_strain"] for r in rows) == 7  # from 2 V, as the paper's own curves


def test_strain_limit_option_moves_the_strain_check(capsys):
    assert main(["estimate", "--voltage", "3V", "--model", "constant", "--json"]) == 0
    row = json.loads(capsys.readouterr().out)["results"][0]
    assert not row["checks"]["strain"] and row["F_block"] is not None and row["theta"] is not None
    assert any("strain limit 0.01" in w for w in row["warnings"])
    assert main(["estimate", "--voltage", "3V", "--model", "constant", "--strain-limit", "5%", "--json"]) == 0
    row5 = json.loads(capsys.readouterr().out)["results"][0]
    assert row5["checks"]["strain"] and row5["max_strain"] == row["max_strain"] < 0.05
    with pytest.raises(SystemExit) as ei:
        main(["estimate", "--strain-limit", "2"])
    assert ei.value.code == 2 and "--strain-limit" in _one_line(capsys.readouterr().err)


def test_step_huge_voltage_is_flagged_at_every_time_point(capsys):
    assert main(["step", "--voltage", "1kV", "--points", "5", "--tol", "none", "--json"]) == 0
    cap = capsys.readouterr()
    out = json.loads(cap.out)
    assert not any(out["valid"]) and not any(out["check_voltage"])
    assert not out["check_strain"][-1]  # charged: the face strain is far past its limit
    assert any(f"{VALIDATED_VOLTAGE:g} V" in w for w in out["warnings"]) and "step: warning" in cap.err
    # past a full turn the tip position is withheld (null), theta kept
    assert out["w"][-1] is None or not math.isfinite(out["w"][-1])
    assert math.isfinite(out["theta"][-1]) and abs(out["theta"][-1]) > 2 * math.pi


def test_step_and_estimate_agree_on_the_checks(capsys):
    """At steady state the step's layer voltage is the applied one: same numbers, same checks."""
    assert main(["step", "--voltage", "5V", "--model", "affine", "--points", "40", "--duration", "20s",
                 "--json"]) == 0
    st = json.loads(capsys.readouterr().out)
    assert main(["estimate", "--voltage", "5V", "--model", "affine", "--json"]) == 0
    est = json.loads(capsys.readouterr().out)["results"][0]
    assert st["theta"][-1] == pytest.approx(est["theta"], rel=1e-6)
    for c in CHECKS:
        assert st["check_" + c][-1] == est["checks"][c], c
    assert not est["checks"]["beam_regime"] and est["w"] is not None  # past a quarter turn: kept


def test_bare_number_and_implausible_inputs_warn_in_one_line(capsys):
    assert main(["estimate", "--thickness", "200", "--model", "constant", "--json"]) == 0
    cap = capsys.readouterr()
    warn = [ln for ln in cap.err.splitlines() if "warning" in ln]
    assert len(warn) == 1 and "200um" in warn[0] and "200 m" in warn[0]
    row = json.loads(cap.out)["results"][0]
    assert not row["checks"]["slender"] and any("L/2e" in w and ">= 10" in w for w in row["warnings"])
    assert main(["estimate", "--length", "100um", "--model", "constant", "--json"]) == 0
    row = json.loads(capsys.readouterr().out)["results"][0]
    assert not row["checks"]["slender"] and row["F_block"] is not None  # kept, flagged
    for d in ("1e10", "1e-30"):
        assert main(["step", "--diffusion", d, "--points", "3", "--json"]) == 0
        err = capsys.readouterr().err
        assert "--diffusion" in err and "plausible range" in err
    assert main(["estimate", "--modulus", "1Pa", "--model", "constant", "--json"]) == 0
    assert "material E = 1 Pa is outside the plausible range" in capsys.readouterr().err


def test_scene_rules_are_the_command_lines(tmp_path, capsys):
    f = tmp_path / "tol.toml"
    f.write_text('voltage = "1V"\ntolerance = 5\n')
    assert main(["scene", str(f)]) == 2
    line = _one_line(capsys.readouterr().err)
    assert "tolerance must be" in line and "(0, 1)" in line
    f = tmp_path / "bare.toml"
    f.write_text(textwrap.dedent('''
        voltage = "1V"
        outputs = ["rotation", "blocking_force"]
        [strip]
        thickness = 200
        [material]
        strain_limit = 0.05
    '''))
    assert main(["scene", str(f), "--json"]) == 0
    res = json.loads(capsys.readouterr().out)
    assert any("200um" in w for w in res["warnings"]) and any("L/2e" in w for w in res["warnings"])
    assert not res["checks"][0]["slender"] and res["outputs"]["blocking_force"]["values"][0] is not None


def test_uq_counts_samples_outside_and_writes_check_variables(tmp_path, capsys):
    xr = pytest.importorskip("xarray")
    sc = tmp_path / "u.toml"
    sc.write_text(textwrap.dedent('''
        model = "constant"
        voltage = "1V"
        tolerance = 1e-2
        outputs = ["rotation"]
        [uncertain]
        modulus = {dist = "lognormal", median = "130MPa", sigma = 0.4}
    '''))
    nc = tmp_path / "u.nc"
    assert main(["uq", str(sc), "--samples", "600", "--fidelity", "leading", "--json", "--out", str(nc)]) == 0
    cap = capsys.readouterr()
    out = json.loads(cap.out)
    n_out = out["n_outside_model"]
    assert n_out > 0 and out["n_used"] == out["n_samples"] - n_out and "--keep-invalid" in cap.err
    with xr.open_dataset(nc) as ds:
        for c in CHECKS:
            assert ("check_" + c) in ds and ds["check_" + c].dims == ("sample",)
        past = np.abs(ds["rotation"].values) > math.pi / 2  # independent: past a quarter turn
        assert np.array_equal(ds["check_beam_regime"].values == 0, past)
        assert int((ds["valid"].values == 0).sum()) == n_out == int(ds.attrs["n_outside_model"])
    assert main(["uq", str(sc), "--samples", "600", "--fidelity", "leading", "--json", "--keep-invalid"]) == 0
    kept = json.loads(capsys.readouterr().out)
    assert kept["n_used"] == kept["n_samples"] and kept["summary"]["rotation"]["n"] == kept["n_samples"]


@pytest.mark.parametrize("argv,name", [
    (["estimate", "--thickness", "200xx"], "thickness"),
    (["step", "--diffusion", "1e-10xx"], "diffusion"),
    (["step", "--sheet-resistance", "1Ohm"], "sheet-resistance"),
    (["drive", "--duration", "1xx"], "duration"),
])
def test_a_unit_refusal_names_its_option_once(argv, name, capsys):
    # argparse says "argument --NAME:"; the converter, which names its parameter for library
    # callers too, must not say "--NAME:" after it
    with pytest.raises(SystemExit) as ei:
        main(argv)
    line = _one_line(capsys.readouterr().err)
    assert ei.value.code == 2 and "unknown unit" in line
    said = line.split(f"argument --{name}: ", 1)[1]
    assert not said.startswith((f"--{name}", name)), line
