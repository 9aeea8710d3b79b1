"""Round trips: the time series ``step --out`` and ``drive --out`` write are fitted by ``fit`` as they are.

The files are written by the commands (the reduced circuit, D = 3e-10 m^2/s, C_moy = 2900 mol/m^3,
not the defaults the fit starts from), 5 % relative noise is added to the measured columns, and
the fit must put the true values inside its 95 % intervals.  What is independent: the true
values are the ones the writing command was given, not anything the fit computed.
"""

import csv
import json

import numpy as np
import pytest

from ipmc_asym.cli import main

D_TRUE = 3e-10
C_TRUE = 2900.0
STRIP = ["--length", "1.5cm", "--width", "4mm", "--thickness", "180um"]


def _noisy(src, dst, columns, rel=0.05, seed=3):
    """The CSV ``src`` with ``rel`` x (the column's root mean square) x N(0, 1) added to ``columns``
    (the fit's noise model without sigma_ columns); every other cell as written."""
    with open(src, newline="") as fh:
        rows = list(csv.reader(fh))
    head = rows[0]
    rng = np.random.default_rng(seed)
    rms = {c: float(np.sqrt(np.mean([float(r[head.index(c)]) ** 2 for r in rows[1:]]))) for c in columns}
    for r in rows[1:]:
        for c in columns:
            j = head.index(c)
            r[j] = repr(float(r[j]) + rel * rms[c] * rng.standard_normal())
    with open(dst, "w", newline="") as fh:
        csv.writer(fh).writerows(rows)
    return head


def _inside(par, true):
    lo, hi = par["ci95"]
    return par["identifiable"] and lo <= true <= hi


def test_step_out_fitted_as_it_is(tmp_path, capsys):
    out = tmp_path / "step.csv"
    assert main(["step", *STRIP, "--points", "30", "--diffusion", "3e-10", "--c-moy", "2900",
                 "--voltage", "0.8V", "--out", str(out)]) == 0
    capsys.readouterr()
    noisy = tmp_path / "step_noisy.csv"
    head = _noisy(out, noisy, ("sigma", "current_density", "w"))
    # the file as step wrote it: per-area columns, the paper's signed w, the model's own columns
    assert {"phi0", "sigma", "current_density", "w", "M_A", "theta", "valid"} <= set(head)
    assert main(["fit", str(noisy), "--free", "diffusion,c_moy", *STRIP, "--json", "--no-progress"]) == 0
    res = json.loads(capsys.readouterr().out)
    assert res["n_points"] == 3 * 30 - 1  # the current at t = 0 (the step's jump) is not compared
    assert _inside(res["parameters"]["diffusion"], D_TRUE), res["parameters"]
    assert _inside(res["parameters"]["c_moy"], C_TRUE), res["parameters"]
    # the units and the sign are read right: a wrong area or sign would leave a noise scale far above 5 %
    assert res["noise_scale"] < 0.08


def test_step_out_other_strip_refused(tmp_path, capsys):
    """The per-area columns are totals only for the strip they are read with: the fit says so."""
    from ipmc_asym.model.params import Strip
    from ipmc_asym.studies.calibrate_dynamic import fit_dynamic, read_file

    p = tmp_path / "s.csv"
    p.write_text("t,phi0,sigma,current_density,w,valid\n0.001,1.0,1.0,100.0,-1e-4,True\n"
                 "0.002,1.0,2.0,50.0,-2e-4,True\n0.003,1.0,2.5,20.0,-2.5e-4,True\n")
    d = read_file(p, Strip(length=0.01, width=0.004))
    assert d.area == pytest.approx(4e-5)
    assert d.measured["charge"] == pytest.approx([4e-5, 8e-5, 1e-4])
    assert d.measured["deflection"] == pytest.approx([1e-4, 2e-4, 2.5e-4])
    with pytest.raises(ValueError, match="electrode area"):
        fit_dynamic([d], "diffusion", strip=Strip(length=0.02, width=0.004))
    many = tmp_path / "m.csv"
    many.write_text("model,t,phi0,sigma\nconstant,0.001,1.0,1.0\n")
    assert main(["fit", str(many), "--free", "diffusion"]) == 2
    err = capsys.readouterr().err
    assert "--model all" in err and err.count("\n") == 1


def test_drive_out_fitted_as_it_is(tmp_path, capsys):
    out = tmp_path / "drive.csv"
    assert main(["drive", *STRIP, "--waveform", "sine:0.5V@20Hz", "--duration", "0.05s", "--points", "80",
                 "--diffusion", "3e-10", "--out", str(out)]) == 0
    capsys.readouterr()
    # the fit drives the strip linearly between the rows' phi0: 80 rows a period keep that within 0.1 %
    noisy = tmp_path / "drive_noisy.csv"
    head = _noisy(out, noisy, ("current_density", "w"))
    # the blocked strip's force is another experiment than the free strip's deflection: keep one
    with open(noisy, newline="") as fh:
        rows = list(csv.reader(fh))
    keep = [j for j, h in enumerate(head) if h not in ("F_block", "sigma")]
    with open(noisy, "w", newline="") as fh:
        csv.writer(fh).writerows([[r[j] for j in keep] for r in rows])
    assert main(["fit", str(noisy), "--free", "D", *STRIP, "--json", "--no-progress"]) == 0
    res = json.loads(capsys.readouterr().out)
    assert _inside(res["parameters"]["diffusion"], D_TRUE), res["parameters"]
    assert res["noise_scale"] < 0.08
