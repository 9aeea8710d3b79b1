"""``validate --measurements``: at least five measured quantities, each with its source, and the
model's values held against independent computations (the forward model and the conductivity
formula evaluated here), never against the table itself."""

import json
import math

import pytest
from references import REPO

from ipmc_asym.cli import main
from ipmc_asym.forward.model import forward
from ipmc_asym.model.params import NAFION_LI, named_material
from ipmc_asym.validation.measurements import MEASUREMENTS, compare, cross_prediction, to_markdown


@pytest.fixture(scope="module")
def rows():
    return compare()


def test_five_measured_quantities_with_sources(rows):
    keys = {r["key"] for r in rows}
    assert keys == {m.key for m in MEASUREMENTS}
    # distinct measured quantities (the two conductivity sources count once)
    assert len({k.split("_")[0] if k.startswith("conductivity") else k for k in keys}) >= 5
    for r in rows:
        assert r["source"] and r["strip"] and r["unit"]
        mid = math.sqrt(r["measured"][0] * r["measured"][1]) if isinstance(r["measured"], list) else r["measured"]
        for m, v in r["model"].items():
            assert r["ratio"][m] == pytest.approx(v / mid, rel=1e-14)


def test_bare_deflection_is_the_forward_model(rows):
    r = next(r for r in rows if r["key"] == "tip_deflection" and r["beam"] == "bare membrane")
    f = forward(0.02, 5e-3, 200e-6, 1.0, material=NAFION_LI, model="constant", fidelity="quadrature")
    assert r["model"]["constant"] == abs(float(f.w))
    layered = [r for r in rows if r["key"] == "tip_deflection" and r["beam"] != "bare membrane"]
    assert layered and all(x["model"]["constant"] < r["model"]["constant"] for x in layered)


def test_conductivity_row_and_cross_prediction(rows):
    m = named_material("nafion-117-h").with_(D=NAFION_LI.D)
    kappa = m.phi4 * m.F**2 * m.D * m.C_moy / (m.R * m.T)
    r = next(r for r in rows if r["key"] == "conductivity_yadav")
    assert r["model"]["constant"] == pytest.approx(kappa, rel=1e-12)
    c = cross_prediction()
    assert m.phi4 * m.F**2 * c["D"] * m.C_moy / (m.R * m.T) == pytest.approx(8.2, rel=1e-12)


def test_cli_json(capsys):
    assert main(["validate", "--measurements", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert len({r["key"] for r in out["measurements"]}) >= 5 and "D" in out["cross_prediction"]


def test_docs_page_holds_the_current_table(rows):
    """docs/measurements.md shows what the code gives (regenerate with validate --measurements --out)."""
    page = (REPO / "docs" / "measurements.md").read_text(encoding="utf-8")
    assert to_markdown(rows) in page


def test_strain_per_charge_is_face_strain_over_sigma(rows):
    """e |M_A| / EI (the bare section written out here) over |sigma| from the charge integral."""
    from ipmc_asym.integral.charge import charge

    r = next(r for r in rows if r["key"] == "strain_per_charge" and r["beam"] == "bare membrane")
    for m in ("constant", "affine"):
        f = forward(0.02, 5e-3, 200e-6, 1.0, material=NAFION_LI, model=m, fidelity="quadrature")
        EI = NAFION_LI.E * 5e-3 * (200e-6) ** 3 / 12
        sigma = float(charge(200e-6, 1.0, m, "quadrature", material=NAFION_LI).sigma)
        assert r["model"][m] == pytest.approx(100e-6 * abs(float(f.M_A)) / EI / abs(sigma), rel=1e-9)
    layered = [x for x in rows if x["key"] == "strain_per_charge" and x["beam"] != "bare membrane"]
    assert layered and all(x["model"]["constant"] < r["model"]["constant"] for x in layered)
