"""Transient Nernst-Planck/Gauss solver across the thickness (the dynamic cross-check).

Seed paper eq. "Nernst" with the pressure term neglected (as in §5) and the solvent at rest
(``V2 = 0``), Gauss's law with ``eps(C)`` (affine models), blocking electrodes, imposed
``phi0(t)`` on the face ``z = -e`` (``z = +e`` grounded).  Thermal scaling ``psi = F phi/(R T)``,
``x = z/e``, ``c = C/C_moy``, time ``t D/e^2``, induction ``d = D_z/(e phi4 F C_moy)``::

    dc/dt = -dN/dx,   N = -(dc/dx + c dpsi/dx),   d = -lambda^2 epshat(c) dpsi/dx,   dd/dx = c - 1

Method of lines, finite volumes on a mesh graded into both layers (:func:`make_fv_mesh`):
cells ``i`` with averages ``c_i``; Scharfetter-Gummel fluxes between cell centres; Gauss's law
on the dual (centre-to-centre) mesh.  The state is the cumulative charge at the interior
faces ``S_f = int_{-1}^{X_f} (c - 1) dx`` (``S_0 = S_N = 0``), so ``c_i = 1 + (S_{i+1} - S_i)/h_i``
and the total charge ``int (c - 1) dx = S_N - S_0`` is zero BY CONSTRUCTION (to rounding);
``dS_f/dt = -N_f`` (the total current ``J = dd/dt + N`` is uniform and drops out).  The anode
induction ``d_0`` (= ``sigma/(e phi4 F C_moy)``) follows from the voltage constraint
``sum_f r_f (d_0 + S_f) = lambda^2 psi0(t)`` with the dual-cell resistances
``r_f = sum of half cells h/(2 epshat)``.  With constant permittivity this discretisation
satisfies the discrete energy identity EXACTLY (semi-discrete):
``psi0 dd_0/dt = dF/dt + sum_f N_f (mu_{f-1} - mu_f)``,
``F = sum_f r_f d_f^2/(2 lambda^2) + sum_i h_i (c_i ln c_i - c_i + 1)``, ``mu = ln c + psi``;
the dissipation is integrated as an extra state, so the energy balance of a step closes to
the integrator's tolerance.

Integrator: SciPy ``solve_ivp`` (variable-order BDF by default, or Radau).  The Jacobian is a
bordered band: the voltage constraint couples every face through ``d_0``, so it is a
tridiagonal part (fluxes at fixed ``d_0``) plus one rank-one term ``u v^T``
(``u = dN/dd_0``, ``v = grad d_0``), built analytically (:meth:`_Problem.jacobian`); the BDF's
Newton systems are solved in O(N) by a tridiagonal LU and Sherman-Morrison (a banded sparsity
pattern alone would drop the term that carries the current).  Radau keeps SciPy's dense
finite-difference Jacobian.

Mesh error: ``tol`` (default 1e-6 relative on sigma) refines the whole mesh by 2 until the
Richardson estimate between successive levels meets it (:func:`solve_transient`); the
long-time limit then equals the static charge (``electrode.charge``) within ``tol``.

The linear model (``eps0 = 0``: ``eps -> 0`` at a depleted anode, where ``E ~ e^{A2}`` within
~1e-19 e of the face -- not representable, nor resolvable by any mesh) is solved in other
variables (:class:`_LinearProblem`): there ``epshat = c``, Gauss's law gives ``c dpsi/dx =
-d/lambda^2`` and the flux ``N = -dc/dx + d/lambda^2`` is linear in ``(c, d)``; the voltage
constraint goes through the electrochemical potential, ``psi0 = ln(c_R/c_L) + int N/c dx``,
with the face concentrations in log form (they may lie below the smallest double).  The same
state, mesh ladder, Richardson estimate and bordered Jacobian (its tridiagonal part constant);
the long-time limit equals the exact static charge (``charge(..., fidelity="exact")``) within
``tol``.  Not supported: custom ``eps(C)`` callables.  Water transport (Darcy) is outside the
model.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from ipmc_asym.base.settings import MAX_PNP_DIFFUSION_TIMES
from ipmc_asym.dynamics.electrode import charge_scale, layer_voltage, time_constant
from ipmc_asym.dynamics.waveforms import voltage_rate
from ipmc_asym.kernels._generated import b1_exact
from ipmc_asym.kernels.bernoulli import bernoulli_array
from ipmc_asym.kernels.pnp import linear_rhs, newton_delta, sg_rhs
from ipmc_asym.model import groups
from ipmc_asym.model.params import NAFION_LI, Material, Strip, check_positive
from ipmc_asym.model.permittivity import Permittivity, get_model

#: cells through which the linear model's face concentration is extrapolated (a polynomial of degree K)
FACE_CELLS = 3

__all__ = ["TransientResult", "make_fv_mesh", "solve_transient", "bernoulli"]


def bernoulli(x):
    """``B(x) = x/(e^x - 1)`` (vectorised, no overflow, ``B(0) = 1``; the compiled
    :func:`ipmc_asym.kernels.bernoulli.bernoulli_point` at each element)."""
    x = np.asarray(x, dtype=float)
    return bernoulli_array(np.ascontiguousarray(x).ravel()).reshape(x.shape)


def bernoulli_prime(x):
    """``B'(x) = B(x) (1 - B(x) - x)/x`` (vectorised; series ``-1/2 + x/6 - x^3/180`` near 0)."""
    x = np.asarray(x, dtype=float)
    out = np.empty_like(x)
    small = np.abs(x) < 1e-2
    xs = x[small]
    out[small] = -0.5 + xs / 6.0 - xs**3 / 180.0
    xb = x[~small]
    bb = bernoulli(xb)
    out[~small] = bb * (1.0 - bb - xb) / xb
    return out


def make_fv_mesh(lam: float, A2max: float, rho: float, *, cells_per_debye: float = 4.0, ratio: float = 1.08,
                 h_core: float = 0.02) -> np.ndarray:
    """Faces ``X`` (ascending, ``X[0] = -1``, ``X[-1] = 1``) graded into both electrode layers.

    At each face the first cell is ``lambda/(cells_per_debye sqrt(B1))`` (the local Debye
    length of the accumulation layer, ``B1 = C/C_moy`` at the cathode for ``A2max``) -- or, for
    ``rho = eps0/eps_core < 1``, ``lambda sqrt(rho)/cells_per_debye`` over the depletion zone
    (where ``eps -> eps0``) --, growing
    by ``1 + (ratio - 1)/2`` to ``lambda/cells_per_debye``, uniform over the depletion zone
    (``lambda sqrt(2 rho (A2 - 1))``) plus 12 Debye lengths, then growing by ``ratio`` up to
    ``h_core`` in the neutral core.  Symmetric (either face may be the cathode).
    """

    b1 = float(b1_exact(A2max, rho)) if A2max > 0 else 1.0
    h1 = lam / cells_per_debye
    r_layer = 1.0 + 0.5 * (ratio - 1.0)
    hs = []
    if 0.0 < rho < 1.0:
        # eps -> eps0 in the depletion zone: local Debye length lambda sqrt(rho) over its width
        hd = lam * math.sqrt(rho) / cells_per_debye
        wd = lam * (math.sqrt(2.0 * rho * max(A2max - 1.0, 0.0)) + 4.0 * math.sqrt(rho))
        hs += [hd] * int(math.ceil(wd / hd))
        h = hd
    else:
        h = h1 / math.sqrt(max(b1, 1.0))  # local Debye length of the accumulation layer
    while h < h1:
        hs.append(h)
        h *= r_layer
    width = lam * (2.0 * math.sqrt(2.0 * rho * max(A2max - 1.0, 0.0)) + 12.0)
    width = min(width, 0.4)
    n0 = int(math.ceil(max(width - sum(hs), 0.0) / h1))
    hs += [h1] * n0
    h = h1
    while h < h_core:
        h = min(h * ratio, h_core)
        hs.append(h)
    d = np.concatenate(([0.0], np.cumsum(hs)))
    if d[-1] >= 1.0:
        raise ValueError("the electrode layers fill the strip (thickness ~ a few Debye lengths): "
                         "the transient solver needs a neutral core; use a thicker strip")
    n_core = int(math.ceil((1.0 - d[-1]) / h_core))
    d = np.concatenate((d, d[-1] + (1.0 - d[-1]) * np.arange(1, n_core + 1) / n_core))
    left = -1.0 + d
    right = 1.0 - d[::-1]
    return np.concatenate((left[:-1], right))


def _layer_voltage(sigma, err, perm, material):
    """``V(sigma)`` (V), NaN where it is not determined: for the linear model ``sigma`` saturates at
    ``S`` (``V = -ln(1 - sigma/S)`` R T/F on the anode side), so ``V`` is withheld where ``|sigma|``
    plus its error estimate ``err`` reaches ``S``."""
    sigma = np.asarray(sigma, dtype=float)
    if perm.eps0 != 0.0:
        return layer_voltage(sigma, perm, material)
    ok = np.abs(sigma) + np.nan_to_num(np.asarray(err, dtype=float), nan=0.0) < charge_scale(perm, material)
    out = np.full(sigma.shape, np.nan)
    if np.any(ok):
        out[ok] = layer_voltage(sigma[ok], perm, material)
    return out


#: factor on the current's error estimate (see solve_transient: the measured ratio of error to
#: estimate reached 1.34 without it)
CURRENT_ERROR_MARGIN = 2.0


#: the first mesh level is dropped where its time integration needs more than this many times the
#: right-hand-side evaluations of the next, finer level (:func:`solve_transient`)
COARSE_NFEV = 4

