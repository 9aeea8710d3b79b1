"""Bench section ``charge``: closed-form ``ia.charge`` ns/point, ``ia.step_response`` at circuit
fidelity for 1000 time points and at PNP fidelity at nominal (1 V, 5 tau, 200 output times),
measured side by side in one run; CPU time, one Numba thread, the load beside."""

from __future__ import annotations

import numpy as np

import ipmc_asym as ia
from ipmc_asym_bench.timing import cpu_best, load, threads

__all__ = ["section", "TARGETS"]

#: the goals: charge 200 ns a point, the circuit step 10 ms, the PNP step 2 s
TARGETS = {"charge_ns_per_point": 200.0, "step_circuit_1000_s": 10e-3, "step_pnp_nominal_s": 2.0}


def section(quick: bool = False) -> dict:
    """The ``charge`` bench section (see the module docstring); ``quick``: 10^5 charge points,
    one repeat, no PNP step."""
    reps = 1 if quick else 3
    v = np.linspace(-3.0, 3.0, 10**5 if quick else 10**6)
    r = {}
    with threads(1):
        ia.charge(200e-6, v[:10])
        r["charge_ns_per_point"] = cpu_best(lambda: ia.charge(200e-6, v, "constant", "corrected"), reps) / v.size * 1e9
        ia.step_response(1.0, points=1000)
        r["step_circuit_1000_s"] = cpu_best(lambda: ia.step_response(1.0, points=1000), reps)
        if not quick:
            r["step_pnp_nominal_s"] = cpu_best(lambda: ia.step_response(1.0, fidelity="pnp", points=200), 1)
    units = {"charge_ns_per_point": "ns/point", "step_circuit_1000_s": "s", "step_pnp_nominal_s": "s"}
    what = {"charge_ns_per_point": "closed-form charge() (sigma, C_d, eps_app), 1 thread",
            "step_circuit_1000_s": "step --fidelity circuit --tol none, 1000 time points (incl. moment and beam)",
            "step_pnp_nominal_s": "step --fidelity pnp, nominal strip, 1 V, 5 tau, 200 output times"}
    note = f"CPU time, load {load():.2f}"
    figs = [{"what": what[k], "value": r[k], "unit": units[k], "target": TARGETS[k],
             "pass": bool(r[k] <= TARGETS[k]), "note": note}
            for k in TARGETS if k in r]
    return {"figures": figs}
