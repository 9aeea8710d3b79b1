"""The fidelity ladder climbed point by point: ``I`` at the cheapest valid rung.

:func:`moment_escalating` climbs ``registry.FIDELITIES`` (cheapest first, whatever rungs it
holds) from the requested rung to the cheapest one valid at each point; a point with no valid
rung gets NaN and the reason (:attr:`Escalated.message`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ipmc_asym.base.ladder import SkipRung, climb, rungs_from
from ipmc_asym.base.registry import FIDELITIES as _FIDELITY_SPECS
from ipmc_asym.base.registry import fidelity_names
from ipmc_asym.base.settings import VALIDITY_LIMIT
from ipmc_asym.integral.api import ANY_THICKNESS, _moment, check_fidelity, check_min_thickness
from ipmc_asym.model.params import NAFION_LI, Material
from ipmc_asym.model.request import Request, check_tol

__all__ = ["moment_escalating", "Escalated", "Climb", "check_tol", "rung_checks", "ladder_inputs", "rung_reason",
           "where_point", "moment_ladder", "flat_inputs"]


def rung_checks(I, error, core, fidelity: str, limit: float):
    """``(electrochemistry, layer_separation)`` of one rung's values, bool arrays.

    ``electrochemistry``: ``I`` finite and its error bound <= ``limit``; ``layer_separation``:
    the neutral core between the layers is positive, or the rung holds at any thickness
    (``integral.api.ANY_THICKNESS``).
    """
    with np.errstate(invalid="ignore"):
        e_ok = np.isfinite(I) & (error <= limit)
    return e_ok, (core > 0) | (fidelity in ANY_THICKNESS)


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


class Climb:
    """What a climb of the ladder records per point, rung by rung (``n`` flat points): the
    bookkeeping of :func:`moment_escalating` and of the per-point ``C_moy`` ladder of
    :mod:`ipmc_asym.forward.model`, which differ in how a rung is evaluated only."""

    def __init__(self, n: int):
        self.I = np.full(n, np.nan)
        self.error = np.full(n, np.inf)
        self.B1 = np.full(n, np.nan)
        self.core = np.full(n, np.nan)
        self.used = np.full(n, "", dtype=f"U{max(len(f) for f in fidelity_names())}")
        self.elec = np.zeros(n, bool)
        self.layer = np.zeros(n, bool)

    def take(self, f: str, idx, ok, I, error, core, e_ok, l_ok, B1=None):
        """Rung ``f`` evaluated at the points ``idx``: its checks recorded there, its values kept
        where ``ok``; returns the points kept."""
        sel = idx[ok]
        self.I[sel], self.error[sel], self.core[sel], self.used[sel] = I[ok], error[ok], core[ok], f
        if B1 is not None:
            self.B1[sel] = B1[ok]
        self.elec[idx], self.layer[idx] = e_ok, l_ok
        return sel

    def result(self, valid, message: str, shape=None) -> "Escalated":
        """The climb as an :class:`Escalated` (arrays reshaped to ``shape`` if given)."""
        rs = (lambda a: a) if shape is None else (lambda a: a.reshape(shape))
        return Escalated(I=rs(self.I), error=rs(self.error), B1=rs(self.B1), core=rs(self.core),
                         fidelity_used=rs(self.used), electrochemistry=rs(self.elec | valid),
                         layer_separation=rs(self.layer | valid), valid=rs(valid), success=rs(valid),
                         message=message)


def flat_inputs(thickness, voltage):
    """``(thickness, voltage, shape)``: the inputs broadcast and flattened, the thickness floor
    checked (one-line ``ValueError``)."""
    th, v = np.broadcast_arrays(np.asarray(thickness, float), np.asarray(voltage, float))
    shape = th.shape
    th, v = th.reshape(-1), v.reshape(-1)
    check_min_thickness(th)
    return th, v, shape


def ladder_inputs(thickness, voltage, fidelity, tol):
    """The checked inputs of a ladder climb: ``(tol, limit, thickness, voltage, shape)`` with the
    inputs broadcast and flattened, ``limit = min(tol, VALIDITY_LIMIT)``, the fidelity and the
    thickness floor checked (one-line ``ValueError``)."""
    check_fidelity(fidelity)
    tol = check_tol(tol)
    limit = VALIDITY_LIMIT if tol is None else min(tol, VALIDITY_LIMIT)
    th, v, shape = flat_inputs(thickness, voltage)
    return tol, limit, th, v, shape


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
    req = Request(model, fidelity, tol, escalate)
    th, v, shape = flat_inputs(thickness, voltage)
    return moment_ladder(th, v, req, material, progress).result(shape)


class _Recorded:
    """A :class:`Climb` filled by a :func:`~ipmc_asym.base.ladder.climb`; ``result`` adds its
    validity and its one-line message (``where`` names a flat point)."""

    def __init__(self, climb: Climb, ladder, where):
        self.climb, self.ladder, self.where = climb, ladder, where

    def result(self, shape=None) -> Escalated:
        lad = self.ladder
        msg = lad.message(self.where(int(lad.left[0]))) if lad.left.size else ""
        return self.climb.result(lad.valid, msg, shape)


def where_point(th, v, perm) -> callable:
    """``k -> "thickness ..., voltage ... (model ...)"``: the flat point ``k`` named in a message."""
    return lambda k: f"thickness (total 2e) {th[k]:.3g} m, voltage {v[k]:.3g} V (model {perm.name})"


def rung_reason(I_k, error_k, l_ok_k, limit, message=""):
    """Why a rung's value is not valid at one point: the solver's message, or the error bound
    above the limit (and the layers overlapping)."""
    if message:
        return message
    return f"error bound {float(error_k):.2g} > {limit:g}" + ("" if l_ok_k else ", electrode layers overlap")


def moment_ladder(th, v, req: Request, material: Material, progress=None) -> _Recorded:
    """The climb of :func:`moment_escalating` on checked flat inputs (thickness floor held) and a
    :class:`~ipmc_asym.model.request.Request`; ``.result(shape)`` is the :class:`Escalated`."""
    perm, limit = req.model, req.limit
    rec = Climb(th.size)

    def evaluate(f, idx):
        if perm.is_custom and _FIDELITY_SPECS[f].compiled:
            raise SkipRung("not available for a custom eps(C)")
        try:
            return _moment(th[idx], v[idx], perm, f, material,
                           progress=(False if _FIDELITY_SPECS[f].compiled else progress))
        except ValueError as exc:  # e.g. closed forms for a non-paper Permittivity
            raise SkipRung(str(exc)) from None

    def checks(f, r, idx):
        e_ok, l_ok = rung_checks(r.I, r.error, r.core, f, limit)
        # r.valid adds the rung's own ceiling (registry) to the checks here
        ok = e_ok & l_ok & np.asarray(r.success) & np.asarray(r.valid)
        rec.take(f, idx, ok, r.I, r.error, r.core, e_ok, l_ok, B1=r.B1)
        if np.all(ok):
            return ok, ""
        k = int(np.flatnonzero(~ok)[0])
        solver = r.message if (r.message and not r.success[k]) else ""
        return ok, rung_reason(r.I[k], r.error[k], l_ok[k], limit, solver)

    lad = climb(rungs_from(fidelity_names(), req.fidelity, req.escalate), evaluate, checks, th.size)
    return _Recorded(rec, lad, where_point(th, v, perm))
