"""BVP problem definitions: the ODE systems, boundary conditions and analytic Jacobians.

The dimensionless model and the choice of variables are described in :mod:`ipmc_asym.bvp.solver`
(paper sections 4-5, docs/design.md).  Two problems:

* :class:`AffineProblem`, ``eps = A0 C + A1`` (the paper's three models): state
  ``(s, D, Q)`` with ``s = A0 C + A1 ln C``, parameter ``b = ln B1``;
* :class:`CustomProblem`, a user ``eps(C)``: state ``(y = ln C, D, Q)``.

Also the post-processing of the linear-model moment (log singularity at the anode,
:func:`moment_y_linear`) and the scalar helpers shared with the mesh module.
Layer rule: moment layer; numpy and params only.
"""

from __future__ import annotations

import math
from typing import Callable

import numpy as np

from ipmc_asym.kernels.quadrature_nodes import leggauss
from ipmc_asym.model import groups
from ipmc_asym.model.params import Groups, Material

__all__ = ["AffineProblem", "CustomProblem", "b1_guess", "eps_bar_custom", "moment_y_linear",
           "expc", "y_of_s", "H", "cumtrapz", "EXP_MAX", "TINY"]

EXP_MAX = 700.0  # exp() argument cap (exp(709.78) overflows)
TINY = np.finfo(float).tiny

# ---------------------------------------------------------------------------------------
# scalar helpers
# ---------------------------------------------------------------------------------------
def b1_guess(A0: float, A1: float, A2: float) -> float:
    """``B1`` from electroneutrality with a neutral core (exponentially accurate).

    :func:`ipmc_asym.model.groups.b1_neutral` at ``rho = A1/(A0 + A1)`` (the secant's ratio
    for a custom ``eps(C)``).
    """
    rho = A1 / (A0 + A1) if A0 + A1 > 0 else 1.0
    return float(groups.b1_neutral(A2, rho))


def expc(y):
    """``exp(y)`` with the argument capped at 700 (no overflow; underflow is harmless)."""
    return np.exp(np.minimum(y, EXP_MAX))


def y_of_s(s, A0: float, A1: float):
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
        ey = expc(y)
        g = A0 * ey + A1 * y - s
        dy = g / (A0 * ey + A1)
        y = y - dy
        if np.all(np.abs(dy) <= 4e-16 * (1.0 + np.abs(y))):
            break
    return y


def H(y, A0: float, A1: float):
    """``G(e^y) - G(1) = A0 (C - 1)^2 / 2 + A1 (C - 1 - y)`` (>= 0)."""
    cm1 = np.expm1(np.minimum(y, EXP_MAX))
    return 0.5 * A0 * cm1 * cm1 + A1 * np.maximum(cm1 - y, 0.0)


# ---------------------------------------------------------------------------------------
# problem definitions
# ---------------------------------------------------------------------------------------
class AffineProblem:
    """State ``(s, D, Q)``, parameter ``b``; ``eps = A0 C + A1``."""

    def __init__(self, g: Groups):
        self.A0, self.A1, self.A2, self.A3 = g.A0, g.A1, g.A2, g.A3
        self.with_y = g.A1 > 0.0  # Q' includes the A3 y z / A2 part

    # conversions -------------------------------------------------------------------
    def S(self, y):
        return self.A0 * expc(y) + self.A1 * y

    def C_y(self, s):
        """Return ``(C, y)`` from ``s`` (``y`` is ``None`` for ``A1 = 0``)."""
        A0, A1 = self.A0, self.A1
        if A1 == 0.0:
            return s / A0, None
        y = y_of_s(s, A0, A1)
        return expc(y), y

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
        dSa = self.A0 * expc(b - self.A2) + self.A1
        dSb = self.A0 * expc(b) + self.A1
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
        Q = cumtrapz(self._qprime(z, y), z)
        return np.vstack((self.S(y), D, Q))

    def _qprime(self, z, y):
        C = expc(y)
        q = C - 1.0
        if self.with_y:
            q = q + self.A3 * y
        return q * z / self.A2

    def profiles(self, z, u, b):
        """Return ``C, y, D`` on the nodes, ``y`` clipped to the physical ``[b - A2, b]``."""
        s, D = u[0], u[1]
        # a diverged iterate (a failed solve) can carry b far above EXP_MAX: capped, it stays
        # finite for the caller's refusal; a converged b is a few units at most (B1 ~ A2)
        b = min(b, EXP_MAX)
        if self.A1 == 0.0:
            cw = max(math.exp(b - self.A2), TINY)  # exp may underflow above ~700 V/25.9 mV
            C = np.clip(s / self.A0, cw, math.exp(b))
            y = np.log(C)
            C[0], y[0] = math.exp(b - self.A2), b - self.A2
        else:
            y = np.clip(y_of_s(s, self.A0, self.A1), b - self.A2, b)
            C = np.exp(y)
        return C, y, D


