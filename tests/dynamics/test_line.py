"""The strip with resistive electrodes: RC line along the length vs a discretised ladder, limits,
the SymPy closed forms, the modal forcing integral and the command line."""

import json

import mpmath as mp
import numpy as np
import pytest
import sympy as sp

from derivations import line as DL
from ipmc_asym.beam.dynamics import Beam, viscous_modulus_from_damping_ratio
from ipmc_asym.cli import main
from ipmc_asym.dynamics.circuit import frequency_response
from ipmc_asym.dynamics.line import line_factors, line_response, moment_modal_integral, voltage_profile
from ipmc_asym.model.params import NAFION_LI, Strip

F = np.geomspace(1e-3, 1e5, 25)


def ladder(f, strip, Rs, N, method="pnp-linear", model="constant", voltage=0.0):
    """Discretised line: N segments of series r h between nodes x_j = j h, shunt y h at the interior
    nodes and y h/2 at the two ends (second order in h), V(0) = 1.  Returns (Z_in, H_w, H_theta, V).

    r = 2 R_s/(2l) (both electrodes in series), y = 2l/Z_area (the through-thickness impedance per
    area of the uniform strip is the input); the tip deflection and rotation are trapezoidal sums of
    the beam's -(L - x) M/(E I_p) and -M/(E I_p) with M = H_M V, H_M = -2 E I_p H_w^u/L^2.
    """
    u = frequency_response(f, strip=strip, model=model, method=method, voltage=voltage)
    L, w2 = strip.length, strip.width
    r = 2.0 * Rs / w2
    y = w2 / u.Z_area
    h = L / N
    a = r * y * h * h  # (nf,)
    # unknowns V_1..V_N: V_{j-1} - (2 + a) V_j + V_{j+1} = 0 (j < N), V_{N-1} - (1 + a/2) V_N = 0
    nf = a.size
    diag = np.empty((N, nf), complex)
    diag[:] = -(2.0 + a)
    diag[-1] = -(1.0 + 0.5 * a)
    rhs = np.zeros((N, nf), complex)
    rhs[0] = -1.0  # V_0 = 1 moved to the right-hand side
    # Thomas algorithm (sub- and super-diagonals are 1), vectorised over the frequencies
    cp = np.empty((N, nf), complex)
    dp = np.empty((N, nf), complex)
    cp[0] = 1.0 / diag[0]
    dp[0] = rhs[0] / diag[0]
    for j in range(1, N):
        m = diag[j] - cp[j - 1]
        cp[j] = 1.0 / m
        dp[j] = (rhs[j] - dp[j - 1]) / m
    V = np.empty((N + 1, nf), complex)
    V[0] = 1.0
    V[N] = dp[N - 1]
    for j in range(N - 1, 0, -1):
        V[j] = dp[j - 1] - cp[j - 1] * V[j + 1]
    x = np.linspace(0.0, L, N + 1)
    wt = np.full(N + 1, h)
    wt[[0, -1]] = 0.5 * h
    # the input current is the sum of the shunt currents (KCL over the open-ended ladder); the
    # same as (V_0 - V_1)/(r h) + y h V_0/2 without its cancellation where r y h^2 is tiny
    I0 = y * (wt @ V)
    EI = NAFION_LI.E * strip.I_p
    HM = -2.0 * EI * u.H_w / L**2
    Hw = -(HM / EI) * ((wt * (L - x)) @ V)
    Hth = -(HM / EI) * (wt @ V)
    return 1.0 / I0, Hw, Hth, V


def rel(a, b):
    return np.abs(a - b) / np.abs(b)


