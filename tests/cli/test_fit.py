"""``ipmc-asym fit`` and ``ipmc-asym uq`` as a user runs them: JSON keys, files, one-line errors."""

import json
import os

import numpy as np
import pytest
from references import REPO

from ipmc_asym.cli import main
from ipmc_asym.forward.estimate import evaluate
from ipmc_asym.model.params import NAFION_LI, Strip

ROOT = str(REPO)


@pytest.fixture(scope="module")
def data_csv(tmp_path_factory):
    """Deflection and force of a strip with E = 90 MPa, C_moy = 2900 (quadrature), 2 % noise."""
    mat = NAFION_LI.with_(E=9e7, c_moy=2900.0)
    rng = np.random.default_rng(5)
    lines = ["voltage,thickness,deflection,blocking_force,sigma_deflection,sigma_blocking_force"]
    for t in ("150um", "250um"):
        for v in np.linspace(0.2, 0.8, 6):
            r = evaluate(Strip(length=0.015, thickness=float(t[:-2]) * 1e-6, voltage=float(v)), "constant",
                         "quadrature", mat)
            w, f = abs(r["w"]), abs(r["F_block"])
            lines.append(f"{v:.4f}V,{t},{w * (1 + 0.02 * rng.standard_normal()) * 1e3:.6g}mm,"
                         f"{f * (1 + 0.02 * rng.standard_normal()) * 1e3:.6g}mN,{0.02 * w:.6g},{0.02 * f:.6g}")
    p = tmp_path_factory.mktemp("fit") / "data.csv"
    p.write_text("\n".join(lines) + "\n")
    return str(p)


def test_fit_json_and_plot(data_csv, tmp_path, capsys):
    png = tmp_path / "fit.png"
    assert main(["fit", data_csv, "--free", "modulus,c_moy", "--length", "1.5cm", "--json",
                 "--plot", str(png)]) == 0
    out = json.loads(capsys.readouterr().out)
    assert {"parameters", "correlation", "chi2_red", "n_points", "fidelity", "model", "noise_scale"} <= set(out)
    assert {"value", "stderr", "ci95", "identifiable", "status"} <= set(out["parameters"]["modulus"])
    assert out["n_points"] == 24
    for k, true in (("modulus", 9e7), ("c_moy", 2900.0)):
        p = out["parameters"][k]
        assert p["identifiable"] and abs(p["value"] / true - 1) < 0.05
    assert png.stat().st_size > 10_000


def test_fit_bad_input_exit_2(data_csv, tmp_path, capsys):
    assert main(["fit", data_csv, "--free", "stiffness"]) == 2
    err = capsys.readouterr().err
    assert "unknown parameter 'stiffness'" in err and err.count("\n") == 1
    bad = tmp_path / "bad.csv"
    bad.write_text("voltage,deflection\n1V,12 furlongs\n")
    assert main(["fit", str(bad), "--free", "modulus"]) == 2
    err = capsys.readouterr().err
    assert "row 2, column 'deflection'" in err and err.count("\n") == 1
    assert main(["fit", data_csv, "--free", "modulus", "--plot", str(tmp_path / "no" / "f.png")]) == 2
    assert main(["fit", data_csv, "--free", "modulus", "--scheduler", "nowhere"]) == 2


def test_uq_json_out_plot(tmp_path, capsys):
    nc, png = tmp_path / "u.nc", tmp_path / "u.png"
    scene = os.path.join(ROOT, "examples", "uq_nominal.toml")
    assert main(["uq", scene, "--samples", "2000", "--json", "--out", str(nc), "--plot", str(png)]) == 0
    out = json.loads(capsys.readouterr().out)
    assert set(out["summary"]["tip_deflection"]) == {"unit", "mean", "sd", "q2.5", "q50", "q97.5", "n",
                                                      "q2.5_interval", "q50_interval", "q97.5_interval",
                                                      "quantile_rank_error"}
    assert set(out["sobol"]["rotation"]["modulus"]) == {"S1", "S1_conf", "ST", "ST_conf"}
    xr = pytest.importorskip("xarray")
    with xr.open_dataset(nc) as ds:
        assert ds.sizes["sample"] == out["n_samples"]
    assert png.stat().st_size > 10_000


