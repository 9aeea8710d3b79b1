"""Full nonlinear boundary-value problem across the thickness (the numerical cross-check).

Dimensionless model (paper sections 4-5; docs/design.md), ``z`` = ``z/e`` in
``[-1, 1]`` (anode ``z = -1``, cathode ``z = +1``)::

    E = -phi'        D = eps E        D' = C - 1        eps = A0 C + A1
    C' = A2 C E      p' = (C + A3) E
    phi(-1) = 1,  phi(1) = 0,  D(1) = D(-1)        (i.e. integral of (C - 1) is 0)

so that ``C = B1 exp(-A2 phi)`` and ``p = C/A2 - A3 phi + B2``.  The moment integral is

    I = int_{-1}^{1} p z dz = (1/A2) int (C - 1) z dz + (A3/A2) int y z dz,   y = ln C.

Variables
---------
For the affine family ``eps = A0 C + A1`` the state is ``(s, D, Q)`` with the well-scaled
``s = A0 C + A1 ln C`` (so that ``s' = eps y' = A2 D`` exactly, also where ``eps -> 0``)::

    s' = A2 D,   D' = C(s) - 1,   Q' = ((C - 1) + A3 y) z / A2,   Q(-1) = 0,  I = Q(1)

and the unknown parameter ``b = ln B1``; boundary conditions ``s(-1) = S(b - A2)``,
``s(1) = S(b)`` with ``S(y) = A0 e^y + A1 y``, ``D(1) = D(-1)``, ``Q(-1) = 0``.
``C(s)`` inverts ``A0 C + A1 ln C = s`` (a safeguarded Newton iteration in ``ln C``, never
overflowing).  Jacobians are analytic.

When ``A1 = 0`` (linear model) ``ln C`` has a logarithmic singularity cut off at
``C(-1) = B1 exp(-A2) ~ 1e-17`` within ~1e-19 of the anode, which no collocation mesh can
resolve; ``Q`` then carries only the ``(C - 1) z / A2`` part and ``int y z dz`` is done after
the solve by quadrature on the collocation spline, with an exact log-integral on the cell
touching the anode (see :func:`ipmc_asym.bvp.problems.moment_y_linear`).

A custom ``eps(C)`` callable (SI) uses ``y = ln C`` as the state
(``y' = A2 D / eps_bar(e^y)``) with a finite-difference derivative of ``eps``.

Negative voltage is the mirror image ``z -> -z`` (``I`` is odd in the voltage); zero volts
gives ``I = 0`` and flat profiles without calling the solver.

Modules: :mod:`ipmc_asym.bvp.problems` (ODE systems, boundary conditions, Jacobians),
:mod:`ipmc_asym.bvp.mesh` (graded mesh, initial guess) and this solve driver
(:func:`solve`, :class:`BVPResult`, :func:`moment_integral_bvp`).
Layer rule: moment layer; params, permittivity, settings, bvp_* (plus numpy/scipy).
"""

from __future__ import annotations

import math
import time
import warnings
from dataclasses import dataclass
from types import SimpleNamespace

import numpy as np
from scipy.integrate import solve_bvp

from ipmc_asym.base.results import Panel, ResultMixin, ResultSpec
from ipmc_asym.base.settings import BVP_MAX_NODES, BVP_MAX_NODES_FIRST, BVP_TOL, BVP_TOL_FALLBACK
from ipmc_asym.bvp.mesh import first_spacings, initial_guess, make_mesh
from ipmc_asym.bvp.problems import (
    EXP_MAX,
    TINY,
    AffineProblem,
    CustomProblem,
    H,
    b1_guess,
    eps_bar_custom,
    moment_y_linear,
)
from ipmc_asym.model import groups
from ipmc_asym.model.params import NAFION_LI, Groups, Material, Strip, check_finite, check_positive
from ipmc_asym.model.permittivity import Permittivity, get_model

__all__ = ["BVPResult", "solve", "moment_integral_bvp", "b1_guess", "make_mesh", "min_voltage"]

