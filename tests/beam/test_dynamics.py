"""The modal beam against the characteristic equations and an independent finite-difference beam."""

import math

import mpmath
import numpy as np
import pytest
from scipy.linalg import lu_factor, lu_solve

from ipmc_asym.beam.dynamics import (
    SUPPORTS,
    Beam,
    ModalIntegrator,
    eigenvalues,
    hydrated_density,
    mode_shape,
    natural_frequencies,
    transfer,
    viscous_modulus_from_damping_ratio,
)
from ipmc_asym.kernels.special import gauss_legendre
from ipmc_asym.model.params import NAFION_LI

BEAM = Beam.from_strip(0.02, 5e-3, 200e-6, NAFION_LI)
CHAR = {
    "clamped-free": lambda x: 1 + mpmath.cos(x) * mpmath.cosh(x),
    "clamped-pinned": lambda x: mpmath.tan(x) - mpmath.tanh(x),
    "clamped-clamped": lambda x: mpmath.cos(x) * mpmath.cosh(x) - 1,
}


@pytest.mark.parametrize("support", SUPPORTS)
def test_modal_frequencies_are_the_roots_of_the_characteristic_equation(support):
    b = eigenvalues(support, 12)
    mpmath.mp.dps = 40
    for x in b:
        root = mpmath.findroot(CHAR[support], mpmath.mpf(x))
        f_exact = float(root) ** 2 * BEAM.omega_scale / (2 * math.pi)
        f = x**2 * BEAM.omega_scale / (2 * math.pi)
        assert abs(f / f_exact - 1) < 1e-10
    assert np.all(np.diff(b) > 2.5)  # one root per bracket, none skipped


def test_first_resonance_of_the_nominal_strip():
    # f1 = (1.8751^2/(2 pi L^2)) sqrt(E I_p/(rho A)), rho of the hydrated membrane
    rho = (1 - 0.38) * 2078 + 0.38 * 1000
    assert hydrated_density(NAFION_LI) == pytest.approx(rho)
    A, Ip = 5e-3 * 200e-6, 5e-3 * (200e-6) ** 3 / 12
    f1 = 1.8751040687**2 / (2 * math.pi * 0.02**2) * math.sqrt(1.3e8 * Ip / (rho * A))
    assert natural_frequencies("clamped-free", BEAM, 1)[0] == pytest.approx(f1, rel=1e-9)
    assert 20 < f1 < 25


@pytest.mark.parametrize("support", SUPPORTS)
def test_mode_shapes_orthonormal_and_boundary_conditions(support):
    b = eigenvalues(support, 30)
    x, w, _ = gauss_legendre(40)
    edges = np.linspace(0, 1, 41)
    xi = np.concatenate([0.5 * (a + c) + 0.5 * (c - a) * x for a, c in zip(edges[:-1], edges[1:])])
    wt = np.concatenate([0.5 * (c - a) * w for a, c in zip(edges[:-1], edges[1:])])
    ph = mode_shape(support, b[:, None], xi[None, :])
    G = (ph * wt) @ ph.T
    assert np.max(np.abs(G - np.eye(b.size))) < 1e-10
    scale = b**2
    assert np.max(np.abs(mode_shape(support, b, 0.0))) < 1e-12
    assert np.max(np.abs(mode_shape(support, b, 0.0, 1) / b)) < 1e-12
    end = {"clamped-free": (2, 3), "clamped-pinned": (0, 2), "clamped-clamped": (0, 1)}[support]
    for k in end:
        assert np.max(np.abs(mode_shape(support, b, 1.0, k)) / b**k) < 1e-10 * np.max(scale)


