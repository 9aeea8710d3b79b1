"""The forward model against independent references, and every caller against the forward model."""

import math

import numpy as np
import pytest

from ipmc_asym.beam.statics import solve_beam
from ipmc_asym.forward.estimate import evaluate
from ipmc_asym.forward.model import (
    CHECKS,
    MECHANICAL_KEYS,
    MOMENT_KEYS,
    TIP_POSITION_KEYS,
    assumption_warnings,
    forward,
)
from ipmc_asym.integral.api import moment
from ipmc_asym.model.params import NAFION_LI, Strip
from ipmc_asym.studies import calibrate, uq
from ipmc_asym.studies.scenes import run_scene
from ipmc_asym.studies.sweeps import sweep

RNG = np.random.default_rng(20261201)
N = 40
PTS = {"length": RNG.uniform(0.01, 0.04, N), "width": RNG.uniform(2e-3, 8e-3, N),
       "thickness": RNG.uniform(120e-6, 400e-6, N), "voltage": RNG.uniform(0.05, 1.5, N)}


def _fwd(**kw):
    return forward(PTS["length"], PTS["width"], PTS["thickness"], PTS["voltage"], **kw)


def test_moment_and_small_displacement_formulas():
    r = _fwd(fidelity="quadrature")
    m = moment(PTS["thickness"], PTS["voltage"], "constant", "quadrature")
    e, l = 0.5 * PTS["thickness"], 0.5 * PTS["width"]
    A5 = 6 * l * e * e * NAFION_LI.F * np.abs(PTS["voltage"]) * NAFION_LI.C_moy
    np.testing.assert_allclose(r.I, m.I, rtol=1e-15)
    np.testing.assert_allclose(r.M_A, A5 * m.I, rtol=1e-14)
    M, L = r.M_A, PTS["length"]
    EI = NAFION_LI.E * 4 * l * e**3 / 3
    np.testing.assert_allclose(r.theta, -M * L / EI, rtol=1e-14)  # eq. 12
    np.testing.assert_allclose(r.w_small, -M * L * L / (2 * EI), rtol=1e-14)  # eq. 13
    np.testing.assert_allclose(r.F_block_small, 3 * M / (2 * L), rtol=1e-14)  # eq. 14
    b = solve_beam(M, L, EI, e=e)
    for k in ("w", "x_tip", "y_tip", "F_block", "max_strain"):
        np.testing.assert_allclose(getattr(r, k), getattr(b, k), rtol=1e-14)
    assert np.all(r.moment_valid) and np.all(r.fidelity_used == "quadrature") and not np.any(r.escalated)
    # the beam checks as the formulas say: past a quarter turn, and the face strain e|M|/EI
    np.testing.assert_array_equal(r.beam_regime, np.abs(M * L / EI) <= np.pi / 2)
    np.testing.assert_array_equal(r.strain, e * np.abs(M) / EI <= 1e-2)


def test_broadcast_and_pair_code_give_the_same_values():
    th = np.array([200e-6, 300e-6])
    v = np.array([0.5, 1.0, 2.0])
    L = np.array([0.01, 0.02])
    grid = np.meshgrid(L, th, v, indexing="ij")
    code = np.meshgrid(np.zeros(2, int), np.arange(2), np.arange(3), indexing="ij")
    a = forward(grid[0].ravel(), 5e-3, grid[1].ravel(), grid[2].ravel(), fidelity="leading")
    b = forward(grid[0].ravel(), 5e-3, grid[1].ravel(), grid[2].ravel(), fidelity="leading",
                pair_code=(code[1] * 3 + code[2]).ravel())
    c = forward(L[:, None, None], 5e-3, th[None, :, None], v[None, None, :], fidelity="leading")
    for k in ("I", "M_A", "theta", "w", "F_block", "valid"):
        assert np.array_equal(getattr(a, k), getattr(b, k))
        assert np.array_equal(getattr(a, k), getattr(c, k).ravel())
    assert c.I.shape == (2, 2, 3)


