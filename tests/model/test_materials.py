"""Material sets: every cited value is the one the code uses; derived values recomputed."""

import sys

import pytest

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

from pathlib import Path

from references import REPO

import ipmc_asym as ia
from ipmc_asym.base.registry import MODELS
from ipmc_asym.model import material_data
from ipmc_asym.model.params import FALLBACK_DEFAULTS, NAFION_LI, Material, material_from_spec

ROOT = Path(__file__).resolve().parents[2]
SETS = sorted((ROOT / "ipmc_asym" / "materials").glob("*.toml"))
# units as the files write them -> SI (written out here, independently of the loader)
UNIT = {"C/kg": 1.0, "kg/m^3": 1.0, "g/cm^3": 1e3, "1": 1.0, "Pa": 1.0, "MPa": 1e6, "K": 1.0, "C/mol": 1.0,
        "J/(mol K)": 1.0, "m^2/s": 1.0, "mol/m^3": 1.0, "meq/g": 1.0, "um": 1e-6}


def raw(path):
    return tomllib.loads(path.read_text(encoding="utf-8"))


def test_sets_are_the_files():
    assert SETS and ia.materials.names() == tuple(sorted(p.stem for p in SETS))


@pytest.mark.parametrize("path", SETS, ids=lambda p: p.stem)
def test_cited_values_are_used(path):
    d = raw(path)
    m = ia.materials.get(d["name"])
    p = d["parameters"]
    si = {k: v["value"] * UNIT[v["unit"]] for k, v in p.items()}
    for k, (v, _src) in FALLBACK_DEFAULTS.items():  # what a set leaves out: the stated defaults
        si.setdefault(k, v)
    if "IEC" in si:  # ion-exchange capacity (mol/kg) -> mass charge, Z3 = -F IEC
        si.setdefault("Z3", -si["F"] * si["IEC"])
    for name, v in p.items():  # a stated range holds the value
        if "range" in v:
            assert v["range"][0] <= v["value"] <= v["range"][1], name
    for k in ("Z3", "rho3", "phi4", "rho2", "E", "T", "F", "R", "D"):
        assert getattr(m, k) == pytest.approx(si[k], rel=1e-15), k
    # C_moy as the source defines it: eq. (17), -(1 - phi4) rho3 Z3 / (phi4 F)
    formula = -(1 - si["phi4"]) * si["rho3"] * si["Z3"] / (si["phi4"] * si["F"])
    assert m.C_moy_formula == pytest.approx(formula, rel=1e-14)
    used = si["C_moy"] if d["c_moy"] == "paper" else formula
    assert m.C_moy == pytest.approx(used, rel=1e-14)
    # every value has a full citation from the file's own [sources]; fallbacks say so
    cites = {v["citation"] for v in d["sources"].values()} | {src for _, src in FALLBACK_DEFAULTS.values()}
    for k, v in p.items():
        assert d["sources"][v["source"]]["citation"] in cites
    assert set(ia.materials.citations(m)) <= cites
    s = material_data.load_set(d["name"], FALLBACK_DEFAULTS)
    assert s.fallbacks() == [k for k, v in p.items() if v.get("fallback")] + [
        k for k in FALLBACK_DEFAULTS if k not in p]
    for model, q in d.get("permittivity", {}).items():  # the permittivity the code uses
        assert (MODELS[model].eps0, MODELS[model].deps) == (q["eps0"], q["deps"])


def test_nafion_li_is_the_default_material_and_the_papers_numbers():
    m = ia.materials.get("nafion-li")
    assert m == NAFION_LI == Material(sources=m.sources)
    assert NAFION_LI.sources == material_data.load_set("nafion-li").citations()
    assert m.C_moy == 3082.0  # stated in section 4
    # slip 1: eq. (17) with the paper's data, by hand: 0.62 * 2078 * 9e4 / (0.38 * 96487)
    assert ia.materials.get("nafion-li-formula").C_moy == pytest.approx(3162.4768, rel=1e-7)
    assert Material.named("nafion-li").C_moy == 3082.0


def test_user_file_units_and_fallbacks():
    path = ROOT / "examples" / "materials" / "paper-values-with-units.toml"
    m = Material.from_file(path)
    ref = ia.materials.get("nafion-li-formula")
    for k in ("Z3", "rho3", "phi4", "rho2", "E", "T", "F", "R", "D", "C_moy"):
        assert getattr(m, k) == pytest.approx(getattr(ref, k), rel=1e-14), k
    info = ia.materials.info(str(path))
    assert info["fallbacks"] == ["rho2", "T", "F", "R", "D"]
    assert all(info["parameters"][k]["fallback"] and info["parameters"][k]["source"] for k in info["fallbacks"])
    # the same file through the one material parser (scene files, --material)
    assert material_from_spec({"preset": str(path)}) == m


def _write(tmp_path, text):
    p = tmp_path / "m.toml"
    p.write_text(text, encoding="utf-8")
    return p