def _fd_beam(f, beam, support, N, M=1.0):
    """Second-order finite differences with ghost nodes, frequency domain: (w_tip, theta_tip, F_tip).

    Rows scaled to integer stencils (exact in floating point) and iterative refinement with the
    residual in extended precision: the solution carries the truncation error only (the
    4th-difference matrix has condition ~N^4).
    """
    L = beam.length
    h = L / N
    out = []
    for fr in np.atleast_1d(f):
        om = 2 * math.pi * fr
        EIs = beam.EI * (1 + 1j * om * beam.tau_v)
        n = N + 4  # unknowns w_{-1} .. w_{N+2}; index j = i + 1
        A = np.zeros((n, n), dtype=np.clongdouble)
        r = np.zeros(n, dtype=np.clongdouble)
        A[0, 1] = 1  # w_0 = 0
        A[1, 0], A[1, 2] = -1, 1  # w'(0) = 0
        last = N if support == "clamped-free" else N - 1
        row = 2
        mass = np.clongdouble(beam.rhoA * om**2 * h**4) / np.clongdouble(EIs)
        for i in range(1, last + 1):
            j = i + 1
            A[row, j - 2:j + 3] = [1, -4, 6, -4, 1]
            A[row, j] -= mass
            row += 1
        j = N + 1
        A[row, j - 1:j + 2] = [1, -2, 1]  # second derivative at L = -M/EI*
        r[row] = -np.clongdouble(M * h * h) / np.clongdouble(EIs)
        row += 1
        if support == "clamped-free":
            A[row, [j - 2, j - 1, j + 1, j + 2]] = [-1, 2, -2, 1]  # third derivative at L = 0
        else:
            A[row, j] = 1  # w_N = 0
            row += 1
            A[row, j + 2] = 1  # the unused ghost
        lu = lu_factor(A.astype(complex))  # one factorisation for the solve and its refinements
        w = lu_solve(lu, r.astype(complex)).astype(np.clongdouble)
        for _ in range(3):
            res = r - A @ w
            w = w + lu_solve(lu, res.astype(complex))
        wi = w[1:N + 2]
        x = np.linspace(0, L, N + 1)
        theta = (w[N + 2] - w[N]) / (2 * h)
        # F = -m'(L): m'' = rho A om^2 w, m(L) = 0, m(0) = EI* w''(0) + M
        m0 = EIs * (w[2] - 2 * w[1] + w[0]) / h**2 + M
        xw = x * wi
        integ = h * (xw.sum() - 0.5 * (xw[0] + xw[-1]))
        F = -(-m0 + beam.rhoA * om**2 * integ) / L
        out.append((complex(w[N + 1]), complex(theta), complex(F)))
    return np.array(out)


def _fd_richardson(f, beam, support, Ns=(30, 60, 120, 240)):
    """Three levels of Richardson extrapolation (errors h^2, h^4, h^6 removed)."""
    res = [_fd_beam(f, beam, support, N) for N in Ns]
    for p in (4, 16, 64):
        res = [(p * res[i + 1] - res[i]) / (p - 1) for i in range(len(res) - 1)]
    return res[0]


@pytest.mark.parametrize("tau_v", [0.0, 2e-4])
def test_free_tip_transfer_against_finite_differences_below_the_third_resonance(tau_v):
    beam = Beam(BEAM.length, BEAM.EI, BEAM.rhoA, tau_v)
    fn = natural_frequencies("clamped-free", beam, 3)
    f = np.array([0.3, 0.9, 1.1, 3.0, 6.0, 6.6, 12.0, 15.0]) * fn[0]
    assert f[-1] < fn[2]
    tr = transfer(f, beam, "clamped-free")
    fd = _fd_richardson(f, beam, "clamped-free")
    assert np.max(np.abs(tr["w"] / fd[:, 0] - 1)) < 1e-6
    assert np.max(np.abs(tr["theta"] / fd[:, 1] - 1)) < 1e-6
    # the static limit is the small-displacement statics, exactly
    t0 = transfer([0.0], beam, "clamped-free")
    assert t0["w"][0] == pytest.approx(-beam.length**2 / (2 * beam.EI), rel=1e-15)