_SUGGEST = (
    "try a looser tol (e.g. 1e-8), a larger max_nodes, continuation=True, or a voltage/"
    "thickness closer to the nominal range (10 um - 4 mm, 1 mV - 10 V)"
)


# ---------------------------------------------------------------------------------------
# result container
# ---------------------------------------------------------------------------------------
@dataclass(repr=False)
class BVPResult(ResultMixin):
    """Solution of the full BVP on its final mesh (all quantities dimensionless).

    Attributes
    ----------
    z : ndarray, shape (n,)
        Mesh, ``z/e`` in ``[-1, 1]`` (anode of the positive voltage at ``-1``).
    C : ndarray, shape (n,)
        Cation concentration ``C/C_moy``.
    phi : ndarray, shape (n,)
        Potential ``phi/|phi0|`` relative to the face ``z = +1``: ``phi(-1) = sign(phi0)``,
        ``phi(1) = 0``.
    E : ndarray, shape (n,)
        Field ``-dphi/dz`` (``E_bar = D_bar / eps_bar``).
    D : ndarray, shape (n,)
        Electric induction ``D_bar`` (``D' = C - 1``).
    rhoZ : ndarray, shape (n,)
        Charge density ``C - 1``.
    p : ndarray, shape (n,)
        Pressure ``p_bar = C/A2 - A3 phi``, i.e. the constant ``B2`` is set to 0 (it does not
        enter ``I`` because ``int z dz = 0``).
    y : ndarray, shape (n,)
        ``ln C``.
    B1 : float
        Constant of ``C = B1 exp(-A2 phi)`` in the convention of ``phi`` above (for a negative
        voltage this is ``B1(|phi0|) exp(-A2)``).
    I : float
        Moment integral ``int p z dz`` (signed, odd in the voltage).  ``M_A = A5 I``.
    groups : Groups
    model : str
    success : bool
        ``True`` iff solve_bvp reported status 0 (and the result is finite).
    status : int
        solve_bvp status (0 converged, 1 max_nodes exceeded, 2 singular Jacobian,
        3 tolerance too small), -1 for an internal failure.
    message : str
    niter : int
        Newton/refinement iterations of the last solve_bvp call.
    n_nodes : int
    max_rms_residual : float
        Largest relative rms collocation residual on the final mesh.
    bc_residual : float
        Largest absolute boundary-condition residual.
    seconds : float
        Wall time of :func:`solve`.
    sol : callable or None
        The continuous solution (solve_bvp's ``sol``, a cubic spline): ``sol(z)`` returns
        the state at ``z`` (shape (3, len(z))), ``(s, D, Q)`` for the paper's models
        (``s = A0 C + A1 ln C``) or ``(ln C, D, Q)`` for a custom ``eps(C)``, in the
        positive-voltage frame (for a negative voltage evaluate at ``-z``); ``None`` at zero
        volts or after an internal failure.
    """

    _result = ResultSpec("z", "z", ("C", "phi", "E", "D", "rhoZ", "p"),
                         (Panel("z", ("C",), ylog=True), Panel("z", ("phi",)), Panel("z", ("p",))), ("B1", "I"))

    z: np.ndarray
    C: np.ndarray
    phi: np.ndarray
    E: np.ndarray
    D: np.ndarray
    rhoZ: np.ndarray
    p: np.ndarray
    y: np.ndarray
    B1: float
    I: float
    groups: Groups
    model: str
    success: bool
    status: int
    message: str
    niter: int
    n_nodes: int
    max_rms_residual: float
    bc_residual: float
    seconds: float
    sol: object = None


