"""``fit`` on sensing data: the tip displacement imposed, the charge, current or voltage measured.

The files are written from ``ia.sensing_transient`` at known values (nu = 0.2, D = 2e-10 m^2/s, not
the fit's defaults or starts) with seeded noise of 5 % of each column's RMS and matching sigma_
columns; the fit must put the true values inside its 95 % profile intervals.  What is independent:
the truth is what the writer was given, the noise is drawn here.
"""

import json

import numpy as np
import pytest

import ipmc_asym as ia
from ipmc_asym.cli import main
from ipmc_asym.model.params import NAFION_LI
from ipmc_asym.studies.calibrate_dynamic import SensingData, fit, read_file

NU, D = 0.2, 2e-10
T = np.linspace(0.0, 200.0, 201)
#: a smooth bend and release (no slope at t = 0: the measured drive's first corner is no kick)
W = 0.5e-3 * (1.0 - np.cos(2.0 * np.pi * 0.01 * T))


def _write(path, load, columns, rel=0.05, seed=7):
    wav = path.parent / "w_truth.csv"
    np.savetxt(wav, np.c_[T, W], delimiter=",")
    r = ia.sensing_transient(f"csv:{wav}", float(T[-1]), T.size, material=NAFION_LI.with_(D=D), nu=NU, load=load)
    rng = np.random.default_rng(seed)
    data = {"t": T, "w": W}
    for c in columns:
        y = np.array(getattr(r, c), dtype=float)
        if c == "I":
            y[0] = np.nan  # the model's current at t = 0 holds the interpolated drive's first corner: not measured
        s = rel * float(np.sqrt(np.nanmean(y**2)))
        data[c] = y + s * rng.standard_normal(y.size)
        data[f"sigma_{c}"] = np.full(y.size, s)
    with open(path, "w") as fh:
        fh.write(",".join(data) + "\n")
        for i in range(T.size):
            fh.write(",".join("" if np.isnan(data[k][i]) else repr(float(data[k][i])) for k in data) + "\n")
    return path


def _inside(par, true):
    lo, hi = par["ci95"]
    return par["identifiable"] and lo <= true <= hi


def test_round_trip_short_circuit_charge_and_current(tmp_path):
    p = _write(tmp_path / "short.csv", "short", ("Q", "I"))
    d = read_file(p)
    assert isinstance(d, SensingData) and d.load == "short" and d.support == "tip-force"
    res = fit(p, "nu,D")
    nu, dd = res.parameters["nu"], res.parameters["diffusion"]
    assert _inside(nu, NU) and _inside(dd, D), (nu, dd)
    assert nu["ci95"][1] - nu["ci95"][0] < 0.02 and dd["ci95"][1] / dd["ci95"][0] < 1.05
    assert 0.5 < res.chi2_red < 1.5 and "sensing transient" in res.fidelity
    # the sensing model's water assumption, not the actuation circuit's
    assert "instantly redistributed" in res.message and "solvent is at rest" not in res.message


def test_open_circuit_voltage_sees_nu_and_D_not_c_moy(tmp_path):
    # V_oc = (RT/F) 2 [(1 - lam) b + (e^2/(3D)) db/dt]: the streaming term carries D, the amplitude
    # (1 - 2 nu); C_moy enters only through lam (~1e-4 here): not identifiable
    p = _write(tmp_path / "open.csv", "open", ("V",))
    res = fit(p, "nu,D,c_moy", load="open")
    assert _inside(res.parameters["nu"], NU) and _inside(res.parameters["diffusion"], D), res.parameters
    assert res.parameters["c_moy"]["status"] == "not_identifiable"


def test_cli_report_in_json(tmp_path, capsys):
    p = _write(tmp_path / "open.csv", "open", ("V",))
    png = tmp_path / "fit.png"
    # the file was written at the transient's default support (tip-force); the command's default is sense's (free)
    assert main(["fit", str(p), "--free", "nu,D", "--load", "open", "--support", "tip-force", "--json", "--no-progress",
                 "--plot", str(png)]) == 0
    assert png.stat().st_size > 0
    out = json.loads(capsys.readouterr().out)
    assert set(out["parameters"]) == {"nu", "diffusion"}
    assert _inside(out["parameters"]["nu"], NU)


