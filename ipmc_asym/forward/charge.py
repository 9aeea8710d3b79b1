"""The static charge report of ``ipmc-asym charge``: the electrode charge, differential
capacitance and apparent permittivity of one strip for each permittivity model, at the cheapest
valid rung (:func:`ipmc_asym.integral.charge.charge_escalated`), with the model-form spread
beside the numerical error.  Static, like the moment of :mod:`ipmc_asym.forward.estimate`: it
sits beside it, above the integral layer that evaluates it.
"""

from __future__ import annotations

from ipmc_asym.base.settings import VALIDITY_LIMIT
from ipmc_asym.forward.estimate import SPREAD_NOTE, model_list, spread_variants
from ipmc_asym.forward.model import model_notes, voltage_reason
from ipmc_asym.integral.charge import charge_escalated
from ipmc_asym.model.params import NAFION_LI, Material, Strip
from ipmc_asym.model.permittivity import MODELS
from ipmc_asym.model.spread import spread_of

__all__ = ["charge_report", "CHARGE_NOTE"]


#: what the outputs of :func:`charge_report` are (the note of ``ipmc-asym charge``)
CHARGE_NOTE = ("sigma: charge per area of the face z = -e where phi0 is applied (the other face carries -sigma); "
               "Q = sigma * 2l * L; C_diff = dsigma/dphi0 per area; eps_app = C_diff * 2e (TOTAL thickness), "
               "what a parallel-plate reading of a capacitance measurement would give")

#: the charge outputs that depend on the permittivity model (and C_moy)
_SPREAD_KEYS = ("sigma", "Q", "C_diff", "eps_app")


def charge_report(strip: Strip, material: Material = NAFION_LI, model: str = "all", fidelity: str = "corrected") -> dict:
    """All of ``ipmc-asym charge --json``: ``{"inputs", "results", "notes", "warnings", "model_spread"}``.

    ``results``: one row per model of ``model`` (a name or ``"all"``) at the cheapest valid rung
    from ``fidelity`` (:func:`charge_escalated`); ``warnings``: beyond the validated voltage,
    and rows whose error estimate is above ``VALIDITY_LIMIT`` (kept, ``valid = false``);
    ``model_spread``: the range of each output over the paper's three models (and C_moy paper
    / formula for the paper's sets) beside the numerical error.  ``strip`` and ``material``
    are built objects (checked when built).
    """
    models = model_list(model)
    notes = model_notes(strip.voltage, material, models)  # from the inputs alone
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
    def one(m, mat, spread_only):
        """``(result, None)``; a spread variant alone with no valid rung: ``(None, why)``, n/a in the
        spread (the caller's rows stand)."""
        try:
            return charge_escalated(strip.thickness, strip.voltage, m, fidelity, width=strip.width,
                                    length=strip.length, material=mat), None
        except ValueError as exc:
            if not spread_only:  # a row the caller asked for: refused, one line
                raise
            return None, str(exc)

    got = [one(m, mat, i >= len(models)) for i, (m, mat) in enumerate(jobs)]
    rows = []
    for m, (r, _) in zip(models, got):
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
            c, why = next(extra)
            if c is None:
                out[label] = dict.fromkeys(("sigma", "Q", "C_diff", "eps_app", "error_estimate",
                                            "error_estimate_C_diff"))
                warnings.append(f"model-form spread: {label} left out (n/a): {why}")
                continue
            out[label] = {"sigma": float(c.sigma), "Q": float(c.Q), "C_diff": float(c.C_diff),
                          "eps_app": float(c.eps_app), "error_estimate": float(c.error),
                          "error_estimate_C_diff": float(c.error_C_diff)}
    err = max(max(r["error_estimate"], r["error_estimate_C_diff"]) for r in out.values()
              if r["error_estimate"] is not None)
    over = ["permittivity model: " + ", ".join(MODELS)]
    if len(variants) > 1:
        over.append("C_moy: paper and formula (eq. (17))")
    spread = {"over": over, "variants": list(out),
              "quantities": {k: spread_of({lab: r[k] for lab, r in out.items()}, err) for k in _SPREAD_KEYS},
              "note": SPREAD_NOTE}
    inputs = {"length": strip.length, "width_total": strip.width, "thickness_total": strip.thickness,
              "half_thickness_e": strip.e, "voltage": strip.voltage, "c_moy": material.C_moy}
    return {"inputs": inputs, "results": rows, "notes": [CHARGE_NOTE] + notes, "warnings": warnings, "model_spread": spread}
