"""Static sensing response at a local curvature, over the fidelity ladder.

Derivation: ``derivations/sensing.py`` (generated into :mod:`ipmc_asym.kernels._generated_sensing`;
point kernels :mod:`ipmc_asym.kernels.sensing`, BVP :mod:`ipmc_asym.bvp.sensing`).  For a local
curvature ``kappa`` (``eps_xx = -kappa z``) the relaxed strip carries, per unit electrode area,
the short-circuit charge ``sigma`` of the face ``z = -e`` and, open, the voltage
``V_oc = phi(-e) - phi(e)``:

* ``b = (1 - 2 nu) kappa e/phi4`` (``nu`` the drained Poisson ratio, plane stress in the width);
* rung ``leading``: ``sigma = -S b (coth(1/lam) - lam)``, ``V_oc = (RT/F) 2 b (1 - lam tanh(1/lam))``
  (linear in ``kappa``, exact in ``lam``), error ``2 |c3| b^2 (1 + lam)``;
* rung ``exact``: the nonlinear layer balance with the Donnan core, every order in ``b``
  (``V_oc = (RT/F) 2 artanh(b) (...)``: the Donnan difference as ``lam -> 0``);
* rung ``bvp``: scipy's solve_bvp of the through-thickness problem with ``C_moy(z)``.

The requested fidelities ``corrected`` and ``quadrature`` have no sensing counterpart: the
closed form is exact in ``lam``, so they start the climb at ``exact``.  The pressure term of
Nernst-Planck (paper eq (5)) is held at linear order only (``leading``): ``F/RT -> g0 F/RT``,
``lam -> lam/sqrt(g0)`` (``derivations.sensing:reciprocity_ratio``); its error bound is the
paper model's cubic term (the cubic term with the pressure term is not derived).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ipmc_asym.base.ladder import climb, rungs_from
from ipmc_asym.base.settings import VALIDITY_LIMIT
from ipmc_asym.kernels.sensing import sense_point
from ipmc_asym.model import groups
from ipmc_asym.model.params import Material
from ipmc_asym.model.permittivity import Permittivity

__all__ = ["SENSE_RUNGS", "SenseHat", "sense_hat", "strain_parameter", "charge_scale_sensing", "B_LIMIT"]

#: the sensing ladder, cheapest first
SENSE_RUNGS = ("leading", "exact", "bvp")
#: ``|b| < 1`` or a face of the strip would lose all its solution (phi4 -> 0): no state exists
B_LIMIT = 1.0
#: stated error of the BVP rung (solve_bvp's tolerance on the response-scaled unknowns, 10x)
BVP_SENSE_ERROR = 1e-7


@dataclass
class SenseHat:
    """Per point: ``sigma/S``, ``V_oc F/RT``, their error estimates and the rung used."""

    sigma_hat: np.ndarray
    v_hat: np.ndarray
    error: np.ndarray
    error_v: np.ndarray
    used: np.ndarray
    valid: np.ndarray
    message: str


def strain_parameter(curvature, thickness, nu: float, material: Material):
    """``b = (1 - 2 nu) kappa e/phi4`` (``derivations.sensing:face_ratios``), e = thickness/2."""
    return (1.0 - 2.0 * nu) * np.asarray(curvature, float) * 0.5 * np.asarray(thickness, float) / material.phi4


def charge_scale_sensing(perm: Permittivity, material: Material) -> float:
    """``S = sqrt(phi4 C_moy eps_core R T)`` (C/m^2), the actuation's charge scale (derivations/charge.py)."""
    m = material
    return math.sqrt(m.phi4 * m.C_moy * perm.eps_moy * m.R * m.T)


def _first_rung(fidelity: str) -> str:
    return {"corrected": "exact", "quadrature": "exact"}.get(fidelity, fidelity)


def sense_hat(b, lam, perm: Permittivity, material: Material, fidelity: str = "leading", tol=None,
              escalate: bool = True, g0: float | None = None) -> SenseHat:
    """The hats at flat arrays ``b``, ``lam`` (``|b| < 1``, checked by the caller), climbing the ladder.

    ``g0``: the pressure term's ``1 - beta (1 + A3)`` (None: the paper's model).
    """
    b = np.ascontiguousarray(np.asarray(b, float).reshape(-1))
    lam = np.ascontiguousarray(np.broadcast_to(np.asarray(lam, float), b.shape).copy())
    rho0 = perm.eps0 / perm.eps_moy
    limit = VALIDITY_LIMIT if tol is None else min(tol, VALIDITY_LIMIT)
    n = b.size

    def evaluate(rung, idx):
        out = np.empty((4, idx.size))
        if rung == "leading":
            for k, i in enumerate(idx):
                if g0 is None:
                    out[:, k] = sense_point(b[i], lam[i], rho0, material.phi4, 1)
                else:  # linear order with the pressure term: lam -> lam/sqrt(g0), RT/F -> RT/(F g0)
                    lb = lam[i] / math.sqrt(g0)
                    s, v, es, ev = sense_point(b[i], lb, rho0, material.phi4, 1)
                    out[:, k] = (s / math.sqrt(g0), v / g0, es, ev)
            return out
        if rung == "exact":
            for k, i in enumerate(idx):
                out[:, k] = sense_point(b[i], lam[i], rho0, material.phi4, 3)
            return out
        from ipmc_asym.bvp.sensing import solve_sensing  # deferred: scipy.integrate's BVP

        for k, i in enumerate(idx):
            rs = solve_sensing(b[i], lam[i], rho0, material.phi4, load="short")
            ro = solve_sensing(b[i], lam[i], rho0, material.phi4, load="open")
            ok = rs.success and ro.success
            out[:, k] = (rs.value, ro.value, BVP_SENSE_ERROR if ok else math.inf, BVP_SENSE_ERROR if ok else math.inf)
        return out

    def checks(rung, res, idx):
        ok = (res[2] <= limit) & (res[3] <= limit)
        if np.all(ok):
            return ok, ""
        j = int(np.argmin(ok))
        return ok, f"error estimate {max(res[2, j], res[3, j]):.2g} > {limit:.2g} at b = {b[idx[j]]:.3g}"

    # the pressure term is held at linear order only: its one rung whatever was requested (the
    # cheaper rung is the only one there is; its error bound says how far it holds)
    rungs = ("leading",) if g0 is not None else rungs_from(SENSE_RUNGS, _first_rung(fidelity), escalate)
    lad = climb(rungs, evaluate, checks, n)
    sig = np.full(n, np.nan)
    v = np.full(n, np.nan)
    err = np.full(n, np.inf)
    errv = np.full(n, np.inf)
    for s in lad.steps:
        # in order: a point's valid rung is its last one; where none is valid the last rung tried
        # is kept (the number is kept and flagged, as everywhere)
        sig[s.idx], v[s.idx], err[s.idx], errv[s.idx] = s.result
    used = lad.used()
    return SenseHat(sig, v, err, errv, used, lad.valid,
                    lad.message(f"b = {b[lad.left[0]]:.3g}" if lad.left.size else ""))


def debye_length(thickness, perm: Permittivity, material: Material):
    """``lam = lambda_D/e`` of the core at rest (:func:`ipmc_asym.model.groups.debye_length`)."""
    return np.asarray(groups.debye_length(thickness, perm.eps_moy, material), float)
