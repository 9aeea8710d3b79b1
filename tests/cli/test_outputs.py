"""Output files: the format from the extension, refused before the work, the same for every
output option; ``drive``'s sidecar ``F.csv.json`` never without its CSV."""

from __future__ import annotations

import os

import pytest
from references import REPO

from ipmc_asym.cli import drive as drive_cmd
from ipmc_asym.cli import main

DRIVE = ["drive", "--waveform", "step:1V", "--duration", "0.1s", "--points", "21", "--beam", "quasi-static"]


@pytest.mark.parametrize("name", ["d.xlsx", "d.nc", "d.txt", "d"])
def test_drive_out_format_from_extension(tmp_path, capsys, name):
    rc = main(DRIVE + ["--out", str(tmp_path / name)])
    err = capsys.readouterr().err
    assert rc == 2 and "allowed: .csv" in err and err.count("\n") == 1, err
    assert os.listdir(tmp_path) == []


def test_design_plot_refused_before_the_optimisation(tmp_path, capsys, monkeypatch):
    import ipmc_asym.cli.design as design_cmd

    def boom(spec):  # the work must not start
        raise AssertionError("the optimisation ran")

    monkeypatch.setattr(design_cmd, "design", boom)
    rc = main(["design", str(REPO / "examples" / "design_blocking_force.toml"), "--plot", str(tmp_path / "x.xlsx")])
    err = capsys.readouterr().err
    assert rc == 2 and "--plot" in err and ".png" in err, err


@pytest.mark.parametrize("argv", [["sweep", "--vary", "voltage=1V:2V:3"], ["validate"], ["figures"],
                                  ["uq", str(REPO / "examples" / "uq_nominal.toml")], ["profiles"], DRIVE])
def test_empty_out_refused_everywhere(argv, capsys):
    rc = main(argv + ["--out", ""])
    err = capsys.readouterr().err
    assert rc == 2 and "--out must be a path; got an empty string" in err, err


def test_drive_sidecar_written_after_the_csv(tmp_path, capsys, monkeypatch):
    """A failure while the CSV streams leaves neither the CSV nor the sidecar (nor a temporary file)."""
    out = tmp_path / "d.csv"
    real = drive_cmd._csv_rows
    calls = []

    def failing(chunk, columns=drive_cmd.COLUMNS):
        calls.append(1)
        if len(calls) > 1:
            raise OSError(28, "No space left on device")
        return real(chunk, columns)

    monkeypatch.setattr(drive_cmd, "_csv_rows", failing)
    rc = main(DRIVE[:-4] + ["--points", "50001", "--out", str(out)])  # chunks of 20000 rows
    err = capsys.readouterr().err
    assert rc == 2 and "d.csv" in err, err
    assert os.listdir(tmp_path) == []
    # and a run that succeeds writes both
    monkeypatch.setattr(drive_cmd, "_csv_rows", real)
    assert main(DRIVE + ["--out", str(out)]) == 0
    assert sorted(os.listdir(tmp_path)) == ["d.csv", "d.csv.json"]


@pytest.mark.parametrize("command", [["estimate"], ["charge"], ["freq", "--from", "1Hz", "--to", "10Hz", "--points", "4"]])
def test_one_document_out_is_the_json_document_or_its_rows(tmp_path, capsys, command):
    """``--out F.json`` holds what ``--json`` prints; ``--out F.csv`` its rows (one per model or
    frequency, the strip's total thickness named), the rest in ``F.csv.json``."""
    import csv
    import json

    def timeless(doc):  # each run's own CPU time aside
        for r in doc.get("results", ()):
            r.pop("seconds", None)
        return doc

    assert main(command + ["--json"]) == 0
    printed = timeless(json.loads(capsys.readouterr().out))
    assert main(command + ["--out", str(tmp_path / "r.json")]) == 0
    assert capsys.readouterr().out.rstrip().endswith(f"wrote {tmp_path / 'r.json'}")
    assert timeless(json.loads((tmp_path / "r.json").read_text())) == printed
    assert main(command + ["--out", str(tmp_path / "r.csv"), "--json"]) == 0
    assert timeless(json.loads(capsys.readouterr().out)) == printed  # stdout stays one JSON document
    with open(tmp_path / "r.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    meta = json.loads((tmp_path / "r.csv.json").read_text())
    if command[0] == "freq":
        assert [float(r["f"]) for r in rows] == printed["f"]
        assert [float(r["Z_phase"]) for r in rows] == printed["Z_phase"]
        assert meta["thickness_total"] == printed["thickness_total"] and "f" not in meta
    else:
        assert [r["model"] for r in rows] == [r["model"] for r in printed["results"]]
        key = "I" if command[0] == "estimate" else "sigma"
        assert [float(r[key]) for r in rows] == [r[key] for r in printed["results"]]
        assert {float(r["thickness_total"]) for r in rows} == {2.0e-4} and "results" not in meta


@pytest.mark.parametrize("command", ["estimate", "charge", "freq"])
def test_one_document_out_format_refused_before_the_work(tmp_path, capsys, command):
    argv = [command] + (["--from", "1Hz", "--to", "10Hz"] if command == "freq" else [])
    rc = main(argv + ["--out", str(tmp_path / "r.xlsx")])
    err = capsys.readouterr().err
    assert rc == 2 and "allowed: .json, .csv" in err and err.count("\n") == 1, err
    assert os.listdir(tmp_path) == []
