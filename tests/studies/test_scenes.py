"""Scenes: planner escalation, reported fidelity/error, malformed input (ipmc_asym.studies.scenes)."""

import json
import math

import numpy as np
import pytest
from references import REPO

from ipmc_asym.beam.statics import blocking_force_large, tip_position
from ipmc_asym.bvp.solver import solve
from ipmc_asym.integral.api import moment
from ipmc_asym.model.params import NAFION_LI, Strip
from ipmc_asym.studies.profiles import layer_widths
from ipmc_asym.studies.scenes import LADDER, run_scene

EX = REPO / "examples"


def _A5(th, width, v):
    m = NAFION_LI
    return 6.0 * (0.5 * width) * (0.5 * th) ** 2 * m.F * abs(v) * m.C_moy


def test_nominal():
    r = run_scene(EX / "nominal.toml")
    assert r["scene"] == "nominal" and len(r["points"]) == 1
    out = r["outputs"]
    assert set(out) == {"I", "moment", "tip_deflection", "rotation", "blocking_force"}
    tol = r["tolerance"]
    for k, o in out.items():
        assert o["fidelity"] == ["leading"], k  # leading meets 1e-2 at nominal
        assert 0 < o["error_estimate"][0] <= tol
    ref = moment(200e-6, 1.0, "constant", "bvp").I
    I = out["I"]["values"][0]
    assert abs(I - ref) / abs(ref) <= out["I"]["error_estimate"][0] * 10
    M = _A5(200e-6, 5e-3, 1.0) * float(ref)
    assert out["moment"]["values"][0] == pytest.approx(M, rel=2 * tol)
    EI = NAFION_LI.E * 4.0 / 3.0 * 2.5e-3 * (100e-6) ** 3
    assert out["rotation"]["values"][0] == pytest.approx(-M * 0.02 / EI, rel=2 * tol)
    # |theta| ~ 0.87 rad: the small-displacement deflection is off by > 1 %, so the arc is used
    assert out["tip_deflection"]["beam"] == ["large"]
    assert out["tip_deflection"]["values"][0] == pytest.approx(float(tip_position(M, 0.02, EI)[1]), rel=2 * tol)
    assert out["blocking_force"]["beam"] == ["small"]
    assert out["blocking_force"]["values"][0] == pytest.approx(float(blocking_force_large(M, 0.02, EI)), rel=2 * tol)


def test_thickness_sweep_and_fit():
    r = run_scene(EX / "thickness_sweep.toml")
    th = np.array([p["thickness"] for p in r["points"]])
    assert th.size == 8 and th[0] == pytest.approx(50e-6) and th[-1] == pytest.approx(1e-3)
    assert r["swept"] == ["thickness"]
    I = np.array(r["outputs"]["I"]["values"])
    err = np.array(r["outputs"]["I"]["error_estimate"])
    assert np.all(err <= r["tolerance"])
    assert np.all(np.diff(I) < 0)  # I decreases with thickness
    ref = moment(th, 1.0, "affine", "quadrature").I
    assert np.all(np.abs(I - ref) / np.abs(ref) <= np.maximum(err, 1e-12) * 10)
    fit = r["outputs"]["scaling_fit"]
    assert fit["variable"] == "thickness"
    assert fit["fits"]["I"]["exponent"] == pytest.approx(-1.0, abs=0.02)  # I ~ 1/e
    assert fit["fits"]["moment"]["exponent"] == pytest.approx(1.0, abs=0.02)  # M ~ e^2 I ~ e
    assert abs(fit["fits"]["I"]["correlation"]) > 0.999
    # cheapest first: the thick end passes at leading, the thin end needed more
    fids = r["outputs"]["I"]["fidelity"]
    assert fids[-1] == "leading" and fids[0] != "leading"


