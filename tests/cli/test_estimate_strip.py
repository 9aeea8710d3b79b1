"""``estimate`` with electrode layers, material-set thickness and the model-form spread.

The layered deflection is held against ``-M_A L^2/(2 EI)`` with ``EI`` from the parallel-axis
theorem (independent of the code's closed form); no layer is held against the default run
(every number equal); the spread against the rows of the models it spans.
"""

import json

import pytest

from ipmc_asym.cli import main
from ipmc_asym.model.electrode import METALS


def _json(capsys, *args):
    assert main(["estimate", "--json", *args]) == 0
    return json.loads(capsys.readouterr().out)


def _no_seconds(rows):
    return [{k: v for k, v in r.items() if k != "seconds"} for r in rows]


def test_zero_layer_equals_default(capsys):
    a = _json(capsys)
    b = _json(capsys, "--electrode-thickness", "0", "--electrode-metal", "platinum")
    assert _no_seconds(a["results"]) == _no_seconds(b["results"])
    assert a["inputs"] == b["inputs"] and a["model_spread"] == b["model_spread"]
    assert a["inputs"]["beam"].startswith("bare membrane")


def test_layer_deflection_is_moment_over_composite_stiffness(capsys):
    t, L, w, h = 5e-6, 0.02, 5e-3, 200e-6
    out = _json(capsys, "--electrode-thickness", "5um", "--electrode-metal", "platinum", "--model", "constant")
    Em = METALS["platinum"][0]
    d = 0.5 * (h + t)
    EI = 1.3e8 * w * h**3 / 12 + 2 * Em * (w * t**3 / 12 + w * t * d * d)
    r = out["results"][0]
    assert r["w_small"] == pytest.approx(-r["M_A"] * L * L / (2 * EI), rel=1e-12)
    assert out["inputs"]["bending_stiffness"] == pytest.approx(EI, rel=1e-13)
    assert "platinum" in out["inputs"]["beam"]
    assert any("electrode layers" in s for s in out["inputs"]["material_sources"])


def test_layer_without_modulus_exit_2_one_line(capsys):
    assert main(["estimate", "--electrode-thickness", "5um"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--electrode-metal" in err


def test_material_set_thickness_is_the_default(capsys):
    assert main(["estimate", "--material", "nafion-117-h", "--model", "constant"]) == 0
    out = capsys.readouterr().out
    assert "183 um" in out and "typical thickness of material set nafion-117-h" in out
    j = _json(capsys, "--material", "nafion-117-h", "--model", "constant")
    assert j["inputs"]["thickness_total"] == pytest.approx(183e-6, rel=1e-12)
    assert "nafion-117-h" in j["inputs"]["thickness_source"]
    j = _json(capsys, "--material", "nafion-117-h", "--model", "constant", "--thickness", "200um")
    assert j["inputs"]["thickness_total"] == pytest.approx(200e-6, rel=1e-12)
    assert "thickness_source" not in j["inputs"]


def test_model_spread_spans_models_and_c_moy(capsys):
    out = _json(capsys, "--fidelity", "quadrature")
    sp = out["model_spread"]
    assert sp["variants"] == [f"{m}/{c}" for c in ("paper", "formula") for m in ("constant", "linear", "affine")]
    rows = {r["model"]: r for r in out["results"]}
    for k in ("w", "F_block", "M_A"):
        q = sp["quantities"][k]
        for m in rows:  # the default c_moy is the paper's: the rows are the paper variants
            assert q["values"][f"{m}/paper"] == rows[m][k]
        vals = [v for v in q["values"].values() if v is not None]
        assert q["min"] == min(vals) and q["max"] == max(vals)
        assert q["numerical_error"] >= max(r["error_estimate"] for r in out["results"])
    # the spread is far wider than the numerical error (measured: 2.32 / 0.77 / 2.00 mN at 2 V)
    q = sp["quantities"]["w_small"]
    width = (q["max"] - q["min"]) / max(abs(q["max"]), abs(q["min"]))
    assert q["ratio"] > 1.2 and width > 1e3 * q["numerical_error"]
    assert main(["estimate"]) == 0
    text = capsys.readouterr().out
    assert "model-form spread over 6 variants" in text and "numerical rel.err" in text


def test_model_spread_other_set_spans_models_only(capsys):
    out = _json(capsys, "--material", "nafion-117-h", "--model", "linear")
    assert out["model_spread"]["variants"] == ["constant", "linear", "affine"]
    assert out["model_spread"]["quantities"]["w"]["values"]["linear"] == out["results"][0]["w"]


def test_charge_spread_spans_the_rows(capsys):
    assert main(["charge", "--json", "--model", "affine"]) == 0
    out = json.loads(capsys.readouterr().out)
    sp = out["model_spread"]
    assert len(sp["variants"]) == 6
    row = out["results"][0]
    for k in ("sigma", "Q", "C_diff", "eps_app"):
        q = sp["quantities"][k]
        assert q["values"]["affine/paper"] == row[k]
        assert q["min"] <= row[k] <= q["max"]
