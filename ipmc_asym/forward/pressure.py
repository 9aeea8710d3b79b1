"""The fidelity ladder with the pressure term of the Nernst-Planck law (``pressure_term=True``).

Only ``exact`` and ``bvp`` hold the term (:data:`ipmc_asym.integral.pressure.PRESSURE_FIDELITIES`):
a cheaper requested rung starts the climb at ``exact``.  Same validity rule as
:func:`ipmc_asym.forward.escalation.moment_escalating`: finite ``I`` with an error bound
``<= min(tol, VALIDITY_LIMIT)``; both rungs hold at any thickness.
"""

from __future__ import annotations

import numpy as np

from ipmc_asym.base.ladder import climb, rungs_from
from ipmc_asym.forward.escalation import Climb, Escalated, flat_inputs, rung_reason, where_point
from ipmc_asym.integral.pressure import PRESSURE_FIDELITIES, moment_pressure_term
from ipmc_asym.model.params import NAFION_LI, Material
from ipmc_asym.model.request import Request

__all__ = ["moment_pressure_escalating", "pressure_ladder"]


def moment_pressure_escalating(thickness, voltage, model="constant", fidelity="exact",
                               material: Material = NAFION_LI, *, tol=None, escalate: bool = True) -> Escalated:
    """``I`` with the pressure term at the cheapest valid rung of ``exact``, ``bvp`` (flat arrays).

    Raises
    ------
    ValueError   ``escalate=False`` with a rung that does not hold the pressure term.
    """
    req = Request(model, fidelity, tol, escalate, pressure_term=True)
    th, v, shape = flat_inputs(thickness, voltage)
    return pressure_ladder(th, v, req, material, shape)


def pressure_ladder(th, v, req: Request, material: Material, shape=None) -> Escalated:
    """The climb of :func:`moment_pressure_escalating` on checked flat inputs (thickness floor
    held) and a :class:`~ipmc_asym.model.request.Request` (arrays reshaped to ``shape`` if given)."""
    fidelity, limit, perm = req.fidelity, req.limit, req.model
    shape = th.shape if shape is None else shape
    if fidelity not in PRESSURE_FIDELITIES:
        if not req.escalate:
            raise ValueError(f"pressure_term: fidelity {fidelity!r} does not hold the pressure term; use one of "
                             f"{', '.join(PRESSURE_FIDELITIES)} (or allow escalation)")
        fidelity = PRESSURE_FIDELITIES[0]
    rec = Climb(th.size)

    def checks(f, r, idx):
        with np.errstate(invalid="ignore"):
            ok = r.success & np.isfinite(r.I) & (r.error <= limit)
        # both rungs hold at any thickness: the core is not a check (inf where kept)
        rec.take(f, idx, ok, r.I, r.error, np.full(idx.size, np.inf), ok, np.ones(idx.size, bool), B1=r.B1)
        if np.all(ok):
            return ok, ""
        k = int(np.flatnonzero(~ok)[0])
        return ok, rung_reason(r.I[k], r.error[k], True, limit, r.message)

    lad = climb(rungs_from(PRESSURE_FIDELITIES, fidelity, req.escalate),
                lambda f, idx: moment_pressure_term(th[idx], v[idx], perm, f, material), checks, th.size)
    msg = lad.message(where_point(th, v, perm)(int(lad.left[0])), what="with the pressure term") if lad.left.size else ""
    out = rec.result(lad.valid, msg, shape)
    out.layer_separation = np.ones(shape, bool)
    return out
