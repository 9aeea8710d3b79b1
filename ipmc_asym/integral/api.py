"""The moment integral ``I(e, phi0)`` at every fidelity, for one point or 10^7.

Fidelity ladder (docs/design.md; the registry :mod:`ipmc_asym.base.registry`), named after the asymptotic order:

``leading``
    ``I ~ lambda J1``: the O(lambda) term of the layer expansion, closed form
    (so ``I ~ 1/e``).  Error estimate: the next term ``lambda^2 |J2|`` plus the truncation of
    the closed-form layer functions.
``corrected``
    ``I ~ lambda J1 + lambda^2 J2``, closed form.  The lambda-expansion stops there exactly
    (derivations/model.py), so what is left is exponentially small in ``1/lambda`` plus the
    truncation of the large-/small-``A2`` expansions of the layer functions.
``quadrature``
    The same two terms with the layer functions integrated numerically (Gauss-Legendre
    panels in a compiled kernel).  Error: exponentially small in ``core/lambda`` while the
    layers do not overlap.
``exact``
    Nothing neglected, at any thickness (overlapping layers, non-neutral core): the first
    integral with the exact ``B1`` and its constant ``K`` from the thickness constraint,
    the moment by Gauss-Legendre panels (``kernels/exact.py``, ``derivations/exact.py``).
    Compiled and parallel like the others, ~10-40 us a point.  Error:
    ``settings.EXACT_STATED_ERROR``.
``bvp``
    The full nonlinear BVP (:mod:`ipmc_asym.bvp.solver`), point by point: an independent method
    (the cross-check) and the only rung for a user ``eps(C)``.

``I`` is computed on ``|phi0|`` and carries the sign of the voltage (mirror symmetry);
``I = 0`` at zero volts.  Below ``A2 = kernels.debye.DH_A2`` (~52 uV) every rung evaluates the
Debye-Hueckel series of ``derivations/debye_hueckel.py`` (``exact`` and ``bvp`` at any lambda,
the layer rungs its two-term limit), whose remainder bound is added to the rung's error:
the rungs' own forms lose ~eps/A2 there.  Thickness is the TOTAL thickness ``2e`` (SI).

Names exported for scripts: ``FIDELITIES`` is the tuple of the rung names, cheapest first
(``registry.fidelity_names()``; the specs are the dict ``ipmc_asym.base.registry.FIDELITIES``);
``MODELS`` is ``ipmc_asym.model.permittivity.MODELS``, ``{name: Permittivity}`` (the specs are
the dict ``ipmc_asym.base.registry.MODELS``); ``ANY_THICKNESS`` is the tuple of the rungs
whose spec has ``any_thickness`` set.
"""

from __future__ import annotations

import contextvars
import math
import warnings
from dataclasses import dataclass

import numba
import numpy as np

from ipmc_asym.base.progress import progress as _progress_bar
from ipmc_asym.base.registry import FIDELITIES as _FIDELITY_SPECS
from ipmc_asym.base.registry import MODELS as _MODEL_SPECS
from ipmc_asym.base.registry import any_thickness_fidelities, check_choice, fidelity_names, is_compiled
from ipmc_asym.base.results import Panel, ResultMixin, ResultSpec
from ipmc_asym.base.settings import (
    BVP_STATED_ERROR,
    EXACT_STATED_ERROR,
    INTERPRET_BUDGET_S,
    MAX_VOLTAGE,
    MIN_THICKNESS,
    ROUNDING_ERROR,
    VALIDITY_LIMIT,
)
from ipmc_asym.base.units import parse_length, parse_voltage
from ipmc_asym.kernels.closed import closed_b1, closed_finish, layer_closed, moment_closed
from ipmc_asym.kernels.debye import DH_A2, dh_exact, dh_layer
from ipmc_asym.kernels.exact import exact_frozen, moment_exact
from ipmc_asym.kernels.jit import interpreted, jit, jit_parallel, prange
from ipmc_asym.kernels.quadrature import moment_quadrature
from ipmc_asym.model import groups
from ipmc_asym.model.params import NAFION_LI, Material, Strip, check_min_thickness, check_voltages
from ipmc_asym.model.permittivity import MODELS, Permittivity, get_model
from ipmc_asym.model.request import check_fidelity

__all__ = ["FIDELITIES", "MomentResult", "moment_integral", "moment", "groups_arrays", "check_fidelity",
           "check_min_thickness", "invalid_message", "validity_limit", "interpret_small", "paper_model_id",
           "run_parallel", "COMPILED_S", "PARALLEL_MIN_S"]

#: the rung names, cheapest first (tuple; the specs: ``registry.FIDELITIES``)
FIDELITIES = fidelity_names()
#: rungs that hold whatever the thickness (overlapping layers, non-neutral core): their
#: ``core`` output is informative only (the registry's ``any_thickness`` flag)
ANY_THICKNESS = any_thickness_fidelities()
#: ``{name: kernel_code}`` of the compiled rungs (the registry's flags; read by ``bench.suite``
#: and the tests of the bare driver)
_ORDER = {k: f.kernel_code for k, f in _FIDELITY_SPECS.items() if f.compiled}