def test_tight_tolerance_escalates():
    r = run_scene(EX / "tight_tolerance.toml")
    tol = r["tolerance"]
    assert tol == 1e-6
    out = r["outputs"]
    f = out["I"]["fidelity"][0]
    assert LADDER.index(f) > LADDER.index("leading")
    assert out["I"]["error_estimate"][0] <= tol
    lead = moment(100e-6, 2.0, "linear", "leading")
    assert float(lead.error) > tol  # the escalation was necessary
    ref = float(moment(100e-6, 2.0, "linear", "bvp").I)
    assert abs(out["I"]["values"][0] - ref) / abs(ref) < 1e-8
    assert out["blocking_force"]["beam"] == ["large"]  # small formula is off by more than 1e-6
    prof = out["profiles"]
    assert prof["fidelity"] == "bvp"
    p0 = prof["values"][0]
    assert p0["I"] == pytest.approx(ref, rel=1e-9)
    assert 0 < p0["anode_layer"]["width_m"] < 100e-6 / 2


def test_escalates_to_exact_where_layers_overlap():
    # 2e = 0.2 um at 1 V: the anode layer alone (~0.2 um, tests/studies/test_profiles.py) fills the
    # strip, so no closed form or quadrature is valid and the planner must end on 'exact'
    # (valid at any thickness), checked against the BVP
    r = run_scene({"model": "constant", "voltage": 1.0, "strip": {"thickness": "0.2um"},
                   "outputs": ["I"], "tolerance": 1e-3})
    assert r["outputs"]["I"]["fidelity"] == ["exact"]
    ref = solve(Strip(thickness=0.2e-6), "constant")
    assert r["outputs"]["I"]["values"][0] == pytest.approx(ref.I, rel=1e-8)


def test_layer_widths_mirror_with_the_voltage():
    # the anode is the face at the higher potential: a negative voltage mirrors the strip,
    # the layer widths are the same
    r = run_scene({"voltages": [-1, 1], "outputs": ["profiles"]})
    neg, pos = r["outputs"]["profiles"]["values"]
    for side in ("anode_layer", "cathode_layer"):
        assert neg[side]["width_m"] == pytest.approx(pos[side]["width_m"], rel=1e-6)
    # and they are the widths of ipmc_asym.studies.profiles (one set of definitions)
    w = layer_widths(solve(Strip(), "constant"), 100e-6)
    assert pos["anode_layer"]["width_m"] == pytest.approx(w["devoid_um"] * 1e-6, rel=1e-12)
    assert pos["cathode_layer"]["width_m"] == pytest.approx(w["accumulation_um"] * 1e-6, rel=1e-12)


def test_custom_eps_forces_bvp():
    r = run_scene({"model": lambda C: 5e-6 + 0.0 * C, "voltage": 1.0, "outputs": ["I"]})
    assert r["outputs"]["I"]["fidelity"] == ["bvp"]
    assert r["outputs"]["I"]["values"][0] == pytest.approx(float(moment(200e-6, 1.0, "constant").I), rel=1e-6)


def test_voltages_list_and_negative():
    r = run_scene({"voltages": ["-1V", "500mV", 0], "outputs": ["I", "tip_deflection"]})
    I = r["outputs"]["I"]["values"]
    assert I[0] < 0 < I[1] and I[2] == 0.0
    assert r["outputs"]["tip_deflection"]["values"][2] == 0.0