@pytest.mark.parametrize("tau_v", [0.0, 2e-4])
def test_blocked_tip_force_against_finite_differences_below_the_third_resonance(tau_v):
    beam = Beam(BEAM.length, BEAM.EI, BEAM.rhoA, tau_v)
    fn = natural_frequencies("clamped-pinned", beam, 3)
    f = np.array([0.0, 0.4, 0.95, 1.2, 2.5, 3.5, 5.8]) * fn[0]
    assert f[-1] < fn[2]
    tr = transfer(f, beam, "clamped-pinned")
    fd = _fd_richardson(f, beam, "clamped-pinned")
    assert np.max(np.abs(tr["F"] / fd[:, 2] - 1)) < 1e-6
    assert np.max(np.abs(tr["theta"] / fd[:, 1] - 1)) < 1e-6
    assert tr["F"][0] == pytest.approx(1.5 / beam.length, rel=1e-15)


def test_clamped_clamped_full_electrode_does_not_move():
    tr = transfer(np.array([0.0, 10.0, 500.0]), BEAM, "clamped-clamped")
    assert np.all(tr["M_root"] == 1.0)
    fd = _fd_beam([10.0], BEAM, "clamped-pinned", 50)  # sanity: the FD beam does move when pinned
    assert abs(fd[0, 1]) > 0


def _fd_ramp_response(beam, N, T_r, times, M0=1.0):
    """Free-tip FD beam (ghosts eliminated), exact in time for the ramp M0 min(t/T_r, 1): tip w(t)."""
    L = beam.length
    h = L / N
    # unknowns w_1..w_N; ghosts: w_{-1} = w_1, w_{N+1} = 2 w_N - w_{N-1} - M h^2/EI,
    # w_{N+2} = 2 w_{N+1} - 2 w_{N-1} + w_{N-2}
    K = np.zeros((N, N))
    c = np.zeros(N)  # load per unit M (from the ghosts)
    for i in range(1, N + 1):
        coef = {i - 2: 1.0, i - 1: -4.0, i: 6.0, i + 1: -4.0, i + 2: 1.0}
        row = np.zeros(N + 3)  # index k -> w_k, k = -1..N+1 stored at k + 1 (w_{N+2} expanded)
        cm = 0.0
        for k, a in coef.items():
            if k == N + 2:  # 2 w_{N+1} - 2 w_{N-1} + w_{N-2}
                for kk, aa in ((N + 1, 2.0), (N - 1, -2.0), (N - 2, 1.0)):
                    row[kk + 1] += a * aa
            else:
                row[k + 1] += a
        # w_{N+1} = 2 w_N - w_{N-1} - M h^2/EI
        a = row[N + 2]
        row[N + 2] = 0.0
        row[N + 1] += 2 * a
        row[N] -= a
        cm -= a * h * h / beam.EI
        row[0 + 2] += row[0]  # w_{-1} = w_1
        row[0] = 0.0
        K[i - 1] = row[2:N + 2] * beam.EI / h**4
        c[i - 1] = cm * beam.EI / h**4
    # rho A w'' + K w + c M = 0
    lam, V = np.linalg.eig(K / beam.rhoA)
    lam, V = lam.real, V.real
    g = np.linalg.solve(V, -c / beam.rhoA) * M0
    om = np.sqrt(lam)
    t = np.asarray(times)[:, None]

    def ramp(tt):
        tt = np.maximum(tt, 0.0)
        return (tt - np.sin(om * tt) / om) / (T_r * om**2)

    z = g * (ramp(t) - ramp(t - T_r))
    return (z @ V.T)[:, -1]


def test_time_response_against_the_finite_difference_beam_and_static_limit():
    fn = natural_frequencies("clamped-free", BEAM, 1)[0]
    T_r = 0.37 / fn
    t = np.linspace(0.0, 4.0 / fn, 401)
    t = np.union1d(t, [T_r])
    M = np.minimum(t / T_r, 1.0)
    w_static = -M * BEAM.length**2 / (2 * BEAM.EI)
    integ = ModalIntegrator(BEAM, "clamped-free")
    out = integ.advance(t, M, {"w": w_static})
    a = _fd_ramp_response(BEAM, 150, T_r, t)
    b = _fd_ramp_response(BEAM, 300, T_r, t)
    fd = (4 * b - a) / 3
    scale = np.max(np.abs(fd))
    # the FD beam's own error (h^4 after one extrapolation, N = 150/300) is ~1e-5 here
    assert np.max(np.abs(out["w"] - fd)) < 1e-4 * scale
    # the high modes the FD beam smears out matter little: the modal response with 8 modes is the same to 1e-4
    i8 = ModalIntegrator(BEAM, "clamped-free", n_modes=8).advance(t, M, {"w": w_static})
    assert np.max(np.abs(i8["w"] - out["w"])) < 1e-4 * scale
    # the dynamics overshoot: a step-like ramp faster than the period rings about the static value
    assert np.min(out["w"]) < 1.3 * w_static[-1]
    # chunked = one pass
    i2 = ModalIntegrator(BEAM, "clamped-free")
    k = 150
    o1 = i2.advance(t[:k + 1], M[:k + 1], {"w": w_static[:k + 1]})
    o2 = i2.advance(t[k:], M[k:], {"w": w_static[k:]})
    assert np.allclose(np.concatenate([o1["w"], o2["w"][1:]]), out["w"], rtol=0, atol=1e-12 * scale)


