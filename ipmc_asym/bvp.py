"""Full nonlinear boundary-value problem across the thickness (the numerical cross-check).

Dimensionless model (paper sections 4-5; docs/design.md), ``z`` = ``z/e`` in
``[-1, 1]`` (anode ``z = -1``, cathode ``z = +1``)::

    E = -phi'        D = eps E        D' = C - 1        eps = A0 C + A1
    C' = A2 C E      p' = (C + A3) E
    phi(-1) = 1,  phi(1) = 0,  D(1) = D(-1)        (i.e. integral of (C - 1) is 0)

so that ``C = B1 exp(-A2 phi)`` and ``p = C/A2 - A3 phi + B2``.  The moment integral is

    I = int_{-1}^{1} p z dz = (1/A2) int (C - 1) z dz + (A3/A2) int y z dz,   y = ln C.

Variables
---------
For the affine family ``eps = A0 C + A1`` the state is ``(s, D, Q)`` with the well-scaled
``s = A0 C + A1 ln C`` (so that ``s' = eps y' = A2 D`` exactly, also where ``eps -> 0``)::

    s' = A2 D,   D' = C(s) - 1,   Q' = ((C - 1) + A3 y) z / A2,   Q(-1) = 0,  I = Q(1)

and the unknown parameter ``b = ln B1``; boundary conditions ``s(-1) = S(b - A2)``,
``s(1) = S(b)`` with ``S(y) = A0 e^y + A1 y``, ``D(1) = D(-1)``, ``Q(-1) = 0``.
``C(s)`` inverts ``A0 C + A1 ln C = s`` (a safeguarded Newton iteration in ``ln C``, never
overflowing).  Jacobians are analytic.

When ``A1 = 0`` (linear model) ``ln C`` has a logarithmic singularity cut off at
``C(-1) = B1 exp(-A2) ~ 1e-17`` within ~1e-19 of the anode, which no collocation mesh can
resolve; ``Q`` then carries only the ``(C - 1) z / A2`` part and ``int y z dz`` is done after
the solve by quadrature on the collocation spline, with an exact log-integral on the cell
touching the anode (see :func:`_moment_y_linear_wall`).

A custom ``eps(C)`` callable (SI) uses ``y = ln C`` as the state
(``y' = A2 D / eps_bar(e^y)``) with a finite-difference derivative of ``eps``.

Negative voltage is the mirror image ``z -> -z`` (``I`` is odd in the voltage); zero volts
gives ``I = 0`` and flat profiles without calling the solver.

Layer rule: imports ``params`` and ``permittivity`` only (plus numpy/scipy).
"""

from __future__ import annotations

import math
import time
import warnings
from dataclasses import dataclass
from types import SimpleNamespace
from typing import Callable

import numpy as np
from scipy.integrate import solve_bvp

from .params import NAFION_LI, Groups, Material, Strip, check_finite, check_positive
from .permittivity import Permittivity, get_model
from .settings import BVP_MAX_NODES, BVP_TOL

__all__ = ["BVPResult", "solve", "moment_integral_bvp", "b1_guess", "make_mesh"]

_EXP_MAX = 700.0
_TINY = np.finfo(float).tiny  # exp() argument cap (exp(709.78) overflows)
_SUGGEST = (
    "try a looser tol (e.g. 1e-8), a larger max_nodes, continuation=True, or a voltage/"
    "thickness closer to the nominal range (10 um - 4 mm, 1 mV - 10 V)"
)


