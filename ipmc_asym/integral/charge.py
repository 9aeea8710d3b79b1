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

from ipmc_asym.base.ladder import climb, rungs_from
from ipmc_asym.base.registry import FIDELITIES as _FIDELITY_SPECS
from ipmc_asym.base.registry import fidelity_names
from ipmc_asym.base.results import Panel, ResultMixin, ResultSpec
from ipmc_asym.base.settings import BVP_STATED_ERROR, VALIDATED_VOLTAGE, VALIDITY_LIMIT
from ipmc_asym.base.units import parse_length, parse_voltage
from ipmc_asym.integral.api import as_numbers, check_fidelity, check_min_thickness, paper_model_id, run_parallel
from ipmc_asym.kernels.charge import GL_W, GL_X, closed_sweep, exact_sweep, near_sweep
from ipmc_asym.model import groups
from ipmc_asym.model.params import NAFION_LI, NOMINAL_STRIP, Material, Strip, check_dimension, check_voltages
from ipmc_asym.model.permittivity import Permittivity, get_model

__all__ = ["ChargeResult", "charge", "charge_escalated", "charge_inputs", "charge_at", "charge_scale", "capacitance_scale", "SUBNORMAL"]

#: largest subnormal magnitude: below it a float carries an absolute rounding of 2^-1075
SUBNORMAL = 2.2250738585072014e-308


@dataclass(repr=False)
class ChargeResult(ResultMixin):
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
    thickness, voltage : ndarray  the inputs (TOTAL 2e, m; phi0, V) broadcast: the points' coordinates
    """

    _result = ResultSpec("point", None, ("sigma", "Q", "C_diff", "eps_app", "error", "error_C_diff", "core", "valid"),
                         (Panel("point", ("sigma",)), Panel("point", ("C_diff",))), names={"error": "error_sigma"},
                         labels=("thickness", "voltage"))

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
    thickness: np.ndarray | None = None
    voltage: np.ndarray | None = None


def charge_scale(perm: Permittivity, material: Material) -> float:
    """``S = sqrt(phi4 C_moy eps_core R T)`` (C/m^2): ``sigma = S Dhat`` (derivations/charge.py)."""
    m = material
    return math.sqrt(m.phi4 * m.C_moy * perm.eps_moy * m.R * m.T)


def capacitance_scale(perm: Permittivity, material: Material) -> float:
    """``S F/(R T) = eps_core/lambda_D`` (F/m^2): ``C_d = that * Cdhat``."""
    return charge_scale(perm, material) * groups.inverse_thermal_voltage(material)


def charge(thickness, voltage=None, model="constant", fidelity="corrected", *, width=None, length=None,
           material: Material | None = None) -> ChargeResult:
    """Electrode charge ``sigma``, ``Q``, differential capacitance and apparent permittivity.

    Parameters
    ----------
    thickness : float, array_like or Strip
        TOTAL thickness ``2e`` (m), > 0; or a :class:`~ipmc_asym.model.params.Strip`, whose
        thickness, voltage, width and length serve where the arguments below are not given.
    voltage : float or array_like
        ``phi0`` (V), any sign (``sigma`` is odd, ``C_diff`` even); broadcast with ``thickness``;
        needed unless a Strip is given.
    model : {"constant", "linear", "affine"}, Permittivity or callable
        A callable ``eps(C)`` needs ``fidelity="bvp"``.
    fidelity : {"leading", "corrected", "quadrature", "exact", "bvp"}
    width, length : float, optional
        TOTAL width ``2l`` and length ``L`` (m), for ``Q = sigma 2l L``; default the Strip's, else
        those of the default ``Strip()`` (5 mm, 20 mm).
    material : Material, optional (default ``nafion-li``)

    Returns
    -------
    ChargeResult
        Arrays of the broadcast shape (0-d for scalar inputs), SI.
    """
    check_fidelity(fidelity)
    thickness, voltage, width, length = _from_strip(thickness, voltage, width, length)
    return charge_at(*charge_inputs(thickness, voltage, model, width, length, material), fidelity)


def _from_strip(thickness, voltage, width, length):
    """``charge``'s geometry from a Strip where one is passed (a Strip is checked when built),
    else the arguments with the default Strip's width and length."""
    s = thickness if isinstance(thickness, Strip) else NOMINAL_STRIP
    if isinstance(thickness, Strip):
        thickness = s.thickness
        voltage = s.voltage if voltage is None else voltage
    elif voltage is None:
        raise ValueError("voltage: needed (V) unless the first argument is a Strip")
    return (thickness, voltage, s.width if width is None else width, s.length if length is None else length)