#: what the transient ladder's cap on work (``max_work``) takes the rest of the ladder to cost: the
#: first run (the second level) at most ``1/_LADDER_SHARE`` of the cap (the level below it at half,
#: the one above at twice, that one's time check at ~1.3 times that: 0.5 + 1 + 2 + 2.6 ~ 6), a next
#: level ``_NEXT_LEVEL_SHARE`` times the last (2 for it, 2.6 for its time check; measured ratios of
#: the check's evaluations to its level's: 1.24-1.44 over constant/linear/affine steps and sines)
_LADDER_SHARE = 6.0
_NEXT_LEVEL_SHARE = 4.6

#: a current at ``t = 0`` is withheld where its changes over three mesh levels shrink by less than this
#: (see :func:`_jump_withheld`)
JUMP_SHRINK = 0.6


def _jump_withheld(t, js, current_error):
    """Where the current at a jump of the applied voltage (``t = 0``) gets no stated error: ``js`` its
    values on three meshes, each twice as fine, ``current_error`` the error stated otherwise.

    At the jump the current is a rate at a discontinuity: where its changes do not shrink with the
    mesh (at least first order, above the rounding of the time integration) no error can be stated
    (linear model, 0.5 V: J(0) moved 8.5, 17, 34, 68 A/m^2 at each halving).  Changes that shrink by
    ``q = d24/d12`` leave a tail ``d24 q/(1 - q)`` beyond the finest level, within the stated error
    (it holds ``d12``, counted twice) for ``q <= 0.618``; the line is drawn at :data:`JUMP_SHRINK` = 0.6,
    not at first order itself (``q = 0.5``): a current converging at exactly first order (constant
    model, 0.8 V, 180 um: ``q = 0.50003``) sits on that line, where the rounding of the output
    arithmetic would decide whether it is withheld.
    """
    d12, d24 = np.abs(js[0] - js[1]), np.abs(js[1] - js[2])
    return ((np.asarray(t) == 0.0) & (d24 > JUMP_SHRINK * d12)
            & (d24 > np.asarray(current_error) / CURRENT_ERROR_MARGIN * 0.1))


def _log_window_max(t, a, factor=2.0):
    """Per output time ``t_i``: the largest ``a_j`` over the times ``t_j`` in ``[t_i/factor, t_i factor]``
    (a window of physical time, independent of how densely the times are sampled); ``t = 0`` joins the
    window of the first times: the current there is the rate at the step's jump, as mesh-dependent as
    the front's."""
    t = np.asarray(t, dtype=float)
    a = np.asarray(a, dtype=float)
    pos = t[t > 0.0]
    t0 = pos[0] if pos.size else 0.0
    tt = np.where(t > 0.0, t, t0)
    lo = np.searchsorted(t, tt / factor, side="left")
    hi = np.searchsorted(t, tt * factor, side="right")
    lo = np.where(t > 0.0, lo, 0)
    out = np.empty_like(a)
    for i in range(t.size):
        out[i] = np.max(a[lo[i]:max(hi[i], i + 1)])
    return out


@dataclass
class TransientResult:
    """Output of :func:`solve_transient` on the requested times (SI unless stated).

    Attributes
    ----------
    t : ndarray (n,) s
    sigma : ndarray (n,)  charge of the face z = -e, C/m^2
    current_density : ndarray (n,)  dsigma/dt, A/m^2
    layer_voltage : ndarray (n,)  V(sigma) (V): the static voltage of the layers carrying sigma (NaN for
        the linear model where sigma is within its error of the saturation charge: V is not determined)
    M_A_profiles : ndarray (n,)  moment from the transient profiles, ``p' = (C + A3) E`` (N m),
        which includes the pressure gradient of the ohmic core field (see notes)
    total_charge : ndarray (n,)  ``int (c - 1) dx`` (dimensionless; 0 by construction)
    c : ndarray (n, cells)  concentration profiles ``C/C_moy``; x : ndarray (cells,) centres ``z/e``;
    faces : ndarray (cells + 1,)  cell faces ``z/e``
    success : bool ; message : str ; extra : dict (mesh, refinement levels, energy balance, nfev, njev)
    sigma_error : ndarray (n,)  estimate of the error of ``sigma`` (C/m^2; NaN without a tolerance)
    current_error : ndarray (n,)  estimate of the error of ``current_density`` (A/m^2; the same Richardson
        estimate from the same mesh levels, its time part ``10 rtol max|J|``; NaN without a tolerance)
    """

    t: np.ndarray
    sigma: np.ndarray
    current_density: np.ndarray
    layer_voltage: np.ndarray
    M_A_profiles: np.ndarray
    total_charge: np.ndarray
    c: np.ndarray
    x: np.ndarray
    faces: np.ndarray
    success: bool
    message: str
    extra: dict = field(default_factory=dict)
    sigma_error: np.ndarray | None = None
    current_error: np.ndarray | None = None


#: rows per block of the vectorised outputs (see _solve_once)
_OUTPUT_BLOCK = 32


class _Problem:
    """The finite-volume problem of the permittivity models with eps0 > 0 (constant, affine; see the module notes).

    ``psi0_fun(t)``: the applied potential at one scaled time (float); ``psi0_many(t)``: the same at an
    array of times (the outputs are computed for blocks of times at once; default: one call per time).
    """

    def __init__(self, X, lam, rho, psi0_fun, A3, psi0_many=None):
        self.X = X
        self.h = np.diff(X)
        self.N = self.h.size
        self.xc = 0.5 * (X[1:] + X[:-1])
        self.delta = np.diff(self.xc)  # centre-to-centre, interior faces 1..N-1
        self.lam2 = lam * lam
        self.rho = rho
        self.psi0 = psi0_fun
        self.psi0_many = psi0_many if psi0_many is not None else (
            lambda ts: np.array([psi0_fun(x) for x in np.atleast_1d(ts)], dtype=float))
        self.A3 = A3

    def unpack(self, S):
        Sf = np.zeros(self.N + 1)
        Sf[1:-1] = S
        c = 1.0 + np.diff(Sf) / self.h
        return Sf, c

    def fields(self, S, t):
        """(c, d at faces, r_f, dpsi at faces, psi at centres)."""
        Sf, c = self.unpack(S)
        eh = self.rho + (1.0 - self.rho) * c
        half = 0.5 * self.h / eh
        r = np.empty(self.N + 1)
        r[0] = half[0]
        r[-1] = half[-1]
        r[1:-1] = half[:-1] + half[1:]
        d0 = (self.lam2 * self.psi0(t) - np.dot(r, Sf)) / np.sum(r)
        d = d0 + Sf
        dpsi = -r * d / self.lam2  # psi jump across each dual cell (f = 0: centre 0 - applied)
        psi = self.psi0(t) + np.cumsum(dpsi[:-1])  # cell centres
        return c, d, r, dpsi, psi

    def jacobian(self, S, t):
        """Analytic Jacobian of ``dS/dt = -N`` as ``-(T + u v^T)``: ``(lower, diag, upper, u, v)``.

        ``N_f`` depends on ``S_{f-1}, S_f, S_{f+1}`` (``c`` of the two cells, ``r_f``, ``d_f``) and on
        ``d_0``, which the voltage constraint ``sum r_f (d_0 + S_f) = lambda^2 psi0`` ties to every
        face: ``T`` is the tridiagonal derivative at fixed ``d_0``, ``u = dN/dd_0``,
        ``v = grad_S d_0``.  Returned for ``-N`` (the right-hand side): ``J = -(T + u v^T)``.
        """
        Sf, c = self.unpack(S)
        rho = self.rho
        eh = rho + (1.0 - rho) * c
        half = 0.5 * self.h / eh
        dhalf = -0.5 * self.h * (1.0 - rho) / (eh * eh)  # d half_i / d c_i
        r = np.empty(self.N + 1)
        r[0] = half[0]
        r[-1] = half[-1]
        r[1:-1] = half[:-1] + half[1:]
        Rs = np.sum(r)
        d0 = (self.lam2 * self.psi0(t) - np.dot(r, Sf)) / Rs
        d = d0 + Sf
        x = -r[1:-1] * d[1:-1] / self.lam2
        Bp = bernoulli(x)
        Bm = Bp + x  # B(-x) = B(x) + x
        dB = bernoulli_prime(x)
        cl, cr = c[:-1], c[1:]
        dNdx = (cl * dB - cr * (dB + 1.0)) / self.delta  # d/dx B(-x) = B'(x) + 1
        dl = d[1:-1] / self.lam2
        a = Bp / self.delta - dNdx * dhalf[:-1] * dl  # dN_f/dc_{f-1}
        b = -Bm / self.delta - dNdx * dhalf[1:] * dl  # dN_f/dc_f
        u = -dNdx * r[1:-1] / self.lam2  # dN_f/dd_0 = dN_f/dS_f through d_f
        hl, hr = self.h[:-1], self.h[1:]
        diag = a / hl - b / hr + u
        lower = -a[1:] / hl[1:]  # dN_f/dS_{f-1}, f = 2..N-1
        upper = b[:-1] / hr[:-1]  # dN_f/dS_{f+1}, f = 1..N-2
        g = dhalf * (d[:-1] + d[1:]) / self.h  # sum_f d_f dr_f/dS_k = g_{k-1} - g_k
        v = -(r[1:-1] + g[:-1] - g[1:]) / Rs
        return -lower, -diag, -upper, -u, v

    def outputs_all(self, S2, t, dpsi0):
        """``(d_0, dd_0/dt, profile moment, free energy, c)`` at the states ``S2`` (m, n), times ``t`` (m,)
        (``dpsi0 = dpsi0/dt``), rows at once (a drive's reference has ~10^4 output times: one NumPy
        pass per time cost ~200 us of call overhead each, most of a sine drive's PNP run)."""
        S2 = np.ascontiguousarray(S2, dtype=float)
        m, N, h, rho, lam2 = S2.shape[0], self.N, self.h, self.rho, self.lam2
        p0 = self.psi0_many(t)
        Sf = np.zeros((m, N + 1))
        Sf[:, 1:-1] = S2
        c = 1.0 + np.diff(Sf, axis=-1) / h
        eh = rho + (1.0 - rho) * c
        half = 0.5 * h / eh
        r = np.zeros((m, N + 1))
        r[:, :-1] += half
        r[:, 1:] += half
        Rs = np.sum(r, axis=-1)
        d0 = (lam2 * p0 - np.einsum("ij,ij->i", r, Sf)) / Rs
        d = d0[:, None] + Sf
        # the flux from the integrator's own kernel (one home for it), a row at a time
        Nfull = np.zeros((m, N + 1))
        for k in range(m):
            Nfull[k, 1:-1] = -sg_rhs(S2[k], float(p0[k]), h, self.delta, lam2, rho)
        # dd0/dt from the constraint: sum r_f (d0 + S_f) = lam^2 psi0(t), with dS_f/dt = -N_f
        cdot = -np.diff(Nfull, axis=-1) / h
        hdot = -0.5 * h * (1.0 - rho) * cdot / (eh * eh)
        rdot = np.zeros((m, N + 1))
        rdot[:, :-1] += hdot
        rdot[:, 1:] += hdot
        J = (lam2 * np.asarray(dpsi0, dtype=float) + np.einsum("ij,ij->i", r, Nfull)
             - np.einsum("ij,ij->i", rdot, d)) / Rs
        M = self._moment(c, d, eh)
        cpos = np.maximum(c, 1e-300)
        Fe = np.einsum("ij,ij->i", r, d * d) / (2 * lam2) + (cpos * np.log(cpos) - cpos + 1.0) @ h
        return d0, J, M, Fe, c

    def _moment(self, c, d, eh):
        """Moment from the profiles (rows): ``(c + A3) (-dpsi)`` over the half cells, weight ``(1 - z^2)/2``."""
        zl = self.xc - 0.25 * self.h
        zr = self.xc + 0.25 * self.h
        drop = 0.5 * self.h / eh / self.lam2  # -dpsi per unit d over a half cell
        return np.sum((c + self.A3) * drop * (d[:, :-1] * 0.75 + d[:, 1:] * 0.25) * (1 - zl * zl) / 2
                      + (c + self.A3) * drop * (d[:, :-1] * 0.25 + d[:, 1:] * 0.75) * (1 - zr * zr) / 2, axis=-1)

    def rhs(self, t, y, with_diss):
        S = y[: self.N - 1]
        minus_N = sg_rhs(S, float(self.psi0(t)), self.h, self.delta, self.lam2, self.rho)
        if not with_diss:
            return minus_N
        c, d, r, dpsi, psi = self.fields(S, t)
        mu = np.log(np.maximum(c, 1e-300)) + psi
        diss = float(np.dot(-minus_N, mu[:-1] - mu[1:]))
        return np.concatenate((minus_N, [diss]))