GOOD = '''name = "x"
c_moy = "formula"
[sources.a]
citation = "A. Author, Journal 1 (2000) 1-2"
[parameters.Z3]
value = -9e4
unit = "C/kg"
source = "a"
[parameters.rho3]
value = "2 g/cm3"
source = "a"
[parameters.phi4]
value = 0.4
source = "a"
range = [0.3, 0.5]
[parameters.E]
value = "100MPa"
source = "a"
'''


def test_user_file_ok_and_iec(tmp_path):
    m = Material.from_file(_write(tmp_path, GOOD))
    assert (m.rho3, m.E, m.phi4) == (2000.0, 1e8, 0.4)
    iec = GOOD.replace('[parameters.Z3]\nvalue = -9e4\nunit = "C/kg"', '[parameters.IEC]\nvalue = 0.9\nunit = "meq/g"')
    m2 = Material.from_file(_write(tmp_path, iec))
    assert m2.Z3 == pytest.approx(-96487.0 * 0.9, rel=1e-15)  # Z3 = -F IEC


@pytest.mark.parametrize("change, words", [
    (("source = \"a\"\nrange", "source = \"b\"\nrange"), "source must name"),
    (("[parameters.E]\nvalue = \"100MPa\"\nsource = \"a\"\n", ""), "parameters.E is missing"),
    (("range = [0.3, 0.5]", "range = [0.45, 0.5]"), "outside its range"),
    (("value = \"100MPa\"", "value = \"100 furlongs\""), "unknown unit"),
    (("c_moy = \"formula\"", "c_moy = \"formula\"\ncolour = 1"), "unknown key"),
])
def test_bad_user_file_one_line(tmp_path, change, words):
    p = _write(tmp_path, GOOD.replace(*change))
    with pytest.raises(ValueError, match=words) as e:
        Material.from_file(p)
    assert "\n" not in str(e.value)


def test_unknown_set_lists_the_sets():
    with pytest.raises(ValueError, match="nafion-li-formula"):
        ia.materials.get("flemion-na")


def test_scene_file_takes_a_material_file():
    from ipmc_asym.studies.scene_schema import parse_scene

    path = str(ROOT / "examples" / "materials" / "paper-values-with-units.toml")
    sc = parse_scene({"model": "constant", "voltage": 1.0, "material": {"preset": path}})
    assert sc.material.name == "paper-values-with-units"
    assert sc.material.C_moy == pytest.approx(ia.materials.get("nafion-li-formula").C_moy, rel=1e-14)
    assert parse_scene({"voltage": 1.0, "material": {"preset": "nafion-li-formula", "E": "100MPa"}}).material.E == 1e8


def test_datasheet_sets_derived_values():
    # Nafion N-115/N-117 (H+): IEC 0.98 meq/g, specific gravity 1.98, phi4 0.38 (fallback), by hand
    for name in ("nafion-115-h", "nafion-117-h"):
        m = ia.materials.get(name)
        assert m.Z3 == pytest.approx(-96487.0 * 0.98, rel=1e-15)
        assert m.C_moy == pytest.approx(0.62 * 1980.0 * 0.98 / 0.38, rel=1e-14)
        assert m.E == 114e6
        assert "phi4" in material_data.load_set(name).fallbacks()


def test_a_material_file_has_the_input_cap_of_every_input_file(tmp_path):
    """A material file is read by the one input reader: the size cap is --max-input-size's (a 1.2 MB
    file, a long comment and the paper's values, is read), a
    directory or a missing file is refused in one line."""
    from ipmc_asym.base.inputs import input_size_cap

    src = REPO / "examples" / "materials" / "paper-values-with-units.toml"
    big = tmp_path / "big.toml"
    big.write_text("# " + "x" * 1_200_000 + "\n" + src.read_text())
    assert material_data.read_set(big).parameters == material_data.read_set(src).parameters
    with input_size_cap(1000), pytest.raises(ValueError, match="more than the cap 1000"):
        material_data.read_set(big)
    with pytest.raises(ValueError, match="does not exist"):
        material_data.read_set(tmp_path / "none.toml")
    (tmp_path / "d.toml").mkdir()
    with pytest.raises(ValueError, match="is a directory"):
        material_data.read_set(tmp_path / "d.toml")


def test_a_material_file_of_an_unknown_schema_is_refused_listing_the_supported_ones(tmp_path):
    text = (ROOT / "ipmc_asym" / "materials" / "nafion-117-h.toml").read_text(encoding="utf-8")
    assert "\nschema = 1\n" in text
    for bad in ("99", "0", "1.0", "true", '"1"'):
        p = tmp_path / "m.toml"
        p.write_text(text.replace("\nschema = 1\n", f"\nschema = {bad}\n"), encoding="utf-8")
        with pytest.raises(ValueError, match=r"schema = .* is not supported; supported: 1$") as ei:
            Material.from_file(p)
        assert "\n" not in str(ei.value)
    p.write_text(text, encoding="utf-8")
    assert Material.from_file(p).E > 0
    p.write_text(text.replace("\nschema = 1\n", "\n"), encoding="utf-8")  # no schema: read as 1
    assert Material.from_file(p).E > 0
