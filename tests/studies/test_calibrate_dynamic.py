"""Dynamic calibration: synthetic round trips (spectra, step transients), identifiability, refusals.

The spectra are generated from the exact linearised Nernst-Planck/Gauss impedance written out
here from the physical constants (``Z_area = [2e + 2 kappa tanh(k e)/(i w eps k)]/(kappa + i w eps)``,
``k^2 = 1/lambda_D^2 + i w/D``), not from the package's kernels; the slow step round trip takes
its data from the PNP solver while the fit uses the reduced circuit.
"""

import cmath
import math

import numpy as np
import pytest

from ipmc_asym.dynamics.circuit import frequency_response, step_response
from ipmc_asym.dynamics.line import line_response
from ipmc_asym.model.params import NAFION_LI, Strip
from ipmc_asym.model.permittivity import get_model
from ipmc_asym.studies.calibrate import fit, read_data
from ipmc_asym.studies.calibrate_dynamic import ImpedanceData, TimeData, fit_dynamic, read_file

STRIP = Strip()
TRUE = {"diffusion": 3e-10, "c_moy": 2600.0}
MAT = NAFION_LI.with_(D=TRUE["diffusion"], c_moy=TRUE["c_moy"])
FREQ = np.geomspace(0.1, 1e5, 25)


def z_exact(f, material, eps, strip=STRIP):
    """The strip's linearised-PNP impedance (Ohm) from the physical constants (independent closed form)."""
    m = material
    kap = m.phi4 * m.F**2 * m.D * m.C_moy / (m.R * m.T)
    lam_d2 = eps * m.R * m.T / (m.phi4 * m.F**2 * m.C_moy)
    e = 0.5 * strip.thickness
    out = []
    for fi in np.atleast_1d(f):
        w = 2 * math.pi * fi
        k = cmath.sqrt(1 / lam_d2 + 1j * w / m.D)
        za = (2 * e + 2 * kap * cmath.tanh(k * e) / (1j * w * eps * k)) / (kap + 1j * w * eps)
        out.append(za / (strip.width * strip.length))
    return np.array(out)


def _spectrum_csv(path, Z, seed, noise=0.01, polar=False, sigma=True):
    rng = np.random.default_rng(seed)
    if polar:
        lines = ["f,Z_abs,Z_phase" + (",sigma_Z_abs,sigma_Z_phase" if sigma else "")]
        for fi, z in zip(FREQ, Z):
            a = abs(z) * (1 + noise * rng.standard_normal())
            ph = math.degrees(cmath.phase(z) + noise * rng.standard_normal())
            lines.append(f"{fi:.17g}Hz,{a:.17g}ohm,{ph:.17g}" + (f",{noise * abs(z):.17g},{math.degrees(noise):.17g}"
                                                                 if sigma else ""))
    else:
        lines = ["f,Z_re,Z_im" + (",sigma_Z_re,sigma_Z_im" if sigma else "")]
        for fi, z in zip(FREQ, Z):
            s = noise * abs(z)
            lines.append(f"{fi:.17g},{z.real + s * rng.standard_normal():.17g},{z.imag + s * rng.standard_normal():.17g}"
                         + (f",{s:.17g},{s:.17g}" if sigma else ""))
    path.write_text("\n".join(lines) + "\n")
    return path


def _inside(res, truth, rel):
    for k, v in truth.items():
        p = res.parameters[k]
        assert p["status"] == "ok", (k, p, res.message)
        lo, hi = p["ci95"]
        assert lo <= v <= hi, (k, v, p)
        assert abs(p["value"] / v - 1) < rel, (k, v, p)


def test_independent_impedance_matches_the_model():
    """The test's own closed form is the package's reference (so the round trip below tests the fit)."""
    eps = get_model("constant").eps_moy
    z = frequency_response(FREQ, strip=STRIP, material=MAT).Z
    assert np.max(np.abs(z_exact(FREQ, MAT, eps) / z - 1)) < 1e-9


