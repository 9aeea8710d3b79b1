"""Static electrode charge and differential capacitance at every fidelity.

Gauss's law with blocking electrodes (seed paper section 4): the face ``z = -e`` (where
``phi0`` is applied) carries the surface charge ``sigma = D_z(-e)`` per unit area, the face
``z = +e`` carries ``-sigma`` (``D_z(e) = D_z(-e)`` by electroneutrality).  Derived in
``derivations/charge.py`` (generated into :mod:`ipmc_asym.kernels._generated_charge`):

* ``sigma = S Dhat(ln B1)`` with ``S = sqrt(phi4 C_moy eps_core R T)`` (C/m^2) for a neutral core:
  the lambda-expansion of the face induction stops at first order, so ``leading`` and
  ``corrected`` give the same closed form;
* ``C_d = dsigma/dphi0 = (eps_core/lambda_D) chat_c chat_a/(chat_c + chat_a)``: the two layer
  capacitances ``chat = exprel(Y) w(Y)`` in series (analytic derivative);
  ``C_d(0) = eps_core/(2 lambda_D)`` (Debye-Hueckel, thick strip);
* ``Q = sigma 2l L`` and the apparent permittivity ``eps_app = C_d 2e`` that a capacitance
  measurement on the strip (parallel-plate reading) would report.

Fidelities: ``leading``/``corrected`` (closed form), ``quadrature`` (``sigma`` as the layer
integral ``int_0^{Yc} chat dy`` by Gauss-Legendre panels, generic-rho kernels), ``exact`` (the
exact solution at any thickness, :mod:`ipmc_asym.kernels.charge_exact`: ``sigma = S sqrt(Dhat^2 +
kappa^2)``, ``C_d`` by implicit differentiation of the thickness constraint; ``C_d(0) = eps_core
coth(e/lambda_D)/(2 lambda_D)``), ``bvp`` (face value of ``D`` from the full BVP; ``C_d`` by a
central difference of two BVP solves with a Richardson error estimate).  The closed forms'
error estimates are twice the neutral-core asymptotics of their difference from the exact
solution (``kernels/charge_exact.py``), or twice the measured difference where that exceeds
``NEAR_LIMIT``.  ``Yc = ln B1`` comes from the generated small-voltage series below
``A2 = 0.25`` (no cancellation), and ``sigma = C_d_secant phi0`` is formed without ``A2^2``, so
``sigma -> C_d(0) phi0`` down to 0 V and subnormal voltages.  Thickness is the TOTAL ``2e``; SI
throughout.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ipmc_asym.base.registry import MODELS as _MODEL_SPECS
from ipmc_asym.base.registry import check_choice, fidelity_names
from ipmc_asym.base.settings import BVP_STATED_ERROR, EXACT_STATED_ERROR, VALIDATED_VOLTAGE, VALIDITY_LIMIT
from ipmc_asym.integral.api import check_min_thickness
from ipmc_asym.kernels import _generated as G
from ipmc_asym.kernels import _generated_charge as GC
from ipmc_asym.kernels.charge_exact import TINY_A2, charge_exact_point, closed_charge_errors, layer_potentials
from ipmc_asym.kernels.jit import jit, jit_parallel, prange
from ipmc_asym.kernels.quadrature import doubling_panels
from ipmc_asym.kernels.special import gauss_legendre
from ipmc_asym.model import groups
from ipmc_asym.model.params import NAFION_LI, Material, Strip, check_positive
from ipmc_asym.model.permittivity import MODELS, Permittivity, get_model

__all__ = ["ChargeResult", "charge", "layer_voltage", "core_resistance", "time_constant", "charge_scale",
           "capacitance_scale", "charge_hat_point",
           "charge_escalated", "CLOSED_TRUNCATION"]

#: rounding of the closed forms (Yc, Dhat, chat are cancellation-free): relative; measured
#: <= 4.4e-16 against the exact rung where the layers are apart (tests/dynamics/test_electrode.py)
CLOSED_TRUNCATION = 2e-14
#: above this neutral-core error estimate the closed forms' error is measured against the exact rung
NEAR_LIMIT = 1e-3
#: largest subnormal magnitude: below it a float carries an absolute rounding of 2^-1075
_SUBNORMAL = 2.2250738585072014e-308
_GL_X, _GL_W, _ = gauss_legendre(20)
_GL_X = np.ascontiguousarray(_GL_X)
_GL_W = np.ascontiguousarray(_GL_W)


@dataclass
class ChargeResult:
    """Static electrode charge and capacitance; arrays broadcast from the inputs (SI).

    Attributes
    ----------
    sigma : ndarray   surface charge of the face z = -e (where phi0 is applied), C/m^2; odd in phi0
    Q : ndarray       total charge of that electrode ``sigma * width * length`` (C)
    C_diff : ndarray  differential capacitance per area ``dsigma/dphi0``, F/m^2
    eps_app : ndarray apparent permittivity ``C_diff * thickness`` (TOTAL 2e), F/m
    error : ndarray   relative error estimate of ``sigma`` and of ``Q`` (including the rounding of a
                      subnormal result: 1 where ``Q`` underflows to 0 at ``|phi0|`` ~ 1e-323 V)
    error_C_diff : ndarray  relative error estimate of ``C_diff`` (and of ``eps_app``)
    core : ndarray    neutral core left between the layers (units of e)
    valid : ndarray of bool  both error estimates below ``VALIDITY_LIMIT`` and ``check_voltage`` (the
                      forward model's convention: valid = accurate and within every assumption)
    fidelity, model : str
    check_voltage : ndarray of bool  ``|phi0| <= settings.VALIDATED_VOLTAGE`` (the range validated against
                      the BVP; beyond it the numbers are kept and flagged, as the forward model's)
    """

    sigma: np.ndarray
    Q: np.ndarray
    C_diff: np.ndarray
    eps_app: np.ndarray
    error: np.ndarray
    error_C_diff: np.ndarray
    core: np.ndarray
    valid: np.ndarray
    fidelity: str
    model: str
    check_voltage: np.ndarray | None = None


def charge_scale(perm: Permittivity, material: Material) -> float:
    """``S = sqrt(phi4 C_moy eps_core R T)`` (C/m^2): ``sigma = S Dhat`` (derivations/charge.py)."""
    m = material
    return math.sqrt(m.phi4 * m.C_moy * perm.eps_moy * m.R * m.T)


def capacitance_scale(perm: Permittivity, material: Material) -> float:
    """``S F/(R T) = eps_core/lambda_D`` (F/m^2): ``C_d = that * Cdhat``."""
    return charge_scale(perm, material) * groups.inverse_thermal_voltage(material)


@jit
def _chat(y, rho, model_id):
    if model_id == 0:
        return GC.layer_capacitance_constant(y)
    if model_id == 1:
        return GC.layer_capacitance_linear(y)
    if model_id == 2:
        return GC.layer_capacitance_affine(y)
    return GC.layer_capacitance(y, rho)


@jit
def _dhat(Y, rho, model_id):
    if model_id == 0:
        return G.dhat_constant(Y)
    if model_id == 1:
        return abs(math.expm1(Y))
    if model_id == 2:
        return G.dhat_affine(Y)
    return G.dhat(Y, rho)


@jit(inline="always")  # a node of the driver's inner loop: no call per node
def _chat_generic(u, sgn, rho, wt):
    """``wt chat(sgn u)`` (generic rho): the integrand of :func:`_layer_integral`."""
    return wt * GC.layer_capacitance(sgn * u, rho)


_chat_panels = doubling_panels(_chat_generic)


@jit
def _layer_integral(Yc, rho, X, Wt):
    """``int_0^Yc chat(y) dy`` (generic rho) on panels with breakpoints 0, 1/2, 1, 2, 4, ..."""
    if Yc == 0.0:
        return 0.0
    sgn = 1.0 if Yc > 0.0 else -1.0
    return _chat_panels(abs(Yc), sgn, rho, X, Wt)


@jit
def charge_hat_point(A2, rho, model_id, quad, X, Wt):
    """``(sigma_hat, Cd_hat, Ya)`` of the neutral-core closed forms at ``A2 = F|phi0|/(R T) >= 0``.

    ``sigma = S sigma_hat``, ``C_d = (S F/R T) Cd_hat``; ``model_id`` 0/1/2 the paper's
    models (per-model kernels), -1 any ``rho`` (generic kernels).  ``quad`` = 1: ``sigma_hat``
    by Gauss-Legendre of the layer capacitance instead of the closed form ``Dhat``.
    """
    if A2 == 0.0:  # no field: sigma = 0, two layers of chat(0) = 1 in series
        return 0.0, 0.5, 0.0
    mid = -1 if quad == 1 else model_id
    Yc, Ya, _ = layer_potentials(A2, rho, mid)
    if quad == 1:
        sh = _layer_integral(Yc, rho, X, Wt)
    else:
        sh = _dhat(Yc, rho, mid)
    cd = GC.series_capacitance(_chat(Yc, rho, mid), _chat(Ya, rho, mid))
    return sh, cd, Ya


@jit
def _core(Ya, lam, rho):
    """Neutral core (units of e) of the closed forms' picture, for information.

    Depletion zone ``lam sqrt(2 rho (|Ya| - 1))`` plus ~10 Debye lengths of exponential tail per
    layer (kernels/closed.py); the validity of a rung follows its error estimate alone.
    """
    return 2.0 - lam * math.sqrt(2.0 * rho * max(-Ya - 1.0, 0.0)) - 20.0 * lam


@jit
def _charge_point(A2, lam, rho, model_id, order, X, Wt):
    """``(g, Cdhat, error_sigma, error_C, core)`` at ``A2 >= 0``; ``g = sigma_hat/A2``.

    ``order`` 1/2: closed forms, 0: quadrature, 3: exact (``kernels/charge_exact.py``).
    """
    if A2 < TINY_A2:
        # Debye-Hueckel limit (linearised Poisson-Boltzmann, eps = eps_core): sigma_hat/A2 and
        # Cdhat are 1/2 (neutral core) or coth(1/lam)/2 (exact), up to relative O(A2) < 1e-29;
        # the closed forms' core error is its value in that limit (independent of A2)
        if order == 3:
            c = 0.5 / math.tanh(1.0 / lam)
            return c, c, EXACT_STATED_ERROR + 10.0 * A2, EXACT_STATED_ERROR + 10.0 * A2, 2.0
        Yc, Ya = 0.5 * TINY_A2, -0.5 * TINY_A2
        es, ec = closed_charge_errors(lam, Yc, Ya, rho, 1.0, 1.0)
        return 0.5, 0.5, CLOSED_TRUNCATION + 10.0 * A2 + es, CLOSED_TRUNCATION + 10.0 * A2 + ec, _core(Ya, lam, rho)
    mid = -1 if order == 0 else model_id
    Yc, Ya, sb = layer_potentials(A2, rho, mid)
    if order == 3:
        g, cd, t, niter = charge_exact_point(lam, A2, rho, Yc, Ya)
        e = EXACT_STATED_ERROR + sb if niter > 0 else math.inf
        return g, cd, e, e, _core(Ya, lam, rho)
    if order == 0:
        sh = _layer_integral(Yc, rho, X, Wt)
    else:
        sh = _dhat(Yc, rho, mid)
    cc = _chat(Yc, rho, mid)
    ca = _chat(Ya, rho, mid)
    g = sh / A2
    cd = GC.series_capacitance(cc, ca)
    es, ec = closed_charge_errors(lam, Yc, Ya, rho, cc, ca)
    if max(es, ec) > NEAR_LIMIT:
        # overlapping layers: the neutral-core asymptotics of kappa loosen (up to ~300x at 1 um,
        # 20 V, constant model); the difference from the exact rung is the error there
        gx, cdx, _, niter = charge_exact_point(lam, A2, rho, Yc, Ya)
        if niter > 0:
            es = 2.0 * abs(g / gx - 1.0) + 2.0 * EXACT_STATED_ERROR
            ec = 2.0 * (abs(cd / cdx - 1.0) if cdx > 0.0 else (0.0 if cd == 0.0 else math.inf)) + 2.0 * EXACT_STATED_ERROR
    return g, cd, CLOSED_TRUNCATION + sb + es, CLOSED_TRUNCATION + sb + ec, _core(Ya, lam, rho)


@jit_parallel
def _sweep(A2, lam, rho, model_id, order, X, Wt, g, cd, err, errc, core):
    for i in prange(A2.size):
        g[i], cd[i], err[i], errc[i], core[i] = _charge_point(A2[i], lam[i], rho, model_id, order, X, Wt)


def _model_id(perm: Permittivity, fidelity: str) -> int:
    if fidelity == "quadrature":
        return -1
    paper = MODELS.get(perm.name)
    if paper is not None and (perm.eps0, perm.deps) == (paper.eps0, paper.deps):
        return _MODEL_SPECS[perm.name].id
    return -1  # the charge closed forms hold for any rho (generic kernels)


def charge(thickness, voltage, model="constant", fidelity="corrected", *, width=5.0e-3, length=0.02,
           material: Material | None = None) -> ChargeResult:
    """Electrode charge ``sigma``, ``Q``, differential capacitance and apparent permittivity.

    Parameters
    ----------
    thickness : float or array_like
        TOTAL thickness ``2e`` (m), > 0.
    voltage : float or array_like
        ``phi0`` (V), any sign (``sigma`` is odd, ``C_diff`` even); broadcast with ``thickness``.
    model : {"constant", "linear", "affine"}, Permittivity or callable
        A callable ``eps(C)`` needs ``fidelity="bvp"``.
    fidelity : {"leading", "corrected", "quadrature", "exact", "bvp"}
    width, length : float
        TOTAL width ``2l`` and length ``L`` (m), for ``Q = sigma 2l L``.
    material : Material, optional (default ``nafion-li``)

    Returns
    -------
    ChargeResult
        Arrays of the broadcast shape (0-d for scalar inputs), SI.
    """
    check_choice("fidelity", fidelity, fidelity_names())
    perm = get_model(model)
    mat = NAFION_LI if material is None else material
    w = check_positive("width (total, 2l)", width, "m")
    L = check_positive("length", length, "m")
    th = np.asarray(thickness, dtype=float)
    v = np.asarray(voltage, dtype=float)
    if not np.all(np.isfinite(th)) or np.any(th <= 0):
        raise ValueError("thickness (total, 2e) must be finite and > 0 m")
    if not np.all(np.isfinite(v)):
        raise ValueError("voltage must be finite (volts)")
    th, v = np.broadcast_arrays(th, v)
    if perm.is_custom and fidelity != "bvp":
        raise ValueError(f"a custom eps(C) needs fidelity 'bvp'; got fidelity {fidelity!r}")
    check_min_thickness(th)
    if fidelity == "bvp":
        sig, cdv, err, errc, core = _bvp(th, v, perm, mat)
    else:
        A2 = np.abs(np.asarray(groups.A2(v, mat), dtype=float)).reshape(-1)
        lam = np.asarray(groups.debye_length(th, perm.eps_moy, mat), dtype=float).reshape(-1)
        rho = perm.eps0 / perm.eps_moy
        outs = [np.empty(A2.size) for _ in range(5)]
        order = {"quadrature": 0, "exact": 3}.get(fidelity, 2)
        _sweep(np.ascontiguousarray(A2), np.ascontiguousarray(lam), rho, _model_id(perm, fidelity),
               order, _GL_X, _GL_W, *outs)
        g, cdh, err, errc, core = (o.reshape(th.shape) for o in outs)
        # sigma = (S F/RT) (sigma_hat/A2) phi0: odd in phi0, -> C_d(0) phi0, no A2^2 formed
        sig = capacitance_scale(perm, mat) * g * v
        cdv = capacitance_scale(perm, mat) * cdh
        err = err + _subnormal_rounding(sig) + _subnormal_rounding(sig * w * L, sig)
    # beyond the validated voltage the numbers are kept and flagged (forward model's check_voltage)
    volt_ok = np.abs(v) <= VALIDATED_VOLTAGE
    valid = _accurate(err, errc) & volt_ok
    return ChargeResult(sigma=sig, Q=sig * w * L, C_diff=cdv, eps_app=cdv * th, error=err,
                        error_C_diff=errc, core=core, valid=valid, fidelity=fidelity, model=perm.name,
                        check_voltage=volt_ok)


def _accurate(err, errc):
    """Both error estimates below ``VALIDITY_LIMIT`` (what a higher rung can improve)."""
    return (np.asarray(err) < VALIDITY_LIMIT) & (np.asarray(errc) < VALIDITY_LIMIT)


def charge_escalated(thickness: float, voltage: float, model="constant", fidelity="corrected", **kw) -> ChargeResult:
    """:func:`charge` of one point at the cheapest VALID rung from ``fidelity`` up the registry's ladder.

    Same arguments as :func:`charge` (scalars); the result's ``fidelity`` names the rung used.
    A rung is climbed for accuracy only: beyond the validated voltage the result is kept with
    ``check_voltage = valid = False``; where ``sigma`` or ``Q`` is subnormal (``|phi0|`` below
    ~1e-300 V) no rung helps, and the first rung's result is returned with its rounding in
    ``error`` (``valid = False`` once that passes ``VALIDITY_LIMIT``).  Raises ``ValueError``
    (one line) where no rung from ``fidelity`` up is accurate otherwise.
    """
    check_choice("fidelity", fidelity, fidelity_names())
    ladder = fidelity_names()
    last = None
    for rung in ladder[ladder.index(fidelity):]:
        last = charge(thickness, voltage, model, rung, **kw)
        if bool(_accurate(last.error, last.error_C_diff)):
            return last
        if float(voltage) != 0.0 and min(abs(float(last.sigma)), abs(float(last.Q))) < _SUBNORMAL:
            # no rung helps: the value itself is below the normal range of a double; its
            # rounding is the stated error (sigma -> C_d(0) phi0 down to the subnormals)
            return last
    raise ValueError(f"no fidelity from {fidelity!r} up is valid for model {get_model(model).name!r} (last rung "
                     f"{last.fidelity!r}: error estimates {float(last.error):.2g} / {float(last.error_C_diff):.2g})")


def _subnormal_rounding(x, nonzero=None):
    """Relative rounding of subnormal results (absolute 2^-1075); 1 where ``x`` underflowed to 0
    although ``nonzero`` (the value it was computed from) is not 0."""
    x = np.asarray(x, dtype=float)
    ref = x if nonzero is None else np.asarray(nonzero, dtype=float)
    ax = np.abs(x)
    with np.errstate(divide="ignore", invalid="ignore"):
        out = np.where((ax > 0.0) & (ax < _SUBNORMAL), 5e-324 / ax, 0.0)
    return np.where((ax == 0.0) & (ref != 0.0), 1.0, out)


def _bvp_sigma(thickness, voltage, perm, mat):
    from ipmc_asym.bvp.solver import solve  # deferred: scipy.integrate is heavy (start-up of the closed forms)

    with np.errstate(all="ignore"):
        try:
            r = solve(Strip(thickness=thickness, voltage=voltage), perm, mat)
        except (ArithmeticError, FloatingPointError):
            r = None
    if r is None or not r.success or not np.all(np.isfinite(r.D)):
        raise RuntimeError(f"BVP did not converge at thickness={thickness:g} m, voltage={voltage:g} V "
                           f"({'no finite solution' if r is None else r.message}); try fidelity 'exact'")
    # D_bar = D_z/(e phi4 F C_moy) at the face z = -1 (mirrored for a negative voltage)
    return 0.5 * thickness * mat.phi4 * mat.F * mat.C_moy * float(r.D[0])


def _bvp(th, v, perm, mat):
    """Point by point: sigma from the BVP face value, C_d by central differences (Richardson)."""
    sig = np.empty(th.shape)
    cd = np.empty(th.shape)
    err = np.full(th.shape, BVP_STATED_ERROR)
    errc = np.empty(th.shape)
    core = np.full(th.shape, 2.0)
    VT = groups.thermal_voltage(mat)
    for idx in np.ndindex(th.shape):
        t, u = float(th[idx]), float(v[idx])
        sig[idx] = _bvp_sigma(t, u, perm, mat)
        h = 1e-3 * VT * max(1.0, abs(u) / VT) ** 0.5
        f = {k: _bvp_sigma(t, u + k * h, perm, mat) if k else sig[idx] for k in (-2, -1, 1, 2)}
        d1 = (f[1] - f[-1]) / (2 * h)
        d2 = (f[2] - f[-2]) / (4 * h)
        cd[idx] = (4 * d1 - d2) / 3  # Richardson: O(h^4)
        if cd[idx] == 0.0:  # below the resolution of the difference quotient: no relative bound
            errc[idx] = math.inf
        else:
            errc[idx] = (abs(d1 - d2) / 3 + 4 * BVP_STATED_ERROR * abs(sig[idx]) / h) / abs(cd[idx])
    return sig, cd, err, errc, core


def layer_voltage(sigma, model="constant", material: Material | None = None):
    """``V(sigma)``: the static voltage at which the electrode charge is ``sigma`` (C/m^2), vectorised.

    Newton on the closed form from ``V = 0`` (``sigma(V)`` is increasing and concave for
    ``V > 0``, so the iterates increase monotonically onto the root); odd in ``sigma``.
    Raises ``ValueError`` where ``|sigma|`` exceeds the saturation charge of the linear model.
    """
    perm = get_model(model)
    mat = NAFION_LI if material is None else material
    sg = np.asarray(sigma, dtype=float)
    target = np.abs(sg)
    if perm.eps0 == 0.0 and np.any(target >= charge_scale(perm, mat)):
        raise ValueError("sigma must be below the saturation charge S of the linear model")
    x = np.zeros_like(target)
    for _ in range(100):
        r = charge(1.0, x, perm, "corrected", material=mat)
        dx = (target - r.sigma) / r.C_diff
        x = x + dx
        if np.all(np.abs(dx) <= 1e-14 * (1.0 + np.abs(x))):
            break
    return np.sign(sg) * x


def core_resistance(thickness, material: Material = NAFION_LI):
    """``R = 2e/kappa`` (Ohm m^2), ``kappa = phi4 F^2 D C_moy/(R T)`` (S/m); thickness TOTAL 2e."""
    return np.asarray(thickness, dtype=float) / groups.kappa(material)


def time_constant(thickness, model="constant", material: Material = NAFION_LI):
    """``tau = R C_d(0) = e lambda_D / D`` (s); thickness TOTAL 2e."""
    perm = get_model(model)
    return core_resistance(thickness, material) * 0.5 * capacitance_scale(perm, material)