# ---------------------------------------------------------------------------------------
# result container
# ---------------------------------------------------------------------------------------
@dataclass
class BVPResult:
    """Solution of the full BVP on its final mesh (all quantities dimensionless).

    Attributes
    ----------
    z : ndarray, shape (n,)
        Mesh, ``z/e`` in ``[-1, 1]`` (anode of the positive voltage at ``-1``).
    C : ndarray, shape (n,)
        Cation concentration ``C/C_moy``.
    phi : ndarray, shape (n,)
        Potential ``phi/|phi0|`` relative to the face ``z = +1``: ``phi(-1) = sign(phi0)``,
        ``phi(1) = 0``.
    E : ndarray, shape (n,)
        Field ``-dphi/dz`` (``E_bar = D_bar / eps_bar``).
    D : ndarray, shape (n,)
        Electric induction ``D_bar`` (``D' = C - 1``).
    rhoZ : ndarray, shape (n,)
        Charge density ``C - 1``.
    p : ndarray, shape (n,)
        Pressure ``p_bar = C/A2 - A3 phi``, i.e. the constant ``B2`` is set to 0 (it does not
        enter ``I`` because ``int z dz = 0``).
    y : ndarray, shape (n,)
        ``ln C``.
    B1 : float
        Constant of ``C = B1 exp(-A2 phi)`` in the convention of ``phi`` above (for a negative
        voltage this is ``B1(|phi0|) exp(-A2)``).
    I : float
        Moment integral ``int p z dz`` (signed, odd in the voltage).  ``M_A = A5 I``.
    groups : Groups
    model : str
    success : bool
        ``True`` iff solve_bvp reported status 0 (and the result is finite).
    status : int
        solve_bvp status (0 converged, 1 max_nodes exceeded, 2 singular Jacobian,
        3 tolerance too small), -1 for an internal failure.
    message : str
    niter : int
        Newton/refinement iterations of the last solve_bvp call.
    n_nodes : int
    max_rms_residual : float
        Largest relative rms collocation residual on the final mesh.
    bc_residual : float
        Largest absolute boundary-condition residual.
    seconds : float
        Wall time of :func:`solve`.
    """

    z: np.ndarray
    C: np.ndarray
    phi: np.ndarray
    E: np.ndarray
    D: np.ndarray
    rhoZ: np.ndarray
    p: np.ndarray
    y: np.ndarray
    B1: float
    I: float
    groups: Groups
    model: str
    success: bool
    status: int
    message: str
    niter: int
    n_nodes: int
    max_rms_residual: float
    bc_residual: float
    seconds: float


# ---------------------------------------------------------------------------------------
# scalar helpers
# ---------------------------------------------------------------------------------------
def b1_guess(A0: float, A1: float, A2: float) -> float:
    """``B1`` from electroneutrality with a neutral core (exponentially accurate).

    Solves ``A0/2 (1 - e^{-2 A2}) B^2 + (A1 - A0)(1 - e^{-A2}) B - A1 A2 = 0`` (the first
    integral ``G(B1) = G(B1 e^{-A2})``, ``G(C) = A0 C^2/2 + (A1 - A0) C - A1 ln C``).
    Constant model: ``A2 / (1 - e^{-A2})``; linear: ``2 / (1 + e^{-A2})``.
    """
    em1 = -math.expm1(-A2)  # 1 - e^{-A2}
    if A0 == 0.0:
        return A2 / em1 if A2 > 0 else 1.0
    if A1 == 0.0:
        return 2.0 / (1.0 + math.exp(-A2))
    a = 0.5 * A0 * em1 * (2.0 - em1)  # A0/2 (1 - e^{-2A2})
    bq = (A1 - A0) * em1
    c = -A1 * A2
    disc = math.sqrt(bq * bq - 4.0 * a * c)
    # positive root, cancellation-free
    return (-bq + disc) / (2.0 * a) if bq <= 0 else (-2.0 * c) / (bq + disc)


def _expc(y):
    """``exp(y)`` with the argument capped at 700 (no overflow; underflow is harmless)."""
    return np.exp(np.minimum(y, _EXP_MAX))


def _y_of_s(s, A0: float, A1: float):
    """Solve ``A0 e^y + A1 y = s`` for ``y`` (vectorised; ``A1 > 0``).

    ``g(y) = A0 e^y + A1 y - s`` is increasing and convex, so Newton started above the
    root decreases monotonically onto it.  Start: ``min(s/A1, max(ln(s/A0), 0))`` (an upper
    bound of the root).  No ``exp`` of a large argument is ever formed.
    """
    s = np.asarray(s, dtype=float)
    if A0 == 0.0:
        return s / A1
    pos = s > 0
    ls = np.log(np.where(pos, s, 1.0) / A0)
    y = np.minimum(s / A1, np.where(pos, np.maximum(ls, 0.0), 0.0))
    for _ in range(100):
        ey = _expc(y)
        g = A0 * ey + A1 * y - s
        dy = g / (A0 * ey + A1)
        y = y - dy
        if np.all(np.abs(dy) <= 4e-16 * (1.0 + np.abs(y))):
            break
    return y


def _H(y, A0: float, A1: float):
    """``G(e^y) - G(1) = A0 (C - 1)^2 / 2 + A1 (C - 1 - y)`` (>= 0)."""
    cm1 = np.expm1(np.minimum(y, _EXP_MAX))
    return 0.5 * A0 * cm1 * cm1 + A1 * np.maximum(cm1 - y, 0.0)