@dataclass(repr=False)
class MomentResult(ResultMixin):
    """Moment integral and its bookkeeping; arrays broadcast from the inputs.

    Attributes
    ----------
    I : ndarray   moment integral (dimensionless, signed like the voltage)
    error : ndarray   relative error estimate of ``I``
    B1 : ndarray   cathode concentration ``C(1)/C_moy`` (for ``|phi0|``)
    core : ndarray   length of the neutral core left between the layers (units of ``e``);
        for ``exact`` the distance between the points where ``|ln C| = 1`` (may be ~0: the
        layers overlap, which ``exact`` handles), for ``bvp`` 2
    lam : ndarray   core Debye length / e
    A2 : ndarray
    valid : ndarray of bool   error estimate below ``VALIDITY_LIMIT`` and layers separate
        (``bvp``: the solve converged)
    thickness, voltage : ndarray   the inputs (TOTAL thickness 2e, m; phi0, V) broadcast to the
        result's shape (views, no copy): the coordinates of :meth:`to_xarray`
    fidelity : str
    model : str
    success : ndarray of bool   ``bvp``: solve_bvp converged at that point (True otherwise)
    message : str   ``bvp``: the first failure's message ("" if none)
    """

    _result = ResultSpec("point", None, ("I", "error", "B1", "core", "lam", "A2", "valid"),
                         (Panel("point", ("I",)), Panel("point", ("error",), ylog=True)),
                         labels=("thickness", "voltage"))

    I: np.ndarray
    error: np.ndarray
    B1: np.ndarray
    core: np.ndarray
    lam: np.ndarray
    A2: np.ndarray
    valid: np.ndarray
    fidelity: str
    model: str
    success: np.ndarray | None = None
    message: str = ""
    thickness: np.ndarray | None = None
    voltage: np.ndarray | None = None


def _material(material, kw) -> Material:
    m = NAFION_LI if material is None else material
    if kw:
        try:
            m = m.with_(**kw)
        except TypeError as exc:
            raise ValueError(f"unknown material parameter: {exc}") from None
    return m


def groups_arrays(thickness, voltage, perm: Permittivity, material: Material):
    """Vectorised groups: ``(lam, A2, A3, rho, sign)``, arrays broadcast to one shape.

    ``lam = sqrt(eps_core R T / (e^2 phi4 F^2 C_moy))`` does not depend on the voltage.
    """
    return _groups_arrays(thickness, voltage, perm, material)


def _groups_arrays(thickness, voltage, perm: Permittivity, material: Material, floor: bool = True):
    """:func:`groups_arrays`; ``floor=False``: the thickness floor and the voltage cap are known to hold."""
    th = np.asarray(thickness, dtype=float)
    v = np.asarray(voltage, dtype=float)
    if not np.all(np.isfinite(th)) or np.any(th <= 0):
        raise ValueError("thickness (total, 2e) must be finite and > 0 m")
    if floor:  # an entry: the thickness floor and the voltage cap (else the caller's edge check holds them)
        check_min_thickness(th)
        check_voltages(v)
    elif not np.all(np.isfinite(v)):
        raise ValueError("voltage must be finite (volts)")
    th, v = np.broadcast_arrays(th, v)
    eps_core = perm.eps0 + perm.deps
    lam = groups.debye_length(th, eps_core, material)
    rho = perm.eps0 / eps_core
    return lam, groups.A2(v, material), groups.A3(material), rho, np.sign(v)


#: where core/lam >= CORE_X_FLOOR the core interaction 4 exp(-core/lam) is bounded by its
#: value there, ~1.7e-17 (below the 1e-11 floor of every stated error by 6 decades)
CORE_X_FLOOR = 40.0
CORE_ERROR_FLOOR = 4.0 * math.exp(-CORE_X_FLOOR)


@jit
def _core_error(core, lam):
    """Relative error of the neutral-core assumption, ~4 exp(-core/lam) (a bound).

    Beyond ``core/lam = CORE_X_FLOOR`` it returns the bound ``CORE_ERROR_FLOOR`` without an
    exp or a division (the test is a product): this sits on the hot path of every sweep,
    and core/lam ranges over 1e2-1e7 at most points.
    """
    c = max(core, 0.0)
    if c < CORE_X_FLOOR * lam:
        return 4.0 * math.exp(-(c / lam))
    return CORE_ERROR_FLOOR


@jit
def _point(lam, A2, A3, rho, model_id, order, fz=None):
    """(I for ``|phi0|``, error, B1, core) of one point; ``order`` 0 = quadrature, 3 = exact, 1 and 2
    the closed forms (:func:`_closed_point`, which a closed-form driver calls directly).

    ``fz``: for ``exact``, the frozen cores of the caller's sweep (:func:`exact_frozen`), or None.

    ``error`` bounds the relative error of the returned ``I`` (not of one term of it).
    Zero volts: no field, I = 0 exactly (the odd extension; no 0/0).
    """
    if order == 1 or order == 2:
        return _closed_point(lam, A2, A3, rho, model_id, order)
    if A2 == 0.0:
        return 0.0, 0.0, 1.0, 2.0
    if A2 < DH_A2:  # small voltage: the Debye-Hueckel series, no eps/A2 rounding
        return _dh_point(lam, A2, A3, rho, order)
    if order == 3:
        Ii, b1, ell, c, niter = moment_exact(lam, A2, A3, rho, fz)
        if niter < 0:  # thickness constraint not met: no number, and invalid
            return math.nan, math.inf, b1, c
        return Ii, EXACT_STATED_ERROR, b1, c
    Ii, J1, J2, b1, c = moment_quadrature(lam, A2, A3, rho)  # order 0
    return Ii, ROUNDING_ERROR + _core_error(c, lam), b1, c


@jit
def _closed_point(lam, A2, A3, rho, model_id, order):
    """:func:`_point` of the closed forms (``order`` 1 leading, 2 corrected): no quadrature or exact
    code is reachable from here, so a driver of the closed forms compiles only them."""
    if A2 == 0.0:
        return 0.0, 0.0, 1.0, 2.0
    if A2 < DH_A2:  # small voltage: the Debye-Hueckel series, no eps/A2 rounding
        return _dh_point(lam, A2, A3, rho, order)
    return _closed_post(lam, *moment_closed(lam, A2, A3, rho, model_id, order))