class CustomProblem:
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
        q = (np.expm1(np.minimum(y, EXP_MAX)) + self.A3 * y) * z / self.A2
        return np.vstack((y, D, cumtrapz(q, z)))

    def profiles(self, z, u, b):
        y = np.clip(u[0], b - self.A2, min(b, EXP_MAX))  # a diverged iterate's b: as AffineProblem.profiles
        return np.exp(y), y, u[1]


def cumtrapz(f, x):
    out = np.zeros_like(f)
    out[1:] = np.cumsum(0.5 * (f[1:] + f[:-1]) * np.diff(x))
    return out


# ---------------------------------------------------------------------------------------
# post-processing of the linear-model moment (log singularity at the anode)
# ---------------------------------------------------------------------------------------
_GL_X, _GL_W = leggauss(10)


def moment_y_linear(sol, z, g: Groups, b: float, D_anode: float) -> float:
    """``int_{-1}^{1} z ln C dz`` for ``A1 = 0`` on the collocation spline of ``s = A0 C``.

    Gauss-Legendre (10 points) on each mesh cell; the first cell at the anode is split
    geometrically (100 halvings) towards the wall, using the spline down to ``2^-20`` of the
    cell and below that the Taylor form ``C ~ c_w + C'(-1) d + C''(-1) d^2 / 2`` (``d = 1 + z``
    is not representable as ``z``); the last ``2^-100`` uses the exact integral of the log of
    the linear part.  ``C`` is clipped to its physical range ``[c_w, B1]`` (phi is monotone).
    """
    A0, A2 = g.A0, g.A2
    cw = max(math.exp(b - A2), TINY)  # floor: exp(b - A2) underflows for A2 > ~708
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


def eps_bar_custom(func: Callable, g: Groups, material: Material) -> Callable:
    scale = float(groups.A0(2.0 * g.e, g.phi0, 1.0, material, g.C_moy))  # A0 per F/m of eps
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