def test_spectrum_round_trip(tmp_path):
    """D = 3e-10, C_moy = 2600, 1 % noise with sigma: both inside their 95 % intervals, within 3 %."""
    Z = z_exact(FREQ, MAT, get_model("constant").eps_moy)
    d = read_file(_spectrum_csv(tmp_path / "imp.csv", Z, seed=1))
    assert isinstance(d, ImpedanceData) and d.n_points == 50
    r = fit_dynamic(d, "D=1e-11m2/s:1e-9m2/s,c_moy", strip=STRIP)
    _inside(r, TRUE, 0.03)
    assert r.chi2_red is not None and 0.5 < r.chi2_red < 1.6
    assert "spectra pnp-linear" in r.fidelity


def test_sheet_resistance_round_trip_polar(tmp_path):
    """|Z| and phase of the electrode line at R_s = 5 Ohm/sq (no sigma): D and R_s recovered."""
    Z = line_response(FREQ, strip=STRIP, material=MAT, sheet_resistance=5.0).Z
    d = read_file(_spectrum_csv(tmp_path / "imp.csv", Z, seed=2, polar=True, sigma=False))
    r = fit_dynamic(d, "diffusion,sheet_resistance", material=MAT.with_(D=1e-10), strip=STRIP)
    _inside(r, {"diffusion": TRUE["diffusion"], "sheet_resistance": 5.0}, 0.03)
    assert r.chi2_red is None and 0.005 < r.noise_scale < 0.02


def test_eps_split_not_identifiable_from_a_spectrum(tmp_path):
    """About 0 V the layers linearise about the core: a spectrum sees eps_moy = eps0 + deps, not the split."""
    aff = get_model("affine")
    Z = z_exact(FREQ, MAT, aff.eps_moy)
    d = read_file(_spectrum_csv(tmp_path / "imp.csv", Z, seed=3))
    r = fit_dynamic(d, "eps0,deps", model="affine", material=MAT, strip=STRIP)
    for k in ("eps0", "deps"):
        p = r.parameters[k]
        assert p["status"] == "not_identifiable", (k, p)
        assert p["stderr"] is None and None in p["ci95"]


def test_at_bound_when_the_truth_is_outside(tmp_path):
    Z = z_exact(FREQ, MAT, get_model("constant").eps_moy)
    d = read_file(_spectrum_csv(tmp_path / "imp.csv", Z, seed=4))
    r = fit_dynamic(d, "D=1e-11m2/s:1e-10m2/s", material=MAT, strip=STRIP)
    p = r.parameters["diffusion"]
    assert p["status"] == "at_bound" and math.isclose(p["value"], 1e-10, rel_tol=1e-4), p


def _step_csv(path, t, out, seed, cols, noise=0.01, volts=0.5):
    rng = np.random.default_rng(seed)
    lines = ["t,voltage," + ",".join(cols) + "," + ",".join(f"sigma_{c}" for c in cols)]
    sig = {c: noise * math.sqrt(float(np.mean(out[c] ** 2))) for c in cols}
    for i, ti in enumerate(t):
        vals = [out[c][i] + sig[c] * rng.standard_normal() for c in cols]
        lines.append(f"{ti * 1e3:.17g}ms,{volts}V," + ",".join(f"{v:.17g}" for v in vals)
                     + "," + ",".join(f"{sig[c]:.17g}" for c in cols))
    path.write_text("\n".join(lines) + "\n")
    return path


def _step_truth(t, fidelity, volts=0.5, **kw):
    r = step_response(volts, strip=STRIP, material=MAT, t=np.concatenate(([0.0], t)), fidelity=fidelity, **kw)
    a = STRIP.width * STRIP.length
    return {"current": r.current_density[1:] * a, "charge": r.sigma[1:] * a, "deflection": -r.w[1:],
            "blocking_force": r.F_block[1:]}