def _int_x_over_linear(H, ln_c0, c1):
    """``int_0^H x/c(x) dx`` for ``c`` linear from ``exp(ln_c0)`` at 0 to ``c1`` at ``H`` (``c0`` in log
    form: it may be below the smallest double); vectorised over ``ln_c0``, ``c1``."""
    ln_c0 = np.asarray(ln_c0, dtype=float)
    c1 = np.asarray(c1, dtype=float)
    c0 = np.exp(ln_c0)
    s = (c1 - c0) / H
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        z = np.where(c0 > 0.0, s * H / c0, np.inf)
        # (H^2/c0) (z - ln(1 + z))/z^2: its series for small z, else H/s - (c0/s^2) ln(c1/c0)
        series = H * H / c0 * (0.5 - z / 3.0 + z * z / 4.0 - z**3 / 5.0)
        closed = H / s - c0 / (s * s) * (np.log(c1) - ln_c0)
    return np.where(np.abs(z) < 1e-3, series, closed)


class _LinearProblem(_Problem):
    """The linear model (``eps0 = 0``, ``epshat(c) = c``) in the charge/log-concentration variables.

    With ``epshat = c`` Gauss's law gives ``c dpsi/dx = -d/lambda^2``, so the flux is LINEAR in the
    state, ``N = -dc/dx + d/lambda^2`` (central differences between cell centres), and the field
    ``E ~ d/c`` never enters the transport.  At a depleted anode ``c -> e^{-A2}`` (and
    ``E ~ e^{A2}``: not representable beyond ~700 R T/F), so the voltage constraint is written
    with the electrochemical potential ``mu = ln c + psi`` (``dmu/dx = -N/c``)::

        psi0 = ln(c_R/c_L) + int_{-1}^{1} N/c dx

    with the face concentrations ``c_L``, ``c_R`` carried as logarithms: each is the polynomial of
    degree ``FACE_CELLS`` through the means of the ``FACE_CELLS`` cells next to its face with the
    face slope ``dc/dx = d_0/lambda^2`` (``N = 0``), ``c_L = a_L - G_L d_0``, ``c_R = a_R + G_R d_0``;
    the unknown solved for is ``delta = ln(c_L/c_R)`` (a monotone scalar equation, Newton inside a
    bracket), from which ``d_0`` follows without cancellation (:meth:`solve_d0`).  ``int N/c``:
    midpoint rule per cell.  The methods take one state ``S`` (n,) or a stack (m, n).
    """

    def __init__(self, X, lam, rho, psi0_fun, A3, psi0_many=None):
        super().__init__(X, lam, 0.0, psi0_fun, A3, psi0_many)
        h = self.h

        def face_coefs(hs):
            # c(x) = c_face + g x + sum_p a_p x^p (x inward, p = 2..K) through the means of the K
            # cells next to the face: c_face = w . (means - g mean(x))
            edges = np.concatenate(([0.0], np.cumsum(hs)))
            K = len(hs)
            mom = np.array([[(edges[j + 1] ** (p + 1) - edges[j] ** (p + 1)) / ((p + 1) * hs[j]) for p in range(K + 1)]
                            for j in range(K)])  # mean of x^p over cell j
            A = np.column_stack((mom[:, 0], mom[:, 2:]))
            w = np.linalg.solve(A.T, np.eye(K)[0])
            return w, float(np.dot(w, mom[:, 1]))

        (self.wL, gl), (self.wR, gr) = face_coefs(h[:FACE_CELLS]), face_coefs(h[::-1][:FACE_CELLS])
        # c_L = a_L - GL d_0, c_R = a_R + GR d_0 (face slope dc/dx = d_0/lambda^2, N = 0)
        self.GL, self.GR = gl / self.lam2, gr / self.lam2
        # the flux is linear: its tridiagonal derivative at fixed d_0 is constant
        hl, hr, dl = h[:-1], h[1:], self.delta
        self.T = (-1.0 / (dl[1:] * hl[1:]), 1.0 / (dl * hl) + 1.0 / (dl * hr) + 1.0 / self.lam2,
                  -1.0 / (dl[:-1] * hr[:-1]))
        # d a_L/dS, d a_R/dS: a_L = sum_j wL_j c_j, c_i = 1 + (S_{i+1} - S_i)/h_i (S index k = face k + 1)
        n = self.N - 1
        self.daL = np.zeros(n)
        self.daR = np.zeros(n)
        for j, (a, b) in enumerate(zip(self.wL, self.wR)):
            self.daL[j] += a / h[j]
            self.daR[n - j - 1] -= b / h[-1 - j]
            if j:
                self.daL[j - 1] -= a / h[j]
                self.daR[n - j] += b / h[-1 - j]
        self._delta = 0.0  # last root (Newton's start for one state)

    def unpack(self, S):
        S = np.asarray(S, dtype=float)
        Sf = np.zeros(S.shape[:-1] + (self.N + 1,))
        Sf[..., 1:-1] = S
        c = 1.0 + np.diff(Sf, axis=-1) / self.h
        return Sf, c

    def _parts(self, S):
        Sf, c = self.unpack(S)
        Nhat = -(c[..., 1:] - c[..., :-1]) / self.delta + Sf[..., 1:-1] / self.lam2  # flux at d_0 = 0
        with np.errstate(divide="ignore"):
            w = 0.5 * (self.h[:-1] / c[..., :-1] + self.h[1:] / c[..., 1:])  # int N/c = sum_f N_f w_f
        K = self.wL.size
        a_L = c[..., :K] @ self.wL
        a_R = c[..., ::-1][..., :K] @ self.wR
        return Sf, c, Nhat, w, a_L, a_R

    def _d0_of(self, x, a_L, a_R):
        """``d_0`` and ``dd_0/ddelta`` at ``delta = x`` (``c_L = c_R e^delta``; scaled by ``e^{-|x|}``)."""
        GL, GR = self.GL, self.GR
        ex = np.exp(-np.abs(x))
        pos = x > 0.0
        num = np.where(pos, a_L * ex - a_R, a_L - a_R * ex)
        den = np.where(pos, GL * ex + GR, GL + GR * ex)
        return num / den, -(a_R * GL + a_L * GR) * ex / (den * den)

    def solve_d0(self, S, t, parts=None):
        """``(d_0, ln c_L, ln c_R)`` from the voltage constraint (see the class notes); NaN where the
        state has a non-positive cell concentration.  ``parts``: :meth:`_parts` of the stacked states,
        when the caller has them."""
        S = np.asarray(S, dtype=float)
        one = S.ndim == 1
        S2 = np.atleast_2d(S)
        Sf, c, Nhat, w, a_L, a_R = self._parts(S2) if parts is None else parts
        p0 = np.broadcast_to(self.psi0_many(t), a_L.shape)
        ok = np.all(c > 0.0, axis=-1) & (a_L * self.GR + a_R * self.GL > 0.0)
        W = np.sum(np.where(ok[:, None], w, 1.0), axis=-1) / self.lam2
        I0 = np.sum(np.where(ok[:, None], Nhat * w, 0.0), axis=-1)
        # F(delta) = d_0(delta) - (delta + psi0 - I0)/W is decreasing: Newton inside a bracket
        if one:
            # one state (the integrator's right-hand side): the same iteration in scalars (numpy's
            # per-call overhead on 1-element arrays is ~10x the arithmetic)
            x = np.array([newton_delta(float(a_L[0]), float(a_R[0]), self.GL, self.GR, float(W[0]), float(I0[0]),
                                        float(p0[0]), self._delta if math.isfinite(self._delta) else 0.0)
                          if ok[0] else 0.0])
        else:
            x = np.zeros(a_L.shape)
            lo = np.full(x.shape, -np.inf)
            hi = np.full(x.shape, np.inf)
        with np.errstate(all="ignore"):
            for _ in range(0 if one else 200):
                d0, dd = self._d0_of(x, a_L, a_R)
                F = d0 - (x + p0 - I0) / W
                lo = np.where(F > 0.0, x, lo)
                hi = np.where(F > 0.0, hi, x)
                xn = x - F / (dd - 1.0 / W)
                step = 2.0 * (1.0 + np.abs(x))
                alt = np.where(np.isinf(hi), x + step, np.where(np.isinf(lo), x - step, 0.5 * (lo + hi)))
                # a root found to the bit (F = 0, or a step below x's resolution: xn = x) is kept:
                # its bracket is empty and would send it away (as newton_delta)
                xn = np.where(xn == x, x, np.where((lo < xn) & (xn < hi), xn, alt))
                done = ~ok | (np.abs(xn - x) <= 1e-14 * (1.0 + np.abs(x)))
                x = np.where(ok, xn, 0.0)
                if np.all(done):
                    break
            d0 = self._d0_of(x, a_L, a_R)[0]
            lnR = np.where(x <= 0.0, np.log(a_R + self.GR * d0), 0.0)
            lnL = np.where(x <= 0.0, lnR + x, np.log(a_L - self.GL * d0))
            lnR = np.where(x <= 0.0, lnR, lnL - x)
        d0, lnL, lnR = (np.where(ok, a, np.nan) for a in (d0, lnL, lnR))
        if one:
            self._delta = float(x[0])
            return float(d0[0]), float(lnL[0]), float(lnR[0])
        return d0, lnL, lnR

    def flux(self, c, d):
        """Flux at the interior faces 1..N-1 (``d``: the induction at the faces 0..N)."""
        return -(c[..., 1:] - c[..., :-1]) / self.delta + d[..., 1:-1] / self.lam2

    def _border(self, S2, t):
        """For states (m, n): ``(d_0, ln c_L, ln c_R, v = grad_S d_0, dd_0/dpsi0, S at the faces, c)`` (the
        tridiagonal part ``T`` and ``u = dN/dd_0 = 1/lambda^2`` are constant)."""
        parts = self._parts(S2)
        Sf, c, Nhat, w, a_L, a_R = parts
        d0, lnL, lnR = self.solve_d0(S2, t, parts)
        lam2 = self.lam2
        lower, diag, upper = self.T
        Nf = Nhat + d0[:, None] / lam2
        # G = ln c_L - ln c_R - sum N_f w_f + psi0 = 0, scaled by m = min(c_L, c_R)
        lm = np.minimum(lnL, lnR)
        sL, sR, cm = np.exp(lm - lnL), np.exp(lm - lnR), np.exp(lm)
        Gd = -self.GL * sL - self.GR * sR - cm * np.sum(w, axis=-1) / lam2
        # sum_f w_f dN_f/dS_k (T^T w) and sum_f N_f dw_f/dS_k
        Tw = diag * w
        Tw[:, 1:] += upper * w[:, :-1]
        Tw[:, :-1] += lower * w[:, 1:]
        Nfull = np.zeros((Nf.shape[0], self.N + 1))
        Nfull[:, 1:-1] = Nf
        ec = -0.5 * self.h * (Nfull[:, :-1] + Nfull[:, 1:]) / (c * c)  # d(sum N w)/dc_i
        dW = ec[:, :-1] / self.h[:-1] - ec[:, 1:] / self.h[1:]
        GS = self.daL * sL[:, None] - self.daR * sR[:, None] - cm[:, None] * (Tw + dW)
        v = -GS / Gd[:, None]
        return d0, lnL, lnR, v, -cm / Gd, Sf, c  # G_psi0 = 1 (scaled: cm)

    def jacobian(self, S, t):
        """As :meth:`_Problem.jacobian`: ``J = -(T + u v^T)``, ``(lower, diag, upper, u, v)`` for ``-N``."""
        v = self._border(S[None, :], t)[3][0]
        lower, diag, upper = self.T
        return -lower, -diag, -upper, np.full(self.N - 1, -1.0 / self.lam2), v

    def fields(self, S, t):
        """(c, d at faces, r_f, dpsi at faces, psi at centres) as :meth:`_Problem.fields`; ``psi`` from
        ``mu = ln c + psi`` (``mu = psi0 + ln c_L`` at the face ``z = -e``, ``dmu/dx = -N/c``), so it
        stays finite where ``E`` is not representable."""
        Sf, c = self.unpack(S)
        d0, lnL, lnR = self.solve_d0(S, t)
        d = d0 + Sf
        half = 0.5 * self.h / c
        r = np.empty(self.N + 1)
        r[0], r[-1] = half[0], half[-1]
        r[1:-1] = half[:-1] + half[1:]
        Nfull = np.concatenate(([0.0], self.flux(c, d), [0.0]))
        q = 0.25 * self.h * (0.5 * (Nfull[:-1] + Nfull[1:]) + Nfull[:-1]) / c  # face f -> centre f
        qr = 0.25 * self.h * (0.5 * (Nfull[:-1] + Nfull[1:]) + Nfull[1:]) / c  # centre f -> face f+1
        mu = (self.psi0(t) + lnL) - np.cumsum(q) - np.concatenate(([0.0], np.cumsum(qr[:-1])))
        psi = mu - np.log(c)
        dpsi = np.empty(self.N + 1)
        dpsi[0] = psi[0] - self.psi0(t)
        dpsi[1:-1] = np.diff(psi)
        dpsi[-1] = -psi[-1]
        return c, d, r, dpsi, psi

    def outputs_all(self, S2, t, dpsi0):
        """``(d_0, dd_0/dt, profile moment, free energy, c)`` at the states ``S2`` (m, n), times ``t`` (m,)
        (``dpsi0 = dpsi0/dt``); ``dd_0/dt = v . dS/dt + (dd_0/dpsi0) dpsi0/dt``."""
        d0, lnL, lnR, v, dpsi, Sf, c = self._border(S2, t)
        d = d0[:, None] + Sf
        J = np.sum(v * -self.flux(c, d), axis=-1) + dpsi * dpsi0
        # the uncharged state at t = 0+: no layer has formed (width sqrt(t)), the face concentrations
        # are the cells' (c = 1), and the charge is the bulk's displacement charge lambda^2 psi0/2 (the
        # face extrapolation with the slope d_0/lambda^2 would put an O(h) layer there)
        at0 = (np.asarray(t) == 0.0) & ~np.any(S2, axis=-1)
        if np.any(at0):
            d0 = np.where(at0, 0.5 * self.lam2 * self.psi0_many(t), d0)
            d = d0[:, None] + Sf
            lnL = np.where(at0, 0.0, lnL)
            lnR = np.where(at0, 0.0, lnR)
        M = self._moment_linear(c, d, lnL, lnR)
        cpos = np.maximum(c, 1e-300)
        half = 0.5 * self.h / c
        r = np.zeros((c.shape[0], self.N + 1))
        r[:, :-1] += half
        r[:, 1:] += half
        Fe = np.sum(r * d * d, axis=-1) / (2 * self.lam2) + (cpos * np.log(cpos) - cpos + 1.0) @ self.h
        return d0, J, M, Fe, c

    def _moment_linear(self, c, d, lnL, lnR):
        """Moment from the profiles, ``int (c + A3) E (1 - z^2)/2 dz`` with ``c E = d/lambda^2`` (rows).

        ``E = d/(lambda^2 c)`` grows like ``1/x`` towards a depleted face while ``E (1 - z^2)`` stays
        smooth: the ``A3`` term takes ``c`` at the quarter points of each cell (linear through the
        neighbours' means, second order), and in the two boundary half cells the closed form of
        ``int_0^H x/(c_face + s x) dx`` with the face concentration in log form (it may be below
        the smallest double); the weight's factor ``(2 - x)/2`` at ``x = H/2``.
        """
        h, xc, lam2, A3 = self.h, self.xc, self.lam2, self.A3
        zl = xc - 0.25 * h
        zr = xc + 0.25 * h
        dl = d[:, :-1] * 0.75 + d[:, 1:] * 0.25
        dr = d[:, :-1] * 0.25 + d[:, 1:] * 0.75
        wl = (1 - zl * zl) / 2
        wr = (1 - zr * zr) / 2
        M = (dl * wl + dr * wr) @ (0.5 * h) / lam2  # c E = d/lambda^2
        slope = np.empty(c.shape)
        slope[:, 1:-1] = (c[:, 2:] - c[:, :-2]) / (xc[2:] - xc[:-2])
        slope[:, 0] = (c[:, 1] - c[:, 0]) / (xc[1] - xc[0])
        slope[:, -1] = (c[:, -1] - c[:, -2]) / (xc[-1] - xc[-2])
        cl = c - 0.25 * h * slope
        cr = c + 0.25 * h * slope
        cl = np.where(cl > 0.0, cl, c)
        cr = np.where(cr > 0.0, cr, c)
        EA = 0.5 * h * (dl * wl / cl + dr * wr / cr) / lam2
        EA[:, 0] -= 0.5 * h[0] * dl[:, 0] * wl[0] / cl[:, 0] / lam2
        EA[:, -1] -= 0.5 * h[-1] * dr[:, -1] * wr[-1] / cr[:, -1] / lam2
        for i, lnf, dc in ((0, lnL, dl[:, 0]), (-1, lnR, dr[:, -1])):
            H = 0.5 * h[i]
            EA[:, i] += (dc / lam2) * (1.0 - 0.5 * H) * _int_x_over_linear(H, lnf, c[:, i])
        return M + A3 * np.sum(EA, axis=-1)

    def rhs(self, t, y, with_diss):
        S = y[: self.N - 1]
        minus_N, self._delta = linear_rhs(S, float(self.psi0(t)), self.h, self.delta, self.lam2, self.wL, self.wR,
                                          self.GL, self.GR, self._delta)
        if not with_diss:
            return minus_N
        c, _, _, _, psi = self.fields(S, t)
        mu = np.log(np.maximum(c, 1e-300)) + psi
        diss = float(np.dot(-minus_N, mu[:-1] - mu[1:]))
        return np.concatenate((minus_N, [diss]))