def test_json_cli(capsys):
    from ipmc_asym.cli import main

    assert main(["scene", str(EX / "nominal.toml"), "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["scene"] == "nominal" and "I" in d["outputs"]


@pytest.mark.parametrize("scene, key", [
    ({"voltage": 1, "colour": "red"}, "colour"),
    ({"voltage": 1, "strip": {"thikness": 1e-4}}, "thikness"),
    ({"voltage": 1, "material": {"E": "abc"}}, "material.E"),
    ({"voltage": 1, "material": {"phi4": 1.5}}, "phi4"),
    ({"voltage": 1, "material": {"preset": "gold"}}, "preset"),
    ({"voltage": 1, "strip": {"thickness": "-2um"}}, "strip.thickness"),
    ({"voltage": 1, "strip": {"thickness": [1, 2]}}, "strip.thickness"),
    ({"voltage": "1 furlong"}, "voltage"),
    ({"voltage": 1, "outputs": ["I", "colour"]}, "colour"),
    ({"voltage": 1, "outputs": "I"}, "outputs"),
    ({"voltage": 1, "tolerance": -1}, "tolerance"),
    ({"voltage": 1, "tolerance": "tight"}, "tolerance"),
    ({"voltage": 1, "model": "quadratic"}, "model"),
    ({"strip": {}}, "voltage"),
    ({"voltage": 1, "voltages": [1, 2]}, "voltage"),
    ({"voltage": 1, "sweep": {"thickness": {"start": 1e-4, "stop": 1e-3}}}, "sweep.thickness.n"),
    ({"voltage": 1, "sweep": {"thickness": {"start": 1e-4, "stop": 1e-3, "n": 3, "step": 2}}}, "step"),
    ({"voltage": 1, "sweep": {"temperature": [1, 2]}}, "temperature"),
    ({"voltage": 1, "outputs": ["scaling_fit"]}, "scaling_fit"),
])
def test_malformed_names_key(scene, key):
    with pytest.raises(ValueError, match=key.replace(".", r"\.")):
        run_scene(scene)


def test_bad_files(tmp_path, capsys):
    from ipmc_asym.cli import main

    with pytest.raises(ValueError, match="missing.toml"):
        run_scene(tmp_path / "missing.toml")
    bad = tmp_path / "bad.toml"
    bad.write_text("voltage = = 1\n")
    with pytest.raises(ValueError, match="not valid TOML"):
        run_scene(bad)
    unk = tmp_path / "unk.toml"
    unk.write_text('voltage = 1\n[strips]\nlength = 0.02\n')
    assert main(["scene", str(unk)]) == 2
    err = capsys.readouterr().err
    assert "strips" in err and len(err.strip().splitlines()) == 1


def test_only_requested_outputs():
    r = run_scene({"voltage": 1, "outputs": ["rotation"]})
    assert list(r["outputs"]) == ["rotation"]
    assert math.isfinite(r["outputs"]["rotation"]["values"][0])


def test_a_uq_scene_runs_as_a_plain_scene_at_its_nominal_values():
    """examples/uq_nominal.toml: `scene` evaluates the nominal strip and says the table is for uq."""
    from ipmc_asym import moment_integral

    res = run_scene(str(REPO / "examples" / "uq_nominal.toml"))
    assert any("uncertain" in n for n in res["notes"])
    p = res["points"][0]
    ref = moment_integral(p["thickness"], p["voltage"], res["model"], "quadrature")
    assert res["outputs"]["I"]["values"][0] == pytest.approx(ref, rel=2 * res["tolerance"])


def test_pressure_term_scene():
    from ipmc_asym.forward.model import forward

    sc = {"model": "affine", "voltage": "1V", "outputs": ["I", "moment"], "pressure_term": True}
    r = run_scene(sc)
    ref = forward(0.02, 5e-3, 200e-6, 1.0, model="affine", fidelity="bvp", pressure_term=True, escalate=False)
    assert r["outputs"]["I"]["values"][0] == pytest.approx(float(ref.I), rel=1e-10)
    plain = run_scene({k: v for k, v in sc.items() if k != "pressure_term"})
    assert abs(plain["outputs"]["I"]["values"][0] / r["outputs"]["I"]["values"][0] - 1.0) > 1e-3
    with pytest.raises(ValueError, match="pressure_term"):
        run_scene({**sc, "pressure_term": "yes"})
    with pytest.raises(ValueError, match="profiles"):
        run_scene({**sc, "outputs": ["profiles"]})


def test_scene_profiles_of_a_negative_voltage_are_the_mirror_image():
    """-V is +V mirrored: the cathode's concentration B1 and the layer widths are the same, I
    changes sign (B1 is the cathode's concentration: at z = +1 for a positive voltage only)."""
    from ipmc_asym.studies.scenes import run_scene

    res = run_scene({"name": "pm", "model": "linear", "outputs": ["profiles", "I"], "strip": {"thickness": "100um"},
                     "sweep": {"voltage": ["-2V", "2V"]}})
    neg, pos = res["outputs"]["profiles"]["values"]
    assert pos["B1"] > 1.5 and neg["B1"] == pytest.approx(pos["B1"], rel=1e-9)
    assert neg["I"] == pytest.approx(-pos["I"], rel=1e-9)
    for k in ("anode_layer", "cathode_layer"):
        assert neg[k]["width_m"] == pytest.approx(pos[k]["width_m"], rel=1e-9)
