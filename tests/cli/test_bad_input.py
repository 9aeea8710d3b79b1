"""Bad input on the command line: one line naming the option and what it allows, exit 2, and no
NumPy warning printed before it (the commands run with NumPy's default floating-point warnings)."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest
from references import REPO

from ipmc_asym.cli import main

EXAMPLES = Path(REPO) / "examples"


def _refused(capsys, argv):
    """The one line of a refusal (exit 2), with no RuntimeWarning raised on the way."""
    with np.errstate(all="warn", under="ignore"), warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            rc = main(argv)
        except SystemExit as exc:  # argparse's own refusals (one line, status 2)
            rc = exc.code
    err = capsys.readouterr().err
    numeric = [str(w.message) for w in caught if issubclass(w.category, RuntimeWarning)]
    assert not numeric, numeric
    # a warning, or the one-off line that the kernels compile (a cold cache), is not the refusal
    lines = [ln for ln in err.splitlines() if ln.strip() and not ln.startswith(
        ("ipmc-asym: warning:", "ipmc-asym: compiling", "ipmc_asym: compiling"))]
    assert rc == 2 and len(lines) == 1, err
    assert "Warning" not in err and "Traceback" not in err
    return lines[0]


@pytest.mark.parametrize("argv, named", [
    (["step", "--diffusion", "1e308"], "--diffusion must be a finite number within 1e-30..1e+10 m^2/s"),
    (["step", "--diffusion", "1e-320"], "--diffusion must be a finite number within 1e-30..1e+10 m^2/s"),
    (["estimate", "--c-moy", "1e-320"], "--c-moy must be a finite number within 0.001..1e+08 mol/m^3"),
    (["charge", "--c-moy", "1e12"], "--c-moy must be a finite number within 0.001..1e+08 mol/m^3"),
    (["step", "--sheet-resistance", "1e308"], "--sheet-resistance must be within 0..1e+12 Ohm/sq"),
    (["drive", "--waveform", "step:1V", "--duration", "1s", "--sheet-resistance", "1e13"],
     "--sheet-resistance must be within 0..1e+12 Ohm/sq"),
])
def test_a_diffusion_coefficient_or_concentration_out_of_range_names_the_option(capsys, argv, named):
    assert named in _refused(capsys, argv)


def test_the_ends_of_the_diffusion_range_run(capsys):
    for d in ("1e-30", "1e10"):
        assert main(["step", "--diffusion", d, "--points", "3", "--tol", "none", "--json"]) == 0
    capsys.readouterr()


@pytest.mark.parametrize("argv, named", [
    (["step", "--duration", "1e308"], "duration is too long for the reduced model's fixed substeps"),
    (["step", "--duration", "1e308", "--fidelity", "pnp"], "duration: the transient PNP runs at most 1e+12 diffusion "
                                                           "times e^2/D (1e+14 s here, 2.96e+15 tau"),
    (["sense", "--curvature", "1e308"], "curvature: |value| up to 1e+09 1/m allowed"),
    (["sense", "--tip-displacement", "1e308"], "tip_displacement: |value| up to 1000 m allowed"),
    (["sense", "--curvature", "1e308", "--nu", "0.5", "--length", "10m"], "curvature: |value| up to"),
    (["sense", "--waveform", "step:1e308m", "--duration", "1s", "--nu", "0.5"], "waveform: a peak tip displacement"),
    (["sense", "--waveform", "sine:1mm@1Hz", "--duration", "1e308"], "needs over 1e300 steps"),
])
def test_a_refusal_comes_without_numpy_warnings_before_it(capsys, argv, named):
    assert named in _refused(capsys, argv)


@pytest.mark.parametrize("line, named", [('voltage = "1e308V"', "voltage: |phi0| up to 1000 V allowed"),
                                         ('voltages = ["1V", "2kV"]', "voltages[1]: |phi0| up to 1000 V"),
                                         ('voltage = "1V"\n[strip]\nthickness = "1e308m"',
                                          "strip.thickness must be at most 1000 m")])
def test_a_scene_past_a_cap_is_refused_by_its_key_before_any_rung_runs(tmp_path, capsys, line, named):
    p = tmp_path / "s.toml"
    p.write_text(f'name = "x"\nmodel = "constant"\n{line}\n', encoding="utf-8")
    assert named in _refused(capsys, ["scene", str(p)])


@pytest.mark.parametrize("argv, flag, ceiling", [
    (["sweep", "--vary", "length=1cm:2cm:3", "--max-rows", "1e12"], "--max-rows", "1e+09"),
    (["fit", str(EXAMPLES / "dynamic_step.csv"), "--free", "diffusion", "--max-rows", "1e12"], "--max-rows", "1e+06"),
    (["uq", str(EXAMPLES / "uq_nominal.toml"), "--max-samples", "1e300"], "--max-samples", "1e+09"),
    (["uq", str(EXAMPLES / "uq_nominal.toml"), "--max-store-samples", "1e12"], "--max-store-samples", "2e+07"),
    (["fit", str(EXAMPLES / "dynamic_step.csv"), "--free", "diffusion", "--max-multistart", "1e9"],
     "--max-multistart", "10000"),
    (["figures", "--out", "{tmp}/figs", "--max-dpi", "1e9"], "--max-dpi", "2400"),
    (["step", "--max-points", "1e9"], "--max-points", "1e+06"),
    (["freq", "--from", "1Hz", "--to", "2Hz", "--max-points", "1e9"], "--max-points", "1e+06"),
])
def test_a_settable_cap_has_a_ceiling(tmp_path, capsys, argv, flag, ceiling):
    line = _refused(capsys, [a.replace("{tmp}", str(tmp_path)) for a in argv])
    assert f"{flag} must be an integer from 1 to {ceiling} (the ceiling of this cap" in line, line


def test_a_ramp_time_below_the_floor_is_refused_naming_the_term(capsys):
    line = _refused(capsys, ["drive", "--waveform", "ramp:1V/1e-320s", "--duration", "1s"])
    assert "waveform term 'ramp:1V/1e-320s': the ramp time TR must be at least 1e-12 s" in line, line
    line = _refused(capsys, ["step", "--duration", "1e-320"])
    assert "--duration must be at least 1e-12 s" in line, line


def test_a_material_file_of_an_unknown_schema_is_refused(tmp_path, capsys):
    text = (Path(REPO) / "ipmc_asym" / "materials" / "nafion-117-h.toml").read_text(encoding="utf-8")
    p = tmp_path / "m.toml"
    p.write_text(text.replace("\nschema = 1\n", "\nschema = 99\n"), encoding="utf-8")
    for argv in (["materials", str(p)], ["estimate", "--material", str(p)]):
        assert "schema = 99 is not supported; supported: 1" in _refused(capsys, argv)


@pytest.mark.parametrize("argv, said", [
    (["drive", "--voltage", "1.5V"], "drive takes its voltage in --waveform (e.g. --waveform step:1.5V"),
    (["estimate", "--voltage", "nan"], "cannot read 'nan' as a voltage: a finite number with one of the units"),
    (["estimate", "--thickness", "abc"], "cannot read 'abc' as a length: a finite number with one of the units"),
])
def test_a_refusal_says_what_to_write_instead(capsys, argv, said):
    assert said in _refused(capsys, argv)


@pytest.mark.parametrize("voltage", ["1", "-1"])
def test_profiles_a_bvp_that_diverges_is_refused_with_the_debye_length(capsys, voltage):
    # 100 nm at C_moy 10 mol/m^3 is 0.012 Debye lengths: the affine solve diverges (b = ln B1 ~ 1e10)
    line = _refused(capsys, ["profiles", "--c-moy", "10", "--thickness", "100nm", "--model", "affine",
                             "--voltage", voltage])
    assert "BVP for the affine profiles did not converge" in line, line
    assert "0.0119 Debye lengths" in line and "a thickness, C_moy or voltage nearer the nominal" in line, line


@pytest.mark.parametrize("command", [["step"], ["drive", "--waveform", "step:1V", "--duration", "1s"]])
def test_an_underresolved_line_names_line_segments_and_its_doubled_line_consistently(capsys, command):
    line = _refused(capsys, command + ["--sheet-resistance", "2.5", "--diffusion", "1e-8"])
    assert ("with line_segments = 16 (the reported line of 32 segments against the 16 of its error estimate); "
            "raise line_segments (--line-segments on the command line) above 16, at most 512") in line, line


@pytest.mark.parametrize("size", ["2GiB", "1.5GB", "1e300"])
def test_the_input_size_cap_has_a_ceiling(capsys, size):
    line = _refused(capsys, ["scene", str(EXAMPLES / "uq_nominal.toml"), "--max-input-size", size])
    assert ("--max-input-size must be a size from 1 to 1073741824 bytes (1 GiB; the ceiling of this cap: memory "
            f"stays bounded); got '{size}'") in line, line


def test_the_input_size_cap_runs_at_its_ceiling(capsys):
    assert main(["scene", str(EXAMPLES / "uq_nominal.toml"), "--max-input-size", "1GiB", "--json"]) == 0
    capsys.readouterr()


@pytest.mark.parametrize("argv", [["sense", "--waveform", "sine:1mm@1Hz", "--duration", "1s", "--points", "1e308"],
                                  ["drive", "--waveform", "step:1V", "--duration", "1s", "--points", "1e308"]])
def test_points_past_the_cap_is_said_as_a_number_not_300_digits(capsys, argv):
    line = _refused(capsys, argv)
    assert line.endswith("; got 1e+308"), line
