"""Static electrode charge and differential capacitance at every fidelity, and the core's RC.

The charge itself is evaluated by :mod:`ipmc_asym.integral.charge` (the integral layer, over
the compiled drivers of :mod:`ipmc_asym.kernels.charge`; re-exported here):
:func:`charge` at one rung, :func:`charge_escalated` at the cheapest valid rung (the ladder of
:func:`ipmc_asym.base.ladder.climb`).  Here: the inverse ``V(sigma)`` (:func:`layer_voltage`),
the core resistance and the linear time constant ``tau = R C_d(0)``.  Thickness is the TOTAL
``2e``; SI throughout.
"""

from __future__ import annotations

import numpy as np

from ipmc_asym.base.ladder import climb, rungs_from
from ipmc_asym.base.registry import fidelity_names
from ipmc_asym.base.settings import VALIDITY_LIMIT
from ipmc_asym.forward.estimate import SPREAD_NOTE, model_list, spread_variants
from ipmc_asym.forward.model import voltage_reason
from ipmc_asym.integral.api import check_fidelity
from ipmc_asym.integral.charge import (
    SUBNORMAL,
    ChargeResult,
    accurate,
    capacitance_scale,
    charge,
    charge_at,
    charge_inputs,
    charge_scale,
)
from ipmc_asym.kernels.charge import CLOSED_TRUNCATION, charge_hat_point
from ipmc_asym.model import groups
from ipmc_asym.model.params import NAFION_LI, Material
from ipmc_asym.model.permittivity import MODELS, get_model
from ipmc_asym.model.spread import spread_of

__all__ = ["ChargeResult", "charge", "layer_voltage", "core_resistance", "time_constant", "charge_scale",
           "capacitance_scale", "charge_hat_point",
           "charge_escalated", "charge_report", "CHARGE_NOTE", "CLOSED_TRUNCATION"]


def charge_escalated(thickness: float, voltage: float, model="constant", fidelity="corrected", **kw) -> ChargeResult:
    """:func:`charge` of one point at the cheapest VALID rung from ``fidelity`` up the registry's ladder.

    Same arguments as :func:`charge` (scalars); the result's ``fidelity`` names the rung used.
    A rung is climbed for accuracy only: beyond the validated voltage the result is kept with
    ``check_voltage = valid = False``; where ``sigma`` or ``Q`` is subnormal (``|phi0|`` below
    ~1e-300 V) no rung helps, and the first rung's result is returned with its rounding in
    ``error`` (``valid = False`` once that passes ``VALIDITY_LIMIT``).  Raises ``ValueError``
    (one line) where no rung from ``fidelity`` up is accurate otherwise.
    """
    check_fidelity(fidelity)
    args = charge_inputs(thickness, voltage, model, **kw)  # checked once; every rung trusts them

    def checks(f, r, idx):
        if bool(accurate(r.error, r.error_C_diff)):
            return True, ""
        if float(voltage) != 0.0 and min(abs(float(r.sigma)), abs(float(r.Q))) < SUBNORMAL:
            # no rung helps: the value itself is below the normal range of a double; its
            # rounding is the stated error (sigma -> C_d(0) phi0 down to the subnormals)
            return True, ""
        return False, f"error estimates {float(r.error):.2g} / {float(r.error_C_diff):.2g}"

    lad = climb(rungs_from(fidelity_names(), fidelity), lambda f, idx: charge_at(*args, f), checks)
    if lad.left.size:
        raise ValueError(lad.message(f"thickness (total 2e) {float(thickness):.3g} m, voltage {float(voltage):.3g} V "
                                     f"(model {args[2].name})"))
    return lad.last.result


#: what the outputs of :func:`charge_report` are (the note of ``ipmc-asym charge``)
CHARGE_NOTE = ("sigma: charge per area of the face z = -e where phi0 is applied (the other face carries -sigma); "
               "Q = sigma * 2l * L; C_diff = dsigma/dphi0 per area; eps_app = C_diff * 2e (TOTAL thickness), "
               "what a parallel-plate reading of a capacitance measurement would give")

