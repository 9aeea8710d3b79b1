"""From strip + material + model to the mechanical outputs (``ipmc-asym estimate``).

``M_A = A5 I`` (paper sections 3-4, ``A5 = 6 l e^2 F |phi0| C_moy``), then the beam
(:mod:`ipmc_asym.beam`).  Signs as in the paper: a positive voltage gives ``M_A > 0``,
``theta < 0`` and ``w < 0``.
"""

from __future__ import annotations

import time

import numpy as np

from .integral import check_fidelity, moment
from .params import NAFION_LI, Material, Strip
from .permittivity import MODELS, get_model

__all__ = ["evaluate", "estimate_rows", "RESULT_KEYS"]

RESULT_KEYS = ("model", "fidelity", "C_moy", "A0", "A1", "A2", "A3", "A5", "B1", "I", "M_A", "theta",
               "w", "w_small", "F_block", "F_block_small", "error_estimate", "seconds")


def _f(x):
    x = float(x)
    return x if np.isfinite(x) else None


def evaluate(strip: Strip, model="constant", fidelity="quadrature", material: Material = NAFION_LI,
             tol: float | None = None) -> dict:
    """One result row (SI units) for one strip and one permittivity model.

    ``tol`` (relative) is the accuracy the caller needs: it decides whether the small-
    displacement formulas count as "small" (``regime``), and a warning is added when the
    fidelity's error estimate exceeds it.

    Returns
    -------
    dict
        The keys of :data:`RESULT_KEYS` plus ``regime``, ``warnings``, ``x_tip``, ``y_tip``,
        ``debye_length`` (m), ``valid``; ``error_estimate`` is the relative error of ``I``
        (hence of ``M_A``, ``theta``, ``w_small``, ``F_block_small``).
    """
    from .beam import solve_beam

    check_fidelity(fidelity)
    perm = get_model(model)
    t0 = time.perf_counter()
    g = perm.groups(strip, material)
    r = moment(strip.thickness, strip.voltage, perm, fidelity, material=material)
    I = float(r.I)
    M_A = g.A5 * I
    EI = material.E * strip.I_p
    beam = solve_beam(M_A, strip.length, EI, tol=tol, e=strip.e)
    warnings = list(beam.warnings)
    if tol is not None and float(r.error) > tol:
        warnings.append(
            f"error estimate {float(r.error):.2g} of fidelity {fidelity!r} exceeds --tol {tol:g}: "
            "use a higher fidelity (corrected, quadrature, bvp)"
        )
    if not bool(r.valid):
        warnings.append(
            f"fidelity {fidelity!r} outside its validity here (error estimate {float(r.error):.2g}, "
            f"neutral core {float(r.core):.3g} e): use a higher fidelity"
        )
    row = {
        "model": perm.name,
        "fidelity": fidelity,
        "C_moy": g.C_moy,
        "A0": g.A0,
        "A1": g.A1,
        "A2": g.A2,
        "A3": g.A3,
        "A5": g.A5,
        "B1": _f(r.B1),
        "I": I,
        "M_A": M_A,
        "theta": _f(beam.theta),
        "w": _f(beam.w),
        "w_small": _f(beam.w_small),
        "F_block": _f(beam.F_block),
        "F_block_small": _f(beam.F_block_small),
        "error_estimate": float(r.error),
        "seconds": time.perf_counter() - t0,
        "x_tip": _f(beam.x_tip),
        "y_tip": _f(beam.y_tip),
        "regime": str(beam.regime),
        "debye_length": float(r.lam) * strip.e,
        "valid": bool(r.valid),
        "warnings": warnings,
    }
    return row


def estimate_rows(strip: Strip, models=("constant", "linear", "affine"), fidelity="quadrature",
                  material: Material = NAFION_LI, tol=None) -> list[dict]:
    return [evaluate(strip, m, fidelity, material, tol) for m in models]


def model_list(name: str) -> list[str]:
    if name == "all":
        return list(MODELS)
    get_model(name)
    return [name]
