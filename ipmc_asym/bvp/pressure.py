"""The BVP with the pressure term of the Nernst-Planck law (cross-check of the ``exact`` rung).

:class:`ipmc_asym.bvp.problems.PressureProblem` solved by ``scipy.integrate.solve_bvp`` from
the paper's solution (:func:`ipmc_asym.bvp.solver.solve`, same mesh) as the initial guess,
with continuation in ``beta`` where the direct solve fails.  Negative voltage: the mirror
image (``I`` odd in the voltage).  Derivation: ``derivations/pressure.py``.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, replace

import numpy as np

from ipmc_asym.base.settings import BVP_MAX_NODES_FIRST, BVP_TOL
from ipmc_asym.bvp.problems import PressureProblem, moment_y_linear
from ipmc_asym.bvp.solver import solve
from ipmc_asym.model.params import NAFION_LI, Material, Strip, check_finite

__all__ = ["PressureBVPResult", "solve_pressure"]


@dataclass
class PressureBVPResult:
    """BVP solution with the pressure term, at ``|phi0|`` (positive frame) except ``I``.

    Attributes
    ----------
    I : float       moment integral ``int p z dz`` (signed like the voltage)
    B1 : float      ``C(1)/C_moy`` at ``|phi0|`` (cathode)
    c_anode : float ``C(-1)/C_moy`` at ``|phi0|``
    D1 : float      face induction ``D(1)/(e phi4 F C_moy)``
    beta : float
    success : bool
    message : str
    z, C, D : ndarray   mesh and profiles (positive frame)
    """

    I: float
    B1: float
    c_anode: float
    D1: float
    beta: float
    success: bool
    message: str
    z: np.ndarray
    C: np.ndarray
    D: np.ndarray


def _run(prob, z, U, p, tol, max_nodes):
    from scipy.integrate import solve_bvp  # deferred: scipy.integrate's BVP

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            return solve_bvp(prob.fun, prob.bc, z, U, p=np.asarray(p, float), fun_jac=prob.fun_jac,
                             bc_jac=prob.bc_jac, tol=tol, bc_tol=tol, max_nodes=max_nodes, verbose=0)
        except (FloatingPointError, np.linalg.LinAlgError, OverflowError, ValueError):
            return None


def solve_pressure(strip: Strip, model="constant", material: Material = NAFION_LI, *, beta: float,
                   tol: float = BVP_TOL, max_nodes: int = BVP_MAX_NODES_FIRST) -> PressureBVPResult:
    """Solve the BVP with the pressure term (``beta = (v1 - M1 v2/M2) C_moy``).

    Parameters
    ----------
    strip : Strip   geometry and voltage (SI, TOTAL thickness 2e)
    model : str or Permittivity   one of the paper's models (``eps = A0 C + A1``)
    material : Material
    beta : float    dimensionless, ``(v1 - M1 v2/M2) C_moy``
    tol : float     solve_bvp tolerance

    Returns
    -------
    PressureBVPResult   ``success=False`` where no converged solution was found.
    """
    beta = check_finite("beta", beta, "a finite number")
    v = strip.voltage
    sgn = math.copysign(1.0, v) if v != 0.0 else 0.0
    if v == 0.0:
        z = np.linspace(-1.0, 1.0, 3)
        return PressureBVPResult(0.0, 1.0, 1.0, 0.0, beta, True, "zero voltage", z, np.ones(3), np.zeros(3))
    base = solve(strip.with_(voltage=abs(v)), model, material, tol=tol)
    g = base.groups
    g = replace(g, sign=1.0)
    fail = PressureBVPResult(math.nan, math.nan, math.nan, math.nan, beta, False, "", base.z, base.C, base.D)
    if not base.success:
        fail.message = f"the paper's BVP (the initial guess) did not converge: {base.message}"
        return fail
    z = base.z
    U = base.sol(z)
    b = math.log(base.B1)
    p = np.array([b, b - g.A2])
    res = None
    steps = 1
    while steps <= 16:
        ok = True
        zc, Uc, pc = z, U, p
        for k in range(1, steps + 1):
            prob = PressureProblem(g, beta * k / steps)
            U0 = prob.state_from_sD(zc, Uc[0], Uc[1])
            r = _run(prob, zc, U0, pc, tol, max_nodes)
            if r is None or r.status != 0:
                ok = False
                break
            zc, Uc, pc = r.x, r.y, r.p
        if ok:
            res = r
            break
        steps *= 4
    if res is None:
        fail.message = "solve_bvp with the pressure term did not converge (continuation in beta up to 16 steps)"
        return fail
    b, a = float(res.p[0]), float(res.p[1])
    I = float(res.y[2, -1])
    if g.A1 == 0.0:  # int y z dz after the solve: the anode's log singularity (moment_y_linear)
        gl = replace(g, A2=b - a)  # C(-1) = exp(b - A2') = e^a
        C_a = math.exp(a)
        D_a = float(res.y[1, 0])
        # moment_y_linear takes C'(-1) = A2' D_a'/A0; here C'(-1) = A2 D_a g0 (1 - b0 (C_a - 1))/A0
        D_eff = g.A2 * D_a * prob.g0 * (1.0 - prob.b0 * (C_a - 1.0)) / gl.A2
        I += g.A3 / (prob.gamma * g.A2) * moment_y_linear(res.sol, res.x, gl, b, D_eff)
    C, _ = prob.C_y(res.y[0])
    return PressureBVPResult(sgn * I, math.exp(b), math.exp(a), float(res.y[1, -1]), beta, True,
                             f"converged ({steps} beta step(s))", res.x, C, res.y[1])
