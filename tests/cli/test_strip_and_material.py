"""The strip and material of the options, built in one place (cli.common.strip_and_material)."""

from __future__ import annotations

import pytest

from ipmc_asym.cli import build_parser
from ipmc_asym.cli.common import strip_and_material


def _args(*argv):
    ap, _ = build_parser("step")
    return ap.parse_args(["step", *argv])


def test_options_become_a_strip_and_a_material():
    strip, material, note = strip_and_material(_args("--thickness", "150um", "--voltage", "2V", "--diffusion",
                                                     "2e-10m2/s", "--modulus", "200MPa"))
    assert (strip.thickness, strip.voltage) == (150e-6, 2.0)
    assert (material.E, material.D, note) == (200e6, 2e-10, "")


def test_the_set_thickness_stands_in_and_is_said():
    strip, material, note = strip_and_material(_args("--material", "nafion-117-h"))
    assert material.name == "nafion-117-h" and strip.thickness == pytest.approx(183e-6, rel=0.01)
    assert "typical thickness" in note


def test_a_thickness_below_the_floor_is_refused_in_one_line():
    with pytest.raises(ValueError) as exc:
        strip_and_material(_args("--thickness", "1nm"))
    assert "\n" not in str(exc.value)
