"""The moment integral with the pressure term of the Nernst-Planck law (option ``pressure_term``).

Two rungs hold it (``derivations/pressure.py``): ``exact`` (the compiled kernel
:func:`ipmc_asym.kernels.pressure.moment_pressure`, any thickness) and ``bvp``
(:func:`ipmc_asym.bvp.pressure.solve_pressure`); the closed forms of the ladder are built on the
paper's Boltzmann relation and do not.  ``beta = (v1 - M1 v2/M2) C_moy`` comes from the
material (:func:`ipmc_asym.model.groups.pressure_beta`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ipmc_asym.base.settings import BVP_STATED_ERROR, EXACT_STATED_ERROR
from ipmc_asym.model import groups
from ipmc_asym.model.params import NAFION_LI, Material, Strip
from ipmc_asym.model.permittivity import get_model

__all__ = ["PRESSURE_FIDELITIES", "PressureMoment", "moment_pressure_term"]

#: the rungs that hold the pressure term, cheapest first
PRESSURE_FIDELITIES = ("exact", "bvp")


@dataclass
class PressureMoment:
    """``I`` with the pressure term; flat arrays.

    Attributes
    ----------
    I : ndarray       signed like the voltage (NaN where the rung failed)
    error : ndarray   stated relative error bound (inf where it failed)
    B1 : ndarray      ``C(1)/C_moy`` at ``|phi0|``
    D1 : ndarray      face induction ``D(1)/(e phi4 F C_moy)`` at ``|phi0|``
    success : ndarray of bool
    beta : float
    message : str     why the first failed point failed ("" if none)
    """

    I: np.ndarray
    error: np.ndarray
    B1: np.ndarray
    D1: np.ndarray
    success: np.ndarray
    beta: float
    message: str


def moment_pressure_term(thickness, voltage, model="constant", fidelity="exact",
                         material: Material = NAFION_LI, *, beta=None) -> PressureMoment:
    """``I`` with the pressure term at each (thickness, voltage) (flat arrays, SI).

    Parameters
    ----------
    thickness, voltage : array_like   TOTAL thickness 2e (m), voltage (V), broadcast
    model : str or Permittivity       one of the paper's models (not a custom ``eps(C)``)
    fidelity : {"exact", "bvp"}
    material : Material
    beta : float, optional            default :func:`ipmc_asym.model.groups.pressure_beta`

    Raises
    ------
    ValueError   a fidelity without the pressure term, or a custom permittivity.
    """
    from ipmc_asym.kernels.pressure import moment_pressure  # deferred: Numba compile of the kernel

    if fidelity not in PRESSURE_FIDELITIES:
        raise ValueError(f"fidelity with the pressure term must be one of {', '.join(PRESSURE_FIDELITIES)}; "
                         f"got {fidelity!r}")
    perm = get_model(model)
    if perm.is_custom:
        raise ValueError("pressure_term: only the paper's permittivity models (eps = eps0 + deps C/C_moy)")
    th, v = np.broadcast_arrays(np.asarray(thickness, float), np.asarray(voltage, float))
    th, v = th.reshape(-1), v.reshape(-1)
    beta = float(groups.pressure_beta(material)) if beta is None else float(beta)
    n = th.size
    I, err, B1, D1 = (np.full(n, np.nan) for _ in range(4))
    err[:] = np.inf
    ok = np.zeros(n, bool)
    msg = ""
    eps_core = perm.eps0 + perm.deps
    lam = groups.debye_length(th, eps_core, material)
    A2 = groups.A2(v, material)
    A3 = float(groups.A3(material))
    rho = perm.eps0 / eps_core
    for i in range(n):
        if v[i] == 0.0:
            I[i], err[i], B1[i], D1[i], ok[i] = 0.0, 0.0, 1.0, 0.0, True
            continue
        if fidelity == "exact":
            r = moment_pressure(float(lam[i]), float(A2[i]), A3, rho, beta)
            if r[4] > 0 and math.isfinite(r[0]):
                I[i], B1[i], D1[i], err[i], ok[i] = math.copysign(r[0], v[i]), r[1], r[5], EXACT_STATED_ERROR, True
            elif not msg:
                msg = (f"exact with the pressure term: no solution found at thickness {th[i]:.3g} m, "
                       f"voltage {v[i]:.3g} V (face values or thickness constraint not met)")
        else:
            from ipmc_asym.bvp.pressure import solve_pressure  # deferred: scipy.integrate's BVP

            r = solve_pressure(Strip(thickness=float(th[i]), voltage=float(v[i])), perm, material, beta=beta)
            if r.success:
                I[i], B1[i], D1[i], err[i], ok[i] = r.I, r.B1, r.D1, BVP_STATED_ERROR, True
            elif not msg:
                msg = f"bvp with the pressure term: {r.message}"
    return PressureMoment(I=I, error=err, B1=B1, D1=D1, success=ok, beta=beta, message=msg)