def test_step_round_trip(tmp_path):
    """Step current and tip deflection (circuit data on a 5x finer grid, 1 % noise): D, C_moy, E recovered;
    the circuit passes its check against the PNP at the optimum."""
    fine = np.linspace(0.0, 0.05, 201)[1:]
    truth = _step_truth(fine, "circuit")
    t = fine[4::5]
    d = read_file(_step_csv(tmp_path / "step.csv", t, {k: v[4::5] for k, v in truth.items()}, 1,
                            ("current", "deflection")))
    assert isinstance(d, TimeData) and d.kinds == {"time", "time_mech"}
    r = fit_dynamic(d, "diffusion,c_moy,modulus", strip=STRIP)
    _inside(r, {**TRUE, "modulus": MAT.E}, 0.03)
    assert "time series circuit" in r.fidelity


@pytest.mark.slow
def test_step_round_trip_coverage(tmp_path):
    """Seeds 0-9 of the step round trip, 3 parameters each: a truth inside its 95 % interval in >= 26 of
    the 30 cases (binomial(30, 0.95): P(<= 25) = 0.016)."""
    fine = np.linspace(0.0, 0.05, 201)[1:]
    truth = _step_truth(fine, "circuit")
    t = fine[4::5]
    good = 0
    for seed in range(10):
        d = read_file(_step_csv(tmp_path / f"s{seed}.csv", t, {k: v[4::5] for k, v in truth.items()}, seed,
                                ("current", "deflection")))
        r = fit_dynamic(d, "diffusion,c_moy,modulus", strip=STRIP)
        good += sum(r.parameters[k]["ci95"][0] <= v <= r.parameters[k]["ci95"][1]
                    for k, v in {**TRUE, "modulus": MAT.E}.items())
    assert good >= 26, good


@pytest.mark.slow
def test_step_round_trip_from_pnp_data_with_spectrum_and_static(tmp_path):
    """Data from the PNP solver (step charge and deflection), a spectrum and static rows, fitted together."""
    t = np.linspace(0.0, 0.05, 31)[1:]
    truth = _step_truth(t, "pnp", pnp_options={"tol": 1e-6})
    step = read_file(_step_csv(tmp_path / "step.csv", t, truth, 6, ("charge", "deflection")))
    imp = read_file(_spectrum_csv(tmp_path / "imp.csv", z_exact(FREQ, MAT, get_model("constant").eps_moy), 7))
    from ipmc_asym.forward.estimate import evaluate

    rng = np.random.default_rng(8)
    lines = ["voltage,deflection,sigma_deflection"]
    for v in (0.3, 0.6, 0.9):
        w = abs(evaluate(STRIP.with_(voltage=v), "constant", "quadrature", MAT)["w"])
        lines.append(f"{v},{w * (1 + 0.01 * rng.standard_normal()):.17g},{0.01 * w:.17g}")
    (tmp_path / "static.csv").write_text("\n".join(lines) + "\n")
    static = read_data(tmp_path / "static.csv", STRIP)
    r = fit_dynamic([static, step, imp], "diffusion,c_moy,modulus", strip=STRIP)
    # one seed: each estimate within 3 % and 4 standard errors (the 95 % coverage is the test above)
    for k, v in {**TRUE, "modulus": MAT.E}.items():
        p = r.parameters[k]
        assert p["status"] == "ok" and abs(p["value"] / v - 1) < 0.03 and abs(p["value"] - v) < 4 * p["stderr"], (k, p)
    assert "time series circuit" in r.fidelity and "static rows" in r.fidelity


@pytest.mark.slow
def test_viscous_modulus_round_trip(tmp_path):
    """Ringing of the free tip after a step (dynamic beam, eta_E = 2e5 Pa s): eta_E and E recovered."""
    t = np.linspace(0.0, 0.3, 151)[1:]
    truth = _step_truth(t, "circuit", beam="dynamic", viscous_modulus=2e5)
    d = read_file(_step_csv(tmp_path / "step.csv", t, truth, 9, ("deflection",)))
    r = fit_dynamic(d, "viscous_modulus,modulus", material=MAT, strip=STRIP)
    _inside(r, {"viscous_modulus": 2e5, "modulus": MAT.E}, 0.03)


