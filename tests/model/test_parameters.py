"""The one parameter table (model/parameters.py): aliases, units, the material fields it sets, and the
fit/uq/design tables built from it."""

import pytest

from ipmc_asym.model.limits import PLAUSIBLE
from ipmc_asym.model.parameters import (
    ALIASES,
    PARAMETERS,
    canonical,
    material_value,
    parse_value,
    with_values,
)
from ipmc_asym.model.params import NAFION_LI


def test_each_old_name_maps_to_one_parameter():
    # the names the fit, the material files and the paper use for the same quantity
    for old, new in (("E", "modulus"), ("D", "diffusion"), ("R_s", "sheet_resistance"), ("eta_E", "viscous_modulus"),
                     ("modulus", "modulus"), ("C_moy", "c_moy")):
        assert canonical(old) == new
    assert len(ALIASES) == len(set(ALIASES))
    assert not set(ALIASES) & set(PARAMETERS)
    with pytest.raises(ValueError, match="unknown parameter 'Young'"):
        canonical("Young")


def test_values_set_the_material_fields_by_hand():
    m = with_values(NAFION_LI, {"E": 2e8, "diffusion": 3e-11, "R_s": 4.0, "c_moy": 2500.0, "eps0": 1e-9})
    assert (m.E, m.D, m.sheet_resistance, m.c_moy) == (2e8, 3e-11, 4.0, 2500.0)
    assert m.phi4 == NAFION_LI.phi4 and with_values(NAFION_LI, {"eps0": 1.0}) is NAFION_LI
    assert material_value(NAFION_LI, "E") == NAFION_LI.E and material_value(NAFION_LI, "c_moy") == NAFION_LI.C_moy
    with pytest.raises(ValueError, match="eps0"):
        material_value(NAFION_LI, "eps0")


@pytest.mark.parametrize("name, text, si", [
    ("modulus", "130MPa", 1.3e8), ("E", "1.3e8", 1.3e8), ("D", "1e-6cm2/s", 1e-10), ("sheet_resistance", "2.5ohm/sq", 2.5),
    ("c_moy", "3mol/L", 3000.0), ("viscous_modulus", "2kPa s", 2000.0), ("eps0", "1e-9F/m", 1e-9),
])
def test_parse_value_units(name, text, si):
    assert parse_value(name, text) == pytest.approx(si, rel=1e-12)


def test_plausible_ranges_come_from_limits():
    assert PARAMETERS["modulus"].plausible == PLAUSIBLE["E"][:2]
    assert PARAMETERS["diffusion"].plausible == PLAUSIBLE["D"][:2]


def test_fit_and_uq_tables_are_the_parameter_table():
    from ipmc_asym.studies.calibrate import FREE_ALIASES, FREE_PARAMETERS, VISIBLE_TO, parse_free
    from ipmc_asym.studies.uq import parse_uncertain

    assert list(FREE_PARAMETERS) == list(PARAMETERS)
    assert FREE_ALIASES["E"] == "modulus" and FREE_ALIASES["D"] == "diffusion"
    assert VISIBLE_TO["sheet_resistance"][0] == ("impedance",)
    assert parse_free("E=50MPa:500MPa") == parse_free("modulus=5e7:5e8") == {"modulus": (5e7, 5e8)}
    # uq reads the alias as the canonical name, with the parameter's units
    u = parse_uncertain({"E": {"dist": "normal", "mean": "130MPa", "sd": "10MPa"}})
    assert u == parse_uncertain({"modulus": {"dist": "normal", "mean": 1.3e8, "sd": 1e7}})


def test_every_field_is_a_material_field_and_the_files_spell_it_as_an_alias():
    import dataclasses

    from ipmc_asym.model.electrode import Electrode
    from ipmc_asym.model.material_data import MATERIAL_FIELDS
    from ipmc_asym.model.params import Material

    fields = {f.name for f in dataclasses.fields(Material)}
    layer_fields = {f.name for f in dataclasses.fields(Electrode)}
    for p in PARAMETERS.values():
        if p.field is not None and p.field.startswith("electrode."):  # a field of Material.electrode
            assert "electrode" in fields and p.field.split(".", 1)[1] in layer_fields, p.name
            continue
        if p.field is not None:
            assert p.field in fields, p.name
            # the material files (material_data) key a parameter by its Material field: the table knows that name
            if p.field in MATERIAL_FIELDS:
                assert canonical(p.field) == p.name
