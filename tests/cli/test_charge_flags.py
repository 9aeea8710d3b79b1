"""``charge``: a ``valid`` flag per row, the voltage warning beyond the validated 20 V, and
subnormal voltages answered (sigma -> C_d(0) phi0 down to the subnormals) with their rounding."""

from __future__ import annotations

import json

import pytest

import ipmc_asym as ia
from ipmc_asym.base.settings import VALIDATED_VOLTAGE
from ipmc_asym.cli import main


def _run(capsys, *argv):
    rc = main(["charge", *argv, "--json"])
    cap = capsys.readouterr()
    return rc, json.loads(cap.out) if rc == 0 else None, cap.err


def test_valid_and_voltage_warning_at_21_v(capsys):
    rc, out, err = _run(capsys, "--voltage", "21V")
    assert rc == 0
    assert all(r["check_voltage"] is False and r["valid"] is False for r in out["results"])
    assert "20 V" in err and "check_voltage = false" in err and len(out["warnings"]) == 1
    rc, out, err = _run(capsys, "--voltage", f"{VALIDATED_VOLTAGE}V")
    assert rc == 0 and all(r["valid"] and r["check_voltage"] for r in out["results"]) and out["warnings"] == []
    # the library: the same flags, the numbers kept
    r = ia.charge(200e-6, 21.0)
    assert not bool(r.valid) and not bool(r.check_voltage) and float(r.sigma) > 0


def test_subnormal_voltage_is_answered(capsys):
    rc, out, err = _run(capsys, "--voltage", "1e-320V", "--model", "linear")
    assert rc == 0, err
    (row,) = out["results"]
    rc, ref, _ = _run(capsys, "--voltage", "1e-10V", "--model", "linear")
    # the small-signal limit: sigma/phi0 = C_d(0), up to the subnormal's stated rounding
    phi = out["inputs"]["voltage"]
    slope = ref["results"][0]["sigma"] / ref["inputs"]["voltage"]
    assert row["sigma"] / phi == pytest.approx(slope, rel=row["error_estimate"] + 1e-9)
    assert 0 < row["error_estimate"] < 1


def test_subnormal_flagged_where_its_rounding_is_above_the_limit(capsys):
    rc, out, err = _run(capsys, "--voltage", "1e-320V", "--model", "constant")
    assert rc == 0
    (row,) = out["results"]
    assert row["valid"] is False and row["error_estimate"] > 0.01 and "subnormal" in err


def test_a_spread_variant_without_a_valid_rung_does_not_refuse_the_rows_asked_for(capsys):
    """--fidelity bvp: the linear model's C_diff (6.5e-14 F/m^2 at 1 V, the corrected rung) is below
    what the BVP's differences resolve, so the linear variants of the model-form spread have no
    valid rung from bvp up. The constant row asked for is answered; those variants are n/a in the
    spread, each said once on stderr; the linear row asked for alone is still refused."""
    import json

    assert main(["charge", "--fidelity", "bvp", "--model", "constant", "--json"]) == 0
    cap = capsys.readouterr()
    doc = json.loads(cap.out)
    assert [r["model"] for r in doc["results"]] == ["constant"] and doc["results"][0]["valid"]
    vals = doc["model_spread"]["quantities"]["sigma"]["values"]
    assert [k for k, v in vals.items() if v is None] == ["linear/paper", "linear/formula"]
    assert cap.err.count("left out (n/a)") == 2 and "inf" not in cap.err
    assert main(["charge", "--fidelity", "bvp", "--model", "linear"]) == 2