def test_parameters_the_data_cannot_see_refused(tmp_path):
    Z = z_exact(FREQ, MAT, get_model("constant").eps_moy)
    imp = read_file(_spectrum_csv(tmp_path / "imp.csv", Z, seed=1))
    with pytest.raises(ValueError, match="modulus: the data given .* deflection") as e:
        fit_dynamic(imp, "modulus", strip=STRIP)
    assert "\n" not in str(e.value)
    (tmp_path / "s.csv").write_text("voltage,deflection\n0.5V,1mm\n1V,2mm\n")
    with pytest.raises(ValueError, match="diffusion: .* time series .* impedance spectrum"):
        fit(read_data(tmp_path / "s.csv"), "D")
    (tmp_path / "t.csv").write_text("t,voltage,current\n1ms,1V,1mA\n2ms,1V,0.8mA\n3ms,1V,0.7mA\n")
    step = read_file(tmp_path / "t.csv")
    with pytest.raises(ValueError, match="sheet_resistance: .* impedance spectrum"):
        fit_dynamic(step, "sheet_resistance")
    with pytest.raises(ValueError, match="viscous_modulus: .* deflection or blocking force"):
        fit_dynamic(step, "viscous_modulus")
    with pytest.raises(ValueError, match="linear model: not validated in the fit"):
        fit_dynamic(step, "diffusion", model="linear")
    with pytest.raises(ValueError, match="time-domain model has ideal electrodes"):
        fit_dynamic([step, read_file(_spectrum_csv(tmp_path / "i2.csv", Z, seed=1, sigma=False))],
                    "diffusion,sheet_resistance")


@pytest.mark.parametrize("text, where", [
    ("t,voltage,current\n2ms,1V,1mA\n1ms,1V,2mA\n", "row 3, column 't'"),
    ("t,current\n1ms,1mA\n2ms,2mA\n", "needs its drive"),
    ("t,voltage,current\n1ms,0V,1mA\n2ms,0V,2mA\n", "0 V at every time"),
    ("t,voltage,current\n1ms,1V,1 furlong\n", "row 2, column 'current'"),
    ("t,voltage,current,sigma_current\n1ms,1V,1mA,\n", "row 2, column 'sigma_current': empty"),
    ("t,voltage,speed\n1ms,1V,1\n", "unknown column 3 'speed'"),
    ("t,f,Z_re\n1,1,1\n", "both t and f"),
    ("f,Z_re\n1Hz,5\n", "pair Z_re, Z_im"),
    ("f,Z_re,Z_im\n1Hz,5,30\n2Hz,5,20\n", "negate that column"),
    ("f,Z_abs,Z_phase\n1Hz,-5,-30\n", "row 2, column 'Z_abs'"),
    ("f,Z_re,Z_im\n0Hz,5,-30\n", "row 2, column 'f'"),
    ("f,Z_re,Z_im\n1Hz,5,\n", "row 2: Z_re and Z_im go together"),
])
def test_bad_files_one_line(tmp_path, text, where):
    p = tmp_path / "bad.csv"
    p.write_text(text)
    with pytest.raises(ValueError) as e:
        read_file(p)
    assert where in str(e.value) and "\n" not in str(e.value), str(e.value)


def test_sigma_in_some_files_only_refused(tmp_path):
    Z = z_exact(FREQ, MAT, get_model("constant").eps_moy)
    a = read_file(_spectrum_csv(tmp_path / "a.csv", Z, seed=1))
    b = read_file(_spectrum_csv(tmp_path / "b.csv", Z, seed=2, sigma=False))
    with pytest.raises(ValueError, match="sigma_ columns in some files only"):
        fit_dynamic([a, b], "diffusion")


def test_time_series_drive_from_a_waveform(tmp_path):
    (tmp_path / "t.csv").write_text("t,current\n1ms,1mA\n2ms,0.8mA\n")
    d = read_file(tmp_path / "t.csv", waveform="step:0.5V")
    assert d.drive_spec == "waveform step:0.5V" and float(d.drive(np.array([1e-3]))[0]) == 0.5
    (tmp_path / "v.csv").write_text("t,voltage,current\n1ms,0.5V,1mA\n2ms,0.5V,0.8mA\n")
    with pytest.raises(ValueError, match="the drive is given twice"):
        read_file(tmp_path / "v.csv", waveform="step:0.5V")