class _BorderedJacobian:
    """``J = -(T + u v^T)`` (tridiagonal ``T``, rank-one border) for the BDF iteration matrix.

    SciPy's BDF forms ``I - c J`` and factorises it; here ``c * J`` and ``I - (c J)`` stay
    symbolic and the factorisation is the tridiagonal LU of ``I + c T`` (LAPACK gttrf), the
    border entering by Sherman-Morrison: O(N) per factorisation and per solve.
    """

    __array_ufunc__ = None  # numpy scalars defer ``c * J`` to __rmul__

    def __init__(self, parts, n_extra, scale=1.0):
        self.parts = parts
        self.n_extra = n_extra
        self.scale = scale
        n = parts[1].size + n_extra
        self.shape = (n, n)

    def __rmul__(self, c):
        return _BorderedJacobian(self.parts, self.n_extra, float(c) * self.scale)


class _Identity:
    def __sub__(self, cJ):
        return cJ  # the factorisation below forms I - cJ itself


def _lu_bordered(cJ):
    from scipy.linalg.lapack import dgttrf, dgttrs  # deferred: heavy import (start-up)

    lower, diag, upper, u, v = cJ.parts
    c = cJ.scale
    dl, d, du, du2, ipiv, info = dgttrf(-c * lower, 1.0 - c * diag, -c * upper)
    if info != 0:
        raise np.linalg.LinAlgError("singular BDF iteration matrix")
    # I - cJ = M - c u v^T with M = I - c T_J (T_J the tridiagonal part of J, u v^T its border)
    w, info = dgttrs(dl, d, du, du2, ipiv, u)
    denom = 1.0 - c * float(np.dot(v, w))
    return (dl, d, du, du2, ipiv, w, v, c, denom, cJ.n_extra)