@jit
def _closed_post(lam, Ii, e_i, b1, c):
    """The closed forms' ``(I, error, B1, core)`` as :func:`_point` returns them."""
    # The kernel keeps ~20 lam of exponential tails in its core; the layer width the
    # quadrature measures (to |y| = 1) is the depletion width +- 0.5 lam (measured on
    # 1 um - 10 mm x 0.1 mV - 20 V), so 2 - dep - lam is a conservative core; the ~20 lam
    # of tails would overstate the core interaction 4 exp(-core/lam) below by ~e^19
    # (and flag ``corrected`` invalid at 10 um, where it is accurate to ~1e-9).
    c = c + 19.0 * lam
    e_i = max(e_i, ROUNDING_ERROR)
    # neglected core interaction: exponentially small in core/lambda
    return Ii, e_i + _core_error(c, lam), b1, c


@jit
def _dh_point(lam, A2, A3, rho, order):
    """:func:`_point` for ``0 < A2 < DH_A2`` (``kernels/debye.py``): ``exact`` gets the series at
    any ``lam`` (error: its remainder bound plus the stated error of the rung), the layer rungs
    the series of ``J1``, ``J2`` with the core interaction added as for the closed forms."""
    if order == 3:
        Ii, e_i, b1 = dh_exact(lam, A2, A3, rho)
        return Ii, EXACT_STATED_ERROR + e_i, b1, 2.0
    Ii, e_i, b1, c = dh_layer(lam, A2, A3, rho, order)
    return _closed_post(lam, Ii, e_i, b1, c)

#: points per block of the closed-form drivers (a few kB of temporaries per thread)
BLOCK = 1024


@jit
def _closed_block(lam, A2, A3, rho, model_id, order, I, err, B1, core):
    """:func:`_point` for the closed forms over a block of points, stage by stage.

    Why: one point is a chain of dependent calls (exp, log, a polynomial, square roots) whose
    latency, not the number of operations, sets its cost; run stage by stage over a block,
    consecutive points are independent and the processor overlaps them.  The operations are
    those of :func:`moment_closed`, in the same order: the results are bit for bit the same
    (tested).  ``I``, ``err``, ``B1``, ``core``: outputs of the block's length, also used as
    the stage-1 and layer temporaries.  ``A2 = 0`` gives :func:`_point`'s zero-volt values and
    ``0 < A2 < DH_A2`` its small-voltage series;
    an ``A2`` that is not a number > 0 gives NaN (callers flag such inputs themselves); both
    run the stages on a stand-in, so no table lookup ever sees a NaN.
    """
    m = lam.size
    tmp = np.empty((5, m))  # one allocation for the block's temporaries
    em, yc, w0a, w1a, a2 = tmp[0], tmp[1], tmp[2], tmp[3], tmp[4]
    acc = 2 if order == 2 else 1
    for k in range(m):
        a2[k] = A2[k] if A2[k] >= DH_A2 else 1.0  # a stand-in where the series or 0 V applies
        em[k], B1[k], yc[k] = closed_b1(a2[k], model_id)
    for k in range(m):  # the cathode layer functions, held in I and err until stage 3
        I[k], err[k] = layer_closed(yc[k], model_id, acc)
    for k in range(m):
        w0a[k], w1a[k] = layer_closed(yc[k] - a2[k], model_id, acc)
    for k in range(m):
        if A2[k] >= DH_A2:
            Ii, e_i, b1, c = closed_finish(lam[k], a2[k], A3, rho, model_id, order, em[k], B1[k], yc[k], I[k],
                                           err[k], w0a[k], w1a[k])
            I[k], err[k], B1[k], core[k] = _closed_post(lam[k], Ii, e_i, b1, c)
        elif A2[k] > 0.0:  # small voltage: the Debye-Hueckel series (as _point)
            I[k], err[k], B1[k], core[k] = _dh_point(lam[k], A2[k], A3, rho, order)
        elif A2[k] == 0.0:  # zero volts: no field, I = 0 exactly (as _point)
            I[k], err[k], B1[k], core[k] = 0.0, 0.0, 1.0, 2.0
        else:
            I[k] = err[k] = B1[k] = core[k] = math.nan