def charge_inputs(thickness, voltage, model="constant", width=NOMINAL_STRIP.width, length=NOMINAL_STRIP.length,
                  material: Material | None = None):
    """The checked arguments of :func:`charge` (one-line ``ValueError`` each): ``(thickness,
    voltage, perm, width, length, material)``, thickness and voltage broadcast arrays."""
    perm = get_model(model)
    mat = NAFION_LI if material is None else material
    w = check_dimension("width (total, 2l)", width)
    L = check_dimension("length", length)
    # numbers, arrays or the units people write ("200um", "1V"), as moment_integral takes them
    th = np.asarray(as_numbers("thickness (total, 2e)", thickness, parse_length), dtype=float)
    v = np.asarray(as_numbers("voltage", voltage, parse_voltage), dtype=float)
    if not np.all(np.isfinite(th)) or np.any(th <= 0):
        raise ValueError("thickness (total, 2e) must be finite and > 0 m")
    check_voltages(v)
    try:
        th, v = np.broadcast_arrays(th, v)
    except ValueError:
        raise ValueError(f"thickness and voltage must broadcast to one shape; got shapes {th.shape} and "
                         f"{v.shape}") from None
    check_min_thickness(th)
    return th, v, perm, w, L, mat


#: compiled seconds per point of the drivers of :mod:`ipmc_asym.kernels.charge`, one thread (order
#: of magnitude, measured on 1-10^4 points of 1e-4 < lam < 0.1, 1e-3 < A2 < 100: the closed forms
#: carry their error estimates and, near overlap, an exact point): with
#: :data:`ipmc_asym.integral.api.PARALLEL_MIN_S`, the work below which one thread runs
CHARGE_COMPILED_S = {"leading": 8e-7, "corrected": 1e-6, "quadrature": 2e-6, "exact": 2e-5}


def charge_at(th, v, perm: Permittivity, w: float, L: float, mat: Material, fidelity: str) -> ChargeResult:
    """:func:`charge` on the checked arguments of :func:`charge_inputs` at the rung ``fidelity``."""
    if perm.is_custom and fidelity != "bvp":
        raise ValueError(f"a custom eps(C) needs fidelity 'bvp'; got fidelity {fidelity!r}")
    if fidelity == "bvp":
        sig, cdv, err, errc, core = _bvp(th, v, perm, mat)
    else:
        A2 = np.abs(np.asarray(groups.A2(v, mat), dtype=float)).reshape(-1)
        lam = np.asarray(groups.debye_length(th, perm.eps_moy, mat), dtype=float).reshape(-1)
        rho = perm.eps0 / perm.eps_moy
        outs = [np.empty(A2.size) for _ in range(5)]
        A2, lam, mid = np.ascontiguousarray(A2), np.ascontiguousarray(lam), paper_model_id(perm)
        code = _FIDELITY_SPECS[fidelity].kernel_code
        work = A2.size * CHARGE_COMPILED_S.get(fidelity, 0.0)
        # the rung's driver chosen here, not by a compiled branch on the code: a compiled dispatcher
        # compiles every rung it can reach, and the exact rung is most of the charge's compile
        # (fresh cache: `ipmc-asym charge` 14 s with one driver for every rung, 5 s with the closed forms' own)
        if code == 3:
            run_parallel(exact_sweep, work, (A2, lam, rho, mid, *outs))
        else:
            near = np.zeros(A2.size, np.uint8)
            run_parallel(closed_sweep, work, (A2, lam, rho, mid, code, GL_X, GL_W, *outs, near))
            idx = np.flatnonzero(near)
            if idx.size:  # overlapping layers: the error measured against the exact rung
                g0, cd0, err0, errc0, _ = outs
                run_parallel(near_sweep, idx.size * CHARGE_COMPILED_S["exact"],
                             (idx, A2, lam, rho, mid, code, g0, cd0, err0, errc0))
        g, cdh, err, errc, core = (o.reshape(th.shape) for o in outs)
        # sigma = (S F/RT) (sigma_hat/A2) phi0: odd in phi0, -> C_d(0) phi0, no A2^2 formed
        sig = capacitance_scale(perm, mat) * g * v
        cdv = capacitance_scale(perm, mat) * cdh
        err = err + _subnormal_rounding(sig) + _subnormal_rounding(sig * w * L, sig)
    # beyond the validated voltage the numbers are kept and flagged (forward model's check_voltage)
    volt_ok = np.abs(v) <= VALIDATED_VOLTAGE
    valid = accurate(err, errc) & volt_ok
    return ChargeResult(sigma=sig, Q=sig * w * L, C_diff=cdv, eps_app=cdv * th, error=err,
                        error_C_diff=errc, core=core, valid=valid, fidelity=fidelity, model=perm.name,
                        check_voltage=volt_ok, thickness=th, voltage=v)


