"""``sense``: the rows of the library, units of the curvature, the load choices, refusals in one
line with exit 2, and the CSV/NetCDF outputs written whole."""

from __future__ import annotations

import csv
import json

import pytest

import ipmc_asym as ia
from ipmc_asym.cli import main


def _run(capsys, *argv):
    try:
        rc = main(["sense", *argv])
    except SystemExit as exc:  # argparse's own refusals (cli.common.Parser: one line, status 2)
        rc = exc.code
    cap = capsys.readouterr()
    return rc, cap.out, cap.err


def test_json_rows_are_the_library(capsys):
    rc, out, err = _run(capsys, "--tip-displacement", "1mm", "--support", "tip-force", "--model", "linear", "--json")
    assert rc == 0 and err == ""
    row = json.loads(out)["results"][0]
    r = ia.sense(ia.NOMINAL_STRIP, tip_displacement=1e-3, support="tip-force", model="linear")
    assert row["Q"] == float(r.Q[0]) and row["V_oc"] == float(r.V_oc[0]) and row["valid"] is True
    assert row["curvature"] == pytest.approx(3e-3 / 0.02**2)


@pytest.mark.parametrize("text", ["2", "2/m", "2 /m", "2m^-1", "0.002/mm", "0.02cm^-1"])
def test_curvature_units(capsys, text):
    rc, out, _ = _run(capsys, "--curvature", text, "--model", "constant", "--json")
    assert rc == 0
    assert json.loads(out)["results"][0]["curvature"] == pytest.approx(2.0)


def test_negative_curvature_is_the_mirror(capsys):
    _, out_p, _ = _run(capsys, "--curvature", "2", "--model", "affine", "--json")
    _, out_m, _ = _run(capsys, "--curvature", "-2", "--model", "affine", "--json")
    p, m = json.loads(out_p)["results"][0], json.loads(out_m)["results"][0]
    assert m["Q"] == -p["Q"] and m["V_oc"] == -p["V_oc"]


@pytest.mark.parametrize("argv,needle", [
    (["--curvature", "2m"], "curvature: unknown unit 'm'"),
    (["--curvature", "2", "--load", "100ohm"], "--load R: after relaxation (DC) a resistive load carries no current"),
    (["--curvature", "2", "--load", "lots"], "--load must be short, open or a resistance"),
    (["--curvature", "2", "--nu", "0.6"], "--nu must be a drained Poisson ratio in [0, 0.5]"),
    (["--curvature", "1e4"], "curvature: (1 - 2 nu) |kappa| e/phi4"),
    (["--tip-displacement", "1mm", "--support", "pinned"], "argument --support: invalid choice"),
    (["--curvature", "2", "--tip-displacement", "1mm"], "not allowed with argument"),
    ([], "one of the arguments --curvature --tip-displacement --waveform is required"),
    (["--curvature", "2", "--out", "x.xlsx"], "allowed: .csv, .nc"),
])
def test_refusals_one_line_exit_2(capsys, argv, needle):
    rc, out, err = _run(capsys, *argv)
    assert rc == 2 and out == ""
    assert len(err.strip().splitlines()) == 1 and needle in err, err


def test_past_the_limits_is_kept_and_flagged(capsys):
    rc, out, err = _run(capsys, "--curvature", "300", "--model", "linear", "--json")
    assert rc == 0
    row = json.loads(out)["results"][0]
    assert row["check_strain"] is False and row["check_beam_regime"] is False and row["valid"] is False
    assert "small-strain limit" in err and "quarter turn" in err


def test_open_load_leads_with_the_voltage(capsys):
    rc, out, _ = _run(capsys, "--curvature", "2", "--load", "open", "--model", "constant")
    assert rc == 0
    head = next(line for line in out.splitlines() if line.startswith("model"))
    assert head.index("V_oc") < head.index("Q [C]")


def test_csv_and_netcdf_outputs(capsys, tmp_path):
    f = tmp_path / "s.csv"
    rc, _, _ = _run(capsys, "--tip-displacement", "0.5mm", "--out", str(f))
    assert rc == 0
    with f.open() as fh:
        rows = list(csv.DictReader(fh))
    assert [r["model"] for r in rows] == ["constant", "linear", "affine"]
    r = ia.sense(ia.NOMINAL_STRIP, tip_displacement=0.5e-3, model="affine")
    assert float(rows[2]["Q"]) == float(r.Q[0])
    xr = pytest.importorskip("xarray")
    g = tmp_path / "s.nc"
    try:
        rc, _, err = _run(capsys, "--tip-displacement", "0.5mm", "--out", str(g))
    except ImportError:
        pytest.skip("no NetCDF engine")
    assert rc == 0, err
    with xr.open_dataset(g) as ds:
        assert list(ds["model"].values) == ["constant", "linear", "affine"]
        assert float(ds["Q"].sel(model="affine")[0]) == float(r.Q[0])
        assert ds["Q"].attrs["units"] == "C"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.csv", "s.csv.json", "s.nc"]  # the CSV with its strip beside it


# ---- --waveform: the time domain -----------------------------------------------------------------