def make_mesh(h0_a: float, h0_c: float, *, ratio: float = 1.06, h_core: float = 0.02) -> np.ndarray:
    """Mesh on ``[-1, 1]`` graded geometrically towards both faces.

    Parameters
    ----------
    h0_a, h0_c : float
        First spacing (dimensionless) at the anode (``z = -1``) and at the cathode (``z = 1``).
    ratio : float
        Growth factor of consecutive spacings.
    h_core : float
        Largest spacing (in the neutral core).

    Returns
    -------
    ndarray, shape (n,)
        Strictly increasing nodes with ``z[0] = -1``, ``z[-1] = 1``.
    """

    def side(h0):
        h0 = min(max(h0, 1e-13), h_core)
        n_geo = int(math.ceil(math.log(h_core / h0) / math.log(ratio))) + 1
        hs = np.minimum(h0 * ratio ** np.arange(n_geo), h_core)
        d = np.concatenate(([0.0], np.cumsum(hs)))
        if d[-1] < 1.0:
            d = np.concatenate((d, d[-1] + h_core * np.arange(1, int((1.0 - d[-1]) / h_core) + 2)))
        return d

    za = -1.0 + side(h0_a)
    zc = 1.0 - side(h0_c)
    # each side reaches the spacing h_core before z = 0 (the geometric part spans
    # h_core / (ratio - 1) < 1), so the two halves join at 0 with that spacing
    z = np.union1d(za[za < -0.5 * h_core], zc[zc > 0.5 * h_core])
    z = np.union1d(z, [-1.0, 0.0, 1.0])
    return z[(z >= -1.0) & (z <= 1.0)]


# ---------------------------------------------------------------------------------------
# problem definitions
# ---------------------------------------------------------------------------------------
class _AffineProblem:
    """State ``(s, D, Q)``, parameter ``b``; ``eps = A0 C + A1``."""

    def __init__(self, g: Groups):
        self.A0, self.A1, self.A2, self.A3 = g.A0, g.A1, g.A2, g.A3
        self.with_y = g.A1 > 0.0  # Q' includes the A3 y z / A2 part

    # conversions -------------------------------------------------------------------
    def S(self, y):
        return self.A0 * _expc(y) + self.A1 * y

    def C_y(self, s):
        """Return ``(C, y)`` from ``s`` (``y`` is ``None`` for ``A1 = 0``)."""
        A0, A1 = self.A0, self.A1
        if A1 == 0.0:
            return s / A0, None
        y = _y_of_s(s, A0, A1)
        return _expc(y), y

    # ODE -----------------------------------------------------------------------------
    def fun(self, z, u, p):
        s, D = u[0], u[1]
        C, y = self.C_y(s)
        q = C - 1.0
        if self.with_y:
            q = q + self.A3 * y
        return np.vstack((self.A2 * D, C - 1.0, q * z / self.A2))

    def fun_jac(self, z, u, p):
        s = u[0]
        n = s.size
        C, y = self.C_y(s)
        eps = self.A0 * C + self.A1
        dC = C / eps if self.A1 > 0.0 else np.full(n, 1.0 / self.A0)
        J = np.zeros((3, 3, n))
        J[0, 1] = self.A2
        J[1, 0] = dC
        dq = dC + (self.A3 / eps if self.with_y else 0.0)
        J[2, 0] = dq * z / self.A2
        return J, np.zeros((3, 1, n))

    def bc(self, ua, ub, p):
        b = p[0]
        return np.array([ua[0] - self.S(b - self.A2), ub[0] - self.S(b), ub[1] - ua[1], ua[2]])

    def bc_jac(self, ua, ub, p):
        b = p[0]
        dSa = self.A0 * _expc(b - self.A2) + self.A1
        dSb = self.A0 * _expc(b) + self.A1
        Ja = np.zeros((4, 3))
        Jb = np.zeros((4, 3))
        Jp = np.zeros((4, 1))
        Ja[0, 0] = 1.0
        Jp[0, 0] = -dSa
        Jb[1, 0] = 1.0
        Jp[1, 0] = -dSb
        Jb[2, 1] = 1.0
        Ja[2, 1] = -1.0
        Ja[3, 2] = 1.0
        return Ja, Jb, Jp

    def eps_of_C(self, C):
        return self.A0 * C + self.A1

    def state_from_yD(self, z, y, D):
        Q = _cumtrapz(self._qprime(z, y), z)
        return np.vstack((self.S(y), D, Q))

    def _qprime(self, z, y):
        C = _expc(y)
        q = C - 1.0
        if self.with_y:
            q = q + self.A3 * y
        return q * z / self.A2

    def profiles(self, z, u, b):
        """Return ``C, y, D`` on the nodes, ``y`` clipped to the physical ``[b - A2, b]``."""
        s, D = u[0], u[1]
        if self.A1 == 0.0:
            cw = max(math.exp(b - self.A2), _TINY)  # exp may underflow above ~700 V/25.9 mV
            C = np.clip(s / self.A0, cw, math.exp(b))
            y = np.log(C)
            C[0], y[0] = math.exp(b - self.A2), b - self.A2
        else:
            y = np.clip(_y_of_s(s, self.A0, self.A1), b - self.A2, b)
            C = np.exp(y)
        return C, y, D