def test_slow_drive_reaches_the_static_result_and_damping_from_a_ratio():
    fn = natural_frequencies("clamped-free", BEAM, 1)[0]
    eta = viscous_modulus_from_damping_ratio(0.05, fn, NAFION_LI.E)
    beam = Beam.from_strip(0.02, 5e-3, 200e-6, NAFION_LI, viscous_modulus=eta)
    assert beam.tau_v * 2 * math.pi * fn / 2 == pytest.approx(0.05)
    t = np.linspace(0.0, 200.0 / fn, 20001)
    M = np.minimum(t / (20.0 / fn), 1.0)
    ws = -1.7e-3 * M  # any static curve (the forward model's in use): reached at rest
    out = ModalIntegrator(beam, "clamped-free").advance(t, M, {"w": ws, "theta": 2 * ws})
    assert out["w"][-1] == pytest.approx(ws[-1], rel=1e-8)
    assert out["theta"][-1] == pytest.approx(2 * ws[-1], rel=1e-8)
    # frequency response: resonance peak near f1 with Q ~ 1/(2 zeta)
    f = np.linspace(0.8, 1.2, 4001) * fn
    tr = transfer(f, beam, "clamped-free")
    peak = np.max(np.abs(tr["dynamic_factor"]["w"]))
    assert 8.0 < peak < 12.0


def test_first_resonance_vectorised_equals_the_modal_beam():
    """first_resonance (arrays) = natural_frequencies of Beam.from_strip (scalar), and the
    textbook f1 = (1.8751^2 / 2 pi L^2) sqrt(E I_p/(rho A)) of a cantilever."""
    from ipmc_asym.beam.dynamics import Beam, first_resonance, hydrated_density, natural_frequencies
    from ipmc_asym.model.params import NAFION_LI, second_moment

    L = np.array([0.01, 0.02, 0.04])
    f = first_resonance(L, 5e-3, 200e-6, NAFION_LI)
    for Li, fi in zip(L, f):
        assert fi == pytest.approx(natural_frequencies("clamped-free", Beam.from_strip(Li, 5e-3, 200e-6, NAFION_LI), 1)[0],
                                   rel=1e-13)
    EIp = NAFION_LI.E * second_moment(5e-3, 200e-6)
    rhoA = hydrated_density(NAFION_LI) * 5e-3 * 200e-6
    np.testing.assert_allclose(f, 1.8751040687**2 / (2 * np.pi * L**2) * np.sqrt(EIp / rhoA), rtol=1e-9)


@pytest.mark.parametrize("support", ["clamped-free", "clamped-pinned"])
def test_moment_kernels_of_a_uniform_moment_are_the_closed_form_statics(support):
    # int kappa_1 dx and int kappa_2 dx over [0, L] against _static_small and _second_static, whose
    # polynomials are built independently (the uniform moment's static deflection integrated)
    from ipmc_asym.beam.dynamics import _second_static, _static_small, moment_kernels

    b = Beam.from_strip(0.02, 5e-3, 200e-6, NAFION_LI, 2e3)
    ker = moment_kernels(support, b)
    w, th, F = _static_small(support, b)
    w2, dw2, _, d3w2 = _second_static(support, b)
    exact = ({"w": (w, w2), "theta": (th, dw2)} if support == "clamped-free"
             else {"F": (F, -b.EI * d3w2), "theta": (th, dw2)})
    for name, (k1, k2) in ker.items():
        i1, i2 = k1.integ(1), k2.integ(1)
        assert (i1(1) - i1(0)) * b.length == pytest.approx(exact[name][0], rel=1e-13)
        assert (i2(1) - i2(0)) * b.length == pytest.approx(exact[name][1], rel=1e-13)
    with pytest.raises(ValueError, match="distributed moment"):
        moment_kernels("clamped-clamped", b)


