"""The public API refuses bad arguments in one line naming the parameter (as the command line does),
and gives one answer for one point."""

from __future__ import annotations

import math

import numpy as np
import pytest

import ipmc_asym as ia
from ipmc_asym.beam.statics import KL_BLOCK_MAX


def _one_line(excinfo, *words):
    msg = str(excinfo.value)
    assert "\n" not in msg and all(w in msg for w in words), msg


def test_laws_names_its_choices():
    with pytest.raises(ValueError) as e:
        ia.laws("x")
    _one_line(e, "model", "constant", "linear", "affine")


def test_evaluate_strip_and_material_arguments():
    with pytest.raises(ValueError) as e:
        ia.evaluate(None)
    _one_line(e, "strip", "Strip")
    with pytest.raises(ValueError) as e:
        ia.evaluate(ia.Strip(), material=3.0)
    _one_line(e, "material", "nafion-li")
    with pytest.raises(ValueError) as e:
        ia.evaluate(ia.Strip(), material="no-such-set")
    _one_line(e, "no-such-set")
    # a set name is the set itself
    a = ia.evaluate(ia.Strip(), material="nafion-li")
    b = ia.evaluate(ia.Strip(), material=ia.NAFION_LI)
    assert a["M_A"] == b["M_A"] and a["w"] == b["w"]


def test_moment_integral_reads_units_and_names_the_parameter():
    assert ia.moment_integral("200um", "1V") == pytest.approx(ia.moment_integral(200e-6, 1.0), rel=1e-14)
    with pytest.raises(ValueError) as e:
        ia.moment_integral("200 parsecs", 1)
    _one_line(e, "thickness")
    with pytest.raises(ValueError) as e:
        ia.moment_integral(200e-6, object())
    _one_line(e, "voltage")


@pytest.mark.parametrize("points", [10**12, 2.5, 1, True, "10"])
def test_step_response_points_checked(points):
    with pytest.raises(ValueError) as e:
        ia.step_response(points=points)
    _one_line(e, "points")


@pytest.mark.parametrize("spec", ["sine:1V@10Hz,nan", "sine:1V@10Hz,inf", "sine:1V@10Hz,x"])
def test_parse_waveform_refuses_a_non_finite_phase(spec):
    with pytest.raises(ValueError) as e:
        ia.parse_waveform(spec)
    _one_line(e, "phase")


def test_solve_beam_withholds_like_evaluate():
    """Scalar inputs: None where evaluate has None (past the tracked blocking-force branch, the
    tip position past a full turn); arrays keep NaN."""
    L, EI = 0.02, 1e-5
    past = ia.solve_beam(-(KL_BLOCK_MAX + 1.0) * EI / L, L, EI)
    assert past.F_block is None and past.w is None and past.w_small is None
    arr = ia.solve_beam(np.array([-(KL_BLOCK_MAX + 1.0) * EI / L]), L, EI)
    assert math.isnan(arr.F_block[0])
    # against evaluate on a strip bent that far: the same outputs withheld
    strip = ia.Strip(length=0.2, thickness=20e-6, voltage=20.0)
    row = ia.evaluate(strip, on_invalid="nan")
    b = ia.solve_beam(row["M_A"], strip.length, ia.NAFION_LI.E * strip.I_p)
    for k in ("F_block", "w", "w_small"):
        assert (row[k] is None) == (getattr(b, k) is None), k
    assert row["F_block"] is None


def test_uq_file_with_a_nan_parameter_refused_by_name(tmp_path, capsys):
    from ipmc_asym.cli import main

    f = tmp_path / "u.toml"
    f.write_text('name = "n"\noutputs = ["tip_deflection"]\n[uncertain]\n'
                 'c_moy = {dist = "normal", mean = nan, sd = 60}\n')
    rc = main(["uq", str(f), "--samples", "128"])
    err = capsys.readouterr().err
    assert rc == 2 and err.count("\n") == 1 and "uncertain.c_moy.mean" in err and "finite" in err, err


def test_charge_takes_units_and_names_what_does_not_broadcast():
    """ia.charge reads the units people write as moment_integral does ("200um" is 2e-4 to the
    bit); shapes that do not broadcast, or a bad string, are one line naming the parameters."""
    import ipmc_asym as ia

    assert ia.charge("200um", "1V").sigma == ia.charge(2e-4, 1.0).sigma
    with pytest.raises(ValueError, match=r"^thickness and voltage must broadcast to one shape; got shapes \(2,\) and \(3,\)$"):
        ia.charge([1e-4, 2e-4], [1.0, -1.0, 2.0])
    with pytest.raises(ValueError, match="^thickness \\(total, 2e\\): cannot read 'abc' as a length"):
        ia.charge("abc", 1.0)
