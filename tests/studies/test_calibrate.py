"""Calibration: synthetic round trip, identifiability, CSV errors.

The synthetic data come from :func:`ipmc_asym.forward.estimate.evaluate` (the scalar, per-strip path
at ``quadrature``), not from the vectorised predictor the fit uses.
"""

import json
import math

import numpy as np
import pytest

from ipmc_asym.forward.estimate import evaluate
from ipmc_asym.model.params import NAFION_LI, Strip
from ipmc_asym.studies.calibrate import fit, read_data

TRUE = {"modulus": 1.0e8, "c_moy": 2600.0}
VOLTS = np.linspace(0.2, 1.2, 8)
THICK = (200e-6, 300e-6)
LENGTH = 0.015


def _truth_rows():
    mat = NAFION_LI.with_(E=TRUE["modulus"], c_moy=TRUE["c_moy"])
    rows = []
    for t in THICK:
        for v in VOLTS:
            r = evaluate(Strip(length=LENGTH, width=5e-3, thickness=t, voltage=float(v)), "constant",
                         "quadrature", mat)
            # the round trip stays inside a quarter turn (where the beam model holds)
            assert abs(r["theta"]) < math.pi / 2
            rows.append((t, float(v), abs(r["w"]), abs(r["F_block"])))
    return rows


def _write(path, rows, seed, cols=("deflection", "blocking_force"), sigma=True, noise=0.02):
    rng = np.random.default_rng(seed)
    hdr = ["length", "thickness", "voltage"] + list(cols) + ([f"sigma_{c}" for c in cols] if sigma else [])
    lines = [",".join(hdr)]
    for t, v, w, f in rows:
        true = {"deflection": w, "blocking_force": f}
        meas = [true[c] * (1 + noise * rng.standard_normal()) for c in cols]
        sig = [noise * true[c] for c in cols] if sigma else []
        # thickness written with units: the reader must convert (200um -> 2e-4 m)
        lines.append(",".join([f"{LENGTH * 100:.6g}cm", f"{t * 1e6:.6g}um", f"{v:.6g}V"]
                              + [repr(x) for x in meas + sig]))
    path.write_text("\n".join(lines) + "\n")
    return path


@pytest.fixture(scope="module")
def truth_rows():
    return _truth_rows()


@pytest.mark.slow
def test_round_trip_ten_seeds(truth_rows, tmp_path):
    """Known modulus and c_moy + 2 % noise: within 5 % and inside the 95 % interval for >= 8 of seeds 0-9."""
    good = 0
    for seed in range(10):
        d = read_data(_write(tmp_path / f"d{seed}.csv", truth_rows, seed), Strip(width=5e-3))
        r = fit(d, ["modulus", "c_moy"], model="constant")
        ok = True
        for k, true in TRUE.items():
            p = r.parameters[k]
            assert p["identifiable"], (seed, k, r.message)
            lo, hi = p["ci95"]
            ok &= abs(p["value"] / true - 1) < 0.05 and lo <= true <= hi
        good += ok
        assert r.n_points == 2 * len(truth_rows)
        assert {"parameters", "correlation", "chi2_red", "n_points", "fidelity", "model"} <= set(r.as_dict())
    assert good >= 8, good


def test_force_only_modulus_not_identifiable(truth_rows, tmp_path):
    """Force sees M_A only (E enters through psi(kappa L) at the 1e-4 level): modulus not identifiable."""
    d = read_data(_write(tmp_path / "f.csv", truth_rows, 0, cols=("blocking_force",)), Strip(width=5e-3))
    r = fit(d, ["modulus", "c_moy"])
    m = r.parameters["modulus"]
    assert m["identifiable"] is False
    assert m["stderr"] is None and None in m["ci95"]
    assert r.correlation[0][1] is None
    c = r.parameters["c_moy"]
    assert c["identifiable"] and c["ci95"][0] <= TRUE["c_moy"] <= c["ci95"][1]
    assert "modulus not identifiable" in r.message


def test_no_sigma_scale_from_residuals(truth_rows, tmp_path):
    """Without sigma columns the noise scale is estimated (2 % relative noise -> s ~ 0.02) and
    chi2_red, 1 by construction, is not reported as a goodness of fit."""
    d = read_data(_write(tmp_path / "n.csv", truth_rows, 3, sigma=False), Strip(width=5e-3))
    r = fit(d, "modulus,c_moy")
    assert r.chi2_red is None and "by construction" in r.chi2_note
    assert 0.5 * 0.02 < r.noise_scale < 2 * 0.02
    for k, true in TRUE.items():
        lo, hi = r.parameters[k]["ci95"]
        assert lo < true < hi