@pytest.mark.parametrize("method", ["pnp-linear", "circuit"])
@pytest.mark.parametrize("Rs", [0.5, 2.5, 25.0])
def test_against_discretised_ladder(Rs, method):
    s = Strip()
    r = line_response(F, strip=s, sheet_resistance=Rs, method=method, x=np.linspace(0, s.length, 1001))
    z1, w1, t1, v1 = ladder(F, s, Rs, 1000, method)
    z2, w2, t2, v2 = ladder(F, s, Rs, 2000, method)
    # the ladder's error is even in h (derivations/line.py: ladder_profile_check): Richardson 1000/2000
    zr, wr, tr = (4 * z2 - z1) / 3, (4 * w2 - w1) / 3, (4 * t2 - t1) / 3
    assert np.max(rel(r.Z, zr)) <= 1e-6
    assert np.max(rel(r.H_w, wr)) <= 1e-6
    assert np.max(rel(r.H_theta, tr)) <= 1e-6
    # the raw 2000-segment ladder is off at second order, and Richardson does improve on it
    assert np.max(rel(r.Z, z2)) > 10 * np.max(rel(r.Z, zr))
    # the profile at the nodes of the 1000-segment ladder (second order: |g h|^2 / 24)
    vr = (4 * v2[::2] - v1) / 3
    assert np.max(np.abs(r.V_profile - vr.T)) <= 1e-6


def _psi(f, beam, x, load):
    """Exact harmonic response of the damped strip (no modes) to a unit tip force or couple:
    ``(psi''(x), psi(L))``.  ``EI (1 + s tau_v) d4psi/dx4 = -s^2 rho A psi``, clamp at 0; at the tip
    ``EI k psi'' = 0, EI k psi''' = -1`` (force) or ``EI k psi'' = 1, psi''' = 0`` (couple).  By the
    symmetry of the beam's bilinear form the tip output of a distributed moment is
    ``-int M psi'' dx``, and the blocked tip force ``-w_free(L)/psi(L)`` (tip force)."""
    L = beam.length
    s = 2j * np.pi * np.asarray(f, float)
    EIk = beam.EI * (1 + s * beam.tau_v)
    beta = (-(s * s) * beam.rhoA / EIk) ** 0.25
    d2 = np.empty((f.size, x.size), complex)
    tip = np.empty(f.size, complex)
    for i, b in enumerate(beta):
        ch, sh, c, sn = np.cosh(b * L), np.sinh(b * L), np.cos(b * L), np.sin(b * L)
        # psi = A (cosh - cos) + B (sinh - sin) meets the clamp
        M = np.array([[ch + c, sh + sn], [sh - sn, ch + c]]) * np.array([[b**2], [b**3]])
        rhs = np.array([0.0, -1.0 / EIk[i]]) if load == "force" else np.array([1.0 / EIk[i], 0.0])
        A, B = np.linalg.solve(M, rhs)
        d2[i] = b**2 * (A * (np.cosh(b * x) + np.cos(b * x)) + B * (np.sinh(b * x) + np.sin(b * x)))
        tip[i] = A * (ch - c) + B * (sh - sn)
    return d2, tip


def ladder_dynamic(f, strip, Rs, N, eta, **kw):
    """The N-segment ladder's node voltages driving the exact (non-modal) damped beam: trapezoidal
    sums of the moment against the tip force's and couple's curvature (even in h).  Returns
    (Z_in, H_w, H_theta, H_F)."""
    u = frequency_response(f, strip=strip, **kw)
    z, _, _, V = ladder(f, strip, Rs, N, **kw)
    beam = Beam.from_strip(strip.length, strip.width, strip.thickness, NAFION_LI, eta)
    x = np.linspace(0.0, strip.length, N + 1)
    wt = np.full(N + 1, strip.length / N)
    wt[[0, -1]] *= 0.5
    M = (-2.0 * beam.EI * u.H_w / strip.length**2)[:, None] * V.T
    pf, tipf = _psi(f, beam, x, "force")
    pc, _ = _psi(f, beam, x, "couple")
    Hw = -np.sum(M * pf * wt, axis=1)
    return z, Hw, -np.sum(M * pc * wt, axis=1), -Hw / tipf


