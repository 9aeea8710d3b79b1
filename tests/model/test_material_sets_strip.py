"""Material sets: the electrode table, the typical thickness and the NRE-211/212 sets, held
against the numbers of their sources (the values as printed in the chart and datasheet)."""

import math

import pytest

from ipmc_asym.model.electrode import METALS
from ipmc_asym.model.params import Material, named_material, set_thickness

SET = """
schema = 1
name = "my-ipmc"
title = "test set"
[sources.s]
citation = "A. Author, A paper, J. 1 (2000) 1"
[parameters.IEC]
value = 0.9
unit = "meq/g"
source = "s"
[parameters.rho3]
value = 2.0
unit = "g/cm^3"
source = "s"
[parameters.phi4]
value = 0.4
source = "s"
[parameters.E]
value = "100MPa"
source = "s"
[parameters.thickness]
value = 150
unit = "um"
source = "s"
[electrode]
metal = "gold"
thickness = "4um"
source = "s"
where = "figure 2"
"""


def test_electrode_table_and_thickness_of_a_user_file(tmp_path):
    p = tmp_path / "my.toml"
    p.write_text(SET)
    m = Material.from_file(str(p))
    Em, rho, src = METALS["gold"]
    assert m.electrode.thickness == pytest.approx(4e-6, rel=1e-15)
    assert (m.electrode.modulus, m.electrode.density, m.electrode.metal) == (Em, rho, "gold")
    assert any("figure 2" in s and "A. Author" in s for s in m.sources)
    t, note = set_thickness(str(p))
    assert t == pytest.approx(150e-6, rel=1e-15) and "my-ipmc" in note


def test_electrode_table_refusals(tmp_path):
    p = tmp_path / "bad.toml"
    p.write_text(SET.replace('metal = "gold"', 'metal = "copper"'))
    with pytest.raises(ValueError, match="electrode.metal must be one of"):
        Material.from_file(str(p))
    p.write_text(SET.replace('source = "s"\nwhere', 'source = "nope"\nwhere'))
    with pytest.raises(ValueError, match="electrode.source must name a key"):
        Material.from_file(str(p))
    p.write_text(SET.replace('metal = "gold"\n', ''))
    with pytest.raises(ValueError, match="modulus"):
        Material.from_file(str(p))


@pytest.mark.parametrize("name,thickness,basis_weight", [("nafion-nre-211-h", 25.4e-6, 50e-3),
                                                         ("nafion-nre-212-h", 50.8e-6, 100e-3)])
def test_nre_sets_against_the_chart(name, thickness, basis_weight):
    m = named_material(name)
    assert m.Z3 == pytest.approx(-96487.0 * 0.92, rel=1e-12)  # available acid capacity 0.92 meq/g
    assert m.E == 249e6 and m.rho3 == pytest.approx(1970.0, rel=1e-12)
    t, note = set_thickness(name)
    assert t == pytest.approx(thickness, rel=1e-12) and name in note
    # the chart's basis weight over its thickness is its specific gravity (an independent check of the data)
    assert basis_weight / thickness == pytest.approx(m.rho3, rel=0.01)


def test_paper_set_states_no_thickness():
    assert set_thickness("nafion-li") is None and set_thickness("nafion-li-formula") is None
    assert set_thickness("nafion-117-h")[0] == pytest.approx(183e-6, rel=1e-12)


def test_117_diffusion_from_the_measured_conductivity():
    """D of nafion-117-h gives back the conductivity it was read from (82 mS/cm)."""
    m = named_material("nafion-117-h")
    kappa = m.phi4 * m.F**2 * m.D * m.C_moy / (m.R * m.T)
    assert kappa == pytest.approx(8.2, rel=1e-3)
    assert math.isclose(m.C_moy, 0.62 * 1980.0 * 0.98 / 0.38, rel_tol=1e-12)


def test_a_strip_takes_the_units_people_write():
    """Strings with units are read at the edge, as on the command line, into the same SI floats
    (rounded once: "200um" is 200e-6 to the bit); a bad one is refused naming the parameter."""
    from ipmc_asym.model.params import Strip

    s = Strip(length="2cm", width="5 mm", thickness="200um", voltage="-500mV")
    assert s == Strip(length=0.02, width=5e-3, thickness=200e-6, voltage=-0.5)
    assert all(type(getattr(s, k)) is float for k in ("length", "width", "thickness", "voltage"))
    with pytest.raises(ValueError, match="^thickness: cannot read 'abc' as a length"):
        Strip(thickness="abc")
    with pytest.raises(ValueError, match="below 1e-07 m"):
        Strip(thickness="50nm")