#: the charge outputs that depend on the permittivity model (and C_moy)
_SPREAD_KEYS = ("sigma", "Q", "C_diff", "eps_app")


def charge_report(strip, material: Material = NAFION_LI, model: str = "all", fidelity: str = "corrected") -> dict:
    """All of ``ipmc-asym charge --json``: ``{"inputs", "results", "notes", "warnings", "model_spread"}``.

    ``results``: one row per model of ``model`` (a name or ``"all"``) at the cheapest valid rung
    from ``fidelity`` (:func:`charge_escalated`); ``warnings``: beyond the validated voltage,
    and rows whose error estimate is above ``VALIDITY_LIMIT`` (kept, ``valid = false``);
    ``model_spread``: the range of each output over the paper's three models (and C_moy paper
    / formula for the paper's sets) beside the numerical error.  ``strip`` and ``material``
    are built objects (checked when built).
    """
    models = model_list(model)
    variants = spread_variants(material)
    beyond = voltage_reason(strip.voltage)
    # every point the report needs, the rows first, then each model and C_moy form of the spread
    # not among them: one evaluation each
    jobs = [(m, material) for m in models]
    labels = []
    for cm, mat in variants:
        for m in MODELS:
            labels.append(m if cm is None else f"{m}/{cm}")
            if not (m in models and mat.c_moy == material.c_moy):
                jobs.append((m, mat))
    got = [charge_escalated(strip.thickness, strip.voltage, m, fidelity, width=strip.width, length=strip.length,
                            material=mat) for m, mat in jobs]
    rows = []
    for m, r in zip(models, got):
        rows.append({"model": m, "fidelity": fidelity, "fidelity_used": r.fidelity,
                     "escalated": r.fidelity != fidelity, "sigma": float(r.sigma), "Q": float(r.Q),
                     "C_diff": float(r.C_diff), "eps_app": float(r.eps_app), "error_estimate": float(r.error),
                     "error_estimate_C_diff": float(r.error_C_diff), "check_voltage": bool(r.check_voltage),
                     "valid": bool(r.valid)})
    warnings = []
    if not all(r["check_voltage"] for r in rows):
        warnings.append(beyond)
    inaccurate = [r["model"] for r in rows if r["check_voltage"] and not r["valid"]]
    if inaccurate:
        warnings.append(f"{', '.join(inaccurate)}: relative error estimate above {VALIDITY_LIMIT:g} (sigma or Q "
                        f"subnormal at {strip.voltage:g} V: doubles round it); kept, flagged valid = false")
    done = {r["model"]: r for r in rows}
    extra = iter(got[len(models):])
    out = {}
    for (cm, mat), block in zip(variants, [labels[i:i + len(MODELS)] for i in range(0, len(labels), len(MODELS))]):
        for m, label in zip(MODELS, block):
            if m in done and mat.c_moy == material.c_moy:
                out[label] = done[m]
                continue
            c = next(extra)
            out[label] = {"sigma": float(c.sigma), "Q": float(c.Q), "C_diff": float(c.C_diff),
                          "eps_app": float(c.eps_app), "error_estimate": float(c.error),
                          "error_estimate_C_diff": float(c.error_C_diff)}
    err = max(max(r["error_estimate"], r["error_estimate_C_diff"]) for r in out.values())
    over = ["permittivity model: " + ", ".join(MODELS)]
    if len(variants) > 1:
        over.append("C_moy: paper and formula (eq. (17))")
    spread = {"over": over, "variants": list(out),
              "quantities": {k: spread_of({lab: r[k] for lab, r in out.items()}, err) for k in _SPREAD_KEYS},
              "note": SPREAD_NOTE}
    inputs = {"length": strip.length, "width_total": strip.width, "thickness_total": strip.thickness,
              "half_thickness_e": strip.e, "voltage": strip.voltage, "c_moy": material.C_moy}
    return {"inputs": inputs, "results": rows, "notes": [CHARGE_NOTE], "warnings": warnings, "model_spread": spread}


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

