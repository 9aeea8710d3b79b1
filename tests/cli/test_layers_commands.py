"""Electrode layers through ``design`` (options on top of the spec's material): the optimum's
outputs are those of the forward model with the layered material, evaluated here."""

import json
from pathlib import Path

import pytest

from ipmc_asym.cli import main
from ipmc_asym.forward.model import forward
from ipmc_asym.model.electrode import electrode_from_spec
from ipmc_asym.model.params import NAFION_LI

SPEC = str(Path(__file__).resolve().parents[2] / "examples" / "design_blocking_force.toml")


def test_design_with_layers(capsys):
    assert main(["design", SPEC, "--electrode-thickness", "0.05um", "--electrode-metal", "gold", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert "gold" in d["beam"] and any("electrode layers" in s for s in d["material_sources"])
    x = d["optimum"]["inputs"]
    mat = NAFION_LI.with_(electrode=electrode_from_spec({"thickness": 0.05e-6, "metal": "gold"}))
    r = forward(x["length"], x["width"], x["thickness"], x["voltage"], material=mat, model=d["model"],
                fidelity=d["fidelity"])
    assert d["optimum"]["outputs"]["tip_deflection"] == pytest.approx(float(r.w), rel=1e-12)
