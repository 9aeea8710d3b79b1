"""Electrode surface resistance in the time domain: the RC line of ``dynamics/line.py`` discretised.

The strip is cut into ``N`` segments along its length (nodes ``x_j = j h``, ``h = L/N``); node
``j`` carries the through-thickness reduced circuit of :mod:`ipmc_asym.dynamics.circuit` over
the electrode area ``2l w_j`` (``w_j = h`` inside, ``h/2`` at the two ends: the trapezoidal
ladder, second order in ``h`` with an error even in ``h``, ``derivations/line.py``), the nodes
are joined by the two electrodes in series, ``r h = 2 R_s h/(2l)``, and the drive ``phi0(t)`` is
applied at the clamp ``x = 0``; the far end is open.  Per node (per unit area) the layers charge
as in the circuit, ``R dsigma_L/dt = v_j - u_j`` (``u_j = V(sigma_L)``), and Kirchhoff's law at
node ``j`` reads ``v_{j-1} - 2 v_j + v_{j+1} = G_j (v_j - u_j)``, ``G_j = 2 R_s w_j h/R``
(``v_{N-1} - v_N = G_N (v_N - u_N)`` at the open end).  The bulk's geometric capacitance is
instantaneous on the scale ``tau`` (as in the circuit): its displacement charge
``C_g (v_j - u_j)`` is added to each node's charge, not to the line's dynamics.

Time stepping: the circuit's variable-step BDF2 (first step backward Euler) for every node at
once; each implicit step is a Newton iteration on the layer voltages and the node voltages
whose linear system, after eliminating the layer voltage of each node, is tridiagonal (one
Thomas sweep, ``O(N)``), with the step limited to 2 ``R T/F`` per iteration (the charge is
exponential in the layer voltage).  State carried over chunks: a run split into chunks is the
same run.

The error of the discretisation is estimated by running ``N`` and ``2 N`` segments side by
side: for an error ``~ h^2`` the ``2 N`` line (whose values are reported) is off by
``|y_2N - y_N|/3`` (Richardson); the stated error is twice that (:data:`ERROR_FACTOR`), which
covers the next order and the time stepping: measured against the inverse Laplace transform of
the exact line (small signal, ``tests/dynamics/test_line_time.py``) the error is at most 1.03 times
the Richardson estimate for ``N`` = 8-32 at 2.5 and 25 Ohm/sq (0.85-1.03).
"""

from __future__ import annotations

import numpy as np
from scipy.linalg import solve_banded

from ipmc_asym.beam.dynamics import _propagate, mode_shape, modes, moment_kernels, natural_frequencies
from ipmc_asym.dynamics.circuit import SUBSTEP_ADVICE, drive_substep, drive_times, layer_rates, strip_beam, substep_grid
from ipmc_asym.dynamics.electrode import charge_scale, core_resistance, time_constant
from ipmc_asym.dynamics.waveforms import voltage_rate
from ipmc_asym.integral.api import paper_model_id
from ipmc_asym.kernels.charge import GL_W, GL_X
from ipmc_asym.kernels.charge_time import integrate_line
from ipmc_asym.model import groups
from ipmc_asym.model.params import Material, Strip, check_sheet_resistance
from ipmc_asym.model.permittivity import Permittivity

__all__ = ["LineStepper", "LineBeamDynamics", "line_weights", "DEFAULT_SEGMENTS", "MAX_SEGMENTS", "ERROR_FACTOR"]

#: segments of the coarser of the two lines (the reported one has twice as many)
DEFAULT_SEGMENTS = 16
#: the stated error of the reported line: this times |y_2N - y_N| (twice the Richardson estimate)
ERROR_FACTOR = 2.0 / 3.0
#: cap on --line-segments (each node is a circuit and a forward-model point per time)
MAX_SEGMENTS = 512


def line_weights(n_segments: int, length: float):
    """Node positions ``x_j`` (m) and trapezoidal area weights ``w_j`` (m) of the ``N``-segment ladder."""
    n = int(n_segments)
    h = float(length) / n
    w = np.full(n + 1, h)
    w[[0, -1]] = 0.5 * h
    return np.linspace(0.0, float(length), n + 1), w