@pytest.mark.parametrize("Rs", [2.5, 25.0])
def test_dynamic_beam_against_the_discretised_line_and_an_exact_beam(Rs):
    s = Strip()
    eta = viscous_modulus_from_damping_ratio(0.02, 22.5, NAFION_LI.E)  # 2 % of critical at the first mode
    # below the third free-tip resonance (396 Hz), through the first two and the first blocked one
    f = np.concatenate([np.geomspace(0.1, 350.0, 12), [22.0, 23.0, 98.0, 141.0]])
    r = line_response(f, strip=s, sheet_resistance=Rs, beam="dynamic", viscous_modulus=eta)
    a, b = ladder_dynamic(f, s, Rs, 1000, eta), ladder_dynamic(f, s, Rs, 2000, eta)
    ref = [(4 * y - x) / 3 for x, y in zip(a, b)]  # Richardson 1000/2000 (both sums even in h)
    for got, want in zip((r.Z, r.H_w, r.H_theta, r.H_F), ref):
        assert np.max(rel(got, want)) <= 1e-6
    # the stated error of the modal quadrature and truncation is small and not exceeded
    assert np.max(r.beam_error) < 1e-6
    # resonances: the free tip peaks near 22.5 Hz (more than the quasi-static line there)
    q = line_response(f, strip=s, sheet_resistance=Rs)
    assert abs(r.H_w[12]) > 5 * abs(q.H_w[12])
    assert r.resonances["clamped-free"][0] == pytest.approx(22.546, rel=1e-3)


# +0.5 V with the slow tests (~5 s each): the quick loop keeps a negative bias
@pytest.mark.parametrize("bias", [pytest.param(0.5, marks=pytest.mark.slow), -0.3])
def test_biased_line_against_the_discretised_line(bias):
    # the shunt admittance about the biased static state (circuit: R, C_d(V), C_g) along the ladder
    s = Strip()
    r = line_response(F, strip=s, sheet_resistance=2.5, method="circuit", voltage=bias)
    z1, w1, t1, _ = ladder(F, s, 2.5, 1000, "circuit", voltage=bias)
    z2, w2, t2, _ = ladder(F, s, 2.5, 2000, "circuit", voltage=bias)
    assert np.max(rel(r.Z, (4 * z2 - z1) / 3)) <= 1e-6
    assert np.max(rel(r.H_w, (4 * w2 - w1) / 3)) <= 1e-6
    assert r.voltage == bias and r.error is None
    u = frequency_response(F, strip=s, method="circuit", voltage=bias)
    assert np.array_equal(r.Z_area, u.Z_area)
    # the bias changes the line (C_d(V) > C_d(0): slower); 0 Ohm/sq is the biased uniform strip
    assert np.max(rel(r.Z, line_response(F, strip=s, sheet_resistance=2.5, method="circuit").Z)) > 1e-2
    r0 = line_response(F, strip=s, sheet_resistance=0.0, method="circuit", voltage=bias)
    assert np.array_equal(r0.Z, u.Z) and np.array_equal(r0.H_w, u.H_w)
    with pytest.raises(ValueError, match="method 'circuit'"):
        line_response(F, sheet_resistance=2.5, voltage=0.5)


def test_circuit_line_error_is_the_deviation_from_the_pnp_line():
    r = line_response(F, sheet_resistance=2.5, method="circuit")
    p = line_response(F, sheet_resistance=2.5)
    dev = np.maximum(rel(r.Z, p.Z), rel(r.H_w, p.H_w))
    assert np.allclose(r.error, dev, rtol=1e-12, atol=0) and r.error_max == np.max(dev)
    assert p.error is None and np.isnan(p.error_max)


def test_zero_sheet_resistance_dynamic_is_the_uniform_modal_strip_exactly():
    eta = 3e3
    u = frequency_response(F, beam="dynamic", viscous_modulus=eta)
    r = line_response(F, sheet_resistance=0.0, beam="dynamic", viscous_modulus=eta)
    for a, b in ((r.Z, u.Z), (r.H_w, u.H_w), (r.H_theta, u.H_theta), (r.H_F, u.H_F)):
        assert np.array_equal(a, b)
    # a vanishing sheet resistance through the distributed moment's quadrature: the same within the
    # stated beam_error (far above the resonances the modal sums cancel the statics: it grows there)
    t = line_response(F, sheet_resistance=1e-14, beam="dynamic", viscous_modulus=eta)
    low = F < 1e3
    for a, b in ((t.H_w, u.H_w), (t.H_theta, u.H_theta), (t.H_F, u.H_F)):
        assert np.all(rel(a, b) <= t.beam_error)
        assert np.max(rel(a, b)[low]) < 1e-9
    # the quasi-static line's blocked-tip force: 3 int (L - x) M dx/L^3, i.e. 1.5 H_M/L uniform
    q = line_response(F, sheet_resistance=0.0)
    assert np.allclose(q.H_F, frequency_response(F).H_F, rtol=1e-14, atol=0)