@pytest.mark.parametrize("support", ["clamped-free", "clamped-pinned"])
def test_distributed_transfer_of_a_uniform_moment_is_the_modal_transfer(support):
    from ipmc_asym.beam.dynamics import distributed_transfer

    b = Beam.from_strip(0.02, 5e-3, 200e-6, NAFION_LI, 2e3)
    f = np.array([0.0, 1.0, 22.0, 141.0, 400.0])
    xg, wg = np.polynomial.legendre.leggauss(40)
    edges = np.linspace(0.0, b.length, 41)
    x = (0.5 * np.diff(edges)[:, None] * np.asarray(xg)[None, :] + 0.5 * (edges[1:] + edges[:-1])[:, None]).ravel()
    wt = (0.5 * np.diff(edges)[:, None] * np.asarray(wg)[None, :]).ravel()

    def integrate(c):  # M_a = 1 N m on [0, L]
        return np.tile(c(x) @ wt, (f.size, 1)).astype(complex)

    d = distributed_transfer(f, b, support, integrate)
    t = transfer(f, b, support)
    for k in ("w", "theta") if support == "clamped-free" else ("F", "theta"):
        assert np.max(np.abs(d[k] / t[k] - 1)) < 1e-11, k


# --- partial electrodes and the clamped-clamped strip -------------------------------------------------------------

PARTIAL = (0.002, 0.012)  # m, on the 2 cm strip


def _exact_beam(f, beam, support, M=1.0):
    """Exact harmonic response of the continuous strip (no modes): per piece cut by the electrode's ends,
    ``w = sum c_k e_k(beta (x - x_j))`` with e = cos, sin, cosh, sinh, ``beta^4 = rho A omega^2/(EI k)``;
    ``w, w', m = EI k w'' + M_a, m' = EI k w'''`` continuous, the support's end conditions.
    Returns dict of the outputs (the clamps' moments and forces, midspan and tip values)."""
    L, EI = beam.length, beam.EI
    x1, x2 = beam.electrode if beam.electrode is not None else (0.0, L)
    brk = sorted({0.0, x1, x2, L})
    ns = len(brk) - 1
    Ma = [M if (brk[j] >= x1 and brk[j + 1] <= x2) else 0.0 for j in range(ns)]
    om = 2 * math.pi * f
    kv = 1 + 1j * om * beam.tau_v
    EIk = EI * kv
    beta = (beam.rhoA * om**2 / EIk) ** 0.25

    def basis(y, d):  # d-th derivative of (cos, sin, cosh, sinh)(beta y)
        z = beta * y
        c, s, ch, sh = np.cos(z), np.sin(z), np.cosh(z), np.sinh(z)
        tab = [(c, s, ch, sh), (-s, c, sh, ch), (-c, -s, ch, sh), (s, -c, sh, ch)]
        return np.array(tab[d]) * beta**d

    A = np.zeros((4 * ns, 4 * ns), complex)
    r = np.zeros(4 * ns, complex)
    row = 0
    for d in (0, 1):
        A[row, 0:4] = basis(0.0, d)
        row += 1
    for j in range(1, ns):
        for d in range(4):
            A[row, 4 * (j - 1):4 * j] = basis(brk[j] - brk[j - 1], d)
            A[row, 4 * j:4 * j + 4] = -basis(0.0, d)
            if d == 2:
                r[row] = (Ma[j] - Ma[j - 1]) / EIk
            row += 1
    ell = brk[-1] - brk[-2]
    end = {"clamped-free": (2, 3), "clamped-pinned": (0, 2), "clamped-clamped": (0, 1)}[support]
    for d in end:
        A[row, -4:] = basis(ell, d)
        r[row] = -Ma[-1] / EIk if d == 2 else 0.0
        row += 1
    c = np.linalg.solve(A, r)

    def at(x, d):
        j = min(max(np.searchsorted(brk, x, side="right") - 1, 0), ns - 1)
        return complex(basis(x - brk[j], d) @ c[4 * j:4 * j + 4])

    return {"w": at(L, 0), "theta": at(L, 1), "F": -EIk * at(L, 3), "w_mid": at(L / 2, 0),
            "M_root": EIk * at(0.0, 2) + Ma[0], "M_tip": EIk * at(L, 2) + Ma[-1], "F_root": EIk * at(0.0, 3),
            "F_tip": -EIk * at(L, 3)}


