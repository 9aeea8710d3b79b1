"""``sense``: the strip as a sensor at rest -- the charge and voltage of an imposed bending.

The electrochemistry of one cross-section is :mod:`ipmc_asym.integral.sensing` (derivation
``derivations/sensing.py``); this module turns an imposed tip displacement into the curvature
along the strip (small-displacement Bernoulli beam, paper section 3, eq (13)) and integrates
the charge over the electrode:

* ``support="free"``: a free end under an end moment, uniform curvature, ``w = kappa L^2/2``
  (eq (13) with ``kappa = M/(E I)``);
* ``support="tip-force"``: a tip force on the cantilever, ``M = P (L - x)``,
  ``kappa(x) = kappa0 (1 - x/L)``, ``w = kappa0 L^2/3`` (``w = P L^3/(3 E I)``).

Short circuit: ``Q = 2l int_0^L sigma(kappa(x)) dx`` (16-point Gauss-Legendre along ``x``; the
integrand is smooth and odd in ``kappa``).  Open circuit: the electrodes are equipotential along
the length, so with a varying curvature the sources ``V_oc(kappa(x))`` stand in parallel behind
the layers' capacitance ``C_d(0)``, uniform along the length: ``V_oc`` is their length average,
exact at linear order; the nonlinear part of ``V_oc`` at the clamp is added to its error bound.
A resistive load at DC after relaxation carries no current, so it reads the open-circuit
voltage; in short circuit the charge flows once (the transient is not modelled here).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ipmc_asym.base.ladder import first_shown
from ipmc_asym.base.registry import check_choice
from ipmc_asym.base.results import Panel, ResultMixin, ResultSpec
from ipmc_asym.base.settings import MAX_DIMENSION, MIN_DIMENSION, VALIDITY_LIMIT
from ipmc_asym.integral.charge import _subnormal_rounding
from ipmc_asym.integral.sensing import B_LIMIT, charge_scale_sensing, debye_length, sense_hat, strain_parameter
from ipmc_asym.model import groups
from ipmc_asym.model.params import NAFION_LI, NOMINAL_STRIP, Material, Strip
from ipmc_asym.model.request import Request

__all__ = ["SenseResult", "sense", "SENSE_SUPPORTS", "SENSE_LOADS", "DEFAULT_NU", "tip_curvature", "MAX_CURVATURE",
           "MAX_TIP_DISPLACEMENT"]

#: support cases of an imposed tip displacement
SENSE_SUPPORTS = ("free", "tip-force")
#: electrical closures after relaxation
SENSE_LOADS = ("short", "open")
#: drained Poisson ratio, an ASSUMPTION: no measured value for hydrated Nafion was read; 0 is the
#: paper's own section 3 kinematics (a volume at z becomes (|R| + z)/|R| dV: no lateral strain).
#: docs/sensing.md tabulates how the answers scale, as (1 - 2 nu).
DEFAULT_NU = 0.0
_GL_X, _GL_W = np.polynomial.legendre.leggauss(16)
_GL_U = 0.5 * (_GL_X + 1.0)  # nodes on [0, 1]
_GL_WU = 0.5 * _GL_W


def tip_curvature(tip_displacement, length: float, support: str):
    """Curvature at the clamp for a tip displacement (small displacement, module docstring)."""
    w = np.asarray(tip_displacement, float)
    return (2.0 if support == "free" else 3.0) * w / length**2


@dataclass(repr=False)
class SenseResult(ResultMixin):
    """Static sensing response per point (arrays along ``point``; SI).

    Attributes
    ----------
    curvature : ndarray   curvature at the clamp (uniform for ``support="free"``), 1/m
    tip_displacement : ndarray   the tip displacement of that curvature (small displacement), m
    sigma : ndarray   short-circuit charge per area of the face z = -e at the clamp, C/m^2
    Q : ndarray       short-circuit charge of the electrode z = -e, C (odd in the curvature)
    V_oc : ndarray    open-circuit voltage phi(-e) - phi(e), V
    Q_per_w : ndarray Q/w (the linear sensitivity where w = 0), C/m
    error, error_V_oc : ndarray   relative error estimates of Q (and sigma) and of V_oc
    strain_parameter : ndarray   b = (1 - 2 nu) kappa e/phi4 at the clamp
    max_strain : ndarray   face strain e|kappa| at the clamp
    check_strain : ndarray of bool   max_strain <= material.strain_limit (small strain; values kept)
    check_beam_regime : ndarray of bool   the strip turns less than a quarter turn, ``|kappa0|`` L <= pi/2
        (the small-displacement beam relating w and kappa; values kept)
    valid : ndarray of bool   a rung met the tolerance and both checks hold
    fidelity_used : ndarray of str   the rung kept at each point
    model, support, load, fidelity : str
    nu : float
    message : str   why a point has no valid rung ("" if every point has one)
    """

    _result = ResultSpec("point", None, ("curvature", "tip_displacement", "sigma", "Q", "V_oc", "Q_per_w", "error",
                                         "error_V_oc", "strain_parameter", "max_strain", "check_strain", "check_beam_regime",
                                         "valid", "fidelity_used"),
                         (Panel("tip_displacement", ("Q",)), Panel("tip_displacement", ("V_oc",))),
                         scalars=("nu",), names={"error": "error_sigma"})
    _HEADLINE = ("model", "fidelity", "support", "load")

    curvature: np.ndarray
    tip_displacement: np.ndarray
    sigma: np.ndarray
    Q: np.ndarray
    V_oc: np.ndarray
    Q_per_w: np.ndarray
    error: np.ndarray
    error_V_oc: np.ndarray
    strain_parameter: np.ndarray
    max_strain: np.ndarray
    check_strain: np.ndarray
    check_beam_regime: np.ndarray
    valid: np.ndarray
    fidelity_used: np.ndarray
    model: str
    support: str
    load: str
    fidelity: str
    nu: float
    message: str = ""

    @property
    def reading(self) -> np.ndarray:
        """What the chosen load reads: ``Q`` (short) or ``V_oc`` (open)."""
        return self.Q if self.load == "short" else self.V_oc


#: largest |curvature| (1/m) and |tip displacement| (m) sense takes: a numerical guard.  A bend radius
#: below the smallest dimension of a strip (settings.MIN_DIMENSION) or a tip moved further than the
#: largest (settings.MAX_DIMENSION) is no bend of an accepted strip; within both, the tip displacement,
#: the curvature and the strain parameter of every accepted strip stay finite (no overflow of kappa L^2)
MAX_CURVATURE = round(1.0 / MIN_DIMENSION)
MAX_TIP_DISPLACEMENT = MAX_DIMENSION


def _check_array(name, value, unit, cap):
    a = np.atleast_1d(np.asarray(value, dtype=float))
    if a.ndim != 1:
        raise ValueError(f"{name} must be a number or a 1-D list of numbers ({unit})")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name} must be finite ({unit})")
    big = float(np.max(np.abs(a), initial=0.0))
    if big > cap:
        raise ValueError(f"{name}: |value| up to {cap:g} {unit} allowed (a numerical guard: a bend radius of at least "
                         f"{MIN_DIMENSION:g} m and a tip displacement of at most {MAX_DIMENSION:g} m); got {big:.3g} {unit}")
    return a


def sense(strip: Strip | None = None, curvature=None, tip_displacement=None, support: str = "tip-force",
          load: str = "short", model="constant", fidelity: str = "leading", tol=None, *, nu: float = DEFAULT_NU,
          material: Material | None = None, pressure_term: bool = False, escalate: bool = True) -> SenseResult:
    """Charge and open-circuit voltage of a strip bent at rest (after relaxation).

    Parameters
    ----------
    strip : Strip, optional   geometry (TOTAL width and thickness; its voltage is not used: the
        electrodes are short-circuited or open).  Default: the nominal strip.
    curvature : float or 1-D array_like, 1/m   curvature at the clamp (``eps_xx = -kappa z``)
    tip_displacement : float or 1-D array_like, m   instead of ``curvature`` (one of the two)
    support : {"free", "tip-force"}   how the displacement is imposed (module docstring; default tip-force,
        the tip pushed: the default of every sensing entry)
    load : {"short", "open"}   which reading the result's summary leads with (both are computed)
    model, fidelity, tol, escalate, pressure_term : as :class:`ipmc_asym.model.request.Request`
    nu : float   drained Poisson ratio in [0, 0.5] (default 0, an assumption: docs/sensing.md)
    material : Material, optional (default ``nafion-li``)
    """
    req = Request(model=model, fidelity=fidelity, tol=tol, escalate=escalate, pressure_term=pressure_term)
    strip = NOMINAL_STRIP if strip is None else strip
    if not isinstance(strip, Strip):
        raise ValueError("strip must be an ipmc_asym.Strip")
    mat = NAFION_LI if material is None else material
    check_choice("support", support, SENSE_SUPPORTS)
    check_choice("load", load, SENSE_LOADS)
    if isinstance(nu, bool) or not isinstance(nu, (int, float, np.floating)) or not 0.0 <= float(nu) <= 0.5:
        raise ValueError(f"nu (drained Poisson ratio) must be a number in [0, 0.5]; got {nu!r}")
    nu = float(nu)
    if (curvature is None) == (tip_displacement is None):
        raise ValueError("give exactly one of curvature (1/m) and tip_displacement (m)")
    perm = req.model
    if perm.is_custom:
        raise ValueError("model: sensing needs one of the paper's permittivity models (constant, linear, affine)")
    L = strip.length
    if curvature is not None:
        kap = _check_array("curvature", curvature, "1/m", MAX_CURVATURE)
        w = kap * L**2 / (2.0 if support == "free" else 3.0)
    else:
        w = _check_array("tip_displacement", tip_displacement, "m", MAX_TIP_DISPLACEMENT)
        kap = tip_curvature(w, L, support)
    b0 = strain_parameter(kap, strip.thickness, nu, mat)
    if np.any(np.abs(b0) >= B_LIMIT):
        j = int(np.argmax(np.abs(b0)))
        what = "curvature" if curvature is not None else "tip_displacement"
        raise ValueError(f"{what}: (1 - 2 nu) |kappa| e/phi4 = {abs(b0[j]):.3g} must be < 1 (a face would lose "
                         f"all its solution); |kappa| < {mat.phi4 / ((1 - 2 * nu) * strip.e):.4g} 1/m here")
    lam = float(debye_length(strip.thickness, perm, mat))
    g0 = None
    if req.pressure_term:
        g0 = 1.0 - float(groups.pressure_beta(mat)) * (1.0 + float(groups.A3(mat)))
    nodes = (np.ones(1), np.ones(1)) if support == "free" else (_GL_U, _GL_WU)
    u, wt = nodes
    bb = (b0[:, None] * u[None, :]).reshape(-1)
    hat = sense_hat(bb, lam, perm, mat, req.fidelity, req.tol, req.escalate, g0)
    sh = hat.sigma_hat.reshape(b0.size, u.size)
    vh = hat.v_hat.reshape(b0.size, u.size)
    S = charge_scale_sensing(perm, mat)
    VT = groups.thermal_voltage(mat)
    area = strip.width * L
    sig = S * (sh[:, 0] if support == "free" else _root_sigma(b0, lam, perm, mat, req, g0))
    Q = area * S * (sh * wt[None, :]).sum(axis=1)
    V = VT * (vh * wt[None, :]).sum(axis=1)
    err = hat.error.reshape(b0.size, u.size).max(axis=1)
    errv = hat.error_v.reshape(b0.size, u.size).max(axis=1)
    if support == "tip-force":  # the length average of V_oc(kappa(x)) is exact at linear order only
        errv = errv + 2.0 * np.abs(np.where(b0 != 0, np.arctanh(b0) / np.where(b0 != 0, b0, 1.0) - 1.0, 0.0))
    # a curvature so small that the response underflows: the rounding of a subnormal (1 where it
    # rounded to 0), as for the electrode charge; a response that is 0 exactly (no bend, or
    # nu = 1/2: the drained volume does not change, so neither does C_moy) has no rounding
    moved = np.where((kap != 0.0) & (1.0 - 2.0 * nu != 0.0), 1.0, 0.0)
    err = err + _subnormal_rounding(Q, moved)
    errv = errv + _subnormal_rounding(V, moved)
    rung_ok = hat.valid.reshape(b0.size, u.size).all(axis=1)
    ok = rung_ok & (err < VALIDITY_LIMIT) & (errv < VALIDITY_LIMIT)
    message = hat.message
    under = rung_ok & ~ok  # every rung met its bound, the doubles' rounding of the result did not
    if not message and under.any():
        j = int(np.argmax(under))
        count = first_shown(int(under.sum()), b0.size)
        message = (f"relative error estimate above {VALIDITY_LIMIT:g}{count} (Q or V_oc subnormal at curvature "
                   f"{kap[j]:.6g} 1/m: doubles round it)")
    used = hat.used.reshape(b0.size, u.size)[:, 0]
    strain = np.abs(kap) * strip.e
    strain_ok = strain <= mat.strain_limit
    # the small-displacement beam (eq (13)) of the w <-> kappa relation: flagged past a quarter turn
    beam_ok = np.abs(kap) * L <= 0.5 * math.pi
    # Q/w; at w = 0 the linear sensitivity (closed form, derivations.sensing:reciprocity_ratio)
    s_lin = _linear_q_per_w(strip, lam, perm, mat, support, nu, g0)
    with np.errstate(divide="ignore", invalid="ignore"):
        qpw = np.where(w != 0.0, Q / np.where(w != 0.0, w, 1.0), s_lin)
    return SenseResult(curvature=kap, tip_displacement=w, sigma=sig, Q=Q, V_oc=V, Q_per_w=qpw, error=err,
                       error_V_oc=errv, strain_parameter=b0, max_strain=strain, check_strain=strain_ok,
                       check_beam_regime=beam_ok, valid=ok & strain_ok & beam_ok, fidelity_used=used,
                       model=perm.name, support=support, load=load, fidelity=req.fidelity, nu=nu, message=message)


def _root_sigma(b0, lam, perm, mat, req, g0):
    """``sigma/S`` at the clamp's curvature (tip-force support), on the same ladder."""
    return sense_hat(b0, lam, perm, mat, req.fidelity, req.tol, req.escalate, g0).sigma_hat


def _linear_q_per_w(strip, lam, perm, mat, support, nu, g0):
    """``dQ/dw`` at ``w = 0``: ``Q = 2l L S sigma_hat(b)``, linear ``sigma_hat = -b (coth(1/lam) - lam)``."""
    lb = lam if g0 is None else lam / math.sqrt(g0)
    pref = 1.0 if g0 is None else 1.0 / math.sqrt(g0)
    kpw = (2.0 if support == "free" else 3.0) / strip.length**2  # curvature at the clamp per w
    mean = 1.0 if support == "free" else 0.5  # length average of kappa(x)/kappa0
    dbdw = (1.0 - 2.0 * nu) * strip.e / mat.phi4 * kpw
    return -strip.width * strip.length * charge_scale_sensing(perm, mat) * pref * (1.0 / math.tanh(1.0 / lb) - lb) \
        * dbdw * mean