def test_no_degree_of_freedom_reports_no_goodness_of_fit(truth_rows, tmp_path):
    """With sigma, as many free parameters as values is allowed (the fit is exact), but
    chi2/(n - p) is 0/0 there: no chi2_red, no noise scale, and a note that says why, not NaN."""
    p = _write(tmp_path / "one.csv", truth_rows[:1], 0, cols=("blocking_force",), sigma=True)
    r = fit(read_data(p, Strip(width=5e-3)), "modulus", fidelity="leading")
    assert r.n_points == 1 and r.chi2_red is None and r.noise_scale is None
    assert "no degree of freedom" in r.chi2_note
    assert "nan" not in json.dumps(r.as_dict(), allow_nan=False).lower()


def test_too_many_parameters_refused(truth_rows, tmp_path):
    p = _write(tmp_path / "s.csv", truth_rows[:2], 0, cols=("blocking_force",), sigma=False)
    with pytest.raises(ValueError, match="too many free parameters") as ei:
        fit(read_data(p), ["modulus", "c_moy"])
    assert "\n" not in str(ei.value)


@pytest.mark.parametrize("text, where", [
    ("thickness,voltage,deflection\n200um,1V,abc\n", "row 2, column 'deflection'"),
    ("thickness,voltage,deflection\n200um,1V,1mm\n200um,2parsecs,1mm\n", "row 3, column 'voltage'"),
    ("thickness,volts,deflection\n200um,1,1e-3\n", "column 2 'volts'"),
    ("thickness,voltage\n200um,1\n", "no measured column"),
    ("thickness,voltage,deflection\n200um,1,-1e-3\n", "row 2, column 'deflection'"),
    ("thickness,voltage,deflection,sigma_deflection\n200um,1,1e-3,\n", "row 2, column 'sigma_deflection'"),
    ("thickness,voltage,deflection\n200um,1\n", "row 2: 2 fields"),
])
def test_bad_files_one_line(tmp_path, text, where):
    p = tmp_path / "bad.csv"
    p.write_text(text)
    with pytest.raises(ValueError) as ei:
        read_data(p)
    msg = str(ei.value)
    assert where in msg and "\n" not in msg


def test_units_and_defaults(tmp_path):
    p = tmp_path / "u.csv"
    p.write_text("thickness,voltage,blocking_force\n0.2mm,500mV,1.5mN\n")
    d = read_data(p, Strip(length=0.03))
    assert d.geometry["thickness"][0] == pytest.approx(2e-4)
    assert d.geometry["voltage"][0] == pytest.approx(0.5)
    assert d.geometry["length"][0] == 0.03 and d.geometry["width"][0] == 5e-3
    assert d.measured["blocking_force"][0] == pytest.approx(1.5e-3)


def test_unknown_free_parameter():
    from ipmc_asym.studies.calibrate import parse_free

    with pytest.raises(ValueError, match="unknown parameter 'young'"):
        parse_free("young")
    assert parse_free("modulus=50MPa:500MPa")["modulus"] == pytest.approx((5e7, 5e8))


def test_precise_data_escalate_fidelity(truth_rows, tmp_path):
    """1e-5 data: leading (error ~1e-3) is refused; the estimates then hit the truth to ~1e-5."""
    d = read_data(_write(tmp_path / "p.csv", truth_rows, 0, noise=1e-5), Strip(width=5e-3))
    r = fit(d, ["modulus", "c_moy"])
    assert r.fidelity in ("corrected", "quadrature")
    assert "leading:" in r.message
    for k, true in TRUE.items():
        assert abs(r.parameters[k]["value"] / true - 1) < 1e-3
        lo, hi = r.parameters[k]["ci95"]
        assert lo <= true <= hi


def test_rows_outside_a_model_assumption_are_flagged(tmp_path):
    """Data at large rotation: the fit says which rows' fitted states fail an assumption, as
    evaluate flags them at the fitted parameters (independent: |theta| = |M| L/(E I_p) > pi/2)."""
    mat = NAFION_LI.with_(E=TRUE["modulus"], c_moy=TRUE["c_moy"])
    rows = []
    for v in (0.3, 0.6, 1.0, 1.5, 2.0, 2.5):
        r = evaluate(Strip(length=0.03, width=5e-3, thickness=200e-6, voltage=v), "constant", "quadrature", mat)
        rows.append((200e-6, v, abs(r["theta"]), abs(r["F_block"])))
    p = tmp_path / "big.csv"
    rng = np.random.default_rng(5)
    lines = ["length,thickness,voltage,blocking_force,sigma_blocking_force"] + [
        f"3cm,{t * 1e6:g}um,{v}V,{f * (1 + 0.01 * rng.standard_normal())!r},{0.01 * f!r}" for t, v, _, f in rows]
    p.write_text("\n".join(lines) + "\n")
    res = fit(read_data(p, Strip(width=5e-3)), ["c_moy"], material=mat)
    E, Ip = mat.E, Strip(width=5e-3).I_p
    c_fit = res.parameters["c_moy"]["value"]
    want = []
    for i, (t, v, _, _) in enumerate(rows):
        e = evaluate(Strip(length=0.03, width=5e-3, thickness=t, voltage=v), "constant", "quadrature",
                     mat.with_(c_moy=c_fit))
        assert (abs(e["M_A"]) * 0.03 / (E * Ip) > math.pi / 2) == (not e["checks"]["beam_regime"])
        if not e["checks"]["beam_regime"]:
            want.append(i)
    assert want and res.flagged_rows.get("beam_regime") == want
    assert "outside a model assumption" in res.message and "beam_regime" in res.message
