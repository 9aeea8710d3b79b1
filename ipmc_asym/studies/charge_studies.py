"""The paper's capacitance and time claims, and the speed measurements of the charge models.

The criteria of these claims are defined here once (:data:`ORDER_FACTOR`,
:data:`ABOUT_ONE_SECOND`, :data:`TIME_CRITERION`, :func:`time_reachable`); ``validate``
builds its rows from the same constants.

:func:`charge_claims` returns rows in the format of :mod:`ipmc_asym.validation.validate` (``claim``,
``section``, ``paper``, ``ours``, ``verdict``, ``key``) plus a ``criterion`` string and the
computed ``numbers``.  :func:`bench_charge` returns the three charge measurements
(closed-form ``charge`` ns/point, ``step --fidelity circuit`` for 1000 points, ``step
--fidelity pnp`` at nominal) measured side by side in one run.
"""

from __future__ import annotations

import time

import numpy as np

from ipmc_asym.dynamics.circuit import step_response, time_constant
from ipmc_asym.dynamics.electrode import charge
from ipmc_asym.model.params import NAFION_LI, Material, Strip
from ipmc_asym.model.permittivity import MODELS

__all__ = ["charge_claims", "bench_charge", "BENCH_TARGETS", "ORDER_FACTOR", "EPS_CAPACITANCE_LITERATURE",
           "ABOUT_ONE_SECOND", "D_LI_NAFION_REPORTED", "TIME_CRITERION", "times_over_D", "time_reachable"]

MODELS3 = ("constant", "linear", "affine")

#: targets of the charge bench
BENCH_TARGETS = {"charge_ns_per_point": 200.0, "step_circuit_1000_s": 10e-3, "step_pnp_nominal_s": 30.0}


#: "de l'ordre de" (paper section 4, capacitance permittivity): within this factor
ORDER_FACTOR = 10.0
#: the permittivity other authors deduce from capacitance measurements (paper section 4, F/m)
EPS_CAPACITANCE_LITERATURE = 1e-3
#: "un temps caracteristique d'une seconde environ" (introduction): within a factor 3 of 1 s
ABOUT_ONE_SECOND = (1.0 / 3.0, 3.0)
#: diffusion coefficients of Li+ in Nafion reported in the sources read, as (D in m^2/s, source).
#: None read: the radiotracer study behind the default D (Goswami et al. 2001) lists Na+, K+, Cs+
#: and Ag+, not Li+ (params.D_CATION_SOURCE).  Studies that do measure Li+ in Nafion by 7Li NMR
#: (V. I. Volkov et al., Int. J. Mol. Sci. 23 (2022) 5011, a review; "Ion mobility in Nafion-117
#: membranes", Desalination 170 (2004) 49) were found, but only their abstracts, which give no
#: value.  A sourced entry here turns the ~1 s verdict on.
D_LI_NAFION_REPORTED: tuple = ()
#: the one criterion of the ~1 s claim (used here and by ``validate``)
TIME_CRITERION = ("~1 s is reachable for a model if, over the range of D reported for Li+ in Nafion, its tau = R C_d(0) "
                  "or its 90 % time of a 1 V step meets [1/3 s, 3 s]; every time of the reduced model scales as 1/D, "
                  "and with no sourced range of D for Li+ the claim cannot be judged")


def times_over_D(t_at_D0: float, D0: float, D_range) -> tuple:
    """(shortest, longest) time over ``D_range`` = (D_lo, D_hi) for a time ``t_at_D0`` at ``D0`` (t ~ 1/D)."""
    lo, hi = D_range
    return (t_at_D0 * D0 / hi, t_at_D0 * D0 / lo)


def time_reachable(interval) -> bool:
    """Does a (shortest, longest) interval of times meet :data:`ABOUT_ONE_SECOND`?"""
    return bool(interval[0] <= ABOUT_ONE_SECOND[1] and interval[1] >= ABOUT_ONE_SECOND[0])


