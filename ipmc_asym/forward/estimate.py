"""From strip + material + model to the mechanical outputs (``ipmc-asym estimate``).

``M_A = A5 I`` (paper sections 3-4, ``A5 = 6 l e^2 F |phi0| C_moy``), then the beam
(:mod:`ipmc_asym.beam.statics`).  Signs as in the paper: a positive voltage gives ``M_A > 0``,
``theta < 0`` and ``w < 0``.

The rule (issue 9): no number whose validity check failed is returned as a result.
:func:`moment_escalating` climbs the fidelity ladder (``registry.FIDELITIES``, cheapest
first, whatever rungs it holds) point by point from the requested rung to the cheapest one
that is valid there; :func:`evaluate` adds the beam and the four checks
(``electrochemistry``, ``layer_separation``, ``beam_regime``, ``strain``).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from ipmc_asym.integral.api import check_fidelity, check_min_thickness, moment
from ipmc_asym.model.params import NAFION_LI, Material, Strip, debye_length
from ipmc_asym.model.permittivity import MODELS, get_model
from ipmc_asym.base.registry import FIDELITIES as _FIDELITY_SPECS
from ipmc_asym.base.registry import check_choice, fidelity_names
from ipmc_asym.base.settings import OUTSIDE_REGIMES, STRAIN_LIMIT, VALIDATED_VOLTAGE, VALIDITY_LIMIT

__all__ = ["evaluate", "estimate_rows", "RESULT_KEYS", "CHECKS", "moment_escalating", "Escalated",
           "check_tol", "FREE_STRIP_KEYS", "MECHANICAL_KEYS"]

RESULT_KEYS = ("model", "fidelity", "fidelity_used", "escalated", "C_moy", "A0", "A1", "A2", "A3", "A5",
               "B1", "I", "M_A", "theta", "w", "w_small", "F_block", "F_block_small", "error_estimate",
               "seconds")

#: the validity checks of a result, in the order of the chain (electrochemistry -> beam)
CHECKS = ("electrochemistry", "layer_separation", "beam_regime", "strain")
#: outputs of the free strip (outside the model past a quarter turn / above the strain limit)
FREE_STRIP_KEYS = ("theta", "w", "w_small", "x_tip", "y_tip")
#: every mechanical output (all withheld where the strain check fails)
MECHANICAL_KEYS = FREE_STRIP_KEYS + ("F_block", "F_block_small")


def check_tol(tol, what="tol"):
    """``tol`` if it is a relative tolerance in (0, 1), else a one-line ``ValueError``."""
    if tol is None:
        return None
    if isinstance(tol, bool) or not isinstance(tol, (int, float, np.floating)) or not math.isfinite(tol) \
            or not 0.0 < float(tol) < 1.0:
        raise ValueError(f"{what} must be a relative tolerance in (0, 1), e.g. 0.01 for 1 %; got {tol!r}")
    return float(tol)


@dataclass
class Escalated:
    """Moment integral after escalation; arrays of the broadcast input shape.

    Attributes
    ----------
    I : ndarray      moment integral (NaN where no rung is valid)
    error : ndarray  relative error bound of ``I`` (inf where no rung is valid)
    B1 : ndarray
    core : ndarray   neutral core length (units of e) of the rung used
    fidelity_used : ndarray of str   rung that produced the value ("" where none)
    electrochemistry : ndarray of bool   error bound <= the tolerance (and finite)
    layer_separation : ndarray of bool   the rung's layers do not overlap (core > 0)
    valid : ndarray of bool   both of the above
    success : ndarray of bool   same as ``valid`` (solver-style name)
    message : str    one line: why the first invalid point has no valid rung ("" if none)
    """

    I: np.ndarray
    error: np.ndarray
    B1: np.ndarray
    core: np.ndarray
    fidelity_used: np.ndarray
    electrochemistry: np.ndarray
    layer_separation: np.ndarray
    valid: np.ndarray
    success: np.ndarray
    message: str


def moment_escalating(thickness, voltage, model="constant", fidelity="quadrature",
                      material: Material = NAFION_LI, *, tol=None, escalate: bool = True,
                      progress: bool | None = None) -> Escalated:
    """``I`` at the cheapest rung, from ``fidelity`` up, that is valid at each point.

    A rung is valid at a point where its error bound is <= ``min(tol, VALIDITY_LIMIT)``,
    its layers are separate and (BVP) it converged.  The ladder is the registry's ordered
    ``FIDELITIES``: a rung added there (e.g. ``exact``) is climbed without change here.

    Parameters
    ----------
    thickness, voltage : array_like
        TOTAL thickness ``2e`` (m) and voltage (V), broadcast.
    model : str or Permittivity or callable
    fidelity : str
        The cheapest rung tried.
    tol : float, optional
        Relative accuracy required of ``I`` (default: ``settings.VALIDITY_LIMIT``).
    escalate : bool
        ``False``: only ``fidelity`` (points where it is invalid get NaN).

    Returns
    -------
    Escalated
    """
    check_fidelity(fidelity)
    tol = check_tol(tol)
    limit = VALIDITY_LIMIT if tol is None else min(tol, VALIDITY_LIMIT)
    th, v = np.broadcast_arrays(np.asarray(thickness, float), np.asarray(voltage, float))
    shape = th.shape
    th, v = th.reshape(-1), v.reshape(-1)
    check_min_thickness(th)
    perm = get_model(model)
    n = th.size
    I = np.full(n, np.nan)
    err = np.full(n, np.inf)
    B1 = np.full(n, np.nan)
    core = np.full(n, np.nan)
    used = np.full(n, "", dtype=f"U{max(len(f) for f in fidelity_names())}")
    elec = np.zeros(n, bool)
    layer = np.zeros(n, bool)
    todo = np.ones(n, bool)
    why = []
    names = fidelity_names()
    rungs = names[names.index(fidelity):] if escalate else (fidelity,)
    for f in rungs:
        idx = np.flatnonzero(todo)
        if idx.size == 0:
            break
        if perm.is_custom and _FIDELITY_SPECS[f].compiled:
            why.append(f"{f}: not available for a custom eps(C)")
            continue
        try:
            r = moment(th[idx], v[idx], perm, f, material=material,
                       progress=(progress if not _FIDELITY_SPECS[f].compiled else False))
        except ValueError as exc:  # e.g. closed forms for a non-paper Permittivity
            why.append(f"{f}: {exc}")
            continue
        e_ok = np.isfinite(r.I) & (r.error <= limit)
        l_ok = (r.core > 0) | _FIDELITY_SPECS[f].any_thickness
        # r.valid adds the rung's own ceiling (registry) to the checks here
        ok = e_ok & l_ok & np.asarray(r.success) & np.asarray(r.valid)
        sel = idx[ok]
        I[sel], err[sel], B1[sel], core[sel], used[sel] = r.I[ok], r.error[ok], r.B1[ok], r.core[ok], f
        elec[idx], layer[idx] = e_ok, l_ok
        todo[sel] = False
        bad = ~ok
        if np.any(bad):
            k = int(np.flatnonzero(bad)[0])
            if r.message and not r.success[k]:
                why.append(f"{f}: {r.message}")
            else:
                why.append(f"{f}: error bound {float(r.error[k]):.2g} > {limit:g}"
                           + ("" if l_ok[k] else ", electrode layers overlap"))
    valid = ~todo
    msg = ""
    if np.any(todo):
        k = int(np.flatnonzero(todo)[0])
        msg = (f"no valid fidelity at thickness (total 2e) {th[k]:.3g} m, voltage {v[k]:.3g} V "
               f"(model {perm.name}): " + "; ".join(why[-3:]))
    rs = (lambda a: a.reshape(shape))
    return Escalated(I=rs(I), error=rs(err), B1=rs(B1), core=rs(core), fidelity_used=rs(used),
                     electrochemistry=rs(elec | valid), layer_separation=rs(layer | valid),
                     valid=rs(valid), success=rs(valid), message=msg)


def _f(x):
    x = float(x)
    return x if np.isfinite(x) else None


def evaluate(strip: Strip, model="constant", fidelity="quadrature", material: Material = NAFION_LI,
             tol: float | None = None, *, escalate: bool = True, on_invalid: str = "raise") -> dict:
    """One result row (SI units) for one strip and one permittivity model.

    Parameters
    ----------
    strip : Strip
    model : str or Permittivity
    fidelity : str
        The cheapest rung tried; with ``escalate`` (default) the first rung from there that
        is valid at this point is used (``fidelity_used``, ``escalated``).
    material : Material
    tol : float, optional
        Relative accuracy the caller needs, in (0, 1): the rung's error bound must meet it
        (default ``settings.VALIDITY_LIMIT``), and it decides whether a displacement counts
        as "small" (``regime``).
    escalate : bool
    on_invalid : {"raise", "nan"}
        A failed check: one-line ``ValueError`` (default), or the row with the affected
        outputs set to ``None`` (NaN) and ``valid = False``.

    Returns
    -------
    dict
        The keys of :data:`RESULT_KEYS` plus ``regime``, ``warnings``, ``x_tip``, ``y_tip``,
        ``debye_length`` (m), ``max_strain``, ``checks`` (each of :data:`CHECKS` -> bool),
        ``valid`` (all checks), ``withheld`` (outputs set to ``None`` by a failed check);
        ``error_estimate`` bounds the relative error of ``I`` (hence of ``M_A``, ``theta``,
        ``w_small``, ``F_block_small``).
    """
    from ipmc_asym.beam.statics import solve_beam

    check_fidelity(fidelity)
    tol = check_tol(tol)
    check_choice("on_invalid", on_invalid, ("raise", "nan"))
    perm = get_model(model)
    t0 = time.perf_counter()
    g = perm.groups(strip, material)
    r = moment_escalating(strip.thickness, strip.voltage, perm, fidelity, material, tol=tol,
                          escalate=escalate)
    if not bool(r.valid) and on_invalid == "raise":
        raise ValueError(r.message)
    I = float(r.I)
    M_A = g.A5 * I if bool(r.valid) else math.nan
    EI = material.E * strip.I_p
    with np.errstate(all="ignore"):
        beam = solve_beam(0.0 if math.isnan(M_A) else M_A, strip.length, EI, tol=tol, e=strip.e)
    used = str(r.fidelity_used)
    strain = float(beam.max_strain)
    checks = {
        "electrochemistry": bool(r.electrochemistry),
        "layer_separation": bool(r.layer_separation),
        "beam_regime": bool(r.valid) and str(beam.regime) not in OUTSIDE_REGIMES,
        "strain": bool(r.valid) and strain <= STRAIN_LIMIT,
    }
    beam_ok = checks["beam_regime"] and checks["strain"]
    # the beam's own lines where its outputs are kept; where a check withholds them, ours say why
    warnings = list(beam.warnings) if bool(r.valid) and beam_ok else []
    withheld = []
    if not bool(r.valid):
        withheld = ["I", "M_A", "B1"] + list(MECHANICAL_KEYS)
        warnings.append(r.message)
    else:
        if not checks["strain"]:
            withheld = list(MECHANICAL_KEYS)
            warnings.append(f"strain at the faces e|kappa| = {strain:.3g} > STRAIN_LIMIT {STRAIN_LIMIT:g}: "
                            "outside the small-strain beam model; mechanical outputs withheld")
        elif not checks["beam_regime"]:
            withheld = list(FREE_STRIP_KEYS)
            warnings.append(f"free strip {beam.regime} (|theta| > pi/2): outside the beam model; "
                            "free-strip outputs withheld (blocking forces kept: the strip is held straight)")
        if used != fidelity:
            warnings.append(f"escalated from {fidelity!r} to {used!r} (first rung valid here)")
    if abs(strip.voltage) > VALIDATED_VOLTAGE:
        warnings.append(f"|voltage| {abs(strip.voltage):g} V > {VALIDATED_VOLTAGE:g} V: beyond the range the toolkit "
                        "is validated on, and far beyond water electrolysis (~1.23 V), which this "
                        "blocking-electrode model leaves out; the numbers solve the equations, not the device")
    valid = all(checks.values())
    if not valid and on_invalid == "raise":
        raise ValueError(f"model {perm.name}: " + next(w for w in warnings[::-1] if "withheld" in w))
    row = {
        "model": perm.name,
        "fidelity": fidelity,
        "fidelity_used": used or None,
        "escalated": bool(used) and used != fidelity,
        "C_moy": g.C_moy,
        "A0": g.A0,
        "A1": g.A1,
        "A2": g.A2,
        "A3": g.A3,
        "A5": g.A5,
        "B1": _f(r.B1),
        "I": _f(I),
        "M_A": _f(M_A),
        "theta": _f(beam.theta),
        "w": _f(beam.w),
        "w_small": _f(beam.w_small),
        "F_block": _f(beam.F_block),
        "F_block_small": _f(beam.F_block_small),
        "error_estimate": _f(r.error),
        "seconds": time.perf_counter() - t0,
        "x_tip": _f(beam.x_tip),
        "y_tip": _f(beam.y_tip),
        "regime": str(beam.regime) if bool(r.valid) else None,
        "debye_length": None if perm.is_custom else
        _f(debye_length(strip.thickness, perm.eps0 + perm.deps, material) * strip.e),
        "max_strain": _f(strain) if bool(r.valid) else None,
        "checks": checks,
        "valid": valid,
        "withheld": withheld,
        "warnings": warnings,
    }
    for k in withheld:
        row[k] = None
    return row


def estimate_rows(strip: Strip, models=("constant", "linear", "affine"), fidelity="quadrature",
                  material: Material = NAFION_LI, tol=None, *, escalate=True, on_invalid="raise") -> list[dict]:
    return [evaluate(strip, m, fidelity, material, tol, escalate=escalate, on_invalid=on_invalid) for m in models]


def model_list(name: str) -> list[str]:
    if name == "all":
        return list(MODELS)
    get_model(name)
    return [name]