def accurate(err, errc):
    """Both error estimates below ``VALIDITY_LIMIT`` (what a higher rung can improve)."""
    return (np.asarray(err) < VALIDITY_LIMIT) & (np.asarray(errc) < VALIDITY_LIMIT)



def _subnormal_rounding(x, nonzero=None):
    """Relative rounding of subnormal results (absolute 2^-1075); 1 where ``x`` underflowed to 0
    although ``nonzero`` (the value it was computed from) is not 0."""
    x = np.asarray(x, dtype=float)
    ref = x if nonzero is None else np.asarray(nonzero, dtype=float)
    ax = np.abs(x)
    with np.errstate(divide="ignore", invalid="ignore"):
        out = np.where((ax > 0.0) & (ax < SUBNORMAL), 5e-324 / ax, 0.0)
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


def charge_escalated(thickness: float, voltage: float, model="constant", fidelity="corrected", **kw) -> ChargeResult:
    """:func:`charge` of one point at the cheapest VALID rung from ``fidelity`` up the registry's ladder.

    Same arguments as :func:`charge` (scalars); the result's ``fidelity`` names the rung used.
    A rung is climbed for accuracy only: beyond the validated voltage the result is kept with
    ``check_voltage = valid = False``; where ``sigma`` or ``Q`` is subnormal (``|phi0|`` below
    ~1e-300 V) no rung helps, and the first rung's result is returned with its rounding in
    ``error`` (``valid = False`` once that passes ``VALIDITY_LIMIT``).  Raises ``ValueError``
    (one line) where no rung from ``fidelity`` up is accurate otherwise.
    """
    check_fidelity(fidelity)
    args = charge_inputs(thickness, voltage, model, **kw)  # checked once; every rung trusts them

    def checks(f, r, idx):
        if bool(accurate(r.error, r.error_C_diff)):
            return True, ""
        if float(voltage) != 0.0 and min(abs(float(r.sigma)), abs(float(r.Q))) < SUBNORMAL:
            # no rung helps: the value itself is below the normal range of a double; its
            # rounding is the stated error (sigma -> C_d(0) phi0 down to the subnormals)
            return True, ""
        ec = float(r.error_C_diff)
        cd = (f"{ec:.2g}" if math.isfinite(ec) else
              f"none (C_diff = {float(r.C_diff):.3g} F/m^2 is below what the rung's differences resolve)")
        return False, f"error estimates of sigma {float(r.error):.2g}, of C_diff {cd}"

    lad = climb(rungs_from(fidelity_names(), fidelity), lambda f, idx: charge_at(*args, f), checks)
    if lad.left.size:
        raise ValueError(lad.message(f"thickness (total 2e) {float(thickness):.3g} m, voltage {float(voltage):.3g} V "
                                     f"(model {args[2].name})"))
    return lad.last.result