@jit_parallel
def _sweep(lam, A2, A3, rho, model_id, order, sign, I, err, B1, core):
    """The bare sweep driver on precomputed groups (prange; the bench's kernel cost):
    ``order`` 1 leading, 2 corrected (blocks, as in :func:`_fused_blocks`), 0 quadrature, 3 exact."""
    n = lam.size
    if order == 1 or order == 2:
        for b in prange((n + BLOCK - 1) // BLOCK):
            i0 = b * BLOCK
            i1 = min(n, i0 + BLOCK)
            _closed_block(lam[i0:i1], A2[i0:i1], A3, rho, model_id, order, I[i0:i1], err[i0:i1], B1[i0:i1],
                          core[i0:i1])
            for i in range(i0, i1):
                I[i] = sign[i] * I[i]
    else:
        fz = exact_frozen(rho, order == 3)
        for i in prange(n):
            Ii, e_i, b1, c = _point(lam[i], A2[i], A3, rho, model_id, order, fz)
            I[i] = sign[i] * Ii
            err[i] = e_i
            B1[i] = b1
            core[i] = c



@jit
def _groups_point(t, vv, lamc, a2c):
    """``(lam, A2)`` of one point: ``lam = lamc / thickness`` (``groups.debye_length``:
    ``lam ~ 1/e``), ``A2 = a2c |phi0|`` (one division, no square root, per point)."""
    return lamc / t, a2c * abs(vv)


def _fused_driver(order: int):
    """The fused sweep driver of the rung ``order`` (``kernel_code`` of the registry): groups,
    sign and validity computed inside the parallel loop.  :func:`_fused_blocks` for the closed
    forms (1 leading, 2 corrected), :func:`_fused_points` for 0 quadrature and 3 exact.

    Chosen here, in Python, rather than by a compiled branch on ``order``: a compiled dispatcher
    compiles every rung it can reach, so a first ``leading`` call would compile the quadrature and
    exact rungs too (measured in a fresh cache: 35 s for an array, against 10 s for the closed
    forms' driver alone).

    Both take ``(th, v, lamc, a2c, A3, rho, model_id, order, any_thickness, limit, I, err, B1,
    core, lam_o, A2_o, valid, nan_invalid)``: ``th``, ``v`` flat arrays of the output size or of
    size 1 (broadcast); the outputs are flat views of the result arrays, so nothing else is
    allocated.  ``I`` and ``valid`` are always written; the other outputs only if they have the
    size of ``I`` (pass empty arrays for those not wanted: :func:`moment_integral` needs ``I`` and
    ``valid`` only), and ``nan_invalid`` puts NaN in ``I`` where the point is invalid (no second
    pass over the arrays).  They return the counts of bad thicknesses (not finite or <= 0), of bad
    voltages (not finite) -- those points are left as NaN and the caller raises -- and of invalid
    points.
    """
    return _fused_blocks if order in (1, 2) else _fused_points


#: the compiled drivers' own guard on |phi0| (V): twice the cap the entries hold (settings.MAX_VOLTAGE),
#: so that points just past it inside the library (a central difference at the cap, a stepper's
#: rounding past its drive) are evaluated, not dropped; the kernels are checked finite up to here
_VOLTAGE_CAP = 2.0 * MAX_VOLTAGE


@jit(inline="always")
def _input_code(t, vv):
    """0 for a usable point, 2 if the thickness is not finite or <= 0, 3 if the voltage is not
    finite or past :data:`_VOLTAGE_CAP` (the codes of :func:`_put`; the same comparison costs nothing
    more than the finiteness test, and the caller says which)."""
    if not (t > 0.0 and t < math.inf):
        return 2
    if not (abs(vv) <= _VOLTAGE_CAP):
        return 3
    return 0


@jit(inline="always")  # seven output arrays: a real call costs more than the point
def _put(i, t, vv, lam, A2, Ii, e_i, b1, c, limit, any_thickness, nan_invalid, full,
         I, err, B1, core, lam_o, A2_o, valid):
    """Write point ``i`` of a fused driver (``Ii`` for ``|phi0|``); returns 0 (written), 1 (invalid,
    NaN in ``I``), 2 (thickness not finite or <= 0) or 3 (voltage not finite): NaN throughout."""
    bad = _input_code(t, vv)
    if bad:
        I[i] = math.nan
        valid[i] = False
        if full:
            err[i] = B1[i] = core[i] = lam_o[i] = A2_o[i] = math.nan
        return bad
    ok = (e_i < limit) and (c > 0.0 or any_thickness)
    valid[i] = ok
    code = 0
    if ok or not nan_invalid:
        I[i] = Ii if vv >= 0.0 else -Ii
    else:
        I[i] = math.nan
        code = 1
    if full:
        err[i] = e_i
        B1[i] = b1
        core[i] = c
        lam_o[i] = lam
        A2_o[i] = A2
    return code


@jit_parallel
def _fused_blocks(th, v, lamc, a2c, A3, rho, model_id, order, any_thickness, limit,
                  I, err, B1, core, lam_o, A2_o, valid, nan_invalid):
    """The fused driver (:func:`_fused_driver`) of the closed forms: blocks of ``BLOCK`` points, stage by stage
    (:func:`_closed_block`); bit for bit the per-point results."""
    n = I.size
    sth = th.size > 1
    sv = v.size > 1
    full = err.size == n  # bookkeeping outputs wanted (all or none)
    nb = (n + BLOCK - 1) // BLOCK
    counts = np.zeros((nb, 3), np.int64)  # per block: bad thickness, bad voltage, invalid
    for b in prange(nb):
        i0 = b * BLOCK
        m = min(n, i0 + BLOCK) - i0
        tmp = np.empty((6, m))  # one allocation for the block's values
        lam, A2, bI, be, bb, bc = tmp[0], tmp[1], tmp[2], tmp[3], tmp[4], tmp[5]
        n_bad = 0
        for k in range(m):
            t = th[i0 + k] if sth else th[0]
            vv = v[i0 + k] if sv else v[0]
            lam[k], A2[k] = _groups_point(t, vv, lamc, a2c)
            if _input_code(t, vv):
                lam[k], A2[k] = math.nan, math.nan  # bad input: _closed_block gives NaN, _put flags it
                n_bad += 1
        _closed_block(lam, A2, A3, rho, model_id, order, bI, be, bb, bc)
        lb_th = 0
        lb_v = 0
        lb_inv = 0
        if n_bad == 0 and nan_invalid and not full:
            # the lean path of moment_integral: what _put does when every input is good,
            # without testing the inputs again or counting bad ones (_put in this loop, told
            # the inputs were checked, measured ~1.5 ns a point slower; the general loop ~8 ns)
            for k in range(m):
                i = i0 + k
                vv = v[i] if sv else v[0]
                ok = (be[k] < limit) and (bc[k] > 0.0 or any_thickness)
                valid[i] = ok
                Ii = bI[k] if vv >= 0.0 else -bI[k]
                I[i] = Ii if ok else math.nan
                lb_inv += not ok
        else:
            for k in range(m):
                i = i0 + k
                t = th[i] if sth else th[0]
                vv = v[i] if sv else v[0]
                code = _put(i, t, vv, lam[k], A2[k], bI[k], be[k], bb[k], bc[k], limit, any_thickness, nan_invalid,
                            full, I, err, B1, core, lam_o, A2_o, valid)
                lb_th += code == 2
                lb_v += code == 3
                lb_inv += code != 0
        counts[b, 0] = lb_th
        counts[b, 1] = lb_v
        counts[b, 2] = lb_inv
    return counts[:, 0].sum(), counts[:, 1].sum(), counts[:, 2].sum()


@jit_parallel
def _fused_points(th, v, lamc, a2c, A3, rho, model_id, order, any_thickness, limit,
                  I, err, B1, core, lam_o, A2_o, valid, nan_invalid):
    """The fused driver (:func:`_fused_driver`) point by point (``quadrature``, ``exact``)."""
    n = I.size
    sth = th.size > 1
    sv = v.size > 1
    full = err.size == n  # bookkeeping outputs wanted (all or none)
    fz = exact_frozen(rho, order == 3)  # the thick points' shared core nodes, once
    bad_th = 0
    bad_v = 0
    n_invalid = 0
    for i in prange(n):
        t = th[i] if sth else th[0]
        vv = v[i] if sv else v[0]
        lam = A2 = Ii = e_i = b1 = c = math.nan
        if not _input_code(t, vv):  # else no kernel call at all
            lam, A2 = _groups_point(t, vv, lamc, a2c)
            Ii, e_i, b1, c = _point(lam, A2, A3, rho, model_id, order, fz)
        code = _put(i, t, vv, lam, A2, Ii, e_i, b1, c, limit, any_thickness, nan_invalid, full,
                    I, err, B1, core, lam_o, A2_o, valid)
        bad_th += code == 2
        bad_v += code == 3
        n_invalid += code != 0
    return bad_th, bad_v, n_invalid


@jit
def _scalar_point(t, vv, lamc, a2c, A3, rho, model_id, order, any_thickness, limit, fz=None):
    """``(I, valid)`` of one point (the scalar fast path of :func:`moment_integral`); ``fz`` as
    :func:`_point` (kept between calls by the caller).  Quadrature and exact; the closed forms have
    :func:`_scalar_closed` (see :func:`_scalar_driver`)."""
    lam, A2 = _groups_point(t, vv, lamc, a2c)
    Ii, e_i, b1, c = _point(lam, A2, A3, rho, model_id, order, fz)
    return (Ii if vv >= 0.0 else -Ii), (e_i < limit) and (c > 0.0 or any_thickness)


@jit
def _scalar_closed(t, vv, lamc, a2c, A3, rho, model_id, order, any_thickness, limit):
    """:func:`_scalar_point` of the closed forms (:func:`_closed_point`: it compiles only them)."""
    lam, A2 = _groups_point(t, vv, lamc, a2c)
    Ii, e_i, b1, c = _closed_point(lam, A2, A3, rho, model_id, order)
    return (Ii if vv >= 0.0 else -Ii), (e_i < limit) and (c > 0.0 or any_thickness)


def _scalar_driver(order: int):
    """The scalar fast path's driver of the rung ``order``, chosen in Python as :func:`_fused_driver`."""
    return _scalar_closed if order in (1, 2) else _scalar_point


def _driver_constants(perm: Permittivity, mat: Material, fidelity: str) -> tuple:
    """Scalar arguments of the fused drivers after ``(th, v)``."""
    eps_core = perm.eps0 + perm.deps
    lamc = float(groups.debye_length(1.0, eps_core, mat))  # lam * thickness (lam ~ 1/e)
    return (lamc, groups.inverse_thermal_voltage(mat), float(groups.A3(mat)), perm.eps0 / eps_core,
            closed_model_id(perm, fidelity), _FIDELITY_SPECS[fidelity].kernel_code,
            _FIDELITY_SPECS[fidelity].any_thickness,
            validity_limit(fidelity))


def validity_limit(fidelity: str) -> float:
    """The error bound above which a result of ``fidelity`` is invalid.

    ``settings.VALIDITY_LIMIT``, or the rung's own ceiling where it is tighter: the
    two-term rungs (``corrected``, ``quadrature``) are exact up to the interaction of the
    layers across the core, so a bound above their ceiling means the layers interact and
    ``exact`` is the method that holds there.
    """
    return min(VALIDITY_LIMIT, _FIDELITY_SPECS[fidelity].ceiling)


#: interpret small inputs (see :func:`interpret_small`); off: always the compiled drivers.
#: A context variable: the switch holds in the context (thread, task) that set it.
_INTERPRET = contextvars.ContextVar("ipmc_asym_interpret_small", default=False)


class _Switch:
    """What :func:`interpret_small` returns: ``with`` restores the previous setting on exit."""

    def __init__(self, token):
        self._token = token

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        _INTERPRET.reset(self._token)
        return False


def interpret_small(enabled: bool = True) -> _Switch:
    """Evaluate small inputs with the interpreted twins of the drivers (``kernels.jit.interpreted``)
    as long as the compiled driver is not loaded in this process.

    ``interpret_small()`` switches it on for the rest of the context (what the one-shot
    ``ipmc-asym estimate`` does); ``with interpret_small(): ...`` only inside the block.

    For one-shot processes (``ipmc-asym estimate``): a few points cost ~30 us each
    interpreted, against ~0.5 s to load the compiled driver from the cache.  Same source,
    same operations: the results are those of the compiled driver (tested bit for bit);
    where the interpreter would raise (an inf or NaN on the way), the compiled driver runs.
    "Small" is ``points x registry interpreted_s <= settings.INTERPRET_BUDGET_S``.
    """
    return _Switch(_INTERPRET.set(bool(enabled)))


#: compiled seconds per point of each rung's fused driver, one thread (``ipmc-asym bench``,
#: order of magnitude): with :data:`PARALLEL_MIN_S`, the work below which one thread runs
COMPILED_S = {"leading": 4e-8, "corrected": 5e-8, "quadrature": 2.5e-6, "exact": 1e-5}
#: below this much single-thread work a parallel launch costs more than it saves: on this
#: 2-core machine 1000 ``leading`` points (~50 us) ran 1.2x slower on 2 threads than on 1,
#: 10 ``exact`` points (~100 us) 0.7x (``ipmc-asym bench``'s notes; wall clock, min of 15)
PARALLEL_MIN_S = 1e-4


def _run_driver(driver, n: int, fidelity: str, args, parallel: bool = False):
    """``driver(*args)``, or its interpreted twin where :func:`interpret_small` says so; a
    ``parallel`` driver on one Numba thread where the work is below :data:`PARALLEL_MIN_S` (the
    thread count changes no bit: blocks and points are independent, the counts are integers)."""
    cost = _FIDELITY_SPECS[fidelity].interpreted_s
    if _INTERPRET.get() and not driver.signatures and 0.0 < n * cost <= INTERPRET_BUDGET_S:
        try:
            with np.errstate(all="raise", under="ignore"):  # underflow: the same 0 compiled
                return interpreted(driver)(*args)
        except (ArithmeticError, ValueError):  # the compiled code returns inf/NaN there
            pass
    if parallel:
        return run_parallel(driver, n * COMPILED_S.get(fidelity, 0.0), args)
    return driver(*args)


def run_parallel(driver, work_s: float, args):
    """``driver(*args)`` for a ``prange`` driver, on one Numba thread where ``work_s`` (its
    single-thread seconds, from a per-point cost such as :data:`COMPILED_S`) is below
    :data:`PARALLEL_MIN_S`, on the caller's thread count above.

    The one thread rule of every parallel driver (moment, charge, per-sample moment): a parallel
    launch there costs more than it saves, and the thread count changes no bit (the points are
    independent).  The caller's setting is restored.
    """
    if work_s < PARALLEL_MIN_S:
        old = numba.get_num_threads()
        if old > 1:
            numba.set_num_threads(1)
            try:
                return driver(*args)
            finally:
                numba.set_num_threads(old)
    return driver(*args)


#: (model name, fidelity) -> driver constants of the default material (scalar fast path)
_SCALAR_CACHE: dict = {}
_SCALAR_TYPES = (float, int, np.float64)


def as_numbers(name: str, value, parse):
    """``value`` as numbers: a string with units (``"200um"``, ``"1V"``) through ``parse``; an
    array or number unchanged; anything else refused in one line naming ``name``."""
    if type(value) in _SCALAR_TYPES or isinstance(value, np.ndarray) and value.dtype.kind in "fiu":
        return value
    if isinstance(value, str):
        return parse(name, value)
    try:
        return np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a number, an array of numbers or a string with units; got "
                         f"{type(value).__name__} {str(value)[:40]!r}") from None