class _Ladder:
    """One ladder of ``n`` segments and its state."""

    def __init__(self, n, strip: Strip, Rs, R):
        self.x, self.w = line_weights(n, strip.length)
        h = strip.length / n
        self.G = 2.0 * Rs * self.w * h / R
        # Kirchhoff's law at nodes 1..N as a banded matrix (solve_banded's layout): the node voltages are
        # algebraic in the layers' and the drive's, psi_{j-1} - (2 + G_j) psi_j + psi_{j+1} = -G_j A_j
        # (the open end: psi_{N-1} - (1 + G_N) psi_N = -G_N A_N)
        self.band = np.zeros((3, n))
        self.band[0, 1:] = 1.0
        self.band[1] = -2.0 - self.G[1:]
        self.band[1, -1] = -1.0 - self.G[-1]
        self.band[2, :-1] = 1.0
        k = n + 1
        self.A, self.A_prev, self.s, self.s_prev, self.P = (np.zeros(k) for _ in range(5))
        self.hp = np.zeros(1)


def _node_voltages(lad, A, ps):
    """The node voltages (n, N+1) of ladder ``lad`` where the layers hold ``A`` (n, N+1) and the drive is
    ``ps`` (n,) (all in R T/F).  Linear, so the same call turns the layers' and the drive's rates
    into the nodes' rates (Kirchhoff's law differentiated in time)."""
    rhs = -lad.G[1:] * A[:, 1:]
    rhs[:, 0] -= ps
    P = np.empty(A.shape)
    P[:, 0] = ps
    P[:, 1:] = solve_banded((1, 1), lad.band, rhs.T).T
    return P


