"""Static electrode charge and differential capacitance at every fidelity, and the core's RC.

The charge itself is evaluated by :mod:`ipmc_asym.integral.charge` (the integral layer, over
the compiled drivers of :mod:`ipmc_asym.kernels.charge`; re-exported here):
:func:`charge` at one rung, :func:`charge_escalated` at the cheapest valid rung (the ladder of
:func:`ipmc_asym.base.ladder.climb`); the report of ``ipmc-asym charge`` is
:func:`ipmc_asym.forward.charge.charge_report` (re-exported here).  Here: the inverse ``V(sigma)`` (:func:`layer_voltage`),
the core resistance and the linear time constant ``tau = R C_d(0)``.  Thickness is the TOTAL
``2e``; SI throughout.
"""

from __future__ import annotations

import numpy as np

from ipmc_asym.forward.charge import CHARGE_NOTE, charge_report
from ipmc_asym.integral.charge import (
    ChargeResult,
    capacitance_scale,
    charge,
    charge_escalated,
    charge_scale,
)
from ipmc_asym.kernels.charge import CLOSED_TRUNCATION, charge_hat_point
from ipmc_asym.model import groups
from ipmc_asym.model.params import NAFION_LI, Material
from ipmc_asym.model.permittivity import get_model

__all__ = ["ChargeResult", "charge", "layer_voltage", "core_resistance", "time_constant", "charge_scale",
           "capacitance_scale", "charge_hat_point",
           "charge_escalated", "charge_report", "CHARGE_NOTE", "CLOSED_TRUNCATION"]


def layer_voltage(sigma, model="constant", material: Material | None = None):
    """``V(sigma)``: the static voltage at which the electrode charge is ``sigma`` (C/m^2), vectorised.

    Newton on the closed form from ``V = 0`` (``sigma(V)`` is increasing and concave for
    ``V > 0``, so the iterates increase monotonically onto the root); odd in ``sigma``.
    Raises ``ValueError`` where ``|sigma|`` exceeds the saturation charge of the linear model.
    """
    perm = get_model(model)
    mat = NAFION_LI if material is None else material
    sg = np.asarray(sigma, dtype=float)
    target = np.abs(sg)
    if perm.eps0 == 0.0 and np.any(target >= charge_scale(perm, mat)):
        raise ValueError("sigma must be below the saturation charge S of the linear model")
    x = np.zeros_like(target)
    for _ in range(100):
        r = charge(1.0, x, perm, "corrected", material=mat)
        dx = (target - r.sigma) / r.C_diff
        x = x + dx
        if np.all(np.abs(dx) <= 1e-14 * (1.0 + np.abs(x))):
            break
    return np.sign(sg) * x


def core_resistance(thickness, material: Material = NAFION_LI):
    """``R = 2e/kappa`` (Ohm m^2), ``kappa = phi4 F^2 D C_moy/(R T)`` (S/m); thickness TOTAL 2e."""
    return np.asarray(thickness, dtype=float) / groups.kappa(material)


def time_constant(thickness, model="constant", material: Material = NAFION_LI):
    """``tau = R C_d(0) = e lambda_D / D`` (s); thickness TOTAL 2e."""
    perm = get_model(model)
    return core_resistance(thickness, material) * 0.5 * capacitance_scale(perm, material)

