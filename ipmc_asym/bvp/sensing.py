"""The through-thickness BVP of a bent strip at rest (cross-check of the sensing rungs).

``derivations/sensing.py`` states the problem: with ``x = z/e``, ``y = ln(C/C_moy_0)`` and the
face-value scaling ``D_bar = D/(e phi4_0 F C_moy_0)`` (eq (22)), Gauss (1), (20) with the
z-dependent solution fraction and fixed charge, and Boltzmann (19) read

    y' = D_bar/(lam^2 eps_hat(C)),   D_bar' = f(x) e^y - h(x),
    f = phi4(x)/phi4_0 = (phi4_0 + t)/(phi4_0 (1 + t)),  h = f c_m = 1/(1 + t),  t = -phi4_0 b x,

``eps_hat = rho0 + (1 - rho0) C/C_moy_0`` (eq (16)).  Short circuit: ``y(-1) = y(1) = y0`` (the
potential ``psi = y0 - y`` is 0 on both electrodes; ``y0`` a parameter) and (21)
``D_bar(1) = D_bar(-1)``; open circuit: ``D_bar(+-1) = 0``.  The unknowns are scaled by the
amplitude ``b`` (``Y = y/b``, ``U = D_bar/(lam b)``) so that solve_bvp's tolerance is relative
to the response, and the mesh is the actuation BVP's graded mesh
(:func:`ipmc_asym.bvp.mesh.make_mesh`) with first spacings a fraction of the Debye length.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np

from ipmc_asym.bvp.mesh import make_mesh

__all__ = ["SenseBVPResult", "solve_sensing", "SENSE_BVP_TOL"]

#: solve_bvp tolerance of the scaled problem (relative to the response: the unknowns are O(1))
SENSE_BVP_TOL = 1e-8


@dataclass
class SenseBVPResult:
    """``sigma_hat = sigma/S`` (short circuit, face ``-e``) or ``v_hat = V_oc F/(R T)`` (open circuit).

    Attributes
    ----------
    value : float   sigma_hat or v_hat
    success : bool
    message : str
    x, y, D : ndarray   mesh, ``ln(C/C_moy_0)`` and ``D_bar`` (unscaled)
    """

    value: float
    success: bool
    message: str
    x: np.ndarray
    y: np.ndarray
    D: np.ndarray


def _stable_ratio(x, lam, fn):
    """``sinh(x/lam)/sinh(1/lam)`` (fn='s') or ``cosh(x/lam)/sinh(1/lam)`` (fn='c') without overflow."""
    ax = np.abs(x)
    e1 = np.exp((ax - 1.0) / lam)
    num = -np.expm1(-2.0 * ax / lam) if fn == "s" else 1.0 + np.exp(-2.0 * ax / lam)
    val = e1 * num / (-math.expm1(-2.0 / lam))
    return np.sign(x) * val if fn == "s" else val


def solve_sensing(b: float, lam: float, rho0: float, phi4: float, *, load: str = "short",
                  tol: float = SENSE_BVP_TOL, max_nodes: int = 200000) -> SenseBVPResult:
    """Solve the bent strip's BVP at ``b = (1 - 2 nu) kappa e/phi4_0`` (``|b| < 1``), ``lam = lambda_D/e``."""
    from scipy.integrate import solve_bvp  # deferred: scipy.integrate's BVP

    if b == 0.0:
        x = np.linspace(-1.0, 1.0, 3)
        return SenseBVPResult(0.0, True, "no curvature", x, np.zeros(3), np.zeros(3))
    a = b
    h0 = 0.02 * lam
    x = make_mesh(h0, h0, ratio=1.08, h_core=0.02)
    # initial guess: the linear (Debye-Hueckel) solution of derivations.sensing:linear_solution
    if load == "short":
        Y = x - _stable_ratio(x, lam, "s")
        U = lam - _stable_ratio(x, lam, "c")
    else:
        th = math.tanh(1.0 / lam)
        Y = x - lam * _stable_ratio(x, lam, "s") * th
        U = lam - lam * _stable_ratio(x, lam, "c") * th
        U = lam * (1.0 - _stable_ratio(x, lam, "c") * th)

    def parts(xx, Yv):
        t = -phi4 * b * xx
        f = (phi4 + t) / (phi4 * (1.0 + t))
        cm1 = -t / (phi4 + t)  # c_m - 1, formed without cancellation
        ey = np.exp(a * Yv)
        eps = rho0 + (1.0 - rho0) * ey
        return f, cm1, ey, eps

    def fun(xx, S, p=None):
        f, cm1, ey, eps = parts(xx, S[0])
        return np.vstack((S[1] / (lam * eps), f * (np.expm1(a * S[0]) - cm1) / (lam * a)))

    def jac(xx, S, p=None):
        f, cm1, ey, eps = parts(xx, S[0])
        J = np.zeros((2, 2, xx.size))
        J[0, 0] = -S[1] * (1.0 - rho0) * a * ey / (lam * eps * eps)
        J[0, 1] = 1.0 / (lam * eps)
        J[1, 0] = f * ey / lam
        if p is None:
            return J
        return J, np.zeros((2, 1, xx.size))

    with warnings.catch_warnings(), np.errstate(all="ignore"):
        warnings.simplefilter("ignore")
        try:
            if load == "short":
                def bc(Sa, Sb, p):
                    return np.array([Sa[0] - p[0], Sb[0] - p[0], Sb[1] - Sa[1]])

                def bcj(Sa, Sb, p):
                    return (np.array([[1.0, 0.0], [0.0, 0.0], [0.0, -1.0]]),
                            np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]),
                            np.array([[-1.0], [-1.0], [0.0]]))

                r = solve_bvp(fun, bc, x, np.vstack((Y, U)), p=np.array([0.0]), fun_jac=jac, bc_jac=bcj,
                              tol=tol, bc_tol=tol, max_nodes=max_nodes)
            else:
                def bc(Sa, Sb):
                    return np.array([Sa[1], Sb[1]])

                def bcj(Sa, Sb):
                    return np.array([[0.0, 1.0], [0.0, 0.0]]), np.array([[0.0, 0.0], [0.0, 1.0]])

                r = solve_bvp(fun, bc, x, np.vstack((Y, U)), fun_jac=jac, bc_jac=bcj,
                              tol=tol, bc_tol=tol, max_nodes=max_nodes)
        except (FloatingPointError, np.linalg.LinAlgError, OverflowError, ValueError) as exc:
            return SenseBVPResult(math.nan, False, f"solve_bvp failed: {exc}", x, Y * a, U * lam * a)
    if r.status != 0 or not np.all(np.isfinite(r.y)):
        return SenseBVPResult(math.nan, False, r.message, r.x, r.y[0] * a, r.y[1] * lam * a)
    if load == "short":
        value = a * float(r.y[1, 0])  # sigma/S = D_bar(-1)/lam
    else:
        value = a * float(r.y[0, -1] - r.y[0, 0])  # V_oc F/RT = psi(-1) - psi(1) = y(1) - y(-1)
    return SenseBVPResult(value, True, "converged", r.x, r.y[0] * a, r.y[1] * lam * a)
