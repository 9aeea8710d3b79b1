"""The static commands' reports from one library call: what ``estimate --json`` and ``charge
--json`` print is the document :func:`estimate_document` / :func:`charge_report` returns, so a
Python user gets the command's behaviour (rows, escalation, spread, warnings) from one call."""

from __future__ import annotations

import json

import numpy as np

from ipmc_asym.base.jsonio import dumps
from ipmc_asym.cli import main
from ipmc_asym.forward.charge import charge_report
from ipmc_asym.forward.estimate import estimate_document, estimate_report, model_list
from ipmc_asym.model.params import NAFION_LI, Strip
from ipmc_asym.model.spread import spread_of
from ipmc_asym.studies.fits import axis_fits


def _without_seconds(doc):
    for r in doc["results"]:
        r.pop("seconds", None)
    return doc


def test_estimate_json_is_the_document(capsys):
    assert main(["estimate", "--json", "--fidelity", "corrected"]) == 0  # the default thickness: 200e-6 m
    printed = json.loads(capsys.readouterr().out)
    doc = json.loads(dumps(estimate_document(Strip(thickness=200e-6), NAFION_LI, "all", "corrected")))
    assert _without_seconds(printed) == _without_seconds(doc)
    assert list(doc) == ["inputs", "results", "model_spread", "notes"]


def test_estimate_document_rows_are_estimate_report_rows():
    strip = Strip(voltage=2.0)
    doc = estimate_document(strip, NAFION_LI, "linear", "leading", pressure_term=False)
    rows, spread = estimate_report(strip, model_list("linear"), "leading", NAFION_LI, on_invalid="nan")
    for a, b in zip(doc["results"], rows):
        a.pop("seconds"), b.pop("seconds")
        assert a == b
    assert doc["model_spread"]["variants"] == spread["variants"]


def test_charge_json_is_the_report(capsys):
    assert main(["charge", "--json", "--model", "affine", "--voltage", "0.5V"]) == 0
    printed = json.loads(capsys.readouterr().out)
    doc = json.loads(dumps(charge_report(Strip(voltage=0.5), NAFION_LI, "affine", "corrected")))
    assert printed == doc
    assert [r["model"] for r in doc["results"]] == ["affine"]
    assert len(doc["model_spread"]["variants"]) == 6  # three models, C_moy paper and formula


def test_spread_of_ratio_and_sign_change():
    s = spread_of({"a": 1.0, "b": 4.0, "c": None}, 1e-6)
    assert (s["min"], s["max"], s["ratio"], s["numerical_error"]) == (1.0, 4.0, 4.0, 1e-6)
    assert spread_of({"a": -1.0, "b": 2.0})["ratio"] is None


def test_axis_fits_notes_an_axis_that_cannot_carry_a_power_law():
    fits, notes = axis_fits({"voltage": np.array([1.0])}, "constant", "leading", Strip())
    assert fits == [] and notes == ["no fit along voltage: only 1 value"]
    fits, notes = axis_fits({"voltage": np.array([0.5, 1.0, 2.0])}, "constant", "leading", Strip())
    assert notes == [] and {f["variable"] for f in fits} == {"voltage"}
