"""The output vocabulary: one table, read by the datasets and documented in design.md."""

import re
from pathlib import Path

import pytest

from ipmc_asym.base.quantities import BY_NAME, QUANTITIES, axis_label, markdown_table, quantity
from ipmc_asym.io.datasets import VARIABLES
from ipmc_asym.studies.scene_schema import OUTPUTS
from ipmc_asym.studies.sweeps import DTYPE

ROOT = Path(__file__).resolve().parents[2]


def test_design_document_shows_the_table():
    text = (ROOT / "docs" / "design.md").read_text(encoding="utf-8")
    block = re.search(r"<!-- vocabulary -->\n(.*?)\n<!-- /vocabulary -->", text, re.S)
    assert block and block.group(1) == markdown_table()


def test_every_sweep_column_and_scene_output_has_an_entry():
    missing = [c for c in DTYPE.names if c not in BY_NAME and c not in ("model", "fidelity")]
    missing += [o for o in OUTPUTS if o not in BY_NAME and o not in ("profiles", "scaling_fit")]
    assert not missing, missing


def test_names_are_unique_and_datasets_read_the_table():
    names = [q.name for q in QUANTITIES] + [q.scene_name for q in QUANTITIES if q.scene_name not in (None, q.name)]
    assert len(names) == len(set(names))
    for n, q in BY_NAME.items():
        assert VARIABLES[n] == (q.unit, q.long_name)


def test_lengths_across_the_strip_say_total():
    assert "total" in quantity("thickness").long_name and "2e" in quantity("thickness").long_name
    assert "total" in quantity("width").long_name and "2l" in quantity("width").long_name


def test_unknown_name_lists_the_known_ones():
    with pytest.raises(ValueError, match="known: length"):
        quantity("deflection_of_the_moon")
    assert axis_label("tip_deflection", "mm") == "tip deflection w (large displacement) [mm]"


@pytest.mark.parametrize("parse, text, si", [
    ("parse_force", "1.2mN", 1.2e-3), ("parse_force", "5uN", 5e-6), ("parse_time", "20ms", 0.02),
    ("parse_time", "2min", 120.0), ("parse_diffusion", "1e-10m2/s", 1e-10), ("parse_diffusion", "1e-6cm2/s", 1e-10),
    ("parse_diffusion", "1e-10", 1e-10), ("parse_length", "200um", 2e-4), ("parse_voltage", "-500mV", -0.5),
])
def test_one_quantity_parser_for_every_unit(parse, text, si):
    import ipmc_asym.base.units as units

    assert getattr(units, parse)("x", text) == pytest.approx(si, rel=1e-15)


def test_unknown_unit_names_the_parameter_and_the_allowed_units():
    import ipmc_asym.base.units as units

    with pytest.raises(ValueError, match=r"--diffusion: unknown unit 'parsec'.*allowed: m2/s"):
        units.parse_diffusion("--diffusion", "5parsec")


@pytest.mark.parametrize("text", ["200um", "0.1mm", "2 cm", "3e-3mm", "123.456789nm", "7um", "1.1e-300m",
                                  "-500mV", "0.3mV", "130MPa", "1.3e-2GPa", "1e-6cm2/s", "20ms", "5e-324m"])
def test_a_power_of_ten_unit_rounds_once(text):
    """A value with a power-of-ten unit is the double nearest the decimal it names (as the same
    number written with an exponent is): ``200um`` is 2e-4 to the bit, not 200 * 1e-6 (one ulp
    below). Reference: the exact rational rounded once by ``float(Fraction)``."""
    import re
    from fractions import Fraction

    import ipmc_asym.base.units as units

    num, unit = re.match(r"\s*([-+0-9.eE]+)\s*(.*)", text).groups()
    table = {"m": 0, "mm": -3, "cm": -2, "um": -6, "nm": -9, "mV": -3, "MPa": 6, "GPa": 9, "cm2/s": -4, "ms": -3}
    parse = {"V": units.parse_voltage, "Pa": units.parse_pressure, "/s": units.parse_diffusion}
    fn = next((f for k, f in parse.items() if unit.endswith(k)), units.parse_time if unit == "ms" else units.parse_length)
    assert fn("x", text) == float(Fraction(num) * Fraction(10) ** table[unit])