# ---- honest output: what the numbers mean --------------------------------------------------
def test_excel_bom_and_case_insensitive_header(tmp_path):
    """Excel's "CSV UTF-8" starts with a byte-order mark; header case does not matter."""
    p = tmp_path / "excel.csv"
    p.write_bytes("\ufeffThickness,VOLTAGE,Deflection\r\n200um,1V,1mm\r\n".encode("utf-8"))
    d = read_data(p)
    assert d.geometry["thickness"][0] == pytest.approx(2e-4) and d.measured["deflection"][0] == pytest.approx(1e-3)


@pytest.mark.parametrize("text, where", [
    # a 2 cm strip (the default length) cannot deflect 800 m, nor 2 cm: the arc's tip stays within 0.72 L
    ("voltage,deflection\n1V,1mm\n1V,800m\n", "row 3, column 'deflection'"),
    ("length,voltage,deflection\n1cm,1V,1cm\n", "row 2, column 'deflection'"),
    ("voltage,blocking_force\n1V,-1mN\n", "row 2, column 'blocking_force'"),
    ("voltage,deflection,sigma_deflection\n1V,1mm,-1um\n", "row 2, column 'sigma_deflection'"),
    ("voltage,deflection\n1V,inf\n", "row 2, column 'deflection'"),
])
def test_impossible_rows_refused_naming_the_row(tmp_path, text, where):
    p = tmp_path / "bad.csv"
    p.write_text(text)
    with pytest.raises(ValueError) as ei:
        read_data(p)
    assert where in str(ei.value) and "\n" not in str(ei.value)


def test_row_cap_refused_before_parsing(tmp_path):
    p = tmp_path / "big.csv"
    p.write_text("voltage,deflection\n" + "1V,1mm\n" * 50)
    with pytest.raises(ValueError, match="more than 20 data rows"):
        read_data(p, max_rows=20)
    assert read_data(p, max_rows=50).n_rows == 50


def test_stderr_matches_a_quadratic_profile(truth_rows, tmp_path):
    """Where a standard error is given, 1.96 of it (in log) is the profile's half-width within 20 %."""
    d = read_data(_write(tmp_path / "q.csv", truth_rows, 1), Strip(width=5e-3))
    r = fit(d, "modulus,c_moy")
    for k, p in r.parameters.items():
        assert p["status"] == "ok"
        if p["stderr"] is not None:
            lo, hi = p["ci95"]
            h = 1.959964 * p["stderr"] / p["value"]
            assert abs(math.log(p["value"] / lo) - h) <= 0.2 * h + 1e-12
            assert abs(math.log(hi / p["value"]) - h) <= 0.2 * h + 1e-12
    assert r.chi2_red is not None and r.noise_scale is None


def test_at_the_bound_is_not_not_identifiable(truth_rows, tmp_path):
    """True E = 100 MPa, bounds 200-500 MPa: the optimum sits on the lower bound and the data pull beyond it."""
    d = read_data(_write(tmp_path / "b.csv", truth_rows, 0), Strip(width=5e-3))
    r = fit(d, {"modulus": (2e8, 5e8)}, fidelity="leading")
    m = r.parameters["modulus"]
    assert m["status"] == "at_bound" and m["value"] == pytest.approx(2e8, rel=1e-6)
    assert m["stderr"] is None and "lower bound" in m["note"]
    # and the misfit is flagged: chi2_red far above 1 with the given sigma
    assert r.chi2_red > 10 and any("outliers" in w for w in r.warnings)


def test_force_only_status_not_identifiable(truth_rows, tmp_path):
    d = read_data(_write(tmp_path / "f.csv", truth_rows, 2, cols=("blocking_force",)), Strip(width=5e-3))
    r = fit(d, "modulus,c_moy")
    assert r.parameters["modulus"]["status"] == "not_identifiable"