class LineStepper:
    """The discretised RC line integrated chunk by chunk (the time-domain rung of the electrode line).

    ``advance(t)`` (s; the first time equal to the previous chunk's last, or 0 at the start,
    uncharged) returns a dict of arrays over the output times: ``u`` and ``v`` (V, shape (n, N+1):
    layer and node voltages of the reported ``2 N``-segment line at its nodes :attr:`x`),
    ``sigma`` (C/m^2, shape (n, N+1): layers plus the bulk's displacement charge per node),
    ``sigma_mean`` (C/m^2: the electrode's charge over its area), ``u_w`` (V: the layer voltage
    weighted by ``2 (L - x)/L^2``, the deflection's weight) and the Richardson estimates ``sigma_error``, ``u_w_error`` (same units,
    ``ERROR_FACTOR |y_2N - y_N|``) of the reported line's discretisation error; ``u_coarse`` and
    ``sigma_coarse``: the same of the ``N``-segment line (nodes :attr:`x_coarse`).

    Parameters
    ----------
    phi0_fun : callable   ``phi0(t)`` (V), vectorised
    strip : Strip ; perm : Permittivity ; material : Material
    sheet_resistance : float   ``R_s`` of each electrode, Ohm/sq (> 0)
    segments : int             ``N`` of the coarse line (the reported one has ``2 N``), 2..MAX_SEGMENTS
    substeps : int             as :class:`ipmc_asym.dynamics.circuit.CircuitStepper`
    """

    def __init__(self, phi0_fun, strip: Strip, perm: Permittivity, material: Material, sheet_resistance,
                 segments: int = DEFAULT_SEGMENTS, substeps: int = 2):
        Rs = check_sheet_resistance(sheet_resistance)
        if Rs <= 0.0:
            raise ValueError(f"sheet_resistance must be > 0 Ohm/sq for the line (0: the uniform strip); got {Rs!r}")
        n = int(segments)
        if not 2 <= n <= MAX_SEGMENTS:
            raise ValueError(f"line_segments must be an integer in [2, {MAX_SEGMENTS}] (--line-segments on the "
                             f"command line); got {segments!r}")
        self.fun, self.strip, self.m = phi0_fun, strip, material
        self.VT = groups.thermal_voltage(material)
        self.tau = float(time_constant(strip.thickness, perm, material))
        R = float(core_resistance(strip.thickness, material))
        # the line's own time 2 R_s L^2 C_d(0) (g^2 = 2 R_s L^2/Z_area, Z_area ~ 1/(s C_d) at low
        # frequency) in units of tau: substeps resolve the faster of the two (down to tau/20: a faster line is
        # uniform within the layers' charging, and the implicit steps are stable)
        Cd0 = 0.5 * charge_scale(perm, material) / self.VT
        self.t_line = 2.0 * Rs * strip.length**2 * Cd0 / self.tau
        self.h_max = 5e-3 * min(1.0, max(self.t_line, 0.05))
        self.h_sub = drive_substep(phi0_fun, self.tau, self.h_max)
        self.substeps = int(substeps)
        self.rho = perm.eps0 / perm.eps_moy
        self.mid = paper_model_id(perm)
        self.Cg = float(groups.geometric_capacitance(strip.thickness, perm.eps_moy))
        self.S = charge_scale(perm, material)
        self.segments = n
        self.fine = _Ladder(2 * n, strip, Rs, R)
        self.coarse = _Ladder(n, strip, Rs, R)
        self.x = self.fine.x
        self.x_coarse = self.coarse.x
        self.t_last = 0.0
        L = strip.length
        self._ww = {id(lad): 2.0 * (L - lad.x) * lad.w / L**2 for lad in (self.fine, self.coarse)}

    def _run(self, lad, tt, ps, idx):
        k = lad.A.size
        A = np.empty((tt.size, k))
        P = np.empty((tt.size, k))
        s = np.empty((tt.size, k))
        bad = integrate_line(tt, ps, self.rho, self.mid, GL_X, GL_W, lad.G, A, P, s, lad.A, lad.A_prev, lad.s,
                              lad.s_prev, lad.P, lad.hp)
        if bad:
            raise RuntimeError(f"electrode line: the implicit step did not converge at {bad} substeps")
        return A[idx], P[idx], s[idx]

    def advance(self, t):
        t = np.asarray(t, dtype=float)
        if t[0] != self.t_last:
            raise ValueError("each chunk must start at the last time of the previous one (0 at the start)")
        tau = self.tau
        tt, idx = substep_grid(t, tau, self.h_sub, self.substeps, ("the line's", SUBSTEP_ADVICE + " or fewer points a chunk"))
        ps = self.fun(drive_times(t, tt, idx, tau)) / self.VT
        out = {}
        L = self.strip.length
        # the layers are integrated with phi0 just before each output time (drive_times); at a jump there
        # the layers' charge is continuous but the node voltages follow phi0 at once: recomputed with
        # phi0(t), the row is the state just after the jump (as the circuit's; its core displacement
        # charge and current take phi0(t)); so is the start, whose nodes the stepper holds at rest.
        # Elsewhere the two drives agree to rounding (relative: a jump of any size is one, down to subnormal
        # drives; a false one near a zero crossing only solves Kirchhoff's law again, to the same rounding).
        ps_t = self.fun(t) / self.VT
        jump = np.abs(ps_t - ps[idx]) > 1e-12 * np.maximum(np.abs(ps_t), np.abs(ps[idx]))
        jump[0] |= t[0] == 0.0
        for name, lad in (("fine", self.fine), ("coarse", self.coarse)):
            A, P, s = self._run(lad, tt, ps, idx)
            if np.any(jump):
                P[jump] = _node_voltages(lad, A[jump], ps_t[jump])
            u, v = self.VT * A, self.VT * P
            sig = self.S * s + self.Cg * (v - u)
            out[name] = (u, v, sig, sig @ lad.w / L, u @ self._ww[id(lad)])
        self.t_last = float(t[-1])
        u, v, sig, sm, uw = out["fine"]
        _, _, _, sm2, uw2 = out["coarse"]
        return {"u": u, "v": v, "sigma": sig, "sigma_mean": sm, "u_w": uw,
                "sigma_error": ERROR_FACTOR * np.abs(sm - sm2), "u_w_error": ERROR_FACTOR * np.abs(uw - uw2),
                "u_coarse": out["coarse"][0], "sigma_coarse": sm2}

    def current(self, t, u, v):
        """The model's current density (A/m^2, over the electrode area) at the output times ``t`` (s)
        where the reported line's layers and nodes hold ``u`` and ``v`` (V, (n, N+1), from :meth:`advance`).

        From the model's own equations, as :meth:`ipmc_asym.dynamics.circuit.CircuitStepper.current`
        at every node, not from differences over the output times: ``J_j = S ds_j/dt +
        C_g d(v_j - u_j)/dt`` with ``ds_j/dt = (psi_j - A_j)/(2 tau)``, ``dA_j/dt = (ds_j/dt)/s'(A_j)``
        and the nodes' rates from Kirchhoff's law differentiated (:func:`_node_voltages`) with the
        drive's ``dphi0/dt`` (:func:`ipmc_asym.dynamics.waveforms.voltage_rate`: at a jump, the current
        just after it); ``J`` is their mean over the area (trapezoidal weights).
        """
        lad = self.fine
        A = np.asarray(u, dtype=float) / self.VT
        sdot, Adot = layer_rates(A, np.asarray(v, dtype=float) / self.VT, self.rho, self.mid, self.tau, self.h_max)
        dps = voltage_rate(self.fun, np.asarray(t, dtype=float), 1e-3 * self.tau) / self.VT
        Pdot = _node_voltages(lad, Adot, dps)
        Jn = self.S * sdot + self.Cg * self.VT * (Pdot - Adot)
        return Jn @ lad.w / self.strip.length