# ---------------------------------------------------------------------------------------
# driver
# ---------------------------------------------------------------------------------------
def _run(prob, z, U, b, tol, max_nodes):
    """solve_bvp; a floating-point error inside it becomes a failed result (status -1)."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return solve_bvp(prob.fun, prob.bc, z, U, p=np.array([b]), fun_jac=prob.fun_jac,
                             bc_jac=prob.bc_jac, tol=tol, bc_tol=tol, max_nodes=max_nodes,
                             verbose=0)
    except (FloatingPointError, np.linalg.LinAlgError, OverflowError) as exc:
        return SimpleNamespace(status=-1, message=f"numerical failure in solve_bvp: {exc}",
                               x=z, y=U, p=np.array([b]), sol=None, rms_residuals=None,
                               niter=0, success=False)


def _solve_abs(strip: Strip, perm: Permittivity, material: Material, tol: float,
               max_nodes: int, guess=None):
    """Solve at ``|phi0|`` (positive frame).  Returns ``(res, prob, g)``."""
    g = perm.groups(strip.with_(voltage=abs(strip.voltage)), material)
    b0 = math.log(b1_guess(g.A0, g.A1, g.A2)) if (g.A0 > 0 or g.A1 > 0) else 0.0
    if perm.is_custom:
        y_lo, y_hi = b0 - g.A2 - 20.0, b0 + 20.0
        prob = CustomProblem(g, eps_bar_custom(perm.func, g, material), y_lo, y_hi)
        # validate eps on the whole window the iterates may visit (raises ValueError)
        prob.eps_of_C(np.exp(np.linspace(y_lo, y_hi, 400)))
    else:
        prob = AffineProblem(g)
    h0_a, h0_c, lam = first_spacings(g, prob.eps_of_C, b0, tol, perm.is_custom)
    z = make_mesh(h0_a, h0_c, h_core=min(0.02, 2.0 * lam + 1e-3))
    if guess is None:
        y, D = initial_guess(z, g, prob, b0, lam)
    else:
        zo, phio, Do, bo = guess  # phi profile of a lower voltage, same geometry
        y = b0 - g.A2 * np.interp(z, zo, phio)
        A0e, A1e = (g.A0, g.A1) if not perm.is_custom else (g.A0, max(g.A1, 1e-300))
        D = np.sqrt(2.0 * np.maximum(H(y, A0e, A1e), 0.0) / g.A2)
    U = prob.state_from_yD(z, y, D)
    res = _run(prob, z, U, b0, tol, max_nodes)
    return res, prob, g


def _bc_res(prob, res) -> float:
    return float(np.max(np.abs(prob.bc(res.y[:, 0], res.y[:, -1], res.p))))


#: below this ``A2 = F |phi0|/(R T)`` (~26 nV at 300 K) the collocation loses ``C - 1 ~ A2`` to
#: rounding (measured: 5e-12 relative at A2 = 3.9e-6, 1.7e-9 at 3.9e-8, no convergence at
#: 3.9e-11, against the Debye-Hueckel series): :func:`solve` refuses rather than exceed
#: ``BVP_STATED_ERROR``
BVP_MIN_A2 = 1e-6


def min_voltage(material: Material) -> float:
    """The smallest ``|phi0|`` (V) that :func:`solve` resolves: :data:`BVP_MIN_A2` thermal voltages."""
    return BVP_MIN_A2 * float(groups.thermal_voltage(material))


def solve(strip: Strip, model="constant", material: Material = NAFION_LI, *, tol: float = BVP_TOL,
          max_nodes: int = BVP_MAX_NODES, continuation: bool = True,
          fallback: bool = True) -> BVPResult:
    """Solve the full nonlinear BVP across the thickness and return profiles and ``I``.

    Parameters
    ----------
    strip : Strip
        Geometry and voltage (SI; ``thickness`` is the total ``2e``).  Only ``thickness``
        and ``voltage`` enter the solution (``width`` enters ``groups.A5``).
    model : str, Permittivity or callable
        ``"constant"``, ``"linear"``, ``"affine"``, a :class:`Permittivity`, or a callable
        ``eps(C)`` (C in mol/m^3, returns F/m; must be finite and > 0 on the solution's
        concentration range, else ``ValueError``).
    material : Material
    tol : float
        solve_bvp relative residual tolerance (also used as ``bc_tol``).
    max_nodes : int
    continuation : bool
        If the direct solve fails, solve at smaller voltages and step up to the target,
        reusing each solution as the next guess.
    fallback : bool
        If ``tol`` cannot be met, retry with the looser ``settings.BVP_TOL_FALLBACK``
        tolerances (rounding-limited meshes where the layers overlap; ``I`` moves by
        < 1e-12 relative there).  The attempts before the last are capped at
        ``settings.BVP_MAX_NODES_FIRST`` nodes so that a hopeless attempt fails fast.
        The message says which tolerance was met.

    Returns
    -------
    BVPResult
        ``success=False`` (with solve_bvp's message) if no converged solution was found;
        the arrays then hold the last iterate.
    """
    t0 = time.perf_counter()
    if not isinstance(strip, Strip):
        raise ValueError(f"strip must be a Strip; got {strip!r}")
    check_positive("tol", tol)
    if int(max_nodes) < 10:
        raise ValueError(f"max_nodes must be an integer >= 10; got {max_nodes!r}")
    perm = get_model(model)
    a2 = float(groups.A2(strip.voltage, material))
    if 0.0 < a2 < BVP_MIN_A2:
        raise ValueError(
            f"voltage |phi0| = {abs(float(strip.voltage)):.3g} V is below the {min_voltage(material):.3g} V "
            "the BVP resolves (C - 1 ~ A2 is lost to rounding); the moment integral there is the "
            "Debye-Hueckel series of ipmc_asym.integral.api.moment (any fidelity)")
    g_signed = perm.groups(strip, material)
    name = perm.name
    if strip.voltage == 0.0:
        z = np.linspace(-1.0, 1.0, 3)
        zero = np.zeros_like(z)
        return BVPResult(z=z, C=np.ones_like(z), phi=zero.copy(), E=zero.copy(), D=zero.copy(),
                         rhoZ=zero.copy(), p=zero.copy(), y=zero.copy(), B1=1.0, I=0.0,
                         groups=g_signed, model=name, success=True, status=0,
                         message="zero voltage: no field, no bending", niter=0, n_nodes=3,
                         max_rms_residual=0.0, bc_residual=0.0,
                         seconds=time.perf_counter() - t0)

    res, prob, g = _solve_abs(strip, perm, material, tol, max_nodes if not fallback
                              else min(int(max_nodes), BVP_MAX_NODES_FIRST))
    if res.status == 0 or not (continuation or fallback):
        return _finish(res, prob, g, g_signed, name, t0, "")
    first = (res, prob, g)
    # Continuation in voltage at the loosest tolerance allowed (the direct solve fails where
    # the neutral-core guess is poor, e.g. overlapping layers); then refine that solution at
    # the tolerances asked for, tightest first, each a single solve from it.
    loose = [t for t in BVP_TOL_FALLBACK if t > tol] if fallback else []
    t_cont = loose[-1] if loose else tol
    cont = _continuation(strip, perm, material, t_cont, int(max_nodes)) if continuation else None
    if cont is None or cont[0].status != 0:
        if fallback and not continuation:
            for t in loose:
                r = _solve_abs(strip, perm, material, t, int(max_nodes))
                if r[0].status == 0:
                    return _finish(*r, g_signed, name, t0, f" (tolerance relaxed to {t:g})")
        return _finish(*first, g_signed, name, t0, "")
    res_c, prob_c, g_c = cont
    for t in [tol] + loose[:-1]:
        r = _run(prob_c, res_c.x, res_c.y, float(res_c.p[0]), t,
                 min(int(max_nodes), BVP_MAX_NODES_FIRST))
        if r.status == 0:
            return _finish(r, prob_c, g_c, g_signed, name, t0, " (after voltage continuation)")
    how = " (after voltage continuation)" + (f" (tolerance relaxed to {t_cont:g})" if t_cont != tol else "")
    return _finish(res_c, prob_c, g_c, g_signed, name, t0, how)


def _continuation(strip, perm, material, tol, max_nodes):
    """Find a voltage where the direct solve works, then step up by factors <= 2."""
    V = abs(strip.voltage)
    v = V
    ok = None
    for _ in range(12):
        v /= 4.0
        r = _solve_abs(strip.with_(voltage=v), perm, material, tol, max_nodes)
        if r[0].status == 0:
            ok = r
            break
    if ok is None:
        return None
    while v < V:
        res, prob, g = ok
        C, y, D = prob.profiles(res.x, res.y, res.p[0])
        phi = (res.p[0] - y) / g.A2
        v_next = min(2.0 * v, V)
        r = _solve_abs(strip.with_(voltage=v_next), perm, material, tol, max_nodes,
                       guess=(res.x, phi, D, res.p[0]))
        if r[0].status != 0:
            return r if v_next == V else None
        ok, v = r, v_next
    return ok


def _finish(res, prob, g, g_signed, name, t0, how) -> BVPResult:
    z = res.x
    b = float(res.p[0])
    C, y, D = prob.profiles(z, res.y, b)
    A2, A3 = g.A2, g.A3
    # b = ln B1 of a converged solution is a few units (B1 ~ A2 at most); above EXP_MAX it is
    # the last iterate of a diverged solve, which has no B1 nor I to report
    diverged = not b <= EXP_MAX
    if res.sol is None or diverged:
        I = float("nan")
    elif isinstance(prob, AffineProblem) and g.A1 == 0.0:
        Iy = moment_y_linear(res.sol, z, g, b, float(res.y[1, 0]))
        I = float(res.y[2, -1]) + A3 / A2 * Iy
    else:
        I = float(res.y[2, -1])
    phi = (b - y) / A2
    eps = prob.eps_of_C(C)
    # linear model: eps -> A0 C(-1) ~ B1 e^{-A2} A0 at the anode, E is huge there (floored
    # denominator only to stay finite when exp(-A2) underflows)
    E = D / np.maximum(eps, TINY)
    B1 = math.inf if diverged else math.exp(b)
    success = bool(res.status == 0 and np.isfinite(I))
    msg = res.message + how
    if g_signed.sign < 0:  # mirror image z -> -z, potential referenced to the face z = +1
        z = -z[::-1]
        C, y = C[::-1].copy(), y[::-1].copy()
        D, E = -D[::-1], -E[::-1]
        phi = phi[::-1] - 1.0
        B1 = math.inf if diverged else math.exp(b - A2)
        I = -I
    p = C / A2 - A3 * phi
    rms = float(np.max(res.rms_residuals)) if res.rms_residuals is not None else float("nan")
    return BVPResult(z=z, C=C, phi=phi, E=E, D=D, rhoZ=C - 1.0, p=p, y=y, B1=B1, I=I,
                     groups=g_signed, model=name, success=success, status=int(res.status),
                     message=msg, niter=int(res.niter), n_nodes=int(z.size),
                     max_rms_residual=rms, bc_residual=math.inf if diverged else _bc_res(prob, res),
                     seconds=time.perf_counter() - t0, sol=res.sol)


def moment_integral_bvp(thickness, voltage, model="constant", material: Material = NAFION_LI,
                        *, tol: float = BVP_TOL) -> float:
    """Moment integral ``I = int p z dz`` from the full BVP (dimensionless, signed).

    Parameters
    ----------
    thickness : float
        TOTAL thickness ``2e``, m (> 0).
    voltage : float
        Applied voltage ``phi0``, V (any sign; 0 gives 0).
    model : str, Permittivity or callable
    material : Material
    tol : float

    Returns
    -------
    float
        ``I``; ``M_A = A5 I``.

    Raises
    ------
    ValueError
        Bad input.
    RuntimeError
        The BVP did not converge (never returns an unconverged number).
    """
    th = check_positive("thickness (total, 2e)", thickness, "m")
    v = check_finite("voltage", voltage, "a finite number of volts")
    r = solve(Strip(thickness=th, voltage=v), model, material, tol=tol)
    if not r.success:
        raise RuntimeError(f"BVP did not converge ({r.message}); {_SUGGEST}")
    return r.I