def _flat_input(a: np.ndarray, shape: tuple) -> np.ndarray:
    """A flat float64 view of ``a`` for the fused driver: size-1 inputs stay size 1, same-shape
    C-contiguous inputs are viewed; only a true broadcast of two arrays is materialised."""
    if a.size == 1:
        return a.reshape(1)
    if a.shape == shape and a.flags.c_contiguous:
        return a.reshape(-1)
    return np.ascontiguousarray(np.broadcast_to(a, shape)).reshape(-1)


def moment(thickness, voltage, model="constant", fidelity="quadrature", *, material: Material | None = None,
           progress: bool | None = None, **material_kw) -> MomentResult:
    """Moment integral with error estimate and validity flags.

    Parameters
    ----------
    thickness : float or array_like
        TOTAL thickness ``2e`` (m), > 0.
    voltage : float or array_like
        Voltage ``phi0`` (V); any sign, zero allowed.  Broadcast against ``thickness``.
    model : {"constant", "linear", "affine"} or Permittivity or callable
        Permittivity model; a custom ``eps(C)`` callable requires ``fidelity="bvp"``.
    fidelity : {"leading", "corrected", "quadrature", "exact", "bvp"}
    material : Material, optional
        Defaults to the ``nafion-li`` preset; ``**material_kw`` override its fields
        (e.g. ``c_moy="formula"``, ``phi4=0.4``).
    progress : bool, optional
        Progress bar for long BVP loops (default: when more than 20 points).

    Returns
    -------
    MomentResult
        Arrays of the broadcast shape (0-d arrays for scalar inputs).
    """
    check_fidelity(fidelity)
    return _moment(thickness, voltage, get_model(model), fidelity, _material(material, material_kw), progress,
                   floor_checked=False)