class _CustomProblem:
    """State ``(y, D, Q)``, parameter ``b``; ``eps_bar(C)`` from a user callable."""

    def __init__(self, g: Groups, eps_bar: Callable, y_lo: float, y_hi: float):
        self.A2, self.A3 = g.A2, g.A3
        self.A0, self.A1 = g.A0, g.A1
        self.eps_bar = eps_bar
        self.with_y = True
        # Newton iterates are confined to this window of ln C (validated beforehand), so a
        # wandering iterate never evaluates eps outside the range the user function was
        # checked on; the converged solution lies well inside it.
        self.y_lo, self.y_hi = y_lo, y_hi

    def _yc(self, y):
        return np.clip(y, self.y_lo, self.y_hi)

    def eps_of_C(self, C):
        e = self.eps_bar(C)
        if not np.all(np.isfinite(e)) or np.any(e <= 0.0):
            raise ValueError(
                "custom permittivity eps(C) must be finite and > 0 F/m on the concentration "
                f"range of the solution (C/C_moy in [{np.min(C):.3g}, {np.max(C):.3g}])"
            )
        return e

    def fun(self, z, u, p):
        y, D = self._yc(u[0]), u[1]
        eps = self.eps_of_C(np.exp(y))
        cm1 = np.expm1(y)
        return np.vstack((self.A2 * D / eps, cm1, (cm1 + self.A3 * y) * z / self.A2))

    def fun_jac(self, z, u, p):
        y, D = self._yc(u[0]), u[1]
        n = y.size
        C = np.exp(y)
        eps = self.eps_of_C(C)
        h = 1e-6
        deps_dy = (self.eps_of_C(np.exp(y + h)) - self.eps_of_C(np.exp(y - h))) / (2 * h)
        J = np.zeros((3, 3, n))
        J[0, 0] = -(self.A2 * D / eps) * (deps_dy / eps)
        J[0, 1] = self.A2 / eps
        J[1, 0] = C
        J[2, 0] = (C + self.A3) * z / self.A2
        return J, np.zeros((3, 1, n))

    def bc(self, ua, ub, p):
        b = p[0]
        return np.array([ua[0] - (b - self.A2), ub[0] - b, ub[1] - ua[1], ua[2]])

    def bc_jac(self, ua, ub, p):
        Ja = np.zeros((4, 3))
        Jb = np.zeros((4, 3))
        Jp = np.zeros((4, 1))
        Ja[0, 0] = 1.0
        Jp[0, 0] = -1.0
        Jb[1, 0] = 1.0
        Jp[1, 0] = -1.0
        Jb[2, 1] = 1.0
        Ja[2, 1] = -1.0
        Ja[3, 2] = 1.0
        return Ja, Jb, Jp

    def state_from_yD(self, z, y, D):
        q = (np.expm1(np.minimum(y, _EXP_MAX)) + self.A3 * y) * z / self.A2
        return np.vstack((y, D, _cumtrapz(q, z)))

    def profiles(self, z, u, b):
        y = np.clip(u[0], b - self.A2, b)
        return np.exp(y), y, u[1]


def _cumtrapz(f, x):
    out = np.zeros_like(f)
    out[1:] = np.cumsum(0.5 * (f[1:] + f[:-1]) * np.diff(x))
    return out


