"""``ipmc-asym drive`` and the dynamic options of step/freq as a user runs them."""

import csv
import json

import pytest

from ipmc_asym.cli import main


def test_drive_csv_streamed(tmp_path, capsys):
    f = tmp_path / "d.csv"
    assert main(["drive", "--waveform", "dc:0.2V+sine:0.5V@10Hz", "--duration", "0.2s", "--points", "801",
                 "--out", str(f)]) == 0
    rows = list(csv.reader(f.read_text().splitlines()))
    assert rows[0][0].startswith("# drive dc:0.2V+sine:0.5V@10Hz") and "Darcy" in ",".join(rows[0])
    assert rows[1] == ["t", "phi0", "sigma", "current_density", "layer_voltage", "M_A", "theta", "w", "F_block"]
    assert len(rows) == 803 and float(rows[-1][0]) == pytest.approx(0.2)
    assert float(rows[2][1]) == pytest.approx(0.2)
    assert not list(tmp_path.glob(".*part"))


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
