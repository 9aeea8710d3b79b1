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
                 "--out", str(f)]) == 0
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
    assert main(["drive", "--waveform", "triangle:1V@5Hz", "--duration", "0.1s", "--points", "201", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert len(out["w"]) == 201 and out["resonances"]["clamped-free"][0] == pytest.approx(22.55, rel=1e-3)
    assert any("Darcy" in n for n in out["notes"])
    assert main(["step", "--model", "all", "--points", "5", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert set(out["models"]) == {"constant", "linear", "affine"}
    assert all(len(v["w"]) == 5 for v in out["models"].values())
    assert any("Darcy" in n for n in out["notes"])


def test_freq_bias_and_beam(capsys):
    assert main(["freq", "--from", "10Hz", "--to", "40Hz", "--points", "3", "--method", "circuit", "--voltage", "0.5V",
                 "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["voltage"] == 0.5 and out["beam"] == "dynamic" and len(out["F_amp"]) == 3
    assert any("Darcy" in n for n in out["notes"])


@pytest.mark.parametrize("args,word", [
    (["drive", "--waveform", "sin:1V@1Hz", "--duration", "1s"], "--waveform"),
    (["drive", "--waveform", "sine:1V@1Hz", "--duration", "10s", "--points", "100"], "points"),
    (["drive", "--waveform", "sine:1V@1Hz", "--duration", "1s", "--points", "2e6", "--json"], "--json"),
    (["drive", "--waveform", "sine:1V@1Hz", "--duration", "1s", "--viscous-modulus", "-1"], "viscous"),
    (["freq", "--from", "1Hz", "--to", "10Hz", "--voltage", "0.5V"], "circuit"),
])
def test_bad_input_exit_2_one_line(args, word, capsys):
    with pytest.raises(SystemExit) as ei:
        raise SystemExit(main(args))
    assert ei.value.code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and word in err[0]