# ---------------------------------------------------------------------------------------
# scales, initial guess
# ---------------------------------------------------------------------------------------
def _first_spacings(g: Groups, eps_of_C, b: float, tol: float, custom: bool):
    """First mesh spacings at the anode and the cathode, and the core Debye length.

    Physical part: ``1e-3`` of the thinnest local scale (cathode: local Debye length
    ``sqrt(eps(B1) / (A2 B1))``; anode: wall scale ``eps_w / (A2 D_w)`` of ``ln C``, floored
    at ``1e-3`` of the core Debye length because ``s`` stays smooth where ``eps -> 0``).
    Rounding floor: solve_bvp's relative residual ``|u' - f| / (1 + |f|)`` of a spline
    through node values rounded to ``eps_mach |u|`` is ``~ eps_mach |u| / h``; the first
    spacing is kept above ``30 eps_mach / tol * max_i |u_i| / (1 + |f_i|)`` at each wall so
    that refinement is never asked to beat rounding.
    """
    A0, A1, A2 = max(g.A0, 0.0), max(g.A1, 0.0), g.A2
    lam = math.sqrt(max(float(eps_of_C(np.array([1.0]))[0]), 1e-300) / A2)
    B1 = math.exp(b)
    cw = math.exp(b - A2)
    eps_c = float(eps_of_C(np.array([B1]))[0])
    eps_w = float(eps_of_C(np.array([cw]))[0])
    if A0 == 0.0 and A1 == 0.0:
        A1 = eps_c
    Dw = math.sqrt(2.0 * max(float(_H(np.array([b]), A0, A1)[0]), 1e-300) / A2)
    h_c = min(lam, math.sqrt(eps_c / (A2 * B1)))
    if custom and eps_w / (A2 * Dw) < 1e-10:
        raise ValueError(
            "custom permittivity eps(C) is too small at the anode (eps(C -> 0) ~ "
            f"{eps_w:.3g} in units of e^2 phi4 F C_moy/|phi0|): ln C would vary on a scale "
            f"~{eps_w / (A2 * Dw):.1e} e, which double precision cannot resolve; use the "
            "built-in 'linear'/'affine' models (solved in s = A0 C + A1 ln C) or give eps a "
            "positive floor eps(0) > 0"
        )
    h_a = min(lam, Dw, max(eps_w / (A2 * Dw), 1e-3 * lam))
    floor = 30.0 * np.finfo(float).eps / tol
    if custom:
        ua, uc = abs(b - A2), abs(b)
        fa, fc = A2 * Dw / eps_w, A2 * Dw / eps_c
    else:
        ua = abs(A0 * cw + A1 * (b - A2))
        uc = abs(A0 * B1 + A1 * b)
        fa = fc = A2 * Dw
    ra = max(ua / (1.0 + fa), Dw / (2.0 - cw))
    rc = max(uc / (1.0 + fc), Dw / B1)
    return max(1e-3 * h_a, floor * ra), max(1e-3 * h_c, floor * rc), lam


def _layer(yw: float, eps_of_C, A0: float, A1: float, A2: float, lam: float, n: int = 600):
    """Half-infinite layer profile ``y(delta)`` from the first integral (guess only).

    ``d delta = eps / sqrt(2 A2 H(y)) |dy|`` integrated from the wall value ``yw``
    towards 0, in ``t = ln(y / yw)``; continued by ``exp(-delta / lam)``.
    """
    if yw == 0.0:
        return np.array([0.0, 1.0]), np.array([0.0, 0.0])
    t = np.linspace(0.0, math.log(1e-5), n)
    y = yw * np.exp(t)
    H = np.maximum(_H(y, A0, A1), 1e-300)
    w = eps_of_C(np.exp(y)) * np.abs(y) / np.sqrt(2.0 * A2 * H)
    delta = _cumtrapz(w, -t)
    return delta, y


def _guess(z: np.ndarray, g: Groups, prob, b: float, lam: float):
    """Initial ``(y, D)`` on ``z`` from two independent layer profiles."""
    A0e = prob.A0 if isinstance(prob, _AffineProblem) else g.A0
    A1e = prob.A1 if isinstance(prob, _AffineProblem) else g.A1
    if A0e == 0.0 and A1e == 0.0:
        A1e = float(prob.eps_of_C(np.array([1.0]))[0])
    y = np.zeros_like(z)
    for yw, dist in ((b, 1.0 - z), (b - g.A2, 1.0 + z)):
        dl, yl = _layer(yw, prob.eps_of_C, A0e, A1e, g.A2, lam)
        inside = dist <= dl[-1]
        yy = np.empty_like(z)
        yy[inside] = np.interp(dist[inside], dl, yl)
        yy[~inside] = yl[-1] * np.exp(-np.minimum((dist[~inside] - dl[-1]) / lam, 700.0))
        y += yy
    y = np.clip(y, b - g.A2, b)
    D = np.sqrt(2.0 * np.maximum(_H(y, A0e, A1e), 0.0) / g.A2)
    return y, D


