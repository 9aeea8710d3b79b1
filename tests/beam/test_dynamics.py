"""The modal beam against the characteristic equations and an independent finite-difference beam."""

import math

import mpmath
import numpy as np
import pytest

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
        A64 = A.astype(complex)
        w = np.linalg.solve(A64, r.astype(complex)).astype(np.clongdouble)
        for _ in range(3):
            res = r - A @ w
            w = w + np.linalg.solve(A64, res.astype(complex))
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