def _solve_bordered(LU, b):
    from scipy.linalg.lapack import dgttrs  # deferred: heavy import (start-up)

    dl, d, du, du2, ipiv, w, v, c, denom, n_extra = LU
    n = d.size
    b = np.asarray(b, dtype=float)
    x, _ = dgttrs(dl, d, du, du2, ipiv, b[:n])
    x = x + w * (c * float(np.dot(v, x)) / denom)
    if n_extra:
        # the dissipation state depends on S but feeds nothing back: its row of J is left
        # out (a simplified Newton: it converges, the iteration only corrects it)
        x = np.concatenate((x, b[n:]))
    return x


def _bordered_bdf(problem, n_extra):
    """A SciPy BDF whose linear algebra is :class:`_BorderedJacobian` (O(N) per step)."""
    from scipy.integrate import BDF  # deferred: heavy import (start-up)
    from scipy.sparse import csc_matrix  # deferred: heavy import (start-up)

    class _BDF(BDF):
        def __init__(self, fun, t0, y0, t_bound, **kw):
            super().__init__(fun, t0, y0, t_bound, **kw)
            self.J = self.jac(self.t, self.y)
            self.lu = self._lu
            self.solve_lu = _solve_bordered
            self.I = _Identity()

        def _lu(self, A):
            self.nlu += 1
            return _lu_bordered(A)

        def _validate_jac(self, jac, sparsity):
            def jac_wrapped(t, y):
                self.njev += 1
                return _BorderedJacobian(problem.jacobian(y[: problem.N - 1], t), n_extra)

            # an empty sparse stand-in until __init__ above puts the bordered Jacobian in its place:
            # with a dense one SciPy's __init__ allocates a dense n x n identity (replaced above, never
            # used; 3.2 GB at 20000 cells, 0.17 s at 5000), with a sparse one an O(n) sparse identity
            return jac_wrapped, csc_matrix((self.n, self.n))

    return _BDF


def solve_transient(t, phi0_fun, strip: Strip, model="constant", material: Material = NAFION_LI, *,
                    cells_per_debye: float = 4.0, ratio: float = 1.08, h_core: float = 0.02, refine: float | None = None,
                    rtol: float | None = None, atol: float = 1e-12, method: str = "BDF", energy: bool = False,
                    profiles: bool = False, moment: bool = True, tol: float | None = 1e-6,
                    max_cells: int = 20000, max_work: float | None = None) -> TransientResult:
    """Integrate the transient Nernst-Planck/Gauss problem from the uncharged state at ``t = 0``.

    Parameters
    ----------
    t : array_like (n,)
        Output times (s), increasing, ``t[0] >= 0``.
    phi0_fun : callable
        ``phi0(t)`` in volts, vectorised (see :func:`ipmc_asym.dynamics.circuit.waveform`).
    strip : Strip ; model : "constant" / "linear" / "affine" or Permittivity ; material : Material
    cells_per_debye, ratio, h_core : float
        Mesh (:func:`make_fv_mesh`); the layer zone is sized for ``max |phi0|`` on ``t``.
    refine : float or None
        Refines the whole mesh: ``cells_per_debye * refine``, ``(ratio - 1)/refine``,
        ``h_core/refine`` (the first level when ``tol`` is set).  Default: 1 without a
        tolerance; with one, ``sqrt(1e-6/tol)`` clipped to [1/4, 1] (a looser tolerance starts on
        a coarser mesh).
    tol : float or None
        Relative tolerance on ``sigma`` (default 1e-6, relative to ``max |sigma|`` over ``t``).
        The mesh is refined by 2 (``refine``, ``2 refine``, ``4 refine``, ...) until the
        Richardson estimate of the returned sigma's error meets it (see notes); ``None``: one
        run at ``refine``, ``sigma_error`` NaN.
    max_cells : int
        Cap on the cells of the finest mesh; the solver fails (``success = False``, one-line
        message) when the tolerance needs more.
    max_work : float or None
        Cap on the cost, counted in cell-evaluations (right-hand-side evaluations times the cells of
        their mesh, summed over every run of the ladder: a count, the same on every machine; ~3e6 a
        second of CPU here).  A level that would pass it is not started (the next level is taken
        to cost twice the last), one that passes it stops there; the solver then fails with
        ``extra["over_budget"] = True``.  Default None: no cap.
    rtol, atol : float
        solve_ivp tolerances; ``rtol`` default: ``tol/100`` with a tolerance, 1e-8 without one
        (``atol`` on ``S``, in units of ``e``; no looser than ``rtol`` times the small-signal
        charge ``lambda max|psi0|/2``, so that the time error stays relative at small signal).
    method : {"BDF", "Radau"}
    energy : bool
        Integrate the dissipation and return the energy balance in ``extra["energy"]``
        (meaningful for constant permittivity: ``eps(C)`` adds an exchange term).
    profiles : bool
        Keep ``c`` at every output time.
    moment : bool
        Compute ``layer_voltage`` = V(sigma) (closed-form inversion); the profile moment is always computed.

    Returns
    -------
    TransientResult
        ``sigma_error``: the estimate of the error of ``sigma`` (C/m^2) at each output time.

    Notes
    -----
    The finite volumes converge at second order in the mesh size (Scharfetter-Gummel fluxes,
    centred Gauss law).  With three successive levels ``s1, s2, s4`` the observed order
    ``p = log2(|s1 - s2|/|s2 - s4|)`` (max norms over ``t``) must lie in [1.5, 2.5] (the
    asymptotic range; otherwise the mesh is refined further); the returned sigma is the
    Richardson extrapolation with the formal order 2, ``E24 = s4 + (s4 - s2)/3``, and its error
    is estimated from the previous extrapolation as ``2 |E24 - E12|/7`` (the next term of the
    error expansion is at least third order, ``2^3 - 1 = 7``, with a safety factor 2), plus the
    spread of the extrapolation over the order observed at each output time,
    ``|s4 - s2| |1/3 - 1/(r - 1)|`` with ``r = |s1 - s2|/|s2 - s4|`` clamped to ``[2^1.5, 2^2.5]``
    (pre-asymptotic points, e.g. the initial layer of a step on a thin strip), plus the
    time integration's ``10 rtol |sigma|`` (``rtol <= tol/100``) or twice its measured part where
    larger (the finest level rerun at a tenth of ``rtol``, the largest change within a factor 2 of
    each time; where the tighter reruns fail, once the change of a rerun at ten times ``rtol``).
    ``current_density`` and ``M_A_profiles`` are extrapolated alike (``current_error``: the
    current's estimate from the same three levels); ``c`` is the finest mesh's.

    Below :data:`SMALL_SIGNAL_V` (``max |phi0|``, a few microvolts) the problem is solved in its
    small-signal limit: the waveform scaled up to ``SMALL_SIGNAL_V`` and to twice that, each
    solved as above, the first scaled back (the response is linear there); the change of the
    response per volt between the two, twice, is added to the errors (the nonlinearity left at
    ``SMALL_SIGNAL_V``: ~1e-9 of sigma on the nominal strip).  The direct solve cannot resolve a
    perturbation of the concentrations near the rounding of 1 (it stalls from ~1e-7 V and returns
    no charging from ~1e-20 V).
    """
    tt = np.asarray(t, dtype=float).reshape(-1)
    check_pnp_duration(tt[-1] if tt.size else 0.0, strip, model, material)
    vmax = float(np.max(np.abs(phi0_fun(np.linspace(tt[0], tt[-1], 2001))))) if tt.size else 0.0
    kw = dict(cells_per_debye=cells_per_debye, ratio=ratio, h_core=h_core, refine=refine, rtol=rtol, atol=atol,
              method=method, energy=energy, profiles=profiles, moment=moment, tol=tol, max_cells=max_cells,
              max_work=None if max_work is None else check_positive("max_work", max_work))
    if not 0.0 < vmax < SMALL_SIGNAL_V or energy:  # (the energy balance is quadratic in phi0: solved as it is)
        return _solve_direct(t, phi0_fun, strip, model, material, **kw)
    return _small_signal(t, phi0_fun, vmax, strip, model, material, kw)


