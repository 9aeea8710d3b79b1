"""The notes of a dynamic result say the diffusion coefficient the run used."""

from ipmc_asym.dynamics.circuit import frequency_response, step_response
from ipmc_asym.dynamics.drive import drive_info
from ipmc_asym.model.params import D_CATION_SOURCE, NAFION_LI, NOMINAL_STRIP


def _d_note(notes):
    (note,) = [n for n in notes if "diffusion coefficient D" in n]
    return note


def test_default_d_cites_its_source():
    r = frequency_response([1.0, 10.0])
    assert D_CATION_SOURCE in _d_note(r.notes)


def test_given_d_is_the_one_stated():
    m = NAFION_LI.with_(D=3e-10)
    for notes in (frequency_response([1.0, 10.0], material=m).notes,
                  step_response(0.1, duration=0.01, points=5, material=m).notes,
                  drive_info(NOMINAL_STRIP, "constant", m)["notes"]):
        note = _d_note(notes)
        assert "D = 3e-10 m^2/s" in note
        assert "D = 1e-10 m^2/s is an assumption" not in note