def test_zero_sheet_resistance_is_the_uniform_strip_exactly():
    for method in ("pnp-linear", "circuit"):
        u = frequency_response(F, method=method, model="affine")
        r = line_response(F, method=method, model="affine")  # material default: 0 Ohm/sq
        assert np.array_equal(r.Z, u.Z) and np.array_equal(r.H_w, u.H_w) and np.array_equal(r.Z_area, u.Z_area)
        r0 = line_response(F, method=method, model="affine", sheet_resistance=0.0, x=[0.0, 0.01, 0.02])
        assert np.array_equal(r0.Z, u.Z) and np.array_equal(r0.w_amp, u.w_amp)
        assert np.array_equal(r0.V_profile, np.ones_like(r0.V_profile))
    # the material parameter is the default of the keyword
    m = NAFION_LI.with_(sheet_resistance=2.5)
    assert np.array_equal(line_response(F, material=m).Z, line_response(F, sheet_resistance=2.5).Z)


def test_small_sheet_resistance_tends_to_uniform():
    u = frequency_response(F)
    for Rs in (1e-4, 1e-8, 1e-12):
        r = line_response(F, sheet_resistance=Rs)
        g2 = np.abs(r.gamma_L) ** 2
        # derived series: Z_in/Z_u = 1 + g^2/3 + ..., w/w_u = 1 - g^2/4 + ...
        assert np.all(rel(r.Z, u.Z) <= g2 / 3 * 1.01 + 1e-15)
        assert np.all(rel(r.H_w, u.H_w) <= g2 / 4 * 1.01 + 1e-15)
    assert np.max(rel(r.Z, u.Z)) < 1e-11


def test_large_sheet_resistance_high_frequency_is_the_characteristic_impedance():
    f = np.geomspace(1e2, 1e5, 7)
    r = line_response(f, sheet_resistance=1e3)
    assert np.all(r.gamma_L.real > 40)
    Z0 = np.sqrt((2 * 1e3 / 5e-3) * r.Z_area / 5e-3)  # sqrt(r / y) from r = 2 R_s/(2l), y = 2l/Z_area
    assert np.max(rel(r.Z, Z0)) < 1e-13
    assert np.max(rel(r.Z0, Z0)) < 1e-13
    # beyond a few decay lengths the strip is not driven: the tip moves as if only ~L/g were active
    assert np.all(np.abs(r.H_w) < 2.1 / np.abs(r.gamma_L) * np.abs(r.uniform.H_w))


def _mp_eval(expr, gv, xv=None):
    mp.mp.dps = 40
    fn = sp.lambdify((DL.g, DL.xi), expr, "mpmath")
    return complex(fn(mp.mpc(gv.real, gv.imag), mp.mpf(0.3) if xv is None else mp.mpf(xv)))


@pytest.mark.parametrize("gv", [1e-90 + 1e-90j, 1e-6 + 2e-7j, 3e-3 + 3e-3j, 0.4 + 0.1j, 2.5 + 2j, 30 + 29j, 700 + 700j, 5.0])
def test_factors_equal_the_sympy_closed_forms(gv):
    fz, fth, fw = line_factors(np.array([gv]))
    cf = DL.closed_forms()
    for got, key in ((fz, "impedance"), (fth, "rotation"), (fw, "deflection")):
        ref = _mp_eval(cf[key], gv)
        assert abs(got[0] - ref) <= 4e-15 * abs(ref), key
    for xv in (0.0, 0.3, 0.999, 1.0):
        ref = _mp_eval(cf["profile"], gv, xv)
        got = voltage_profile(np.array([gv]), xv)[0]
        # g xi is rounded once: a phase error of eps |g xi| is inherent to double-precision input
        assert abs(got - ref) <= 4e-15 * (1 + abs(gv)) * abs(ref)


