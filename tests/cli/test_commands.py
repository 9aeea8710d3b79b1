"""The command line as a user runs it: exit codes, JSON keys, units, one-line errors."""

import json
import subprocess
import sys

import pytest

from ipmc_asym.base.units import parse_length, parse_voltage
from ipmc_asym.bvp.solver import moment_integral_bvp
from ipmc_asym.cli import main
from ipmc_asym.integral.api import moment
from ipmc_asym.model.params import NAFION_LI, Strip

KEYS = {"model", "fidelity", "C_moy", "A0", "A1", "A2", "A3", "A5", "B1", "I", "M_A", "theta", "w", "w_small",
        "F_block", "F_block_small", "error_estimate", "seconds"}


def run(*args):
    return subprocess.run([sys.executable, "-m", "ipmc_asym", *args], capture_output=True, text=True, timeout=300)


@pytest.mark.parametrize("fid", ["leading", "corrected", "quadrature", "bvp"])
def test_estimate_json_all_models(fid, capsys):
    assert main(["estimate", "--fidelity", fid, "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["inputs"]["thickness_total"] == 200e-6 and out["inputs"]["half_thickness_e"] == 100e-6
    assert [r["model"] for r in out["results"]] == ["constant", "linear", "affine"]
    for r in out["results"]:
        assert KEYS <= set(r)
        assert r["C_moy"] == 3082.0
        # the BVP is the reference of the other rungs; the BVP rung is checked against the
        # compiled layer quadrature (an independent method, ~1e-13 at nominal)
        ref = (moment_integral_bvp(200e-6, 1.0, r["model"]) if fid != "bvp"
               else float(moment(200e-6, 1.0, r["model"], "quadrature").I))
        tol = {"leading": 5e-2, "corrected": 1e-8, "quadrature": 1e-8, "bvp": 1e-8}[fid]
        assert abs(r["I"] / ref - 1) < tol
        # paper's signs: positive voltage bends towards negative z
        assert r["M_A"] > 0 and r["theta"] < 0 and r["w"] < 0 and r["F_block"] > 0


def test_estimate_units_and_negative_voltage(capsys):
    assert main(["estimate", "--model", "constant", "--thickness", "0.2mm", "--length", "2 cm",
                 "--voltage=-1V", "--json"]) == 0
    r = json.loads(capsys.readouterr().out)["results"][0]
    assert r["I"] < 0 and r["w"] > 0


def test_table_says_which_thickness(capsys):
    assert main(["estimate"]) == 0
    out = capsys.readouterr().out
    assert "total thickness 2e = 200 µm" in out and "half thickness e = 100 µm" in out


@pytest.mark.parametrize("args,word", [
    (["--thickness=-3um"], "thickness"),
    (["--thickness", "0"], "thickness"),
    (["--voltage", "nan"], "voltage"),
    (["--model", "quadratic"], "model"),
    (["--fidelity", "exactly"], "fidelity"),
    (["--c-moy", "lots"], "c-moy"),
    (["--length", "3 furlongs"], "length"),
])
def test_bad_input_exit_2_one_line(args, word, capsys):
    # in process (the status main() returns, or argparse's exit): the same code path as the
    # command; the process's own exit status and stderr are checked once, below
    try:
        rc = main(["estimate", *args])
    except SystemExit as exc:
        rc = exc.code
    err = capsys.readouterr().err
    assert rc == 2
    assert "Traceback" not in err
    assert len(err.strip().splitlines()) == 1 and word in err


@pytest.mark.parametrize("args,word", [(["--thickness=-3um"], "thickness"), (["--model", "quadratic"], "model")])
def test_bad_input_exit_2_one_line_as_a_process(args, word):
    p = run("estimate", *args)
    assert p.returncode == 2
    assert "Traceback" not in p.stderr
    assert len(p.stderr.strip().splitlines()) == 1 and word in p.stderr


def test_zero_voltage_gives_zero_deflection(capsys):
    assert main(["estimate", "--voltage", "0", "--json"]) == 0
    for r in json.loads(capsys.readouterr().out)["results"]:
        assert r["I"] == 0 and r["w"] == 0 and r["theta"] == 0 and r["F_block"] == 0


def test_units_parse():
    assert parse_length("x", "200um") == pytest.approx(200e-6)
    assert parse_length("x", "200µm") == pytest.approx(200e-6)
    assert parse_length("x", "2 cm") == pytest.approx(0.02)
    assert parse_length("x", "0.02") == 0.02
    assert parse_voltage("x", "500mV") == pytest.approx(0.5)
    with pytest.raises(ValueError, match="x"):
        parse_length("x", "2 parsecs")


@pytest.mark.parametrize("kw,word", [(dict(phi4=1.0), "phi4"), (dict(phi4=0.0), "phi4"), (dict(E=-1), "modulus"),
                                     (dict(c_moy="magic"), "c_moy"), (dict(T=float("nan")), "temperature")])
def test_material_validation(kw, word):
    with pytest.raises(ValueError, match=word):
        NAFION_LI.with_(**kw)


@pytest.mark.parametrize("kw,word", [(dict(length=0), "length"), (dict(width=-1), "width"),
                                     (dict(thickness=float("inf")), "thickness"), (dict(voltage="x"), "voltage")])
def test_strip_validation(kw, word):
    with pytest.raises(ValueError, match=word):
        Strip(**kw)


def test_derive_check_cli(monkeypatch, tmp_path):
    """``derive --check`` runs the drift check of every generated module (``codegen.check()``, no
    selection) and exits with its status: 0 when the regenerated text is the file's, 1 on any
    difference.  The comparison itself runs here on one module; each module is compared to its
    derivation once, in tests/derivations/test_codegen.py."""
    import ipmc_asym_derivations.codegen as cg

    real, seen = cg.check, []

    def check(only=None):
        seen.append(only)
        return real(only)

    monkeypatch.setattr(cg, "check", check)
    exact = next(t for t in cg.TARGETS if t.name == "_generated_exact.py")
    monkeypatch.setattr(cg, "TARGETS", (exact,))
    assert main(["derive", "--check"]) == 0 and seen == [None]
    # the same module with one character changed on disk: the check fails
    changed = tmp_path / "kernels" / exact.name
    changed.parent.mkdir()
    changed.write_text(exact.path.read_text(encoding="utf-8").replace("GENERATED", "GENERATEd", 1), encoding="utf-8")
    monkeypatch.setattr(cg, "ROOT", tmp_path)
    monkeypatch.setattr(cg, "TARGETS", (exact._replace(path=changed),))
    assert main(["derive", "--check"]) == 1


def test_estimate_pressure_term(capsys):
    # the option against the BVP with the pressure term (an independent solver)
    from ipmc_asym.bvp.pressure import solve_pressure
    from ipmc_asym.model.groups import pressure_beta

    assert main(["estimate", "--model", "constant", "--pressure-term", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    row = out["results"][0]
    assert out["inputs"]["pressure_term"] is True and row["pressure_term"] is True
    assert row["fidelity_used"] == "exact"
    ref = solve_pressure(Strip(), "constant", NAFION_LI, beta=float(pressure_beta(NAFION_LI)))
    assert row["I"] == pytest.approx(ref.I, rel=1e-10)
    assert main(["estimate", "--pressure-term", "--fidelity", "leading", "--no-escalate"]) == 2