def check_pnp_duration(duration, strip: Strip, model, material: Material) -> float:
    """Refuse a duration (s) past :data:`~ipmc_asym.base.settings.MAX_PNP_DIFFUSION_TIMES` diffusion
    times ``e^2/D`` in one line, before any run (the integrator would fail near the top of the doubles)."""
    t_d = strip.e * strip.e / float(material.D)
    span = MAX_PNP_DIFFUSION_TIMES * t_d
    if not float(duration) <= span:
        tau = float(time_constant(strip.thickness, model, material))
        raise ValueError(f"duration: the transient PNP runs at most {MAX_PNP_DIFFUSION_TIMES:.0e} diffusion times "
                         f"e^2/D ({span:.3g} s here, {span / tau:.3g} tau; a step's strip is at rest after a few); "
                         f"got {float(duration):.3g} s (--duration on the command line)")
    return float(duration)


#: below this ``max |phi0|`` (V) :func:`solve_transient` solves the small-signal limit, scaled from
#: a run at this amplitude (and one at twice it, which measures the nonlinearity left).  10 uV
#: (psi0 = 3.9e-4): the direct solve is converged there (the 1e-5 V step test, both signs) and
#: its charge per volt equals the 1 uV run's to 2e-9, while it stalls at 0.1 uV
SMALL_SIGNAL_V = 1e-5


def _small_signal(t, phi0_fun, vmax, strip, model, material, kw):
    """:func:`solve_transient` of a drive of amplitude ``vmax < SMALL_SIGNAL_V``: the runs at
    ``SMALL_SIGNAL_V`` and ``2 SMALL_SIGNAL_V`` with the waveform's shape, the first scaled by
    ``vmax/SMALL_SIGNAL_V`` (the shape divided by ``vmax`` first: no overflow at a subnormal
    amplitude); its errors scaled alike plus twice the change per volt from the second."""
    runs = []
    if kw["max_work"] is not None:  # the cap is on the whole: half of it for each of the two runs
        kw = dict(kw, max_work=0.5 * kw["max_work"])
    for amp in (SMALL_SIGNAL_V, 2.0 * SMALL_SIGNAL_V):
        def fun(tt, amp=amp):
            return (np.asarray(phi0_fun(tt), dtype=float) / vmax) * amp
        r = _solve_direct(t, fun, strip, model, material, **kw)
        if not r.success:
            return r
        runs.append(r)
    r, r2 = runs
    q = vmax / SMALL_SIGNAL_V
    # the change of the response per volt from SMALL_SIGNAL_V to twice it, scaled to this amplitude:
    # the first nonlinear term (it grows like the amplitude), counted twice
    nl_sigma = 2.0 * np.abs(0.5 * r2.sigma - r.sigma) * q
    nl_current = 2.0 * np.abs(0.5 * r2.current_density - r.current_density) * q
    r.sigma = r.sigma * q
    r.current_density = r.current_density * q
    r.layer_voltage = r.layer_voltage * q
    r.M_A_profiles = r.M_A_profiles * q
    r.total_charge = r.total_charge * q
    if r.c is not None and np.size(r.c):
        r.c = 1.0 + (r.c - 1.0) * q
    if r.sigma_error is not None:
        r.sigma_error = r.sigma_error * q + nl_sigma
    if r.current_error is not None:
        r.current_error = r.current_error * q + nl_current
    r.extra = dict(r.extra, small_signal={"amplitude_V": SMALL_SIGNAL_V, "scale": q,
                                          "nonlinearity_max_rel": float(np.max(nl_sigma)) / max(
                                              float(np.max(np.abs(r.sigma))), np.finfo(float).tiny)})
    r.message = (f"{r.message}; small signal: solved at {SMALL_SIGNAL_V:g} V and scaled by the amplitude "
                 f"(the nonlinearity measured at twice it is in the errors)")
    return r


