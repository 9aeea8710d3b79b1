"""``freq --mode sensing``: the library's numbers, the load's units, refusals in one line with exit 2,
and ``--mode actuation`` (the default) the same output as before."""

from __future__ import annotations

import json

import numpy as np
import pytest

import ipmc_asym as ia
from ipmc_asym.cli import main

BASE = ["freq", "--from", "1mHz", "--to", "10Hz", "--points", "5"]


def _run(capsys, *argv):
    try:
        rc = main([*argv])
    except SystemExit as exc:  # argparse's own refusals (one line, status 2)
        rc = exc.code
    cap = capsys.readouterr()
    return rc, cap.out, cap.err


def test_json_is_the_library(capsys):
    rc, out, err = _run(capsys, *BASE, "--mode", "sensing", "--model", "linear", "--load", "10kOhm", "--json")
    assert rc == 0
    d = json.loads(out)
    f = np.geomspace(1e-3, 10.0, 5)
    r = ia.sensing_response(f, model="linear", load=1e4)
    assert d["mode"] == "sensing" and d["load_resistance"] == 1e4 and d["support"] == "tip-force"
    assert d["Q_per_w_amp"] == np.abs(r.Q_per_w).tolist()
    assert d["V_oc_per_w_phase"] == np.angle(r.V_oc_per_w, deg=True).tolist()
    assert d["power"] == r.power.tolist()
    assert d["valid"] == r.valid.tolist()
    # the matched power is the largest a resistance can take
    assert all(m >= p for m, p in zip(d["matched_power"], d["power"]))
    assert "past the one-way coupling bound" in err


@pytest.mark.parametrize("text", ["10kOhm", "10 kΩ", "1e4", "10000ohm", "0.01MOhm"])
def test_load_units(capsys, text):
    rc, out, _ = _run(capsys, *BASE, "--mode", "sensing", "--load", text, "--json")
    assert rc == 0 and json.loads(out)["load_resistance"] == pytest.approx(1e4, rel=1e-15)


def test_short_and_open_have_no_load_columns(capsys):
    for load in ("short", "open"):
        rc, out, _ = _run(capsys, *BASE, "--mode", "sensing", "--load", load, "--support", "free", "--json")
        d = json.loads(out)
        assert rc == 0 and "power" not in d and d["load"] == load and d["support"] == "free"


def test_text_table(capsys):
    rc, out, _ = _run(capsys, *BASE, "--mode", "sensing", "--load", "1kOhm", "--solver", "circuit")
    assert rc == 0
    assert "|Q/w| [C/m]" in out and "P [W]" in out and "note: water instantly redistributed" in out


@pytest.mark.parametrize("argv,needle", [
    (["--mode", "sensing", "--voltage", "0.5V"], "--mode sensing does not take --voltage"),
    (["--mode", "sensing", "--beam", "dynamic"], "--mode sensing does not take --beam dynamic"),
    (["--mode", "sensing", "--support", "clamped-free"], "--support clamped-free (it takes free or tip-force)"),
    (["--mode", "sensing", "--sheet-resistance", "2.5"], "--mode sensing does not take --sheet-resistance"),
    (["--mode", "sensing", "--load", "-5ohm"], "--load must be short, open or a resistance > 0"),
    (["--mode", "sensing", "--load", "10parsec"], "unknown unit 'parsec'"),
    (["--mode", "sensing", "--nu", "0.7"], "--nu must be a drained Poisson ratio"),
    (["--mode", "sensing", "--amplitude", "0mm"], "--amplitude must be > 0"),
    (["--mode", "sensing", "--amplitude", "1m"], "amplitude: (1 - 2 nu) |kappa0| e/phi4 must be < 1"),
    (["--load", "10kOhm"], "--load is an option of --mode sensing"),
    (["--support", "tip-force"], "--support tip-force is how --mode sensing imposes"),
    (["--mode", "harvest"], "argument --mode: invalid choice"),
])
def test_refusals_one_line_exit_2(capsys, argv, needle):
    rc, out, err = _run(capsys, *BASE, *argv)
    assert rc == 2 and out == ""
    assert len(err.strip().splitlines()) == 1 and needle in err, err


def test_actuation_is_the_default_and_unchanged(capsys):
    rc, plain, _ = _run(capsys, *BASE, "--json")
    rc2, explicit, _ = _run(capsys, *BASE, "--mode", "actuation", "--json")
    assert rc == rc2 == 0 and plain == explicit
    d = json.loads(plain)
    # the keys of the actuation output (as before this mode existed) and its values from frequency_response
    assert set(d) == {"tau", "model", "method", "thickness_total", "f_d", "voltage", "beam", "viscous_modulus",
                      "resonances", "error_max", "reference", "electrode_area", "diffusion_coefficient", "units",
                      "notes", "f", "Z_re", "Z_im", "Z_abs", "Z_phase", "w_amp", "w_phase", "theta_amp",
                      "theta_phase", "F_amp", "F_phase"}
    r = ia.frequency_response(np.geomspace(1e-3, 10.0, 5), model="constant")
    assert d["Z_re"] == r.Z.real.tolist() and d["w_amp"] == r.w_amp.tolist()
    assert d["F_amp"] == np.abs(r.H_F).tolist()