def charge_claims(material: Material = NAFION_LI, strip: Strip | None = None) -> list[dict]:
    """Rows for ``validate``: the capacitance-permittivity statement (section 4), the apparent permittivity of
    the modelled strip, and the ~1 s time (introduction).

    The capacitance statement is judged as the paper makes it: the permittivity it *chose* for the linear and
    affine models (``eps_moy``) against the literature's ~1e-3 F/m.  What a capacitance measurement on the
    modelled strip would report, ``eps_app = C_d 2e``, is a separate row.
    """
    s = Strip() if strip is None else strip
    m = material
    rows = []
    e0 = {mm: float(charge(s.thickness, 0.0, mm, material=m).eps_app) for mm in MODELS3}
    e1 = {mm: float(charge(s.thickness, s.voltage, mm, material=m).eps_app) for mm in MODELS3}
    eps_moy = {mm: float(MODELS[mm].eps_moy) for mm in ("linear", "affine")}

    def order(v):
        return 1.0 / ORDER_FACTOR <= v / EPS_CAPACITANCE_LITERATURE <= ORDER_FACTOR

    crit = (f"reproduced if the permittivity the paper chose for the linear and affine models (eps_moy) is within a "
            f"factor {ORDER_FACTOR:g} ('de l'ordre de') of the {EPS_CAPACITANCE_LITERATURE:g} F/m deduced from "
            "capacitance measurements")
    rows.append({
        "claim": "permittivity deduced from capacitance measurements ~1e-3 F/m is the order of the linear/affine values",
        "section": "§4", "paper": "~1e-3 F/m (Nemat-Nasser 2002, Farinholt), 'of the order' of eps_moy = 1e-3 F/m",
        "ours": "eps_moy chosen: " + ", ".join(f"{mm} {v:.4g}" for mm, v in eps_moy.items()) + " F/m",
        "verdict": "reproduced" if all(order(v) for v in eps_moy.values()) else "differs",
        "key": "capacitance_permittivity", "criterion": crit,
        "numbers": {"eps_moy": eps_moy, "eps_app_0V": e0, "eps_app_nominal": e1},
    })
    crit = (f"reproduced if eps_app = C_d 2e (small signal at 0 V: what a capacitance measurement on the modelled "
            f"strip reports) is within a factor {ORDER_FACTOR:g} of {EPS_CAPACITANCE_LITERATURE:g} F/m for every model")
    rows.append({
        "claim": "a capacitance measurement on the modelled strip gives the literature's ~1e-3 F/m",
        "section": "§4 (finding)", "paper": "~1e-3 F/m (Nemat-Nasser 2002, Farinholt)",
        "ours": ("eps_app = C_d 2e at 0 V: " + ", ".join(f"{mm} {e0[mm]:.3g}" for mm in MODELS3)
                 + f" F/m; at {s.voltage:g} V: " + ", ".join(f"{mm} {e1[mm]:.3g}" for mm in MODELS3)
                 + " F/m. eps_app(0 V) = eps_core e/lambda_D: the two double layers in series seen across the "
                 "strip, not the bulk permittivity; it grows with the thickness"),
        "verdict": "reproduced" if all(order(v) for v in e0.values()) else "differs",
        "key": "capacitance_apparent", "criterion": crit,
        "numbers": {"eps_app_0V": e0, "eps_app_nominal": e1},
    })
    tau = {mm: float(time_constant(s.thickness, mm, m)) for mm in MODELS3}
    t90 = {}
    for mm in MODELS3:
        r = step_response(1.0, 20 * tau[mm], strip=s, model=mm, material=m, points=4000)
        t90[mm] = float(r.t[np.argmax(r.sigma >= 0.9 * r.sigma[-1])])
    D_for_1s = {"tau": {mm: m.D * tau[mm] for mm in MODELS3}, "t90": {mm: m.D * t90[mm] for mm in MODELS3}}
    numbers = {"tau": tau, "t90": t90, "D": m.D, "D_for_1s": D_for_1s, "D_reported": list(D_LI_NAFION_REPORTED)}
    if D_LI_NAFION_REPORTED:
        Ds = [d for d, _ in D_LI_NAFION_REPORTED]
        rng = (min(Ds), max(Ds))
        spans = {mm: {k: times_over_D(t[mm], m.D, rng) for k, t in (("tau", tau), ("t90", t90))} for mm in MODELS3}
        ok = [any(time_reachable(v) for v in spans[mm].values()) for mm in MODELS3]
        verdict = "reproduced" if all(ok) else "partly" if any(ok) else "differs"
        numbers["spans"] = spans
        where = "D reported for Li+ in Nafion: " + "; ".join(f"{d:.2g} m^2/s ({src})" for d, src in D_LI_NAFION_REPORTED)
    else:
        verdict = "not-reproducible"
        where = ("no diffusion coefficient of Li+ in Nafion was found in the sources read (the source of the default D "
                 "lists Na+, K+, Cs+, Ag+): the ~1 s cannot be judged")
    rows.append({
        "claim": "characteristic time of about one second", "section": "introduction",
        "paper": "~1 s (Nemat-Nasser 2000, experiments)",
        "ours": (f"at D = {m.D:.3g} m^2/s: tau = R C_d(0) = e lambda_D/D: " + ", ".join(
            f"{mm} {tau[mm]:.3g} s" for mm in MODELS3) + "; 90 % of the charge after a 1 V step: "
            + ", ".join(f"{mm} {t90[mm]:.3g} s" for mm in MODELS3) + ". 1 s needs D = "
            + ", ".join(f"{mm} {D_for_1s['tau'][mm]:.2g} (tau) / {D_for_1s['t90'][mm]:.2g} (t90)" for mm in MODELS3)
            + " m^2/s. " + where),
        "verdict": verdict, "key": "characteristic_time", "criterion": TIME_CRITERION, "numbers": numbers,
    })
    return rows


def bench_charge(points: int = 10**6, repeats: int = 3, pnp: bool = True) -> dict:
    """Seconds of the three charge measurements (best of ``repeats``), compiled kernels warmed first."""
    v = np.linspace(-3.0, 3.0, int(points))
    charge(200e-6, v[:10])
    best = np.inf
    for _ in range(repeats):
        t0 = time.perf_counter()
        charge(200e-6, v, "constant", "corrected")
        best = min(best, time.perf_counter() - t0)
    out = {"charge_ns_per_point": best / v.size * 1e9}
    step_response(1.0, points=1000)
    best = np.inf
    for _ in range(repeats):
        t0 = time.perf_counter()
        step_response(1.0, points=1000)
        best = min(best, time.perf_counter() - t0)
    out["step_circuit_1000_s"] = best
    if pnp:
        t0 = time.perf_counter()
        step_response(1.0, fidelity="pnp", points=200)
        out["step_pnp_nominal_s"] = time.perf_counter() - t0
    out["targets"] = dict(BENCH_TARGETS)
    out["meets"] = {k: bool(out[k] <= BENCH_TARGETS[k]) for k in BENCH_TARGETS if k in out}
    return out