def test_outliers_with_known_sigma_warned(truth_rows, tmp_path):
    """Two deflections 40 % off with 2 % sigma: chi2_red >> 1, a warning names the rows."""
    rows = [list(r) for r in truth_rows]
    for i in (3, 11):
        rows[i][2] *= 1.4
    d = read_data(_write(tmp_path / "o.csv", [tuple(r) for r in rows], 4, noise=0.0 + 0.02), Strip(width=5e-3))
    r = fit(d, "modulus,c_moy", fidelity="corrected")
    assert r.chi2_red > 3
    w = [x for x in r.warnings if "outliers" in x]
    assert w and "row 5" in w[0] and "row 13" in w[0]


def test_rows_past_a_quarter_turn_warned(tmp_path):
    """A 100 um, 2 cm strip past 0.5 V turns more than a quarter turn: the fit says so (forward's check)."""
    from ipmc_asym.forward.model import forward

    v = np.array([0.2, 0.3, 0.4, 0.6, 0.8, 1.0])
    r = forward(0.02, 5e-3, 100e-6, v, material=NAFION_LI, model="constant", fidelity="quadrature")
    past = np.abs(np.asarray(r.theta)) > math.pi / 2  # the independent reading of the beam-regime check
    assert past.any() and not past.all()
    lines = ["thickness,voltage,deflection,blocking_force,sigma_deflection,sigma_blocking_force"]
    for vi, w, f in zip(v, np.abs(r.w), np.abs(r.F_block)):
        lines.append(f"100um,{float(vi)!r},{float(w)!r},{float(f)!r},{0.02 * float(w)!r},{0.02 * float(f)!r}")
    p = tmp_path / "turn.csv"
    p.write_text("\n".join(lines) + "\n")
    res = fit(read_data(p), "c_moy", fidelity="quadrature")
    w = [x for x in res.warnings if "quarter turn" in x]
    assert w and w[0].startswith(f"{int(past.sum())} of 6 rows")


def test_negative_seed_refused_before_work(truth_rows, tmp_path):
    d = read_data(_write(tmp_path / "s.csv", truth_rows, 0), Strip(width=5e-3))
    with pytest.raises(ValueError, match="seed must be an integer >= 0"):
        fit(d, "modulus", multistart=2, seed=-5)


@pytest.mark.slow
def test_four_free_parameters_no_misleading_stderr():
    """The example file with modulus, c_moy, eps0, deps free: a strongly non-quadratic profile
    gets no standard error (the linearised one contradicted the profile interval)."""
    from references import REPO

    d = read_data(REPO / "examples" / "fit_synthetic.csv")
    r = fit(d, "modulus,c_moy,eps0,deps")
    for k, p in r.parameters.items():
        if p["stderr"] is not None and p["ci95"][0] is not None and p["ci95"][1] is not None:
            h = 1.959964 * p["stderr"] / p["value"]
            assert abs(math.log(p["value"] / p["ci95"][0]) - h) <= 0.2 * h
    assert r.parameters["c_moy"]["stderr"] is None and "not locally quadratic" in r.parameters["c_moy"]["note"]


def test_free_bounds_with_units_and_aliases():
    """The dynamic names take units on their bounds; D, E, R_s, eta_E are other names of them."""
    from ipmc_asym.studies.calibrate import parse_free

    b = parse_free("D=1e-11m2/s:1e-5cm2/s,viscous_modulus=1kPa s:1MPa s,R_s=0.01ohm/sq:2kohm/sq,c_moy=1M:3M")
    assert b["diffusion"] == pytest.approx((1e-11, 1e-9))
    assert b["viscous_modulus"] == pytest.approx((1e3, 1e6))
    assert b["sheet_resistance"] == pytest.approx((1e-2, 2e3))
    assert b["c_moy"] == pytest.approx((1e3, 3e3))
    with pytest.raises(ValueError, match="unknown unit"):
        parse_free("D=1e-11furlong:1e-9")


def test_free_bounds_wholly_outside_the_plausible_range_are_said():
    from ipmc_asym.model.limits import PLAUSIBLE
    from ipmc_asym.studies.calibrate import free_warnings, parse_free

    (line,) = free_warnings(parse_free("modulus=1:2"))  # Pa: a bare number is SI
    assert line.startswith("--free modulus 1:2 Pa") and f"{PLAUSIBLE['E'][0]:g}" in line
    (line,) = free_warnings(parse_free("diffusion=1e-20:1e-19,modulus=50MPa:500MPa"))
    assert line.startswith("--free diffusion")
    # touching the range is enough: the fit may end inside it
    lo = PLAUSIBLE["E"][1]
    assert free_warnings(parse_free(f"modulus={lo:g}:{10 * lo:g}")) == []
    assert free_warnings(parse_free("modulus,c_moy")) == []  # the default bounds
