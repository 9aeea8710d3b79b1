"""Bench section ``charge``: closed-form ``charge()`` ns/point, ``step --fidelity circuit`` for
1000 time points and ``step --fidelity pnp`` at nominal (:func:`ipmc_asym.studies.charge_studies.bench_charge`,
measured side by side in one run)."""

from __future__ import annotations

from ipmc_asym.studies.charge_studies import BENCH_TARGETS, bench_charge

__all__ = ["section"]


def section(quick: bool = False) -> dict:
    """The ``charge`` bench section (see the module docstring)."""
    r = bench_charge(points=10**5 if quick else 10**6, repeats=1 if quick else 3, pnp=not quick)
    units = {"charge_ns_per_point": "ns/point", "step_circuit_1000_s": "s", "step_pnp_nominal_s": "s"}
    what = {"charge_ns_per_point": "closed-form charge() (sigma, C_d, eps_app), 2 threads",
            "step_circuit_1000_s": "step --fidelity circuit, 1000 time points (incl. moment and beam)",
            "step_pnp_nominal_s": "step --fidelity pnp, nominal strip, 1 V, 5 tau, 200 output times"}
    figs = [{"what": what[k], "value": r[k], "unit": units[k], "target": BENCH_TARGETS[k],
             "pass": bool(r[k] <= BENCH_TARGETS[k]), "note": "wall clock on this machine"}
            for k in BENCH_TARGETS if k in r]
    return {"figures": figs}