def test_withholding_and_flags():
    # 0: fine; 1: huge voltage (multi-turn, strain above the limit, beyond the validated voltage);
    # 2: past a quarter turn with a small strain (a long strip);
    # 3: the leading rung invalid, no escalation (no valid rung)
    L = np.array([0.02, 0.02, 0.05, 0.02])
    th = np.array([200e-6, 200e-6, 200e-6, 2e-6])
    v = np.array([1.0, 30.0, 1.0, 1.0])
    r = forward(L, 5e-3, th, v, fidelity="leading", escalate=False)
    assert list(r.valid) == [True, False, False, False]
    assert list(r.moment_valid) == [True, True, True, False]
    assert r.withheld(0) == () and r.flagged(0) == []
    # a failed model assumption keeps every number; past a full turn the tip position is withheld
    assert not r.strain[1] and not r.voltage[1] and r.regime[1] == "multi-turn"
    assert r.withheld(1) == TIP_POSITION_KEYS and set(r.flagged(1)) == {"beam_regime", "blocked_regime", "strain", "voltage"}
    assert r.strain[2] and not r.beam_regime[2] and r.withheld(2) == () and r.flagged(2) == ["beam_regime"]
    assert r.withheld(3) == MOMENT_KEYS + MECHANICAL_KEYS and np.isnan(r.I[3]) and r.regime[3] == ""
    w = r.withhold()
    for k in MOMENT_KEYS + MECHANICAL_KEYS:
        got = np.isnan(getattr(w, k))
        want = np.array([k in r.withheld(i) for i in range(4)])
        assert np.array_equal(got, want | np.isnan(getattr(r, k))), k
    # what a flag concerns: the free strip past a quarter turn flags theta, not the blocking force
    assert list(r.flag_mask("theta")) == [False, True, True, False]
    assert list(r.flag_mask("F_block")) == [False, True, False, False]
    # the first invalid point is 1; its first failed assumption in the order of CHECKS, the line
    # assumption_warnings gives for it
    assert "multi-turn" in r.message and r.message == assumption_warnings(r, (1,))[0]
    assert r.checks_mask["voltage"] is not r.inputs["voltage"] and list(r.checks_mask["voltage"]) == list(r.voltage)
    assert r.checks(2) == {"electrochemistry": True, "layer_separation": True, "beam_regime": False,
                           "blocked_regime": True, "strain": True, "voltage": True, "slender": True}
    # the nominal strip at 5 V (kappa L = 7.4): the blocked strip itself passes a quarter turn,
    # F_block kept and flagged by its own check; at 3 V (kappa L = 3.6) only the free strip does
    b = forward(0.02, 5e-3, 200e-6, np.array([3.0, 5.0]), fidelity="leading")
    assert list(b.blocked_regime) == [True, False] and not np.any(b.beam_regime)
    from ipmc_asym.forward.model import blocked_rotation

    r2 = forward(PTS["length"] * 4, PTS["width"], PTS["thickness"], PTS["voltage"] * 4, fidelity="leading")
    assert r2.blocked_regime.any() and not r2.blocked_regime.all()
    assert np.array_equal(r2.blocked_regime, blocked_rotation(r2.theta) <= np.pi / 2)
    assert np.all(np.isfinite(b.F_block)) and list(b.flag_mask("F_block")) == [True, True]  # strain too
    assert any("blocked strip past a quarter turn" in w for w in assumption_warnings(b))
    # the blocked strip's largest rotation |m| (1 - psi/2) against a direct evaluation of
    # theta_b(t) = m [psi (t - t^2/2) - t] on a fine grid (independent of the closed form)
    from ipmc_asym.beam.statics import blocking_force_ratio
    from ipmc_asym.forward.model import blocked_rotation

    t = np.linspace(0, 1, 20001)
    for m in (0.3, 2.0, 6.0, 30.0):
        psi = float(blocking_force_ratio(m))
        assert float(blocked_rotation(m)) == pytest.approx(np.max(np.abs(m * (psi * (t - t * t / 2) - t))), rel=1e-9)


def test_strain_limit_is_a_material_property():
    s = Strip(thickness=10e-6)
    r = forward(s.length, s.width, s.thickness, s.voltage)
    assert not r.strain and r.max_strain > 0.01
    r2 = forward(s.length, s.width, s.thickness, s.voltage, material=NAFION_LI.with_(strain_limit=0.5))
    assert r2.strain and r2.max_strain == r.max_strain
    with pytest.raises(ValueError, match="strain_limit"):
        NAFION_LI.with_(strain_limit=5.0)


def test_evaluate_at_10um_returns_the_flagged_row():
    """A failed model assumption never raises: the row, I included, comes back flagged."""
    row = evaluate(Strip(thickness=10e-6), "constant")
    assert row["I"] is not None and row["theta"] is not None and row["F_block_small"] is not None
    assert not row["valid"] and not row["checks"]["strain"] and "strain" in row["flagged"]
    assert any("strain limit 0.01" in w and "STRAIN_LIMIT" in w for w in row["warnings"])