def test_waveform_json_rows_are_the_library(capsys):
    rc, out, err = _run(capsys, "--waveform", "sine:1mm@5mHz", "--duration", "400s", "--points", "41",
                        "--support", "tip-force", "--model", "linear", "--load", "1kOhm", "--json")
    assert rc == 0 and err == ""
    doc = json.loads(out)
    r = ia.sensing_transient("sine:1mm@5mHz", 400.0, 41, model="linear", load=1e3, support="tip-force")
    rows = doc["results"]
    assert len(rows) == 41 and doc["inputs"]["load"] == 1000.0
    assert [x["Q"] for x in rows] == r.Q.tolist() and [x["power"] for x in rows] == r.power.tolist()
    assert doc["summary"]["linear"]["error"] == r.error


def test_waveform_table_columns(capsys):
    rc, out, _ = _run(capsys, "--waveform", "step:1mm", "--duration", "2s", "--points", "5", "--model", "constant",
                      "--load", "open")
    assert rc == 0 and "V [V]" in out and "Q [C]" not in out and "stated relative error" in out
    rc, out, _ = _run(capsys, "--waveform", "step:1mm", "--duration", "2s", "--points", "5", "--model", "constant",
                      "--load", "470ohm")
    assert rc == 0 and all(h in out for h in ("Q [C]", "V [V]", "I [A]", "power [W]", "mean power"))


def test_waveform_csv(capsys, tmp_path):
    p = tmp_path / "s.csv"
    rc, _, _ = _run(capsys, "--waveform", "step:1mm", "--duration", "1s", "--points", "11", "--out", str(p))
    assert rc == 0
    with p.open(newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert len(rows) == 33 and {r["model"] for r in rows} == {"constant", "linear", "affine"}
    r = ia.sensing_transient("step:1mm", 1.0, 11, model="affine")  # the one default support
    got = [float(x["Q"]) for x in rows if x["model"] == "affine"]
    assert got == r.Q.tolist()


@pytest.mark.parametrize("argv,needle", [
    (["--waveform", "step:1mm"], "--waveform needs --duration"),
    (["--waveform", "step:1V", "--duration", "1s"], "unknown unit"),
    (["--waveform", "step:1mm", "--duration", "1s", "--points", "2000001"], "--points must be at most"),
    (["--waveform", "step:1mm", "--duration", "1s", "--points", "200001", "--json"], "--json holds every row"),
    (["--waveform", "step:1mm", "--duration", "-1s"], "--duration must be > 0"),
    (["--waveform", "step:1mm", "--duration", "1s", "--load", "-5ohm"], "--load must be short, open or a resistance > 0"),
    (["--waveform", "step:1mm", "--duration", "1s", "--fidelity", "bvp"], "--fidelity is not read with --waveform"),
    (["--waveform", "step:5m", "--duration", "1s"], "a face would lose all its water"),
    (["--waveform", "sine:1mm@100Hz", "--duration", "1e4s", "--points", "10001"], "steps over the duration"),
    (["--curvature", "2", "--duration", "1s"], "--duration needs --waveform"),
])
def test_waveform_refusals_one_line_exit_2_and_no_file(capsys, tmp_path, argv, needle):
    p = tmp_path / "never.csv"
    rc, out, err = _run(capsys, *argv, "--out", str(p))
    assert rc == 2 and out == ""
    assert len(err.strip().splitlines()) == 1 and needle in err, err
    assert not p.exists() and list(tmp_path.iterdir()) == []


def test_time_domain_with_a_load_prints_no_nan_mean_power(capsys):
    """Too few rows in the power's window: the mean power is not computed; the text says n/a
    and a note says why, as the JSON's null does."""
    assert main(["sense", "--waveform", "step:1mm", "--duration", "1s", "--points", "5", "--model", "constant",
                 "--load", "10kOhm"]) == 0
    out = capsys.readouterr().out
    import re

    assert not re.search(r"(?<![A-Za-z_])nan(?![A-Za-z_])", out, re.I)  # ("Donnan" is a word)
    assert "mean power n/a W" in out and "mean power not computed" in out


@pytest.mark.parametrize("extra", [[], ["--waveform", "sine:1mm@1Hz", "--duration", "1s", "--points", "5"]])
def test_sense_csv_has_its_strip_beside_it(tmp_path, capsys, extra):
    """The CSV keeps its columns; the strip (total and half thickness) and notes go in F.csv.json."""
    import json

    out = tmp_path / "s.csv"
    args = ["sense", "--thickness", "150um", "--out", str(out)] + (extra or ["--curvature", "2/m"])
    assert main(args) == 0
    assert capsys.readouterr().out.rstrip().endswith(f"wrote {out} and {out}.json")
    meta = json.loads((tmp_path / "s.csv.json").read_text())
    assert meta["inputs"]["thickness_total"] == 150e-6 and meta["inputs"]["half_thickness_e"] == 75e-6
    assert meta["notes"]


def test_sense_gives_the_model_form_spread(capsys):
    assert main(["sense", "--tip-displacement", "1mm", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    q = [r["Q"] for r in doc["results"]]
    s = doc["model_spread"]["Q"]
    assert (s["min"], s["max"]) == (min(q), max(q)) and s["ratio"] == pytest.approx(max(map(abs, q)) / min(map(abs, q)))
    assert main(["sense", "--tip-displacement", "1mm", "--model", "constant", "--json"]) == 0
    assert "model_spread" not in json.loads(capsys.readouterr().out)  # one model: no spread to give