def _static_by_quadrature(beam, support, n=20_001):
    """Small-displacement statics per unit moment by integrating the curvature ``(m - M_a)/EI`` twice
    (trapezoidal, a grid through the electrode's ends); ``m = a + b x`` from the end conditions."""
    L, EI = beam.length, beam.EI
    x1, x2 = beam.electrode
    brk = [v for v in sorted({0.0, x1, x2, L})]
    # each piece its own nodes (the breaks twice): the jumps of M_a fall between two coincident nodes
    x = np.concatenate([np.linspace(a, b, n) for a, b in zip(brk[:-1], brk[1:])])
    Ma = np.concatenate([np.full(n, 1.0 if (a >= x1 and b <= x2) else 0.0) for a, b in zip(brk[:-1], brk[1:])])

    def integ(y):
        return np.concatenate(([0.0], np.cumsum(0.5 * (y[1:] + y[:-1]) * np.diff(x))))

    def deflect(kappa):  # w with w(0) = w'(0) = 0
        slope = integ(kappa)
        return integ(slope), slope

    # w is linear in (a, b): w = w_0 + a w_a + b w_b; Ma's jumps at the ends counted on the right side
    w0, t0 = deflect(-Ma / EI)
    wa, ta = deflect(np.ones_like(x) / EI)
    wb, tb = deflect(x / EI)
    if support == "clamped-free":
        a, b = 0.0, 0.0  # m = 0
    elif support == "clamped-pinned":  # m(L) = 0, w(L) = 0
        a, b = np.linalg.solve([[1.0, L], [wa[-1], wb[-1]]], [0.0, -w0[-1]])
    else:  # w(L) = w'(L) = 0
        a, b = np.linalg.solve([[wa[-1], wb[-1]], [ta[-1], tb[-1]]], [-w0[-1], -t0[-1]])
    w = w0 + a * wa + b * wb
    th = t0 + a * ta + b * tb
    mid = np.interp(L / 2, x, w)
    return {"w": w[-1], "theta": th[-1], "F": -b, "w_mid": mid, "M_root": a, "M_tip": a + b * L,
            "F_root": b, "F_tip": -b}


@pytest.mark.parametrize("support", SUPPORTS)
@pytest.mark.parametrize("electrode", [PARTIAL, (0.0, 0.008), (0.011, 0.02)])
def test_static_outputs_of_a_partial_electrode_against_quadrature_of_the_curvature(support, electrode):
    from ipmc_asym.beam.dynamics import SUPPORT_OUTPUTS, static_outputs

    beam = Beam(BEAM.length, BEAM.EI, BEAM.rhoA, 0.0, electrode)
    ref = _static_by_quadrature(beam, support)
    got = static_outputs(support, beam)
    tr = transfer(np.array([0.0]), beam, support)
    for name in SUPPORT_OUTPUTS[support]:
        # scale: the moments per unit moment 1; forces 1/L; kinematic the cantilever's tip values
        scale = {"M_root": 1.0, "M_tip": 1.0, "F_root": 1 / BEAM.length, "F_tip": 1 / BEAM.length,
                 "F": 1 / BEAM.length, "theta": BEAM.length / BEAM.EI}.get(name, BEAM.length**2 / BEAM.EI)
        assert abs(got[name][0] - ref[name]) < 1e-8 * scale, name
        assert abs(tr[name][0] - ref[name]) < 1e-8 * scale, name  # the frequency -> 0 limit