# ---------------------------------------------------------------------------------------
# post-processing of the linear-model moment (log singularity at the anode)
# ---------------------------------------------------------------------------------------
_GL_X, _GL_W = np.polynomial.legendre.leggauss(10)


def _moment_y_linear(sol, z, g: Groups, b: float, D_anode: float) -> float:
    """``int_{-1}^{1} z ln C dz`` for ``A1 = 0`` on the collocation spline of ``s = A0 C``.

    Gauss-Legendre (10 points) on each mesh cell; the first cell at the anode is split
    geometrically (100 halvings) towards the wall, using the spline down to ``2^-20`` of the
    cell and below that the Taylor form ``C ~ c_w + C'(-1) d + C''(-1) d^2 / 2`` (``d = 1 + z``
    is not representable as ``z``); the last ``2^-100`` uses the exact integral of the log of
    the linear part.  ``C`` is clipped to its physical range ``[c_w, B1]`` (phi is monotone).
    """
    A0, A2 = g.A0, g.A2
    cw = max(math.exp(b - A2), _TINY)  # floor: exp(b - A2) underflows for A2 > ~708
    cmax = math.exp(b)

    def integ(a, bb):
        xm = 0.5 * (a + bb)
        hr = 0.5 * (bb - a)
        xs = (xm[:, None] + hr[:, None] * _GL_X[None, :]).ravel()
        C = np.clip(sol(xs)[0] / A0, cw, cmax)
        val = (xs * np.log(C)).reshape(xm.size, -1) @ _GL_W
        return float(np.sum(val * hr))

    total = integ(z[1:-1], z[2:])
    # first cell [-1, z1]: offsets delta in (0, h1], local C = cw + a1 delta + a2 delta^2/2
    h1 = z[1] - z[0]
    a1 = A2 * D_anode / A0  # C'(-1)
    a2 = A2 * (cw - 1.0) / A0  # C''(-1)
    edges = h1 * 2.0 ** (-np.arange(0, 101, dtype=float))
    lo, hi = edges[1:], edges[:-1]
    xm = 0.5 * (lo + hi)
    hr = 0.5 * (hi - lo)
    d = (xm[:, None] + hr[:, None] * _GL_X[None, :])
    C = np.maximum(cw + a1 * d + 0.5 * a2 * d * d, cw)
    # where 1 + z is still well represented, use the spline itself
    spl = lo >= h1 * 2.0 ** -20
    C[spl] = np.clip(sol((-1.0 + d[spl]).ravel())[0].reshape(d[spl].shape) / A0, cw, cmax)
    total += float(np.sum(((-1.0 + d) * np.log(C)) @ _GL_W * hr))
    # [0, dmin]: z ~ -1, int_0^dm ln(cw + a1 x) dx exactly
    dm = edges[-1]
    if a1 > 0:
        u = cw + a1 * dm
        total += -((u * math.log(u) - u) - (cw * math.log(cw) - cw)) / a1
    else:
        total += -dm * math.log(cw)
    return total


# ---------------------------------------------------------------------------------------
# driver
# ---------------------------------------------------------------------------------------
def _eps_bar_custom(func: Callable, g: Groups, material: Material) -> Callable:
    scale = abs(g.phi0) / (g.e * g.e * material.phi4 * material.F * g.C_moy)
    cm = g.C_moy

    def eps_bar(Cb):
        Cb = np.asarray(Cb, dtype=float)
        try:
            v = np.asarray(func(Cb * cm), dtype=float)
            if v.shape != Cb.shape:
                v = np.broadcast_to(v, Cb.shape).astype(float)
        except Exception:  # not vectorised
            v = np.array([float(func(c)) for c in (Cb * cm).ravel()]).reshape(Cb.shape)
        return v * scale

    return eps_bar