@pytest.mark.parametrize("text, extra, what", [
    ("t,w\n0,0\n1,1e-4\n", [], "no measured column"),
    ("t,w,Q\n0,0,0\n1,1,1e-9\n", [], "w is in metres"),
    ("t,w,V\n0,0,0\n1,1e-4,1e-6\n", [], "needs its load"),
    ("t,w,Q\n0,0,0\n1,1e-4,1e-9\n", ["--load", "open"], "open circuit"),
    ("t,w,Q\n0,0,0\n1,1e-4,1e-9\n1.5,1e-4,1e-9\n2.2,1e-4,1e-9\n", [], "uniform grid"),
    ("t,w,Q\n0,0,0\n1,1e-4,1e-9\n", ["--waveform", "step:1V"], "carry their drive"),
])
def test_refusals_in_one_line_exit_2(tmp_path, capsys, text, extra, what):
    p = tmp_path / "bad.csv"
    p.write_text(text)
    assert main(["fit", str(p), "--free", "nu", *extra]) == 2
    err = capsys.readouterr().err
    assert what in err and len(err.strip().splitlines()) == 1, err


def test_a_parameter_sensing_does_not_see_is_refused(tmp_path, capsys):
    p = tmp_path / "s.csv"
    p.write_text("t,w,Q\n0,0,0\n1,1e-4,1e-9\n2,2e-4,2e-9\n")
    assert main(["fit", str(p), "--free", "modulus"]) == 2
    assert "do not depend on it" in capsys.readouterr().err
    with pytest.raises(ValueError, match="drained Poisson ratio"):
        fit(str(p), "D", nu=0.5)
    # the sensing settings on a file of another kind
    static = tmp_path / "static.csv"
    static.write_text("voltage,deflection\n0.5V,1mm\n")
    assert main(["fit", str(static), "--free", "modulus", "--load", "open"]) == 2
    assert "--load is for sensing data" in capsys.readouterr().err


def test_a_file_sense_wrote_round_trips_through_the_commands(tmp_path, capsys):
    # sense --waveform --out at its defaults (support free) and a 1 kOhm load; fit at its defaults
    wav = tmp_path / "w.csv"
    np.savetxt(wav, np.c_[T, W], delimiter=",")
    out = tmp_path / "s.csv"
    assert main(["sense", "--waveform", f"csv:{wav}", "--duration", "200s", "--points", "201", "--load", "1kOhm",
                 "--nu", "0.2", "--model", "constant", "--out", str(out)]) == 0
    capsys.readouterr()
    lines = out.read_text().splitlines()
    head = lines[0].split(",")
    rng = np.random.default_rng(11)
    vals = np.array([[float(x) for x in ln.split(",")[1:9]] for ln in lines[1:]])  # t .. power, after model
    rms = {c: float(np.sqrt(np.mean(vals[:, head.index(c) - 1] ** 2))) for c in ("Q", "V")}
    rows = ["t,w,Q,V"]
    for r in vals:
        q, v = (r[head.index(c) - 1] + 0.05 * rms[c] * rng.standard_normal() for c in ("Q", "V"))
        rows.append(",".join(repr(float(x)) for x in (r[0], r[1], q, v)))
    noisy = tmp_path / "noisy.csv"
    noisy.write_text("\n".join(rows) + "\n")
    assert main(["fit", str(noisy), "--free", "nu,D", "--load", "1kOhm", "--json", "--no-progress"]) == 0
    res = json.loads(capsys.readouterr().out)
    assert _inside(res["parameters"]["nu"], NU) and _inside(res["parameters"]["diffusion"], NAFION_LI.D), res
    # a file of several models is not one strip
    assert main(["sense", "--waveform", f"csv:{wav}", "--duration", "200s", "--points", "201", "--load", "1kOhm",
                 "--out", str(tmp_path / "all.csv")]) == 0
    assert main(["fit", str(tmp_path / "all.csv"), "--free", "nu", "--load", "1kOhm"]) == 2
    assert "several models" in capsys.readouterr().err
