"""The fidelity ladder with the pressure term of the Nernst-Planck law (``pressure_term=True``).

Only ``exact`` and ``bvp`` hold the term (:data:`ipmc_asym.integral.pressure.PRESSURE_FIDELITIES`):
a cheaper requested rung starts the climb at ``exact``.  Same validity rule as
:func:`ipmc_asym.forward.escalation.moment_escalating`: finite ``I`` with an error bound
``<= min(tol, VALIDITY_LIMIT)``; both rungs hold at any thickness.
"""

from __future__ import annotations

import numpy as np

from ipmc_asym.base.registry import fidelity_names
from ipmc_asym.forward.escalation import Escalated, ladder_inputs
from ipmc_asym.integral.pressure import PRESSURE_FIDELITIES, moment_pressure_term
from ipmc_asym.model.params import NAFION_LI, Material

__all__ = ["moment_pressure_escalating"]


def moment_pressure_escalating(thickness, voltage, model="constant", fidelity="exact",
                               material: Material = NAFION_LI, *, tol=None, escalate: bool = True) -> Escalated:
    """``I`` with the pressure term at the cheapest valid rung of ``exact``, ``bvp`` (flat arrays).

    Raises
    ------
    ValueError   ``escalate=False`` with a rung that does not hold the pressure term.
    """
    tol, limit, th, v, shape = ladder_inputs(thickness, voltage, fidelity, tol)
    if fidelity not in PRESSURE_FIDELITIES:
        if not escalate:
            raise ValueError(f"pressure_term: fidelity {fidelity!r} does not hold the pressure term; use one of "
                             f"{', '.join(PRESSURE_FIDELITIES)} (or allow escalation)")
        fidelity = PRESSURE_FIDELITIES[0]
    rungs = PRESSURE_FIDELITIES[PRESSURE_FIDELITIES.index(fidelity):] if escalate else (fidelity,)
    n = th.size
    I = np.full(n, np.nan)
    err = np.full(n, np.inf)
    B1 = np.full(n, np.nan)
    used = np.full(n, "", dtype=f"U{max(len(f) for f in fidelity_names())}")
    todo = np.arange(n)
    why = ""
    for f in rungs:
        if todo.size == 0:
            break
        r = moment_pressure_term(th[todo], v[todo], model, f, material)
        with np.errstate(invalid="ignore"):
            ok = r.success & np.isfinite(r.I) & (r.error <= limit)
        sel = todo[ok]
        I[sel], err[sel], B1[sel], used[sel] = r.I[ok], r.error[ok], r.B1[ok], f
        if not np.all(ok):
            why = r.message or f"{f}: error bound above {limit:g}"
        todo = todo[~ok]
    valid = np.ones(n, bool)
    valid[todo] = False
    msg = ""
    if todo.size:
        k = int(todo[0])
        msg = (f"no valid fidelity with the pressure term at thickness (total 2e) {th[k]:.3g} m, voltage "
               f"{v[k]:.3g} V: {why}")
    core = np.where(valid, np.inf, np.nan)  # both rungs hold at any thickness
    rs = (lambda a: a.reshape(shape))
    return Escalated(I=rs(I), error=rs(err), B1=rs(B1), core=rs(core), fidelity_used=rs(used),
                     electrochemistry=rs(valid.copy()), layer_separation=rs(np.ones(n, bool)), valid=rs(valid),
                     success=rs(valid), message=msg)