def _run(prob, g: Groups, z, U, b, tol, max_nodes):
    """solve_bvp; a floating-point error inside it becomes a failed result (status -1)."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return solve_bvp(prob.fun, prob.bc, z, U, p=np.array([b]), fun_jac=prob.fun_jac,
                             bc_jac=prob.bc_jac, tol=tol, bc_tol=tol, max_nodes=max_nodes,
                             verbose=0)
    except (FloatingPointError, np.linalg.LinAlgError, OverflowError) as exc:
        return SimpleNamespace(status=-1, message=f"numerical failure in solve_bvp: {exc}",
                               x=z, y=U, p=np.array([b]), sol=None, rms_residuals=None,
                               niter=0, success=False)


def _solve_abs(strip: Strip, perm: Permittivity, material: Material, tol: float,
               max_nodes: int, guess=None):
    """Solve at ``|phi0|`` (positive frame).  Returns ``(res, prob, g)``."""
    g = perm.groups(strip.with_(voltage=abs(strip.voltage)), material)
    b0 = math.log(b1_guess(g.A0, g.A1, g.A2)) if (g.A0 > 0 or g.A1 > 0) else 0.0
    if perm.is_custom:
        y_lo, y_hi = b0 - g.A2 - 20.0, b0 + 20.0
        prob = _CustomProblem(g, _eps_bar_custom(perm.func, g, material), y_lo, y_hi)
        # validate eps on the whole window the iterates may visit (raises ValueError)
        prob.eps_of_C(np.exp(np.linspace(y_lo, y_hi, 400)))
    else:
        prob = _AffineProblem(g)
    h0_a, h0_c, lam = _first_spacings(g, prob.eps_of_C, b0, tol, perm.is_custom)
    z = make_mesh(h0_a, h0_c, h_core=min(0.02, 2.0 * lam + 1e-3))
    if guess is None:
        y, D = _guess(z, g, prob, b0, lam)
    else:
        zo, phio, Do, bo = guess  # phi profile of a lower voltage, same geometry
        y = b0 - g.A2 * np.interp(z, zo, phio)
        A0e, A1e = (g.A0, g.A1) if not perm.is_custom else (g.A0, max(g.A1, 1e-300))
        D = np.sqrt(2.0 * np.maximum(_H(y, A0e, A1e), 0.0) / g.A2)
    U = prob.state_from_yD(z, y, D)
    res = _run(prob, g, z, U, b0, tol, max_nodes)
    return res, prob, g


def _bc_res(prob, res) -> float:
    return float(np.max(np.abs(prob.bc(res.y[:, 0], res.y[:, -1], res.p))))


def solve(strip: Strip, model="constant", material: Material = NAFION_LI, *, tol: float = BVP_TOL,
          max_nodes: int = BVP_MAX_NODES, continuation: bool = True) -> BVPResult:
    """Solve the full nonlinear BVP across the thickness and return profiles and ``I``.

    Parameters
    ----------
    strip : Strip
        Geometry and voltage (SI; ``thickness`` is the total ``2e``).  Only ``thickness``
        and ``voltage`` enter the solution (``width`` enters ``groups.A5``).
    model : str, Permittivity or callable
        ``"constant"``, ``"linear"``, ``"affine"``, a :class:`Permittivity`, or a callable
        ``eps(C)`` (C in mol/m^3, returns F/m; must be finite and > 0 on the solution's
        concentration range, else ``ValueError``).
    material : Material
    tol : float
        solve_bvp relative residual tolerance (also used as ``bc_tol``).
    max_nodes : int
    continuation : bool
        If the direct solve fails, solve at smaller voltages and step up to the target,
        reusing each solution as the next guess.

    Returns
    -------
    BVPResult
        ``success=False`` (with solve_bvp's message) if no converged solution was found;
        the arrays then hold the last iterate.
    """
    t0 = time.perf_counter()
    if not isinstance(strip, Strip):
        raise ValueError(f"strip must be a Strip; got {strip!r}")
    check_positive("tol", tol)
    if int(max_nodes) < 10:
        raise ValueError(f"max_nodes must be an integer >= 10; got {max_nodes!r}")
    perm = get_model(model)
    g_signed = perm.groups(strip, material)
    name = perm.name
    if strip.voltage == 0.0:
        z = np.linspace(-1.0, 1.0, 3)
        zero = np.zeros_like(z)
        return BVPResult(z=z, C=np.ones_like(z), phi=zero.copy(), E=zero.copy(), D=zero.copy(),
                         rhoZ=zero.copy(), p=zero.copy(), y=zero.copy(), B1=1.0, I=0.0,
                         groups=g_signed, model=name, success=True, status=0,
                         message="zero voltage: no field, no bending", niter=0, n_nodes=3,
                         max_rms_residual=0.0, bc_residual=0.0,
                         seconds=time.perf_counter() - t0)

    res, prob, g = _solve_abs(strip, perm, material, tol, max_nodes)
    how = ""
    if res.status != 0 and continuation:
        res2 = _continuation(strip, perm, material, tol, max_nodes)
        if res2 is not None:
            res, prob, g = res2
            how = " (after voltage continuation)"
    return _finish(res, prob, g, g_signed, name, t0, how)


def _continuation(strip, perm, material, tol, max_nodes):
    """Find a voltage where the direct solve works, then step up by factors <= 2."""
    V = abs(strip.voltage)
    v = V
    ok = None
    for _ in range(12):
        v /= 4.0
        r = _solve_abs(strip.with_(voltage=v), perm, material, tol, max_nodes)
        if r[0].status == 0:
            ok = r
            break
    if ok is None:
        return None
    while v < V:
        res, prob, g = ok
        C, y, D = prob.profiles(res.x, res.y, res.p[0])
        phi = (res.p[0] - y) / g.A2
        v_next = min(2.0 * v, V)
        r = _solve_abs(strip.with_(voltage=v_next), perm, material, tol, max_nodes,
                       guess=(res.x, phi, D, res.p[0]))
        if r[0].status != 0:
            return r if v_next == V else None
        ok, v = r, v_next
    return ok


def _finish(res, prob, g, g_signed, name, t0, how) -> BVPResult:
    z = res.x
    b = float(res.p[0])
    C, y, D = prob.profiles(z, res.y, b)
    A2, A3 = g.A2, g.A3
    if res.sol is None:
        I = float("nan")
    elif isinstance(prob, _AffineProblem) and g.A1 == 0.0:
        Iy = _moment_y_linear(res.sol, z, g, b, float(res.y[1, 0]))
        I = float(res.y[2, -1]) + A3 / A2 * Iy
    else:
        I = float(res.y[2, -1])
    phi = (b - y) / A2
    eps = prob.eps_of_C(C)
    # linear model: eps -> A0 C(-1) ~ B1 e^{-A2} A0 at the anode, E is huge there (floored
    # denominator only to stay finite when exp(-A2) underflows)
    E = D / np.maximum(eps, _TINY)
    B1 = math.exp(b)
    success = bool(res.status == 0 and np.isfinite(I))
    msg = res.message + how
    if g_signed.sign < 0:  # mirror image z -> -z, potential referenced to the face z = +1
        z = -z[::-1]
        C, y = C[::-1].copy(), y[::-1].copy()
        D, E = -D[::-1], -E[::-1]
        phi = phi[::-1] - 1.0
        B1 = math.exp(b - A2)
        I = -I
    p = C / A2 - A3 * phi
    rms = float(np.max(res.rms_residuals)) if res.rms_residuals is not None else float("nan")
    return BVPResult(z=z, C=C, phi=phi, E=E, D=D, rhoZ=C - 1.0, p=p, y=y, B1=B1, I=I,
                     groups=g_signed, model=name, success=success, status=int(res.status),
                     message=msg, niter=int(res.niter), n_nodes=int(z.size),
                     max_rms_residual=rms, bc_residual=_bc_res(prob, res),
                     seconds=time.perf_counter() - t0)


def moment_integral_bvp(thickness, voltage, model="constant", material: Material = NAFION_LI,
                        *, tol: float = BVP_TOL) -> float:
    """Moment integral ``I = int p z dz`` from the full BVP (dimensionless, signed).

    Parameters
    ----------
    thickness : float
        TOTAL thickness ``2e``, m (> 0).
    voltage : float
        Applied voltage ``phi0``, V (any sign; 0 gives 0).
    model : str, Permittivity or callable
    material : Material
    tol : float

    Returns
    -------
    float
        ``I``; ``M_A = A5 I``.

    Raises
    ------
    ValueError
        Bad input.
    RuntimeError
        The BVP did not converge (never returns an unconverged number).
    """
    th = check_positive("thickness (total, 2e)", thickness, "m")
    v = check_finite("voltage", voltage, "a finite number of volts")
    r = solve(Strip(thickness=th, voltage=v), model, material, tol=tol)
    if not r.success:
        raise RuntimeError(f"BVP did not converge ({r.message}); {_SUGGEST}")
    return r.I