def test_uq_store_samples_bounds_the_file_not_the_statistics(tmp_path, capsys):
    """--store-samples keeps the first whole groups in the NetCDF; the statistics and counts
    are over every run, and each quantile's interval holds it."""
    nc = tmp_path / "u.nc"
    scene = os.path.join(ROOT, "examples", "uq_nominal.toml")
    assert main(["uq", scene, "--samples", "2000", "--fidelity", "leading", "--json", "--out", str(nc),
                 "--store-samples", "100"]) == 0
    cap = capsys.readouterr()
    out = json.loads(cap.out)
    D = len(out["inputs"])
    assert out["n_samples_stored"] == (100 // (D + 2)) * (D + 2) < out["n_samples"]
    assert "the first" in cap.err
    for s in out["summary"].values():
        assert s["q2.5_interval"][0] <= s["q2.5"] <= s["q2.5_interval"][1]
    xr = pytest.importorskip("xarray")
    with xr.open_dataset(nc) as ds:
        assert ds.sizes["sample"] == out["n_samples_stored"]
        assert ds.attrs["n_samples"] == out["n_samples"]
        assert ds["quantile_low"].shape == ds["quantile_value"].shape
    assert main(["uq", scene, "--samples", "2000", "--store-samples", "1e9"]) == 2
    assert "--max-store-samples" in capsys.readouterr().err


def test_uq_bad_scene_exit_2(tmp_path, capsys):
    p = tmp_path / "s.toml"
    p.write_text('voltage = "1V"\n[uncertain]\nthickness = {dist = "cauchy", loc = 1}\n')
    assert main(["uq", str(p), "--samples", "100"]) == 2
    err = capsys.readouterr().err
    assert "dist must be one of" in err and err.count("\n") == 1
    with pytest.raises(SystemExit) as ei:  # argparse: one line, status 2
        main(["uq", str(p), "--samples", "0"])
    assert ei.value.code == 2


def test_sweep_netcdf_out(tmp_path, capsys):
    xr = pytest.importorskip("xarray")
    from ipmc_asym.studies.sweeps import sweep

    nc = tmp_path / "s.nc"
    assert main(["sweep", "--vary", "thickness=100um:300um:3", "--vary", "voltage=0.5V:2V:2", "--model", "all",
                 "--fidelity", "corrected", "--out", str(nc), "--no-progress"]) == 0
    with xr.open_dataset(nc) as ds:
        # the same grid in the library (the CLI's parsed values, e.g. 100 * 1e-6, from the file)
        arr = sweep({"thickness": ds["thickness"].values, "voltage": ds["voltage"].values}, "all", "corrected",
                    progress=False)
        assert ds["thickness"].attrs["long_name"] == "total thickness 2e"
        got = ds["I"].sel(model="linear").values.ravel()
        np.testing.assert_array_equal(got, arr["I"][arr["model"] == "linear"])
        assert ds.attrs["fidelity"] == "corrected"


@pytest.mark.slow
def test_sweep_scheduler_local_identical_csv(tmp_path, capsys):
    pytest.importorskip("distributed")
    a, b = tmp_path / "a.csv", tmp_path / "b.csv"
    common = ["sweep", "--vary", "thickness=100um:300um:3", "--vary", "voltage=0.5V:2V:3", "--fidelity",
              "leading", "--no-progress"]
    assert main(common + ["--out", str(a)]) == 0
    assert main(common + ["--out", str(b), "--scheduler", "local"]) == 0
    assert a.read_text() == b.read_text()
    assert main(common + ["--scheduler", "udp://x"]) == 2


def test_fit_spectrum_and_static_files_together(data_csv, tmp_path, capsys):
    """Two files of two kinds (static rows + a spectrum from the linearised PNP at D = 3e-10) on one command."""
    from ipmc_asym.dynamics.circuit import frequency_response

    strip = Strip(length=0.015)
    mat = NAFION_LI.with_(E=9e7, c_moy=2900.0, D=3e-10)
    f = np.geomspace(0.1, 1e5, 20)
    Z = frequency_response(f, strip=strip, material=mat).Z
    rng = np.random.default_rng(11)
    lines = ["f,Z_re,Z_im,sigma_Z_re,sigma_Z_im"]
    for fi, z in zip(f, Z):
        s = 0.01 * abs(z)
        lines.append(f"{fi:.17g}Hz,{z.real + s * rng.standard_normal():.17g},{z.imag + s * rng.standard_normal():.17g},"
                     f"{s:.17g},{s:.17g}")
    imp = tmp_path / "imp.csv"
    imp.write_text("\n".join(lines) + "\n")
    assert main(["fit", data_csv, str(imp), "--free", "modulus,c_moy,D=1e-11m2/s:1e-9m2/s", "--length", "1.5cm",
                 "--json", "--no-progress"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["n_points"] == 24 + 40
    for k, true in (("modulus", 9e7), ("c_moy", 2900.0), ("diffusion", 3e-10)):
        p = out["parameters"][k]
        assert p["status"] == "ok" and p["ci95"][0] <= true <= p["ci95"][1], (k, p)
    # a parameter the files cannot see, a bad spectrum file, the plot of dynamic data: one line, exit 2
    assert main(["fit", str(imp), "--free", "viscous_modulus"]) == 2
    err = capsys.readouterr().err
    assert "viscous_modulus" in err and "deflection or blocking force" in err and err.count("\n") == 1
    bad = tmp_path / "bad.csv"
    bad.write_text("f,Z_re,Z_im\n1Hz,5,30\n")
    assert main(["fit", str(bad), "--free", "D"]) == 2
    err = capsys.readouterr().err
    assert "negate that column" in err and err.count("\n") == 1
    png = tmp_path / "f.png"
    assert main(["fit", data_csv, str(imp), "--free", "c_moy,D", "--length", "1.5cm", "--modulus", "90MPa",
                 "--plot", str(png)]) == 0
    assert png.stat().st_size > 10_000
    assert main(["fit", data_csv, "--free", "modulus", "--waveform", "step:1V"]) == 2


def test_a_strip_option_the_file_overrides_is_said(capsys):
    """fit_synthetic.csv has a length column: --length is not used for it (said), --width is."""
    base = ["fit", os.path.join(ROOT, "examples", "fit_synthetic.csv"), "--free", "modulus", "--no-progress", "--json"]
    assert main(base + ["--length", "3cm", "--width", "4mm"]) == 0
    err = capsys.readouterr().err
    assert "--length is not used for fit_synthetic.csv: its length column" in err and "--width is not used" not in err
    assert main(base) == 0
    assert "is not used" not in capsys.readouterr().err


def test_fit_says_the_strip_its_rows_assumed(capsys):
    """A spectrum's fit depends on the electrode area: the strip is in the text and the JSON."""
    path = os.path.join(ROOT, "examples", "dynamic_spectrum.csv")
    assert main(["fit", path, "--free", "D", "--no-progress", "--json", "--width", "4mm"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["strip"]["width_total"] == 4e-3 and doc["strip"]["half_thickness_e"] == doc["strip"]["thickness_total"] / 2
    assert doc["strip"]["columns_from_files"] == {"dynamic_spectrum.csv": []}
    assert main(["fit", path, "--free", "D", "--no-progress", "--width", "4mm"]) == 0
    assert "strip: L = 2 cm, total width 2l = 4 mm, total thickness 2e = " in capsys.readouterr().out