def test_evaluate_agrees_with_forward():
    for i in range(0, N, 7):
        s = Strip(length=PTS["length"][i], width=PTS["width"][i], thickness=PTS["thickness"][i],
                  voltage=PTS["voltage"][i])
        row = evaluate(s, "linear", "leading", on_invalid="nan")
        r = forward(s.length, s.width, s.thickness, s.voltage, model="linear", fidelity="leading")
        assert row["checks"] == r.checks() and row["valid"] == bool(r.valid)
        for k in ("I", "M_A", "B1") + MECHANICAL_KEYS:
            v = float(getattr(r, k))
            assert (row[k] is None) if k in r.withheld() else row[k] == v, k
        assert row["fidelity_used"] == str(r.fidelity_used) and row["error_estimate"] == float(r.error)


def test_sweep_agrees_with_forward():
    vary = {"thickness": np.array([100e-6, 250e-6]), "voltage": np.array([0.2, 1.0, 3.0])}
    arr = sweep(vary, model="affine", fidelity="corrected")
    r = forward(0.02, 5e-3, arr["thickness"], arr["voltage"], model="affine", fidelity="corrected")
    rw = r.withhold()  # the sweep withholds what evaluate withholds (NaN here)
    for k in ("I", "M_A", "theta", "w", "w_small", "F_block", "F_block_small", "B1", "error", "max_strain",
              "regime", "fidelity_used", "valid"):
        assert np.array_equal(arr[k], getattr(rw, k), equal_nan=arr[k].dtype.kind == "f"), k
    for c in CHECKS:
        assert np.array_equal(arr["check_" + c], getattr(r, c))


def test_scene_agrees_with_forward():
    v = [0.3, 0.9, 1.4]
    res = run_scene({"strip": {"length": "2cm", "width": "5mm", "thickness": "200um"}, "voltages": [f"{x}V" for x in v],
                     "outputs": ["I", "moment", "rotation", "tip_deflection", "blocking_force"],
                     "tolerance": 0.01})
    p = [res["points"][i] for i in range(len(v))]
    r = forward(*(np.array([q[k] for q in p]) for k in ("length", "width", "thickness", "voltage")),
                fidelity="leading", tol=0.01)
    np.testing.assert_array_equal(res["outputs"]["I"]["values"], r.I)
    np.testing.assert_array_equal(res["outputs"]["moment"]["values"], r.M_A)
    np.testing.assert_array_equal(res["outputs"]["rotation"]["values"], r.theta)
    assert res["outputs"]["I"]["fidelity"] == list(r.fidelity_used)
    for i, chk in enumerate(res["checks"]):
        assert {c: chk[c] for c in CHECKS} == r.checks(i)
    big = np.where(r.small_error <= 0.01, r.w_small, r.w)
    np.testing.assert_array_equal(res["outputs"]["tip_deflection"]["values"], big)


def test_uq_samples_agree_with_forward():
    n = 500
    cols = {"length": RNG.uniform(0.015, 0.025, n), "width": RNG.uniform(4e-3, 6e-3, n),
            "thickness": RNG.uniform(150e-6, 250e-6, n), "voltage": RNG.uniform(0.5, 1.5, n),
            "modulus": RNG.uniform(1e8, 1.6e8, n), "c_moy": RNG.uniform(2900, 3200, n)}
    out, counts, checks, _ = uq.evaluate_samples(cols, ["I", "moment", "rotation", "tip_deflection", "blocking_force"],
                                                 "constant", NAFION_LI, 1e-3)
    assert sum(counts.values()) == n
    # per-sample c_moy: each sample against forward with that material
    for i in range(0, n, 97):
        mat = NAFION_LI.with_(E=float(cols["modulus"][i]), c_moy=float(cols["c_moy"][i]))
        r = forward(cols["length"][i], cols["width"][i], cols["thickness"][i], cols["voltage"][i], material=mat,
                    fidelity="leading", tol=1e-3)
        for k, a in (("I", "I"), ("moment", "M_A"), ("rotation", "theta"), ("tip_deflection", "w")):
            assert math.isclose(out[k][i], float(getattr(r, a)), rel_tol=1e-12), k
        assert math.isclose(out["blocking_force"][i], float(r.F_block_small), rel_tol=1e-12)