@pytest.mark.parametrize("tau_v", [0.0, 2e-4])
@pytest.mark.parametrize("support,electrode", [("clamped-clamped", PARTIAL), ("clamped-clamped", (0.0, 0.012)),
                                               ("clamped-free", PARTIAL), ("clamped-pinned", (0.005, 0.02))])
def test_transfer_of_a_partial_electrode_against_the_exact_continuous_beam(support, electrode, tau_v):
    from ipmc_asym.beam.dynamics import SUPPORT_OUTPUTS

    beam = Beam(BEAM.length, BEAM.EI, BEAM.rhoA, tau_v, electrode)
    fn = natural_frequencies(support, beam, 3)
    # below, between and past the first two resonances (not on them: the undamped response is singular)
    f = np.array([0.01, 0.5, 0.93, 1.07, 1.5, 2.4]) * fn[0]
    f = f[np.abs(f - fn[1]) > 0.02 * fn[1]]
    tr = transfer(f, beam, support)
    for i, fr in enumerate(f):
        ref = _exact_beam(fr, beam, support)
        for name in SUPPORT_OUTPUTS[support]:
            scale = max(abs(ref[name]), abs(tr["static"][name]) if name in tr["static"] else 0.0)
            assert abs(tr[name][i] - ref[name]) < 1e-9 * scale, (name, fr)  # measured ~5e-12


def test_clamped_clamped_full_electrode_gives_the_moment_to_the_clamps():
    """The uniform moment: nothing moves, both reaction moments = M_A, no forces (any frequency)."""
    beam = Beam(BEAM.length, BEAM.EI, BEAM.rhoA, 1e-4)
    tr = transfer(np.array([0.0, 10.0, 500.0]), beam, "clamped-clamped")
    assert np.all(tr["M_root"] == 1.0) and np.all(tr["M_tip"] == 1.0)
    assert np.all(tr["F_root"] == 0.0) and np.all(tr["F_tip"] == 0.0) and np.all(tr["w_mid"] == 0.0)
    ref = _exact_beam(50.0, Beam(BEAM.length, BEAM.EI, BEAM.rhoA, 1e-4, (0.0, BEAM.length)), "clamped-clamped")
    assert abs(ref["M_root"] - 1.0) < 1e-9 and abs(ref["w_mid"]) < 1e-12 * BEAM.length**2 / BEAM.EI


@pytest.mark.parametrize("support,electrode", [("clamped-clamped", PARTIAL), ("clamped-pinned", (0.005, 0.02)),
                                               ("clamped-free", PARTIAL)])
def test_time_response_of_a_partial_electrode_reaches_the_exact_harmonic_state(support, electrode):
    """A sine moment switched on at rest, damped: after the transient the modal integrator's outputs
    (every output of the support) are the exact continuous beam's harmonic response."""
    from ipmc_asym.beam.dynamics import SUPPORT_OUTPUTS, static_outputs

    f1 = natural_frequencies(support, BEAM, 1)[0]
    eta = viscous_modulus_from_damping_ratio(0.1, f1, NAFION_LI.E)
    beam = Beam.from_strip(0.02, 5e-3, 200e-6, NAFION_LI, viscous_modulus=eta, electrode=electrode)
    fd = 0.6 * f1
    t = np.linspace(0.0, 60.0 / fd, 60 * 200 + 1)
    M = np.sin(2 * math.pi * fd * t)
    st = static_outputs(support, beam)
    names = SUPPORT_OUTPUTS[support]
    out = ModalIntegrator(beam, support).advance(t, M, {n: st[n][0] * M for n in names})
    ref = _exact_beam(fd, beam, support)
    last = t > 58.0 / fd
    for n in names:
        want = np.imag(ref[n] * np.exp(2j * math.pi * fd * t[last]))
        assert np.max(np.abs(out[n][last] - want)) < 2e-3 * abs(ref[n]), n
