"""The shared option types live in cli/common.py: no command imports another command's names, and the
solver option has one name (--solver) with each command's older name as an alias of the same dest."""

import ast
from pathlib import Path

import pytest

from ipmc_asym.cli import build_parser, main

CLI = Path(__file__).resolve().parents[2] / "ipmc_asym" / "cli"
SHARED = {"common", "__init__"}  # the modules every command may import from


def _cross_imports(path: Path):
    """(line, module, names) of the imports of ``path`` from another command module."""
    own = path.stem
    out = []
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.ImportFrom) and node.module and node.module.startswith("ipmc_asym.cli."):
            mod = node.module.split(".")[2]
            if mod not in SHARED and mod != own:
                out.append((node.lineno, node.module, [a.name for a in node.names]))
        elif isinstance(node, ast.Import):
            for a in node.names:
                parts = a.name.split(".")
                if a.name.startswith("ipmc_asym.cli.") and parts[2] not in SHARED and parts[2] != own:
                    out.append((node.lineno, a.name, []))
    return out


def test_the_scan_finds_a_cross_import(tmp_path):
    """The scan itself fails on the pattern it guards against."""
    f = tmp_path / "fit.py"
    f.write_text("from ipmc_asym.cli.drive import _waveform\nimport ipmc_asym.cli.freq\n"
                 "from ipmc_asym.cli.common import arg_type\n")
    assert [m for _, m, _ in _cross_imports(f)] == ["ipmc_asym.cli.drive", "ipmc_asym.cli.freq"]


def test_no_command_imports_another_command():
    bad = {p.name: hits for p in sorted(CLI.glob("*.py")) if (hits := _cross_imports(p))}
    assert not bad, f"commands importing other commands (shared options belong in cli/common.py): {bad}"


@pytest.mark.parametrize("command, old, value, dest", [
    ("step", "--fidelity", "pnp", "fidelity"),
    ("freq", "--method", "circuit", "method"),
    ("fit", "--time-fidelity", "pnp", "time_fidelity"),
])
def test_solver_option_and_its_alias_share_a_dest(command, old, value, dest):
    ap, _ = build_parser(command, {})
    need = {"step": [], "freq": ["--from", "1Hz", "--to", "2Hz"], "fit": ["d.csv", "--free", "modulus"]}[command]
    a = ap.parse_args([command, *need, "--solver", value])
    b = ap.parse_args([command, *need, old, value])
    assert getattr(a, dest) == getattr(b, dest) == value


@pytest.mark.parametrize("command, need", [
    ("step", []), ("drive", ["--waveform", "step:1V", "--duration", "1s"]), ("freq", ["--from", "1Hz", "--to", "2Hz"]),
])
def test_one_beam_default(command, need):
    from ipmc_asym.dynamics.entry import DEFAULT_BEAM
    from ipmc_asym.dynamics.reduction import transfer_function

    ap, _ = build_parser(command, {})
    assert ap.parse_args([command, *need]).beam == DEFAULT_BEAM == "quasi-static"
    # the export's library function: frequency_response's default beam
    import inspect

    from ipmc_asym.dynamics.circuit import frequency_response
    assert inspect.signature(frequency_response).parameters["beam"].default == DEFAULT_BEAM
    assert "beam" not in inspect.signature(transfer_function).parameters  # passed through to frequency_response


def test_phases_in_degrees_in_and_out(tmp_path, capsys):
    """freq writes phases in degrees; fit reads Z_phase in degrees (a value may say rad)."""
    import json

    import numpy as np

    from ipmc_asym.cli import main
    from ipmc_asym.dynamics.circuit import frequency_response
    from ipmc_asym.model.params import Strip
    from ipmc_asym.studies.calibrate_dynamic import read_file

    assert main(["freq", "--from", "1Hz", "--to", "10Hz", "--points", "3", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    r = frequency_response(np.geomspace(1.0, 10.0, 3), strip=Strip())
    assert out["units"]["w_phase"] == "deg" and np.allclose(out["w_phase"], np.angle(r.H_w) * 180 / np.pi, rtol=1e-14)
    deg, rad = tmp_path / "deg.csv", tmp_path / "rad.csv"
    deg.write_text("f,Z_abs,Z_phase\n1,100,-45\n10,50,-30\n")
    rad.write_text(f"f,Z_abs,Z_phase\n1,100,{-np.pi / 4!r}rad\n10,50,{-np.pi / 6!r}rad\n")
    a, b = read_file(str(deg), Strip()), read_file(str(rad), Strip())
    assert np.allclose(a.measured["Z_phase"], b.measured["Z_phase"], rtol=1e-14, atol=0)
    assert np.allclose(a.measured["Z_phase"], [-np.pi / 4, -np.pi / 6], rtol=1e-14)


def test_a_sweep_axis_of_bare_numbers_is_held_to_the_plausible_range(capsys, tmp_path):
    """--vary thickness=200:400:2 is 200 m to 400 m (a bare number is SI), as --thickness 200 is:
    the same one-line warning suggests the unit; an axis with units says nothing."""
    out = tmp_path / "s.csv"
    assert main(["sweep", "--vary", "thickness=200:400:2", "--fidelity", "leading", "--no-progress",
                 "--out", str(out)]) == 0
    err = capsys.readouterr().err
    assert err.count("--vary thickness 200 is read as 200 m") == 1 and "did you mean 200um?" in err
    assert main(["sweep", "--vary", "thickness=200um:400um:2", "--fidelity", "leading", "--no-progress",
                 "--out", str(out)]) == 0
    assert "read as" not in capsys.readouterr().err


def test_an_export_tolerance_without_export_is_said(capsys):
    from ipmc_asym.cli import main

    argv = ["freq", "--from", "1Hz", "--to", "10Hz", "--points", "2"]
    assert main(argv + ["--export-tol", "1e-3"]) == 0
    assert "--export-tol 0.001 is not used" in capsys.readouterr().err
    assert main(argv) == 0
    assert "is not used" not in capsys.readouterr().err