@pytest.fixture(scope="module")
def precise_charge(tmp_path_factory):
    """A step charge from the PNP solver (tol 1e-7) with 2e-4 noise: finer than the circuit's error."""
    t = np.linspace(0.0, 0.05, 21)[1:]
    truth = _step_truth(t, "pnp", pnp_options={"tol": 1e-7})
    return read_file(_step_csv(tmp_path_factory.mktemp("precise") / "s.csv", t, truth, 3, ("charge",), noise=2e-4))


def test_circuit_refused_on_data_finer_than_its_error(precise_charge):
    """The circuit's difference from the PNP exceeds a tenth of sigma: forced to the circuit, the fit refuses."""
    with pytest.raises(ValueError, match="no rung is accurate enough .* time rows: model error .* leave the fidelity "
                                         "unset") as e:
        fit_dynamic(precise_charge, "diffusion", material=MAT, strip=STRIP, time_fidelity="circuit")
    assert "\n" not in str(e.value)


@pytest.mark.slow
def test_precise_data_escalate_to_pnp(precise_charge):
    """Left to choose, the fit climbs to the PNP rung and recovers D inside its interval."""
    r = fit_dynamic(precise_charge, "diffusion", material=MAT.with_(D=2e-10), strip=STRIP)
    assert r.fidelity.startswith("time series pnp"), r.fidelity
    _inside(r, {"diffusion": TRUE["diffusion"]}, 0.003)


def test_multistart_on_a_spectrum(tmp_path):
    Z = z_exact(FREQ, MAT, get_model("constant").eps_moy)
    d = read_file(_spectrum_csv(tmp_path / "imp.csv", Z, seed=1))
    r = fit_dynamic(d, "diffusion,c_moy", strip=STRIP, multistart=2, seed=3)
    assert "multistart: best of 3 starts" in r.message
    _inside(r, TRUE, 0.03)


def test_two_static_files_equal_the_static_fit_of_their_rows(tmp_path):
    """The joint path on static rows split over two files gives the static fit of one file with all rows."""
    from ipmc_asym.forward.estimate import evaluate

    mat = NAFION_LI.with_(E=9e7, c_moy=2900.0)
    rng = np.random.default_rng(5)
    head = "voltage,thickness,deflection,blocking_force,sigma_deflection,sigma_blocking_force"
    rows = {}
    for name, t in (("a", 150e-6), ("b", 250e-6)):
        rows[name] = []
        for v in np.linspace(0.2, 0.8, 6):
            r = evaluate(Strip(length=0.015, thickness=t, voltage=float(v)), "constant", "quadrature", mat)
            w, f = abs(r["w"]), abs(r["F_block"])
            rows[name].append(f"{v:.4f}V,{t},{w * (1 + 0.02 * rng.standard_normal())},"
                              f"{f * (1 + 0.02 * rng.standard_normal())},{0.02 * w},{0.02 * f}")
        (tmp_path / f"{name}.csv").write_text("\n".join([head] + rows[name]) + "\n")
    (tmp_path / "ab.csv").write_text("\n".join([head] + rows["a"] + rows["b"]) + "\n")
    base = Strip(length=0.015)
    one = fit(read_data(tmp_path / "ab.csv", base), "modulus,c_moy")
    two = fit_dynamic([read_file(tmp_path / "a.csv", base), read_file(tmp_path / "b.csv", base)], "modulus,c_moy")
    assert two.fidelity == f"static rows {one.fidelity}"
    assert two.chi2_red == pytest.approx(one.chi2_red, rel=1e-9)
    for k in ("modulus", "c_moy"):
        assert two.parameters[k]["value"] == pytest.approx(one.parameters[k]["value"], rel=1e-6)
        assert two.parameters[k]["ci95"] == pytest.approx(one.parameters[k]["ci95"], rel=1e-6)