@pytest.mark.slow
def test_derivation_checks():
    assert DL.check_all()


# second cantilever root; a mode of order ~10 (~4 s: with the slow tests)
@pytest.mark.parametrize("betaL", [4.694091, pytest.param(30.0, marks=pytest.mark.slow)])
def test_modal_integral_against_independent_quadrature(betaL):
    L = 0.02
    beta = betaL / L

    def curv(x):
        return np.cos(beta * x) + 0.3 * np.sinh(beta * x) / np.sinh(beta * L)

    g = np.array([0.0, 0.5 + 0.2j, 3 + 2j, 60 + 55j, 900 + 900j])
    val, err = moment_modal_integral(curv, g, L, error=True)
    mp.mp.dps = 30
    for k, gv in enumerate(g):
        gm = mp.mpc(gv.real, gv.imag)

        def f(x, gm=gm):
            xi = x / L
            return mp.cosh(gm * (1 - xi)) / mp.cosh(gm) * (mp.cos(beta * x) + 0.3 * mp.sinh(beta * x) / mp.sinh(beta * L))

        decay = [L / abs(gv) * c for c in (1, 5, 20)] if abs(gv) > 1 else []
        pts = sorted(set([p for p in decay if p < L] + list(np.linspace(0, L, 9))))
        ref = complex(mp.quad(f, pts))
        scale = complex(mp.quad(lambda x, gm=gm: abs(f(x, gm)), pts)).real
        assert abs(val[k] - ref) <= 1e-12 * scale
        assert err[k] <= 1e-8 * scale
    # g = 0: the uniform moment, int phi'' dx = phi'(L) - phi'(0)
    exact = np.sin(beta * L) / beta + 0.3 * (np.cosh(beta * L) - 1) / (beta * np.sinh(beta * L))
    assert val[0].real == pytest.approx(exact, rel=1e-13)
    # several modes at once: (k, n) curvatures give (len(g), k)
    both = moment_modal_integral(lambda x: np.vstack([curv(x), np.cos(x / L)]), g, L)
    assert both.shape == (g.size, 2) and np.allclose(both[:, 0], val, rtol=1e-14, atol=0)
    # LineResult.modal_forcing = H_M times the same integral
    r = line_response(F[:3], sheet_resistance=2.5)
    assert np.allclose(r.modal_forcing(curv), r.H_M * moment_modal_integral(curv, r.gamma_L, L), rtol=1e-15, atol=0)
    two = r.modal_forcing(lambda x: np.vstack([curv(x), 2 * curv(x)]))
    assert two.shape == (3, 2) and np.allclose(two[:, 1], 2 * r.modal_forcing(curv), rtol=1e-15, atol=0)


def test_bad_inputs():
    with pytest.raises(ValueError, match="sheet_resistance"):
        line_response(F, sheet_resistance=-1.0)
    with pytest.raises(ValueError, match="sheet_resistance"):
        line_response(F, sheet_resistance=float("nan"))
    with pytest.raises(ValueError, match="sheet_resistance"):
        NAFION_LI.with_(sheet_resistance=-2.0)
    with pytest.raises(ValueError, match="x must be"):
        line_response(F, sheet_resistance=1.0, x=[0.0, 1.0])
    with pytest.raises(ValueError, match="uniform_panels"):
        moment_modal_integral(np.cos, np.array([1.0]), 0.02, uniform_panels=0)