def _moment(thickness, voltage, perm: Permittivity, fidelity: str, mat: Material, progress=None, *,
            floor_checked: bool = True) -> MomentResult:
    """:func:`moment` on checked arguments (a rung name, a resolved model, a material; with
    ``floor_checked`` the thickness is known to be >= ``settings.MIN_THICKNESS``)."""
    if perm.is_custom and fidelity != "bvp":
        raise ValueError(f"a custom eps(C) needs fidelity 'bvp' (closed forms exist for "
                         f"constant, linear, affine); got fidelity {fidelity!r}")
    gperm = perm
    if perm.is_custom:  # groups of the secant through C = 0 and C_moy (bookkeeping only)
        e0, de = perm.secant(mat.C_moy)
        gperm = Permittivity("secant", eps0=e0, deps=de)
    if fidelity != "bvp":
        I, valid, (err, B1, core, lam, A2), (bad_th, bad_v, _) = _fused(thickness, voltage, gperm, mat, fidelity,
                                                                       full=True, floor=not floor_checked)
        if bad_th:
            raise ValueError("thickness (total, 2e) must be finite and > 0 m")
        if bad_v:  # not finite or past the cap: the line that says which
            check_voltages(voltage)
            raise ValueError("voltage must be finite (volts)")
        return MomentResult(I=I, error=err, B1=B1, core=core, lam=lam, A2=A2, valid=valid,
                            fidelity=fidelity, model=perm.name, success=np.ones(I.shape, bool),
                            **_inputs(thickness, voltage, I.shape))
    lam, A2, A3, rho, sign = _groups_arrays(thickness, voltage, gperm, mat, floor=not floor_checked)
    shape = lam.shape
    I = np.empty(shape)
    err = np.empty(shape)
    B1 = np.empty(shape)
    core = np.empty(shape)
    success, message = _bvp_loop(thickness, voltage, perm, mat, I, err, B1, core, progress)
    valid = (err < validity_limit(fidelity)) & ((core > 0) | _FIDELITY_SPECS[fidelity].any_thickness) & success
    return MomentResult(I=I, error=err, B1=B1, core=core, lam=lam, A2=A2, valid=valid,
                        fidelity=fidelity, model=perm.name, success=success, message=message,
                        **_inputs(thickness, voltage, shape))


