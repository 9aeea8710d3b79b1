"""``freq --export`` at its defaults meets its tolerance, and ``ia.load_export`` reads it back.

The reference is :func:`ipmc_asym.transfer_function`'s full model (``frequency_response``, the
exact linearised PNP) evaluated independently of the file: the loaded models, their state space
and the python-control objects built from them must agree with it within the stated error.
"""

import json

import numpy as np
import pytest

import ipmc_asym as ia
from ipmc_asym.cli import main
from ipmc_asym.model.params import Strip

BAND = (0.01, 1000.0)


@pytest.fixture(scope="module")
def export(tmp_path_factory):
    p = tmp_path_factory.mktemp("export") / "tf.json"
    assert main(["freq", "--from", "0.01Hz", "--to", "1kHz", "--points", "5", "--export", str(p)]) == 0
    return p


def test_export_defaults_meet_their_tolerance(export, capsys):
    doc = json.loads(export.read_text())
    for o in ("w", "charge"):
        m = doc["models"][o]
        assert m["success"] and m["max_rel_error"] < 1e-4, m["message"]


def test_load_export_against_the_full_model(export):
    exp = ia.load_export(export)
    assert set(exp.models) == {"w", "charge"}
    assert exp.thickness_total == Strip().thickness
    f = np.geomspace(*BAND, 37)
    full = ia.frequency_response(f, strip=Strip())  # the model the export fitted, evaluated anew
    s = 2j * np.pi * f
    # charge per volt = current per volt / s = 1 / (s Z), Z of the whole strip (electrode area 2l L)
    for o, H in (("w", full.H_w), ("charge", 1.0 / (s * full.Z))):
        got = exp.frequency_response(f, o)
        assert np.max(np.abs(got / H - 1)) < 1e-4
        A, B, C, D = exp[o].state_space()
        ss = np.array([(C @ np.linalg.solve(si * np.eye(A.shape[0]) - A, B) + D)[0, 0] for si in s])
        assert np.max(np.abs(ss / H - 1)) < 1e-4


def test_load_export_to_python_control(export):
    control = pytest.importorskip("control")
    exp = ia.load_export(export)
    f = np.geomspace(*BAND, 11)
    H = ia.frequency_response(f, strip=Strip()).H_w
    sys_ss = exp.to_control("w")
    sys_tf = exp.to_control("w", form="tf")
    assert isinstance(sys_ss, control.StateSpace) and isinstance(sys_tf, control.TransferFunction)
    for sys_ in (sys_ss, sys_tf):
        got = np.array([complex(sys_(2j * np.pi * fi)) for fi in f])
        assert np.max(np.abs(got / H - 1)) < 1e-4


def test_load_export_bad_file_one_line(tmp_path):
    bad = tmp_path / "bad.json"
    bad.write_text("{not json")
    with pytest.raises(ValueError, match="not a JSON file"):
        ia.load_export(bad)
    bad.write_text(json.dumps({"models": {"w": {"output": "w"}}}))
    with pytest.raises(ValueError, match="no key 'poles'"):
        ia.load_export(bad)


def test_load_export_is_transfer_function_undamped_beam(tmp_path):
    """With the undamped dynamic beam (resonances on the imaginary axis) the file still meets its
    tolerance, and the loaded model is ``transfer_function``'s own (JSON keeps every digit)."""
    p = tmp_path / "dyn.json"
    assert main(["freq", "--from", "0.01Hz", "--to", "1kHz", "--points", "5", "--beam", "dynamic",
                 "--export", str(p)]) == 0
    exp = ia.load_export(p)
    assert exp["w"].success and exp["w"].max_rel_error < 1e-4
    tf = ia.transfer_function(*BAND, beam="dynamic", output="w")
    f = np.geomspace(*BAND, 301)
    assert np.array_equal(exp.frequency_response(f, "w"), tf(f))
    H = ia.frequency_response(f, beam="dynamic").H_w
    assert np.max(np.abs(exp.frequency_response(f, "w") / H - 1)) < 1e-4


def test_w_and_F_phases_one_convention():
    """Quasi-static small displacements: ``w = -M L^2/(2 EI)``, ``F = 3 M/(2 L)`` (eqs (13), (14)), so
    ``H_F/H_w = -3 EI/L^3`` at every frequency: both phases are ``arg H`` of the signed output, 180 deg
    apart (the docs' convention), not of opposite sign conventions."""
    s = Strip()
    f = np.geomspace(0.1, 100.0, 7)
    r = ia.frequency_response(f, strip=s)
    EI = ia.NAFION_LI.E * s.width * s.thickness**3 / 12.0
    assert np.allclose(r.H_F / r.H_w, -3.0 * EI / s.length**3, rtol=1e-9)
    d = np.degrees(np.angle(r.H_F) - r.w_phase) % 360.0
    assert np.allclose(d, 180.0, atol=1e-9)