def test_calibrate_predict_agrees_with_forward():
    geom = {k: PTS[k] for k in ("length", "width", "thickness", "voltage")}
    out, errs, valid = calibrate.predict({"modulus": 1.5e8}, geom, "constant", "corrected")
    r = forward(geom["length"], geom["width"], geom["thickness"], geom["voltage"], fidelity="corrected",
                escalate=False, material=NAFION_LI.with_(E=1.5e8))
    np.testing.assert_array_equal(out["deflection"], np.abs(r.w))
    np.testing.assert_array_equal(out["blocking_force"], np.abs(r.F_block))
    np.testing.assert_array_equal(valid, r.moment_valid)


def test_bad_input_is_refused():
    with pytest.raises(ValueError, match="tol"):
        forward(0.02, 5e-3, 200e-6, 1.0, tol=2.0)
    with pytest.raises(ValueError, match="thickness"):
        forward(0.02, 5e-3, 1e-12, 1.0)


def test_step_uq_figures_and_estimate_agree_on_every_points_checks():
    """Random strips, some outside each model assumption: estimate, uq's samples, the sweep rows
    the figures draw (and their dotted-curve rule) and step's time points report the same checks."""
    from ipmc_asym.dynamics.circuit import step_response
    from ipmc_asym.forward.model import ASSUMPTION_CHECKS, FLAGS, flag_mask

    rng = np.random.default_rng(18)
    n = 24
    L = np.exp(rng.uniform(np.log(5e-3), np.log(5e-2), n))
    wd = np.exp(rng.uniform(np.log(1e-3), np.log(2e-2), n))
    th = np.exp(rng.uniform(np.log(20e-6), np.log(2e-3), n))
    v = rng.choice([-1, 1], n) * np.where(rng.random(n) < 0.8, rng.uniform(0.05, 15.0, n), rng.uniform(25.0, 40.0, n))
    rows = [evaluate(Strip(length=L[i], width=wd[i], thickness=th[i], voltage=v[i]), "constant") for i in range(n)]
    est = {c: np.array([r["checks"][c] for r in rows]) for c in CHECKS}
    for c in ASSUMPTION_CHECKS:  # the draw reaches both sides of every assumption
        assert est[c].any() and not est[c].all(), c
    # uq's per-sample evaluation
    cols = {"length": L, "width": wd, "thickness": th, "voltage": v, "modulus": np.full(n, NAFION_LI.E),
            "c_moy": np.full(n, NAFION_LI.C_moy)}
    _, _, uchk, _ = uq.evaluate_samples(cols, ["rotation"], "constant", NAFION_LI, 1e-3, fidelity="quadrature")
    for c in CHECKS:
        assert np.array_equal(uchk[c], est[c]), c
    # the figures: sweep rows and the dotted-curve rule, one point at a time
    for i in range(n):
        a = sweep({"voltage": np.array([v[i]])}, "constant", "quadrature",
                  Strip(length=L[i], width=wd[i], thickness=th[i], voltage=v[i]))
        assert {c: bool(a["check_" + c][0]) for c in CHECKS} == rows[i]["checks"]
        for q in ("w", "F_block", "theta"):
            want = any(not rows[i]["checks"][c] for c, keys in FLAGS.items() if q in keys)
            assert bool(flag_mask(lambda c: a["check_" + c], q)[0]) == want
    # step: each time point against estimate at that point's layer voltage (the voltage check
    # also sees the applied voltage)
    for i in range(0, n, 4):
        s = Strip(length=L[i], width=wd[i], thickness=th[i], voltage=v[i])
        r = step_response(v[i], strip=s, points=4)
        for j in range(1, 4):
            ev = evaluate(s.with_(voltage=float(r.layer_voltage[j])), "constant")["checks"]
            ev["voltage"] = ev["voltage"] and abs(r.phi0[j]) <= 20.0
            assert {c: bool(r.checks[c][j]) for c in CHECKS} == ev, (i, j)


@pytest.mark.parametrize("strain", [0.0100004, 0.01000000000000001, 0.0116, 0.5])
def test_a_strain_just_past_its_limit_reads_past_it(strain):
    """The strain the warning shows is above the limit it names (0.0100004 read '0.01 > 0.01')."""
    import re

    from ipmc_asym.forward.model import strain_reason

    shown = re.search(r"e\|kappa\| = (\S+) > strain limit (\S+) ", strain_reason(strain, 0.01))
    assert float(shown.group(1)) > float(shown.group(2)) == 0.01
