"""``estimate`` and ``sweep`` at tiny voltages: tiny (correct) numbers, or a one-line refusal.

Reference: the Debye-Hueckel limit ``I -> (1 + A3)(lam coth(1/lam) - lam^2)`` (the linear
solution, ``derivations/debye_hueckel.py``), evaluated here with mpmath from the groups, and
``M_A = A5 I`` with ``A5`` proportional to ``|phi0|``.
"""

import csv
import json
import math

import mpmath as mp
import pytest

from ipmc_asym.cli import main
from ipmc_asym.model import groups
from ipmc_asym.model.params import NAFION_LI
from ipmc_asym.model.permittivity import MODELS


def _dh_limit(thickness, model):
    perm = MODELS[model]
    lam = mp.mpf(float(groups.debye_length(thickness, perm.eps0 + perm.deps, NAFION_LI)))
    return float((1 + mp.mpf(float(groups.A3(NAFION_LI)))) * (lam * mp.coth(1 / lam) - lam**2))


@pytest.mark.parametrize("v", [1e-200, -1e-200, 1e-300, 5e-324, -5e-324])
def test_estimate_tiny_voltage(v, capsys):
    assert main(["estimate", f"--voltage={v!r}", "--model", "constant", "--json"]) == 0
    row = json.loads(capsys.readouterr().out)["results"][0]
    ref = _dh_limit(200e-6, "constant")
    assert row["I"] == pytest.approx(math.copysign(ref, v), rel=1e-9)
    a5 = float(groups.A5(5e-3, 200e-6, v, NAFION_LI))
    assert row["M_A"] == pytest.approx(math.copysign(a5 * ref, v), rel=1e-9, abs=1e-320)
    for key in ("theta", "w", "F_block"):
        if row[key] is not None:
            assert abs(row[key]) < 1e-150, (key, row[key])


def test_estimate_zero_volt(capsys):
    assert main(["estimate", "--voltage", "0", "--model", "affine", "--json"]) == 0
    row = json.loads(capsys.readouterr().out)["results"][0]
    assert row["I"] == 0.0 and row["M_A"] == 0.0


def test_sweep_tiny_voltages(tmp_path):
    out = tmp_path / "s.csv"
    assert main(["sweep", "--vary", "voltage=1e-300:1e-200:3:log", "--model", "constant",
                 "--out", str(out)]) == 0
    with open(out, newline="") as f:
        rows = [r for r in csv.DictReader(ln for ln in f if not ln.startswith("#"))]
    assert len(rows) == 3
    ref = _dh_limit(200e-6, "constant")
    for r in rows:
        assert float(r["I"]) == pytest.approx(ref, rel=1e-9)
        assert abs(float(r["w"])) < 1e-150


@pytest.mark.parametrize("volts", ["3e-8V", "1e-9V", "-1e-200V"])
def test_profiles_near_and_below_the_bvp_floor(volts, capsys):
    """At 3e-8 V (the BVP's floor is 2.58e-8 V; below it the Debye-Hueckel profiles) C_bar changes
    by ~1e-6 or less: the anode widths' levels (C_bar = 0.5, 0.01) are never crossed and print as
    n/a, not NaN; the cathode's 1/e width is the Debye-Hueckel limit's, the Debye length
    (C_bar - 1 ~ exp(-d/lambda) from the face)."""
    assert main(["profiles", "--voltage", volts, "--model", "constant"]) == 0
    out = capsys.readouterr().out
    assert ("Debye-Hueckel profiles" in out) == (volts != "3e-8V")
    assert "nan" not in out.lower()
    row = next(ln.split() for ln in out.splitlines() if ln.startswith("constant"))
    assert row[1] == row[2] == "n/a"
    acc, debye = float(row[3]), float(row[6])
    assert acc == pytest.approx(debye, rel=2e-3)