def test_cli_sheet_resistance(capsys):
    assert main(["freq", "--from", "0.1Hz", "--to", "1kHz", "--points", "5", "--sheet-resistance", "2.5ohm/sq", "--beam",
                 "quasi-static", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    r = line_response(np.geomspace(0.1, 1e3, 5), sheet_resistance=2.5)
    assert out["sheet_resistance"] == 2.5
    assert np.allclose(out["Z_re"], r.Z.real, rtol=1e-15) and np.allclose(out["w_amp"], r.w_amp, rtol=1e-15)
    assert any("sheet resistance" in n for n in out["notes"])
    assert main(["freq", "--from", "0.1Hz", "--to", "1kHz", "--points", "5", "--json"]) == 0
    base = json.loads(capsys.readouterr().out)
    assert base["Z_re"] == list(frequency_response(np.geomspace(0.1, 1e3, 5)).Z.real)
    for bad in ("-1ohm/sq", "2V", "x"):
        with pytest.raises(SystemExit) as e:
            main(["freq", "--from", "1Hz", "--to", "2Hz", "--sheet-resistance", bad])
        assert e.value.code == 2
        assert "--sheet-resistance" in capsys.readouterr().err


def test_cli_sheet_resistance_with_the_dynamic_beam_a_bias_and_an_export(capsys, tmp_path):
    f = np.geomspace(0.1, 1e3, 6)
    base = ["freq", "--from", "0.1Hz", "--to", "1kHz", "--points", "6", "--sheet-resistance", "2.5ohm/sq", "--json"]
    assert main(base + ["--viscous-modulus", "2e3", "--beam", "dynamic"]) == 0
    out = json.loads(capsys.readouterr().out)
    r = line_response(f, sheet_resistance=2.5, beam="dynamic", viscous_modulus=2e3)
    assert out["beam"] == "dynamic" and out["resonances"]["clamped-free"] == r.resonances["clamped-free"]
    assert np.allclose(out["w_amp"], r.w_amp, rtol=1e-15) and np.allclose(out["F_amp"], np.abs(r.H_F), rtol=1e-15)
    assert 0.0 <= out["beam_error_max"] < 1e-6
    # with a DC bias (circuit): the small-signal line about the biased static state
    assert main(base + ["--method", "circuit", "--voltage", "0.4V", "--beam", "quasi-static"]) == 0
    out = json.loads(capsys.readouterr().out)
    r = line_response(f, sheet_resistance=2.5, method="circuit", voltage=0.4)
    assert np.allclose(out["Z_re"], r.Z.real, rtol=1e-15) and out["voltage"] == 0.4 and "error" not in out
    # the reduced-order model of the line, its stated error measured here against the full line
    path = tmp_path / "tf.json"
    assert main(base + ["--viscous-modulus", "2e3", "--beam", "dynamic", "--export", str(path), "--export-tol", "1e-3"]) == 0
    out = json.loads(capsys.readouterr().out)
    doc = json.loads(path.read_text())
    m = doc["models"]["w"]
    fc = np.geomspace(0.1, 1e3, 301)
    fit = m["d"] + np.sum(np.array([complex(*p) for p in m["residues"]])
                          / (2j * np.pi * fc[:, None] - np.array([complex(*p) for p in m["poles"]])), axis=1)
    full = line_response(fc, sheet_resistance=2.5, beam="dynamic", viscous_modulus=2e3).H_w
    assert np.max(rel(fit, full)) <= 1.5 * m["max_rel_error"] and m["max_rel_error"] <= 1e-3
    assert "order" in out["export"]["w"]
    # 0 Ohm/sq is the uniform strip's response, value for value, with the modal beam too
    plain = ["freq", "--from", "0.1Hz", "--to", "1kHz", "--points", "6", "--viscous-modulus", "2e3", "--beam", "dynamic",
             "--json"]
    assert main(plain) == 0
    a = json.loads(capsys.readouterr().out)
    assert main(plain + ["--sheet-resistance", "0"]) == 0
    b = json.loads(capsys.readouterr().out)
    assert all(a[k] == b[k] for k in ("Z_re", "Z_im", "w_amp", "w_phase", "theta_amp", "F_amp", "F_phase"))


def test_a_sheet_resistance_past_the_guard_is_refused_in_one_line():
    from ipmc_asym.dynamics.drive import drive_response
    from ipmc_asym.dynamics.line import line_response

    for call in (lambda: line_response([1.0], sheet_resistance=1e300),
                 lambda: drive_response("step:1V", 0.01, 11, beam="quasi-static", sheet_resistance=1e308)):
        with pytest.raises(ValueError, match=r"sheet_resistance must be a finite number within 0\.\.1e\+12 Ohm/sq"):
            call()