def _solve_direct(t, phi0_fun, strip, model, material, *, cells_per_debye, ratio, h_core, refine, rtol, atol, method,
                  energy, profiles, moment, tol, max_cells, max_work) -> TransientResult:
    """:func:`solve_transient` without its small-signal branch (its arguments, defaults there)."""
    if tol is None:
        r = _solve_once(t, phi0_fun, strip, model, material, cells_per_debye=cells_per_debye, ratio=ratio,
                        h_core=h_core, refine=1.0 if refine is None else refine,
                        rtol=1e-8 if rtol is None else rtol, atol=atol, method=method, energy=energy,
                        profiles=profiles, moment=moment, max_work=max_work)
        r.sigma_error = np.full(r.t.size, np.nan)
        r.current_error = np.full(r.t.size, np.nan)
        return r
    tol = check_positive("tol", tol)
    if not tol < 1e-2:
        raise ValueError(f"tol must be in (0, 1e-2) (relative on sigma); got {tol!r}")
    mc = int(max_cells)
    if mc < 10:
        raise ValueError(f"max_cells must be an integer >= 10; got {max_cells!r}")
    # the time integration's share of the error is 10 rt |sigma| = tol/10 (a looser tolerance
    # takes longer steps); an explicit rtol is kept when tighter
    rt = 1e-2 * tol if rtol is None else min(rtol, 1e-2 * tol)

    def allowance(a, peak=False):
        # the time integration's assumed part: rtol on the state (~ sigma); the current is its rate,
        # whose time error follows the largest current (peak), not the current at each time
        return 10.0 * rt * (np.max(np.abs(a)) if peak else np.abs(a))

    runs = []
    # the first mesh level: the mesh error falls like h^2 and is ~1e-6 at refine 1 (measured on
    # the nominal strip, 20 um - 2 mm alike), so a looser tolerance starts coarser, by
    # sqrt(1e-6/tol) down to a quarter (one cell per Debye length); the ladder below still
    # refines until its Richardson estimate meets tol, so the start only saves work.  At the
    # default tol = 1e-6 the start is 1, as before
    rf = min(1.0, max(0.25, math.sqrt(1e-6 / tol))) if refine is None else refine
    t_start = time.perf_counter()
    spent = [0]  # cell-evaluations of every run so far (max_work's measure of cost)
    dropped = []

    def level(q, max_nfev=None, rtol_=rt, atol_=min(atol, 1e-6 * tol), keep=profiles, share=1.0):
        left = None if max_work is None else share * max_work - spent[0]
        x = _solve_once(t, phi0_fun, strip, model, material, cells_per_debye=cells_per_debye, ratio=ratio,
                        h_core=h_core, refine=q, rtol=rtol_, atol=atol_, method=method, energy=energy,
                        profiles=keep, moment=False, max_nfev=max_nfev, max_work=left)
        spent[0] += x.extra["cells"] * x.extra.get("nfev", 0)
        return x

    def over_budget(x, what):
        # stopped by max_work, or the next run would pass it: the estimate is not made (the caller's
        # budget, e.g. time_response's tol="auto", says what to do instead)
        return _failed(x, f"{what} needs more than max_work = {max_work:.3g} cell-evaluations "
                          f"({spent[0]:.3g} spent)", levels(), over_budget=True, work=spent[0])

    def entry(q, x):
        return {"refine": q, "cells": x.extra["cells"], "seconds": x.extra["seconds"], "nfev": x.extra.get("nfev")}

    def levels():
        return dropped + [entry(q, x) for q, x in runs]

    while True:
        if not runs:
            # the first two levels, the finer one first: a coarsest level whose time integration
            # needs more than COARSE_NFEV times the evaluations of the next (its stiffness, not the
            # physics, sets the steps: affine model, 1 V step, 200 um, one cell per Debye length:
            # 98 522 evaluations where the next level took 1 673, 4.9 of the run's 5.5 s) is dropped;
            # the ladder goes on from the next (it extrapolates from its last three levels only)
            # (the ladder needs at least the level below this one, the one above at about twice its
            # cost and that one's time check: ~6 times this run, so this run gets a sixth of max_work)
            r2 = level(2.0 * rf, share=1.0 / _LADDER_SHARE)
            if not r2.success:
                return over_budget(r2, "the run") if r2.extra.get("over_budget") else _failed(r2, r2.message, [])
            r = level(rf, max_nfev=COARSE_NFEV * int(r2.extra["nfev"]))
            if r.success:
                runs.append((rf, r))
            elif r.extra.get("over_budget"):
                return over_budget(r, "the run")
            elif r.extra["nfev"] >= COARSE_NFEV * int(r2.extra["nfev"]):
                dropped.append(dict(entry(rf, r), dropped=f"more than {COARSE_NFEV} times the next level's evaluations"))
            else:
                return _failed(r, r.message, [])
            rf, r = 2.0 * rf, r2
        else:
            # the next level costs about twice the last (cells double, evaluations alike), and its
            # time check (the level again at a tenth of rtol) ~1.3 times that
            w_last = runs[-1][1].extra["cells"] * runs[-1][1].extra["nfev"]
            if max_work is not None and spent[0] + _NEXT_LEVEL_SHARE * w_last > max_work:
                return over_budget(runs[-1][1], "the next mesh level")
            r = level(rf)
            if not r.success:
                return over_budget(r, "the run") if r.extra.get("over_budget") else _failed(r, r.message, levels())
        runs.append((rf, r))
        lv = levels()
        if len(runs) >= 3:
            s1, s2, s4 = (x.sigma for _, x in runs[-3:])
            scale = float(np.max(np.abs(s4)))
            d12 = float(np.max(np.abs(s1 - s2)))
            d24 = float(np.max(np.abs(s2 - s4)))
            p = math.log2(d12 / d24) if d24 > 0 and d12 > 0 else float("nan")
            if not 1.5 <= p <= 2.5 and max(d12, d24) <= 0.1 * tol * scale:
                # the mesh changes sigma by less than tol/10 (rounding level: no order to observe,
                # e.g. phi0 = 0): the finest run, its error bounded by both changes
                err = np.full(r.t.size, d12 + d24) + allowance(r.sigma)
                if moment:
                    r.layer_voltage = _layer_voltage(r.sigma, err, get_model(model), material)
                r.sigma_error = err
                j1, j2, j4 = (x.current_density for _, x in runs[-3:])
                r.current_error = (np.full(r.t.size, float(np.max(np.abs(j1 - j2)) + np.max(np.abs(j2 - j4))))
                                   + allowance(r.current_density, peak=True))
                r.extra = dict(r.extra, refinement=lv, observed_order=p, tol=tol, work=spent[0],
                               sigma_error_max_rel=float(np.max(err)) / scale if scale > 0 else 0.0,
                               seconds=time.perf_counter() - t_start)
                return r
            if 1.5 <= p <= 2.5:
                # in the asymptotic range: extrapolate with the formal order 2 (an observed order
                # from three levels carries O(h) noise, and the extrapolation is sensitive to it)
                fac = 1.0 / 3.0

                def rich(a, b):
                    return b + (b - a) * fac

                def estimate(a1, a2, a4, peak=False):
                    E12 = rich(a1, a2)
                    E24 = rich(a2, a4)
                    # plus the spread of the extrapolation over the orders observed at each output
                    # time (ratio |a1 - a2|/|a2 - a4| = 2^p, p clamped to [1.5, 2.5]): before the
                    # asymptotic range a point's error may fall like h^2.3 (an initial layer), where
                    # the formal order over-corrects by more than the next term of the expansion
                    a12, a24 = np.abs(a1 - a2), np.abs(a2 - a4)
                    with np.errstate(divide="ignore", invalid="ignore"):
                        rpt = np.clip(np.where(a24 > 0.0, a12 / a24, 4.0), 2.0**1.5, 2.0**2.5)
                    spread = a24 * np.abs(fac - 1.0 / (rpt - 1.0))
                    return E24, 2.0 * np.abs(E24 - E12) / 7.0 + spread + allowance(E24, peak)

                E24, err = estimate(s1, s2, s4)
                if float(np.max(err)) <= tol * scale:
                    rc, rf_ = runs[-2][1], r
                    out = rf_
                    out.sigma = E24
                    out.sigma_error = err
                    # the current's error alike (the same three levels; not part of the mesh criterion)
                    js = [x.current_density for _, x in runs[-3:]]
                    out.current_density, cur = estimate(*js, peak=True)
                    # the current's mesh error follows the charging front across the mesh and
                    # converges erratically there (measured: affine model, 2 V, 200 um, 11x the
                    # pointwise Richardson estimate at 0.05 tau): the larger of the estimate and the
                    # levels' own changes, the largest over the output times within a factor 2 of t
                    # and the time integration's part measured, not assumed: the finest of the
                    # three levels again at a tenth of rtol (the current is a rate: its time error
                    # after the front was 200x the 10 rtol max|J| allowance at 2 V).  The finest,
                    # because the time error grows with the mesh's stiffness: 0.1 mV, 200 um,
                    # rtol 1e-6 measured 4.9e-9 C/m^2 of mesh error and no time error at refine
                    # 0.25, 3-4e-9 of time error at refine 2 and 4
                    q0, r0 = runs[-1]
                    jt = None
                    # BDF may fail at the tighter rtol (overflow in its differences), or its step control
                    # chase rounding on the settled state (measured: constant model, -0.1 V, 200 um, to
                    # 30 tau: 93320 evaluations at atol 9.999999999999999e-14, 841 at 1e-13, where the
                    # level itself took 748): each try is capped at 5 times the finest level's
                    # evaluations.  Where both fail, the level again at ten times rtol: its change
                    # is taken whole as the finest level's time error (no credit for an error
                    # proportional to rtol).  At a small signal the tighter runs chase the state's
                    # rounding (linear model, 10 uV, 200 um, refine 16: 10 and 34 times the level's
                    # evaluations at rtol/3 and rtol/10, changes of +-1e-8 of max|sigma| that do not
                    # shrink with rtol), and the assumed 10 rtol |sigma| did not cover the time
                    # error: 1.2 times the stated error on aarch64 at 0.5 tau, where the run at
                    # 10 rtol differs by twice the error.  Unmeasured, the allowance serves and the
                    # output says so
                    cap = 5 * int(r0.extra.get("nfev", 1000))
                    for f_rt in (0.1, 0.3, 10.0):
                        if max_work is not None and spent[0] + r0.extra["cells"] * r0.extra["nfev"] > max_work:
                            return over_budget(r0, "the time integration's check (the finest level again)")
                        try:
                            with np.errstate(all="ignore"):
                                rtt = level(q0, max_nfev=cap, rtol_=f_rt * rt, atol_=min(atol, 1e-6 * f_rt * tol),
                                            keep=False)
                        except (FloatingPointError, ValueError, np.linalg.LinAlgError):
                            continue
                        if rtt.extra.get("over_budget"):
                            return over_budget(rtt, "the time integration's check (the finest level again)")
                        # the finest level's own values (out, the same object, holds the extrapolation)
                        # (a tighter run's change is the finest level's error less its own; the
                        # looser run's, that run's error: already the margin, counted once)
                        div, mult = (1.0 - f_rt, 2.0) if f_rt < 1.0 else (1.0, 1.0)
                        d = np.abs(js[2] - rtt.current_density) / div
                        ds = np.abs(s4 - rtt.sigma) / div
                        if rtt.success and np.all(np.isfinite(d)) and np.all(np.isfinite(ds)):
                            jt = d
                            # sigma's time part measured too: the assumed 10 rtol |sigma| was 8x short
                            # at the early times of a small step on a loose tol (constant model,
                            # 0.1 mV, 200 um, tol 1e-4: 1.0e-9 C/m^2 off the exact linearised
                            # response at 1.4e-3 tau where 10 rtol |sigma| is 1.3e-10).  The larger
                            # of the assumed and twice the measured part (the window keeps a time
                            # where two runs happen to agree from reading as exact; the looser
                            # run's change once)
                            err = err + np.maximum(0.0, mult * _log_window_max(t, ds) - allowance(E24))
                            out.sigma_error = err
                            break
                    if jt is None:  # not measured: the allowance of the time integration's tolerance
                        jt = np.full(r0.t.size, float(allowance(js[2], peak=True)))
                        out.extra = dict(out.extra, current_time_error="assumed (10 rtol max|J|): the reruns at "
                                                                     "other rtols failed")
                    # the sum counted twice: the margin of an estimate that is not a proven bound
                    # (measured against a run at tol 1e-7, rtol 1e-11: the sum reached 0.98 of the
                    # error at the default tol, 1.34 at tol 1e-4 with rtol 1e-8; affine, 2 V, 200 um)
                    out.current_error = CURRENT_ERROR_MARGIN * _log_window_max(t, np.maximum.reduce(
                        [cur, np.abs(js[0] - js[1]), np.abs(js[1] - js[2])]) + 2.0 * jt)
                    out.current_error = np.where(_jump_withheld(t, js, out.current_error), np.nan, out.current_error)
                    out.M_A_profiles = rich(rc.M_A_profiles, rf_.M_A_profiles)
                    if moment:
                        perm = get_model(model)
                        out.layer_voltage = _layer_voltage(E24, err, perm, material)
                    out.extra = dict(out.extra, refinement=lv, observed_order=p, tol=tol, work=spent[0],
                                     sigma_error_max_rel=float(np.max(err)) / scale if scale > 0 else 0.0,
                                     seconds=time.perf_counter() - t_start)
                    return out
        nxt = 2 * rf
        # cells grow about linearly with refine
        if r.extra["cells"] * 2 > mc:
            est = "n/a" if len(runs) < 3 else f"{float(np.max(np.abs(runs[-1][1].sigma - runs[-2][1].sigma))):.2g} C/m^2"
            msg = (f"mesh refinement cannot meet tol = {tol:g} within max_cells = {mc} "
                   f"(finest {r.extra['cells']} cells; last change {est})")
            return _failed(r, msg, lv)
        rf = nxt