def _inputs(thickness, voltage, shape) -> dict:
    """The inputs broadcast to the result's shape, as read-only views."""
    return {"thickness": np.broadcast_to(np.asarray(thickness, dtype=float), shape),
            "voltage": np.broadcast_to(np.asarray(voltage, dtype=float), shape)}


def paper_model_id(perm: Permittivity) -> int:
    """Registry id of the paper's model that ``perm`` is (same name, eps0 and eps_moy - eps0), else -1.

    The kernels specialised per model take this id; -1 selects their generic-rho form.
    """
    paper = MODELS.get(perm.name)
    if paper is None or (perm.eps0, perm.deps) != (paper.eps0, paper.deps):
        return -1
    return _MODEL_SPECS[perm.name].id


def closed_model_id(perm: Permittivity, fidelity: str) -> int:
    """Model id of the closed-form moment kernels (-1 for ``quadrature``/``exact``: any rho).

    The closed forms of ``I`` are derived for the paper's three (eps0, eps_moy - eps0) pairs
    only: a one-line ``ValueError`` for any other model at a closed-form rung.  (The charge's
    closed forms hold for any rho: :func:`paper_model_id`.)
    """
    if not _FIDELITY_SPECS[fidelity].closed_form:
        return -1
    mid = paper_model_id(perm)
    if mid < 0:
        raise ValueError(
            f"closed forms ({fidelity!r}) are derived for the paper's constant, linear and affine "
            f"models only; use fidelity 'quadrature' or 'bvp' for {perm.name!r} with "
            f"eps0={perm.eps0:g}, eps_moy-eps0={perm.deps:g} F/m"
        )
    return mid


def _bvp_loop(thickness, voltage, perm, mat, I, err, B1, core, progress):
    """Point-by-point BVP; a failed point gets ``I = NaN``, ``error = inf`` (never raises).

    Solved at ``|phi0|`` and signed afterwards (``I`` is odd): ``B1`` is that of ``|phi0|``
    directly, with no ``B1 exp(A2)`` round trip (which overflows above ~18 V).

    Returns ``(success, first failure message)``.
    """
    from ipmc_asym.bvp.solver import (
        solve,  # deferred: scipy.integrate is heavy (start-up of the closed forms)
    )

    th, v = np.broadcast_arrays(np.asarray(thickness, float), np.asarray(voltage, float))
    n = th.size
    ok = np.ones(th.shape, bool)
    msg = ""
    show = (n > 20) if progress is None else progress
    bar = _progress_bar(n, "BVP", enabled=show)
    eps_core = perm.eps0 + perm.deps if not perm.is_custom else None
    for idx in np.ndindex(th.shape):
        vi = float(v[idx])
        a2 = float(groups.A2(vi, mat))
        if eps_core is not None and 0.0 < a2 < DH_A2:
            # small voltage: the collocation loses ~eps/A2 of C - 1 (and fails in the subnormal
            # range); the Debye-Hueckel series is exact there, its bound far below BVP_STATED_ERROR
            lam = float(groups.debye_length(float(th[idx]), eps_core, mat))
            Ii, e_i, b1 = dh_exact(lam, a2, float(groups.A3(mat)), perm.eps0 / eps_core)
            I[idx], err[idx], B1[idx], core[idx] = math.copysign(Ii, vi), BVP_STATED_ERROR + e_i, b1, 2.0
            bar.update(1)
            continue
        res = solve(Strip(thickness=float(th[idx]), voltage=abs(vi)), perm, mat)
        core[idx] = 2.0
        if not res.success:
            ok[idx] = False
            I[idx], err[idx], B1[idx] = math.nan, math.inf, math.nan
            if not msg:
                msg = (f"BVP did not converge at thickness (total) {float(th[idx]):.3g} m, voltage "
                       f"{vi:.3g} V ({res.message.rstrip('.')})")
        else:
            I[idx] = math.copysign(res.I, vi) if vi != 0.0 else 0.0
            err[idx] = BVP_STATED_ERROR
            B1[idx] = res.B1
        bar.update(1)
    bar.close()
    return ok, msg


