"""``ipmc-asym materials``, ``--material`` and ``--cite`` as a user runs them."""

import json
from pathlib import Path

import pytest

from ipmc_asym.cli import main

ROOT = Path(__file__).resolve().parents[2]
USER = str(ROOT / "examples" / "materials" / "paper-values-with-units.toml")


def test_materials_list_and_show(capsys):
    assert main(["materials", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert {"nafion-li", "nafion-li-formula", "nafion-117-h"} <= {m["name"] for m in d["materials"]}
    assert d["not_offered"]
    assert main(["materials", "nafion-li", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["parameters"]["phi4"]["value"] == 0.38 and d["parameters"]["D"]["fallback"] is True
    assert d["used"]["C_moy"] == 3082.0 and all(d["parameters"][k]["source"] for k in d["parameters"])
    assert main(["materials", USER]) == 0
    out = capsys.readouterr().out
    assert "FALLBACK" in out and "[1] M. Tixier" in out


def test_estimate_with_material_set_and_file(capsys):
    assert main(["estimate", "--model", "constant", "--material", "nafion-li-formula", "--json"]) == 0
    a = json.loads(capsys.readouterr().out)
    assert a["results"][0]["C_moy"] == pytest.approx(3162.4768, rel=1e-7)
    assert main(["estimate", "--model", "constant", "--material", USER, "--json", "--cite"]) == 0
    cap = capsys.readouterr()
    b = json.loads(cap.out)  # the bibliography goes to stderr with --json
    assert b["results"][0]["I"] == a["results"][0]["I"]
    assert "material set: paper-values-with-units" in cap.err and "[1] M. Tixier" in cap.err
    # an explicit option still overrides the set's value
    assert main(["estimate", "--model", "constant", "--material", "nafion-li-formula", "--c-moy", "paper",
                 "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["results"][0]["C_moy"] == 3082.0


@pytest.mark.parametrize("value", ["flemion-k", "missing.toml"])
def test_bad_material_one_line(value, capsys):
    assert main(["estimate", "--material", value]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--material" in err


def test_sweep_csv_names_material_and_sources(tmp_path):
    out = tmp_path / "s.csv"
    assert main(["sweep", "--vary", "length=1cm:2cm:3", "--fidelity", "leading", "--no-progress",
                 "--material", "nafion-li-formula", "--out", str(out)]) == 0
    lines = out.read_text(encoding="utf-8").splitlines()
    head = [ln for ln in lines if ln.startswith("#")]
    assert head[0] == "# material set: nafion-li-formula" and head[1].startswith("# source [1]: M. Tixier")
    assert lines[len(head)].startswith("length,") and len(lines) == len(head) + 4


def test_scene_material_option_and_paper_c_moy_guard(capsys):
    scene = str(ROOT / "examples" / "nominal.toml")
    assert main(["scene", scene, "--json", "--material", "nafion-117-h", "--cite"]) == 0
    cap = capsys.readouterr()
    d = json.loads(cap.out)
    assert d["material"]["name"] == "nafion-117-h"
    assert d["material"]["C_moy"] == pytest.approx(0.62 * 1980.0 * 0.98 / 0.38, rel=1e-14)  # eq. (17), its own data
    assert "material set: nafion-117-h" in cap.err
    # 3082 mol/m^3 is the paper's Nafion Li+ value: refused for another material
    assert main(["estimate", "--material", "nafion-117-h", "--c-moy", "paper"]) == 2
    assert "--c-moy" in capsys.readouterr().err