def _hat_integrals(x, fn, panel_points=8):
    """``int_0^L hat_j(x) fn(x) dx`` for the piecewise-linear hats of the nodes ``x`` (Gauss-Legendre
    per segment); ``fn(x)`` returns (k, n) at n positions.  Returns (nodes, k)."""
    xg, wg = np.polynomial.legendre.leggauss(panel_points)
    a, b = x[:-1, None], x[1:, None]
    tq = 0.5 * (xg + 1.0)  # position in the segment, 0..1
    xq = (a + (b - a) * tq[None, :]).ravel()
    wq = (0.5 * (b - a) * wg[None, :])  # (segments, points)
    f = np.atleast_2d(fn(xq)).reshape(-1, x.size - 1, panel_points)  # (k, segments, points)
    left = np.einsum("ksp,sp,p->sk", f, wq, 1.0 - tq)
    right = np.einsum("ksp,sp,p->sk", f, wq, tq)
    out = np.zeros((x.size, f.shape[0]))
    out[:-1] += left
    out[1:] += right
    return out


class LineBeamDynamics:
    """The strip's modes driven by the line's node moments ``M_j(t)`` (the time-domain counterpart of
    :func:`ipmc_asym.beam.dynamics.distributed_transfer`), chunk by chunk.

    The moment is linear between the nodes ``x`` and between the times (first-order hold); mode
    ``n`` of each support is forced by ``Q_n(t) = int M phi_n'' dx = sum_j c_jn M_j(t)`` (``c_jn``
    the hat integrals of ``phi_n''``) and propagated exactly by the transition matrices of
    :class:`ipmc_asym.beam.dynamics.ModalIntegrator` (one mode at a time, ``P = 1``,
    ``M = Q_n``).  The outputs are the quasi-static ones (``advance``'s ``statics``, through the
    creep filter; forces unfiltered) plus the modal sums of ``q_n - q_n^qs``; the blocked tip's
    force adds the modes past the kept ones as the second static of the distributed moment
    (:func:`ipmc_asym.beam.dynamics.moment_kernels`) minus the kept modes' share, times ``EI``
    and the second time derivative (as the uniform ModalIntegrator).
    """

    def __init__(self, strip: Strip, material: Material, viscous_modulus, n_modes, x):
        self.beam = b = strip_beam(strip, material, viscous_modulus)
        self.period = 1.0 / float(natural_frequencies("clamped-free", b, 1)[0])
        L = b.length
        self.sup = {}
        for sup in ("clamped-free", "clamped-pinned"):
            md = modes(sup, b, n_modes)
            c = _hat_integrals(np.asarray(x, float), lambda xx, md=md, sup=sup: mode_shape(
                sup, md.b[:, None], np.asarray(xx)[None, :] / L, 2) / (L * L))
            st = {"md": md, "c": c, "q": np.zeros(md.b.size), "v": np.zeros(md.b.size), "y": None, "ys": None,
                  "hist_t": np.zeros(0), "hist_y": np.zeros(0)}
            if sup == "clamped-pinned":
                k2 = moment_kernels(sup, b)["F"][1]  # kappa_2 of F = -EI w'''(L): -EI times that of w2'''(L)
                ct = _hat_integrals(np.asarray(x, float), lambda xx: k2(np.asarray(xx) / L)[None, :])[:, 0]
                # w2'''(L) of the moment minus the kept modes' sum_n g_n phi_n'''(L)/omega_n^4, g_n = -Q_n/(rho A L)
                st["tail"] = -ct / b.EI + c @ (md.d3phi_L / (b.rhoA * L * md.omega**4))
            self.sup[sup] = st

    def _modal(self, st, t, Q, S):
        b, md = self.beam, st["md"]
        nt, nm = t.size, md.b.size
        oq = np.empty((nt, nm))
        odq = np.empty((nt, nm))
        first = st["y"] is None
        if first:
            st["y"] = Q[0].copy()
            st["ys"] = S[0].copy()
        oys = np.empty((nt, S.shape[1]))
        oy = np.empty(nt)
        none = np.zeros((nt, 0))
        oqn = np.empty((nt, 1))
        odqn = np.empty((nt, 1))
        for n in range(nm):
            qn = np.ascontiguousarray(Q[:, n])
            Sn = S if n == 0 else none
            ys_in = st["ys"] if n == 0 else np.zeros(0)
            q, v, y, ys = _propagate(t, qn, Sn, md.omega[n:n + 1], b.tau_v, np.ones(1), b.rhoA * b.length,
                                     st["q"][n:n + 1], st["v"][n:n + 1], float(st["y"][n]), ys_in,
                                     oqn, odqn, oy, oys if n == 0 else np.empty((nt, 0)))
            oq[:, n], odq[:, n] = oqn[:, 0], odqn[:, 0]
            st["q"][n], st["v"][n], st["y"][n] = q[0], v[0], y
            if n == 0:
                st["ys"] = np.asarray(ys)
        return oq, odq, oys

    def advance(self, t, M, statics_free, F_static):
        """``(theta, w, F_block)`` at the times ``t`` (s) for node moments ``M`` (nt, nodes, N m) and the
        quasi-static ``statics_free = (theta, w)`` and ``F_static`` at those times."""
        t = np.ascontiguousarray(t, dtype=float)
        M = np.asarray(M, dtype=float)
        b = self.beam
        fr = self.sup["clamped-free"]
        oq, _, oys = self._modal(fr, t, M @ fr["c"], np.ascontiguousarray(np.column_stack(statics_free)))
        theta = oys[:, 0] + oq @ fr["md"].dphi_L
        w = oys[:, 1] + oq @ fr["md"].phi_L
        bl = self.sup["clamped-pinned"]
        tail = M @ bl["tail"]
        oq, odq, oys = self._modal(bl, t, M @ bl["c"], np.ascontiguousarray(tail[:, None]))
        # the filtered tail's second time derivative: backward second difference carried over chunks
        th = np.concatenate((bl["hist_t"], t[1:] if bl["hist_t"].size else t))
        yh = np.concatenate((bl["hist_y"], oys[1:, 0] if bl["hist_y"].size else oys[:, 0]))
        ydd = np.zeros(th.size)
        if th.size > 2:
            h1, h0 = th[2:] - th[1:-1], th[1:-1] - th[:-2]
            ydd[2:] = 2.0 * ((yh[2:] - yh[1:-1]) / h1 - (yh[1:-1] - yh[:-2]) / h0) / (h0 + h1)
        ydd = ydd[th.size - t.size:]
        bl["hist_t"], bl["hist_y"] = th[-2:], yh[-2:]
        dd = oq + b.tau_v * odq if b.tau_v > 0.0 else oq
        F = np.asarray(F_static, dtype=float) - b.EI * (dd @ bl["md"].d3phi_L) + b.EI * ydd
        return theta, w, F