class PressureProblem:
    """:class:`AffineProblem` with the pressure term of the Nernst-Planck law (paper eq. (5)).

    Derivation in ``derivations/pressure.py``: ``y' = A2 E (gamma - beta C)``, so with the
    state ``s = A0 C + A1 ln C`` (``s' = eps y'``)::

        s' = A2 D g0 (1 - b0 (C - 1)),   D' = C - 1,   Q' = P(y) z / A2,   Q(-1) = 0

    ``g0 = 1 - beta (1 + A3)``, ``b0 = beta/g0``, ``P`` the closed-form pressure
    (:func:`ipmc_asym.kernels.pressure.pressure_of_y`, ``p = P/A2 + const``).  The Boltzmann
    relation is no longer ``Ya = Yc - A2``: both face values are parameters ``(b, a)``
    (``ln C`` at the cathode and the anode), with the voltage condition
    ``V(b) - V(a) = A2`` (:func:`ipmc_asym.kernels.pressure.volt_of_y`) as the fifth boundary
    condition.  For ``A1 = 0`` (linear model) ``Q`` carries ``P - A3 y/gamma`` (bounded at the
    anode) and ``int y z dz`` is added after the solve (:func:`moment_y_linear`).
    """

    def __init__(self, g: Groups, beta: float):
        from ipmc_asym.kernels.pressure import pressure_groups, pressure_of_y, volt_of_y  # deferred: Numba compile

        self.A0, self.A1, self.A2, self.A3 = g.A0, g.A1, g.A2, g.A3
        self.beta = float(beta)
        self.g0, self.b0 = pressure_groups(self.beta, g.A3)
        self.gamma = self.g0 * (1.0 + self.b0)
        self._p = pressure_of_y
        self._v = volt_of_y

    def S(self, y):
        return self.A0 * expc(y) + self.A1 * y

    def C_y(self, s):
        if self.A1 == 0.0:
            C = np.maximum(s / self.A0, TINY)
            return C, np.log(C)
        y = y_of_s(s, self.A0, self.A1)
        return expc(y), y

    def pq(self, y):
        """``P(y)``, or ``P(y) - A3 y/gamma`` for the linear model (bounded at the anode)."""
        y = np.atleast_1d(np.asarray(y, dtype=float))
        P = self._p(np.ascontiguousarray(y), self.A3, self.b0, self.g0, np.empty(y.size))
        return P - self.A3 * y / self.gamma if self.A1 == 0.0 else P

    def fun(self, z, u, p):
        s, D = u[0], u[1]
        C, y = self.C_y(s)
        fac = self.g0 * (1.0 - self.b0 * (C - 1.0))
        return np.vstack((self.A2 * D * fac, C - 1.0, self.pq(y) * z / self.A2))

    def fun_jac(self, z, u, p):
        s, D = u[0], u[1]
        n = s.size
        C, y = self.C_y(s)
        eps = self.A0 * C + self.A1
        dC = C / eps if self.A1 > 0.0 else np.full(n, 1.0 / self.A0)
        den = 1.0 - self.b0 * (C - 1.0)
        J = np.zeros((3, 3, n))
        J[0, 0] = -self.A2 * D * self.g0 * self.b0 * dC
        J[0, 1] = self.A2 * self.g0 * den
        J[1, 0] = dC
        if self.A1 > 0.0:
            dq = (C + self.A3) / (self.g0 * den) / eps
        else:  # d(P - A3 y/gamma)/dy = C (gamma + A3 beta)/(gamma g0 den); dy/ds = 1/(A0 C)
            dq = (self.gamma + self.A3 * self.beta) / (self.gamma * self.g0 * den * self.A0)
        J[2, 0] = dq * z / self.A2
        return J, np.zeros((3, 2, n))

    def _dv(self, y):
        return 1.0 / (self.g0 * (1.0 - self.b0 * math.expm1(y)))

    def bc(self, ua, ub, p):
        b, a = p
        return np.array([ua[0] - self.S(a), ub[0] - self.S(b), ub[1] - ua[1], ua[2],
                         self._v(b, self.b0, self.g0) - self._v(a, self.b0, self.g0) - self.A2])

    def bc_jac(self, ua, ub, p):
        b, a = p
        Ja = np.zeros((5, 3))
        Jb = np.zeros((5, 3))
        Jp = np.zeros((5, 2))
        Ja[0, 0] = 1.0
        Jp[0, 1] = -(self.A0 * math.exp(min(a, EXP_MAX)) + self.A1)
        Jb[1, 0] = 1.0
        Jp[1, 0] = -(self.A0 * math.exp(min(b, EXP_MAX)) + self.A1)
        Jb[2, 1] = 1.0
        Ja[2, 1] = -1.0
        Ja[3, 2] = 1.0
        Jp[4, 0] = self._dv(b)
        Jp[4, 1] = -self._dv(a)
        return Ja, Jb, Jp

    def eps_of_C(self, C):
        return self.A0 * C + self.A1

    def state_from_sD(self, z, s, D):
        """``(s, D, Q)`` with ``Q`` integrated from ``s`` (trapezoid; an initial guess)."""
        _, y = self.C_y(s)
        return np.vstack((s, D, cumtrapz(self.pq(y) * z / self.A2, z)))