def _failed(r, message, levels, **extra) -> TransientResult:
    """An unsuccessful result on ``r``'s times and mesh: every output NaN, ``message`` one line."""
    nan = np.full(r.t.size, np.nan)
    return TransientResult(t=r.t, sigma=nan, current_density=nan.copy(), layer_voltage=nan.copy(),
                           M_A_profiles=nan.copy(), total_charge=r.total_charge, c=r.c, x=r.x, faces=r.faces,
                           success=False, message=message, extra=dict(r.extra, refinement=levels, **extra),
                           sigma_error=nan.copy(), current_error=nan.copy())


class _TooManyEvaluations(Exception):
    """The integration passed its cap on right-hand-side evaluations (``_solve_once(max_nfev=...)``)."""


def _solve_once(t, phi0_fun, strip, model, material, *, cells_per_debye, ratio, h_core, refine, rtol, atol, method,
                energy, profiles, moment, max_nfev=None, max_work=None) -> TransientResult:
    """One run on one mesh (see :func:`solve_transient`); with ``max_nfev``, a run that needs more
    right-hand-side evaluations stops there and is returned unsuccessful; ``max_work`` caps them at
    ``max_work // cells`` alike (the run's cost in cell-evaluations; ``extra["over_budget"]`` says
    that this cap stopped it).  ``extra["nfev"]`` holds the evaluations made, stopped or not."""
    from scipy.integrate import solve_ivp  # deferred: heavy import (start-up)

    perm: Permittivity = get_model(model)
    m = material
    if perm.is_custom:
        raise ValueError("the transient solver needs an affine permittivity (constant, linear, affine or a Permittivity)")
    if method not in ("BDF", "Radau"):
        raise ValueError(f"method must be BDF or Radau; got {method!r}")
    check_positive("cells_per_debye", cells_per_debye)
    tt = np.asarray(t, dtype=float).reshape(-1)
    VT = groups.thermal_voltage(m)
    e = strip.e
    tscale = e * e / m.D
    lam = float(groups.debye_length(strip.thickness, perm.eps_moy, m))
    rho = perm.eps0 / perm.eps_moy
    A2max = float(np.max(np.abs(phi0_fun(np.linspace(tt[0], tt[-1], 2001))))) / VT
    check_positive("refine", refine)
    X = make_fv_mesh(lam, A2max, rho, cells_per_debye=cells_per_debye * refine, ratio=1.0 + (ratio - 1.0) / refine,
                     h_core=h_core / refine)
    A3 = float(groups.A3(m))

    def psi0(th):
        return float(phi0_fun(np.array([th * tscale]))[0]) / VT

    def psi0_many(th):
        return np.asarray(phi0_fun(np.asarray(th, dtype=float).reshape(-1) * tscale), dtype=float) / VT

    P = (_LinearProblem if rho == 0.0 else _Problem)(X, lam, rho, psi0, A3, psi0_many)
    n = P.N - 1 + (1 if energy else 0)
    y0 = np.zeros(n)
    # atol is absolute on S (units of e) while the charge scales with the signal: the small-signal
    # anode charge is ~ lambda psi0/2 (two Debye layers in series), so a fixed atol of 1e-12 is
    # 1e-6 of sigma at 0.1 mV on 200 um -- a time error the mesh ladder cannot see (it does not
    # converge with h) and the stated 10 rtol |sigma| does not cover.  atol no looser than rtol
    # on that charge keeps the time error relative (unchanged where the charge is large).
    if A2max > 0.0:
        atol = min(atol, rtol * 0.5 * lam * A2max)
    t0 = time.perf_counter()
    # one BLAS thread: Radau's dense LU factorisations (~500^2) are 5-10x slower when OpenBLAS
    # threads compete for the cores
    from threadpoolctl import threadpool_limits  # deferred: only the transient solver needs it

    with threadpool_limits(1):
        meth = _bordered_bdf(P, 1 if energy else 0) if method == "BDF" else method
        # the dissipation integral is a quadrature of the state, left out of the step-size
        # control (its integrand, sum N (mu_{f-1} - mu_f), is rounding noise times ln c in a
        # depleted layer and would stall the steps); the state's steps integrate it to the
        # same order
        at = np.concatenate((np.full(P.N - 1, atol), [1e300])) if energy else atol
        # a trial Newton iterate of the BDF may leave the state's domain (a negative
        # concentration: NaN in the flux); the integrator rejects that step and halves it, so its
        # arithmetic runs with floating-point errors ignored whatever the caller's errstate (under
        # np.seterr(all="raise") the rejection itself raised, depending on rounding-level
        # differences between runs); the accepted states are checked finite below
        count = [0]
        by_work = max_work is not None and (max_nfev is None or max_work // P.N < max_nfev)
        cap = max(0, int(max_work) // P.N) if by_work else max_nfev

        def rhs(th, y):
            count[0] += 1
            if cap is not None and count[0] > cap:
                raise _TooManyEvaluations
            return P.rhs(th, y, energy)

        with np.errstate(all="ignore"):
            try:
                sol = solve_ivp(rhs, (0.0, tt[-1] / tscale), y0, method=meth, t_eval=tt / tscale, rtol=rtol,
                                atol=at, dense_output=False)
                failed = None
                if sol.success and sol.y.shape[1] == tt.size and not np.all(np.isfinite(sol.y[: P.N - 1])):
                    failed = "the integration returned a non-finite state"
                elif not sol.success or sol.y.shape[1] != tt.size:
                    failed = str(sol.message)
            except _TooManyEvaluations:
                failed = (f"more than {cap} right-hand-side evaluations on {P.N} cells (the cap of this run"
                          + (f": max_work = {max_work:.3g} cell-evaluations left)" if by_work else ")"))
    secs = time.perf_counter() - t0
    if failed is not None:
        return TransientResult(t=tt, sigma=np.full(tt.size, np.nan), current_density=np.full(tt.size, np.nan),
                               layer_voltage=np.full(tt.size, np.nan),
                               M_A_profiles=np.full(tt.size, np.nan), total_charge=np.full(tt.size, np.nan),
                               c=np.empty((0, P.N)), x=P.xc, faces=P.X, success=False, message=failed,
                               extra={"cells": P.N, "seconds": secs, "nfev": min(count[0], cap or count[0]),
                                      "over_budget": by_work and count[0] > cap})
    sig_scale = e * m.phi4 * m.F * m.C_moy
    nt = tt.size
    d0 = np.empty(nt)
    J = np.empty(nt)
    qtot = np.empty(nt)
    Mprof = np.empty(nt)
    Fe = np.empty(nt)
    cs = np.empty((nt, P.N)) if profiles else np.empty((0, P.N))
    # dpsi0/dt (scaled time): the waveform's regular derivative, or a difference one-sided at a
    # jump (whose impulse is not a current density: at a jump, the current just after it)
    th = np.asarray(sol.t, dtype=float)
    dpsi0 = voltage_rate(phi0_fun, th * tscale, 1e-3 * tscale) * (tscale / VT)
    # in blocks of rows: the vectorised outputs build ~15 temporaries of the block's size, which
    # at 1000 times on the finest mesh (~8000 cells) stream through memory 2x slower than blocks
    # that stay in the cache
    Y = sol.y[: P.N - 1].T
    for a in range(0, nt, _OUTPUT_BLOCK):
        b = min(a + _OUTPUT_BLOCK, nt)
        d0[a:b], J[a:b], Mprof[a:b], Fe[a:b], cb = P.outputs_all(Y[a:b], sol.t[a:b], dpsi0[a:b])
        qtot[a:b] = (cb - 1.0) @ P.h
        if profiles:
            cs[a:b] = cb
    sigma = sig_scale * d0
    Jsi = sig_scale * J / tscale

    u = _layer_voltage(sigma, np.zeros(nt), perm, m) if moment else np.full(nt, np.nan)
    Mscale = float(groups.A5(strip.width, strip.thickness, VT, m))  # A5 at |phi0| = R T/F, N m
    extra = {"cells": P.N, "h_min_over_debye": float(P.h.min() / lam), "nfev": int(sol.nfev),
             "njev": int(sol.njev), "seconds": secs, "rtol": rtol, "method": method}
    if energy:
        diss = sol.y[-1]
        # supplied after t = 0+ (the ideal step's instantaneous half-loss is not in the model)
        c0, dd0, r0, _, _ = P.fields(np.zeros(P.N - 1), 0.0)
        Fe0 = float(np.dot(r0, dd0 * dd0) / (2 * P.lam2))
        psi_end = psi0(sol.t[-1])
        supplied = psi_end * (d0[-1] - dd0[0])
        stored = Fe[-1] - Fe0
        dissipated = float(diss[-1])
        extra["energy"] = {"supplied": supplied, "stored": stored, "dissipated": dissipated,
                           "relative_residual": abs(supplied - stored - dissipated) / abs(supplied),
                           "unit": "e phi4 C_moy R T per unit area (J/m^2)",
                           "scale_J_per_m2": e * m.phi4 * m.C_moy * m.R * m.T}
    res = TransientResult(t=tt, sigma=sigma, current_density=Jsi, layer_voltage=u,
                          M_A_profiles=Mscale * Mprof, total_charge=qtot, c=cs, x=P.xc, faces=P.X, success=True,
                          message=str(sol.message), extra=extra)
    return res