def test_public_fit_takes_every_kind_of_data(tmp_path):
    """``ia.fit`` is one entry: a spectrum's path goes to the dynamic fit (D recovered against the
    independent closed form), static rows stay static, a time-series option on static rows is refused."""
    import ipmc_asym as ia

    Z = z_exact(FREQ, MAT, get_model("constant").eps_moy)
    path = _spectrum_csv(tmp_path / "imp.csv", Z, seed=1)
    r = ia.fit(path, "D,c_moy", strip=STRIP)
    _inside(r, TRUE, 0.03)
    assert "spectra pnp-linear" in r.fidelity
    static = tmp_path / "static.csv"
    static.write_text("voltage,deflection\n0.5V,1.0mm\n1V,2.1mm\n1.5V,2.9mm\n")
    with pytest.raises(ValueError, match="diffusion"):
        ia.fit(str(static), "diffusion")
    with pytest.raises(ValueError, match="beam: only for time series"):
        ia.fit(read_data(static), "modulus", beam="dynamic")


@pytest.mark.slow
def test_precise_step_series_pnp_optimum_by_defect_correction(tmp_path):
    """A long precise step series (100 rows of PNP current and deflection, 0.5 % noise) escalates to
    the PNP rung, whose optimum the fit finds by correcting the circuit: the truth lies inside the
    intervals, and at the estimate the PNP itself (run here, residuals built here) is stationary: its
    Gauss-Newton step is below 0.01 standard errors (the correction's stopping rule)."""
    t = np.linspace(0.0, 0.05, 101)[1:]
    truth = _step_truth(t, "pnp", pnp_options={"tol": 1e-6})
    cols = ("current", "deflection")
    path = _step_csv(tmp_path / "step.csv", t, truth, 11, cols, noise=0.005)
    r = fit_dynamic(read_file(path), "diffusion,c_moy,modulus", strip=STRIP)
    assert r.fidelity.startswith("time series pnp"), r.fidelity
    assert "defect correction of the circuit" in r.message, r.message
    _inside(r, {**TRUE, "modulus": MAT.E}, 0.01)

    tol = float(r.fidelity.split("tol ")[1].split(")")[0])
    rows = np.loadtxt(path, delimiter=",", skiprows=1, dtype=str)
    meas = {c: rows[:, 2 + i].astype(float) for i, c in enumerate(cols)}
    sig = {c: rows[:, 4 + i].astype(float) for i, c in enumerate(cols)}
    keys = ("diffusion", "c_moy", "modulus")
    x = np.log([r.parameters[k]["value"] for k in keys])

    def res(xv):
        d, c, e = np.exp(xv)
        out = step_response(0.5, strip=STRIP, material=NAFION_LI.with_(D=d, c_moy=c, E=e),
                            t=np.concatenate(([0.0], t)), fidelity="pnp", pnp_options={"tol": tol})
        a = STRIP.width * STRIP.length
        pred = {"current": out.current_density[1:] * a, "deflection": -out.w[1:]}
        return np.concatenate([(pred[c] - meas[c]) / sig[c] for c in cols])

    r0 = res(x)
    sd = np.array([r.parameters[k]["stderr"] / r.parameters[k]["value"] for k in keys])
    J = np.empty((r0.size, 3))
    for j in range(3):
        h = np.zeros(3)
        h[j] = 0.2 * sd[j]
        J[:, j] = (res(x + h) - res(x - h)) / (2 * h[j])
    step = np.linalg.lstsq(J, -r0, rcond=None)[0]
    sd_pnp = np.sqrt(np.diag(np.linalg.inv(J.T @ J)))
    assert np.all(np.abs(step) < 0.01 * sd_pnp), (step / sd_pnp, r.message)
    # the reported standard errors are the PNP's own (its Jacobian here) within 1 %
    assert np.allclose(sd, sd_pnp, rtol=0.01), (sd, sd_pnp)
