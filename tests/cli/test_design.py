"""``ipmc-asym design SPEC.toml [--json] [--plot F.png]`` as a user runs it."""

import json
from pathlib import Path

from ipmc_asym.cli import main

ROOT = Path(__file__).resolve().parents[2]
SPEC = str(ROOT / "examples" / "design_blocking_force.toml")


def test_design_json_keys_and_plot(tmp_path, capsys):
    png = tmp_path / "front.png"
    assert main(["design", SPEC, "--json", "--plot", str(png)]) == 0
    d = json.loads(capsys.readouterr().out)
    assert {"optimum", "active_constraints", "pareto"} <= set(d)
    assert set(d["optimum"]) == {"inputs", "outputs", "checks"}
    assert {"tip_deflection", "blocking_force", "rotation", "moment"} <= set(d["optimum"]["outputs"])
    assert abs(d["optimum"]["outputs"]["tip_deflection"]) >= 2e-3 * (1 - 1e-12)
    # the optimum sits on the thickness bound (400 um) with the deflection constraint active
    assert [a["name"] for a in d["active_constraints"]] == ["tip_deflection", "thickness"]
    assert d["material"] == "nafion-li" and d["material_sources"]
    assert 150 <= len(d["pareto"]) <= 200
    assert png.stat().st_size > 10_000


def test_design_text_material_and_refusal(tmp_path, capsys):
    assert main(["design", SPEC, "--material", "nafion-li-formula", "--cite"]) == 0
    out = capsys.readouterr().out
    assert "material nafion-li-formula" in out and "active constraints" in out and "[1] M. Tixier" in out
    bad = tmp_path / "bad.toml"
    bad.write_text(Path(SPEC).read_text().replace('min = "2mm"', 'min = "80cm"'))
    assert main(["design", str(bad)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "no design" in err