def moment_integral(thickness, voltage, model="constant", fidelity="quadrature", *, material=None,
                    on_invalid="raise", **material_kw):
    """Moment integral ``I = int_{-1}^{1} p_bar z_bar dz_bar`` (dimensionless).

    Parameters
    ----------
    thickness : float or array_like
        TOTAL thickness ``2e`` in metres (>= ``settings.MIN_THICKNESS``).
    voltage : float or array_like
        Voltage ``phi0`` in volts (sign = bending direction; 0 gives 0).
    model : {"constant", "linear", "affine"}, Permittivity or callable
    fidelity : {"leading", "corrected", "quadrature", "exact", "bvp"}
    material : Material, optional; ``**material_kw`` override fields of the preset.
    on_invalid : {"raise", "nan", "warn"}
        Where the fidelity is outside its validity (error estimate above ``VALIDITY_LIMIT``,
        overlapping layers, or a BVP that did not converge): a one-line ``ValueError``
        (default), or NaN at those points (``"warn"``: NaN plus a ``RuntimeWarning``).  A
        number whose validity check failed is never returned; :func:`moment` gives the
        flags and estimates, and :func:`ipmc_asym.evaluate` escalates.

    Returns
    -------
    float or ndarray
        ``I`` with the broadcast shape of the inputs (a float for scalar inputs).
        ``M_A = A5 I`` with ``A5 = 6 l e^2 F |phi0| C_moy``.
    """
    check_choice("on_invalid", on_invalid, ("raise", "nan", "warn"))
    thickness = as_numbers("thickness (total, 2e)", thickness, parse_length)
    voltage = as_numbers("voltage", voltage, parse_voltage)
    # scalar fast path: one compiled call, no arrays (falls through on anything unusual,
    # including an invalid point, which then gets the full treatment below)
    if (type(thickness) in _SCALAR_TYPES and type(voltage) in _SCALAR_TYPES and material is None
            and not material_kw and type(model) is str):
        consts = _SCALAR_CACHE.get((model, fidelity))
        if consts is None and model in _MODEL_SPECS and is_compiled(fidelity):
            consts = _driver_constants(get_model(model), NAFION_LI, fidelity)
            if _FIDELITY_SPECS[fidelity].kernel_code == 3:  # exact: the frozen cores, once a process
                consts += (exact_frozen(consts[3], True),)
            _SCALAR_CACHE[(model, fidelity)] = consts
        t, vv = float(thickness), float(voltage)
        if consts is not None and t >= MIN_THICKNESS and math.isfinite(t) and abs(vv) <= MAX_VOLTAGE:
            Ii, ok = _run_driver(_scalar_driver(consts[5]), 1, fidelity, (t, vv, *consts))
            if ok:
                return Ii
    lean = _lean_integral(thickness, voltage, model, fidelity, material, material_kw)
    if lean is not None:  # I and valid only; the bookkeeping of moment() for invalid points only
        I, valid, n_invalid = lean
        if n_invalid:  # I is NaN there already
            bad = ~valid
            if on_invalid in ("raise", "warn"):
                shape = I.shape
                sub = moment(np.broadcast_to(np.asarray(thickness, float), shape)[bad],
                             np.broadcast_to(np.asarray(voltage, float), shape)[bad], model, fidelity,
                             material=material, **material_kw)
                msg = invalid_message(sub, total=I.size)
                if on_invalid == "raise":
                    raise ValueError(msg)
                warnings.warn(msg, RuntimeWarning, stacklevel=2)
        return float(I) if I.ndim == 0 else I
    r = moment(thickness, voltage, model, fidelity, material=material, **material_kw)
    bad = ~np.asarray(r.valid)
    I = np.array(r.I, dtype=float)
    if np.any(bad):
        msg = invalid_message(r)
        if on_invalid == "raise":
            raise ValueError(msg)
        if on_invalid == "warn":
            warnings.warn(msg, RuntimeWarning, stacklevel=2)
        I[bad] = np.nan
    return float(I) if I.ndim == 0 else I


def _lean_integral(thickness, voltage, model, fidelity, material, material_kw):
    """``(I, valid, n_invalid)`` from the fused driver with no bookkeeping outputs (9 bytes a
    point; NaN in ``I`` where invalid), or None where :func:`moment` is needed (BVP, custom
    eps(C), bad input: its messages)."""
    if not is_compiled(fidelity) or not (isinstance(model, str) or isinstance(model, Permittivity)):
        return None
    perm = get_model(model)
    if perm.is_custom:
        return None
    I, valid, _, (bad_th, bad_v, n_invalid) = _fused(thickness, voltage, perm, _material(material, material_kw),
                                                     fidelity, full=False)
    if bad_th or bad_v:
        return None
    return I, valid, n_invalid


def _fused(thickness, voltage, perm: Permittivity, mat: Material, fidelity: str, full: bool, floor: bool = True):
    """Run the fused driver on broadcast inputs (TOTAL thickness in m, volts).

    Returns ``(I, valid, bookkeeping, counts)``: ``bookkeeping`` is ``(error, B1, core, lam,
    A2)`` if ``full``, else ``()`` and ``I`` is NaN where invalid (what :func:`moment_integral`
    returns); ``counts`` are the driver's (bad thicknesses, bad voltages, invalid points).
    ``floor``: check the thickness floor (False where the caller has).
    """
    th = np.asarray(thickness, dtype=np.float64)
    v = np.asarray(voltage, dtype=np.float64)
    shape = np.broadcast_shapes(th.shape, v.shape)
    I = np.empty(shape)
    valid = np.empty(shape, dtype=np.bool_)
    extra = tuple(np.empty(shape) for _ in range(5)) if full else ()
    if floor:  # False: the caller's Strip or edge check holds the thickness floor and the voltage cap
        check_min_thickness(th)
        if v.size:  # max and min: no temporary array (NaN and inf are the driver's to report)
            m = max(float(np.max(v)), -float(np.min(v)))
            if MAX_VOLTAGE < m < math.inf:
                check_voltages(v)
    outs = [a.reshape(-1) for a in extra] if full else [np.empty(0)] * 5
    counts = _run_driver(_fused_driver(_FIDELITY_SPECS[fidelity].kernel_code), I.size, fidelity, (
        _flat_input(th, shape), _flat_input(v, shape), *_driver_constants(perm, mat, fidelity),
        I.reshape(-1), *outs, valid.reshape(-1), not full), parallel=True)
    return I, valid, extra, counts


def invalid_message(r: MomentResult, total: int | None = None) -> str:
    """One line: where and why ``r`` is outside its validity (``total``: the number of points
    of the call, when ``r`` holds only some of them)."""
    bad = ~np.asarray(r.valid)
    n = int(bad.sum())
    total = bad.size if total is None else int(total)
    if r.fidelity == "bvp" and r.message:
        return f"{r.message}; no valid result at {n} of {total} point(s)"
    e = np.asarray(r.error)
    worst = float(np.max(np.where(bad, e, 0.0))) if n else 0.0
    return (f"fidelity {r.fidelity!r} is outside its validity at {n} of {total} point(s) "
            f"(error estimate up to {worst:.2g} > {validity_limit(r.fidelity):g}, or electrode layers "
            "overlapping); use a higher fidelity ('exact' where layers overlap), or ipmc_asym.evaluate, which escalates")
