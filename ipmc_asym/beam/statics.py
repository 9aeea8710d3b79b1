r"""Cantilever mechanics of the strip: rotation, tip deflection and blocking force.

Seed paper (Tixier & Pouget), section 3 "Modèle de poutre en grands déplacements".
The strip of length ``L`` is clamped at ``x = 0`` (point O) and loaded at its end A by the
bending moment ``M`` (the paper's :math:`M_A^p`, produced by the electro-osmotic pressure)
and, in the blocked case, by a transverse force ``F`` (the paper's :math:`F^p`).
``EI`` is the bending stiffness :math:`E I^p` with :math:`I^p = 4 l e^3/3` (``l``, ``e`` the
half width and half thickness).  All quantities are SI (N m, m, N m^2, N, rad).

Sign conventions (exactly the paper's)
--------------------------------------
Unstretched beam (``ds = ds_bar``), arc length ``s`` from O, section rotation ``theta(s)``,
axis ``Ox`` along the undeformed strip and ``Oz`` normal to it:

.. math::

    \frac{d\theta}{ds} = \frac{F}{EI}(L - s) - \frac{M}{EI}, \qquad
    \frac{dx}{ds} = \cos\theta, \qquad \frac{dz}{ds} = \sin\theta,

with ``theta(0) = x(0) = z(0) = 0``.  A positive ``M`` therefore bends the strip towards
``z < 0``.  The lever arm of ``F`` is taken as ``L - s`` (the paper's simplification, kept
here) so that ``theta(s) = F s (2L - s)/(2 EI) - M s/EI`` (paper eq. after the strain law).

Free end (``F = 0``), with the curvature ``kappa = M/EI`` (paper eq. (w)):

* ``theta = -kappa L``                                  (:func:`rotation`)
* ``w = z(L) = (cos(kappa L) - 1)/kappa = -2 sin^2(kappa L/2)/kappa``
  (:func:`tip_deflection`; evaluated as ``-(kappa L^2/2) sinc^2(kappa L/2)``, no cancellation)
* ``x(L) = sin(kappa L)/kappa = L sinc(kappa L)``       (:func:`tip_position`, derived here)
* small displacements: ``w_p = -M L^2/(2 EI)``          (:func:`tip_deflection_small`)

so that ``w / w_p = sinc^2(kappa L/2) = 1 - (kappa L)^2/12 + O((kappa L)^4)`` and the
relative error of the small-displacement formula is
``|w_p - w|/|w| = u^2/sin^2 u - 1 = u^2/3 + u^4/15 + 2u^6/189 + ...``, ``u = kappa L/2``
(:func:`small_displacement_error`), i.e. ``(kappa L)^2/12`` to leading order.

Blocked end (``z(L) = 0``):

* small displacements: ``F = 3 M/(2 L)`` (paper eq. (FP), :func:`blocking_force_small`);
* large displacements: ``F`` solves (paper, last eq. of section 3)
  ``int_0^L sin[F x (2L - x)/(2 EI) - M x/EI] dx = 0`` (:func:`blocking_force_large`).
  With ``m = kappa L`` and ``F = psi(m) M/L`` this is
  ``G(psi, m) = int_0^1 sin(m [psi (t - t^2/2) - t]) dt = 0``, evaluated in closed form with
  Fresnel integrals.  ``psi`` is even in ``m`` and the branch continuous with the small
  solution ``psi(0) = 3/2`` has the series (derived with SymPy, see ``tests/beam/test_statics.py``)
  ``psi = 3/2 - m^2/2240 - 221 m^4/165580800 - 29479 m^6/7232569344000 - ...``, so
  ``|F_small - F|/|F| = m^2/3360 + O(m^4)`` -- 2.5e-4 at ``kappa L = 0.92``, well inside the
  paper's "< 1 %".

Beyond the series range the branch is followed by numerical continuation in ``m`` (done
once, Newton's method on the Fresnel expression at every node, cached on disk), and a point
between the nodes is an 8-point interpolation of the table, at rounding level (<= 3.3e-15,
measured and tested against Newton-converged roots).  The branch has no fold as far as it
was traced (``|kappa L|`` up to 550 in development; ``psi`` decreases slowly towards 1), but
it is only tabulated up to :data:`KL_BLOCK_MAX`; beyond that ``F_block`` is NaN and
:func:`solve_beam` says so in its warnings -- never a root of another branch.

Validity: the beam model is a small-strain one (``e |kappa| << 1``, :func:`max_strain`).
Past a quarter turn (``|theta| > pi/2``) the arc curls back and ``w`` is no longer monotone
in ``M``; past a full turn (``|theta| > 2 pi``) ``w`` is periodic in ``M``
(:func:`regime`).
"""

from __future__ import annotations

import functools
import hashlib
import math
import os
import tempfile
from dataclasses import dataclass, field

import numpy as np

from ipmc_asym.base.results import Panel, ResultMixin, ResultSpec
from ipmc_asym.kernels.jit import CACHE_DIR
from ipmc_asym.kernels.quadrature_nodes import leggauss01

__all__ = [
    "KL_BLOCK_MAX",
    "DEFAULT_SMALL_TOL",
    "REGIMES",
    "regime_code",
    "BeamResult",
    "rotation",
    "curvature",
    "tip_deflection",
    "tip_deflection_small",
    "tip_position",
    "small_displacement_error",
    "blocking_force_small",
    "blocking_force_large",
    "blocking_force_ratio",
    "blocking_force_error",
    "blocking_residual",
    "max_strain",
    "regime",
    "solve_beam",
]

#: Largest ``|kappa L|`` (rad) for which the large-displacement blocking force is returned.
KL_BLOCK_MAX = 100.0
#: Default relative tolerance for calling the small-displacement formula "small" (1 %).
DEFAULT_SMALL_TOL = 0.01
#: Regime labels returned by :func:`regime`, in increasing order of bending.
REGIMES = ("small", "large", "past-quarter-turn", "multi-turn")

# Series psi(m) = 3/2 + sum c_k m^k of the blocking-force branch (even in m).
_PSI_SERIES = (1.5, -1.0 / 2240.0, -221.0 / 165580800.0, -29479.0 / 7232569344000.0)
_SERIES_KL = 0.25  # |m| below which the series is used (next term ~ 1e-16 relative)
_TABLE_STEP = 0.02


def _out(x):
    """Return a Python float for 0-d results, the array otherwise."""
    x = np.asarray(x)
    return float(x) if x.ndim == 0 else x


def _check_pos(name, v):
    a = np.asarray(v, dtype=float)
    if not np.all(np.isfinite(a)) or np.any(a <= 0.0):
        raise ValueError(f"{name} must be finite and > 0; got {v!r}")
    return a


def _mLEI(M, L, EI):
    M = np.asarray(M, dtype=float)
    L = _check_pos("L", L)
    EI = _check_pos("EI", EI)
    if not np.all(np.isfinite(M)):
        raise ValueError(f"M must be finite; got {M!r}")
    return M, L, EI


def curvature(M, EI):
    """Curvature magnitude of the free strip, ``kappa = M/EI``.

    Parameters
    ----------
    M : array_like
        End bending moment (N m).
    EI : array_like
        Bending stiffness ``E I_p`` (N m^2).

    Returns
    -------
    float or ndarray
        ``kappa`` (1/m); the section rotates as ``dtheta/ds = -kappa``.
    """
    M = np.asarray(M, dtype=float)
    return _out(M / _check_pos("EI", EI))


def rotation(M, L, EI):
    """Rotation of the free end, ``theta = -M L/EI`` (paper eq. (w)).

    Parameters
    ----------
    M : array_like
        End bending moment (N m).
    L : array_like
        Strip length (m).
    EI : array_like
        Bending stiffness (N m^2).

    Returns
    -------
    float or ndarray
        ``theta`` (rad); negative for ``M > 0``.  Not wrapped to ``(-pi, pi]``.
    """
    M, L, EI = _mLEI(M, L, EI)
    return _out(-M * L / EI)


def tip_deflection(M, L, EI):
    """Large-displacement tip deflection of the free strip (arc of circle, paper eq. (w)).

    ``w = (EI/M)[cos(M L/EI) - 1]``, evaluated without cancellation as
    ``-(kappa L^2/2) sinc^2(kappa L/2)``; ``M = 0`` gives exactly 0.

    Parameters
    ----------
    M : array_like
        End bending moment (N m).
    L : array_like
        Strip length (m).
    EI : array_like
        Bending stiffness (N m^2).

    Returns
    -------
    float or ndarray
        ``w`` (m), the ``z`` coordinate of the tip; negative for ``M > 0``.
    """
    M, L, EI = _mLEI(M, L, EI)
    k = M / EI
    s = np.sinc(k * L / (2.0 * np.pi))  # sin(kL/2)/(kL/2)
    return _out(-0.5 * k * L * L * s * s)


def tip_deflection_small(M, L, EI):
    """Small-displacement tip deflection, ``w_p = -M L^2/(2 EI)`` (paper).

    Parameters
    ----------
    M : array_like
        End bending moment (N m).
    L : array_like
        Strip length (m).
    EI : array_like
        Bending stiffness (N m^2).

    Returns
    -------
    float or ndarray
        ``w_p`` (m).
    """
    M, L, EI = _mLEI(M, L, EI)
    return _out(-0.5 * M * L * L / EI)


def tip_position(M, L, EI):
    """Tip coordinates ``(x, z)`` of the free strip bent into an arc.

    From ``dtheta/ds = -kappa``, ``dx/ds = cos theta``, ``dz/ds = sin theta``:
    ``x = sin(kappa L)/kappa = L sinc(kappa L)`` and ``z = w`` (:func:`tip_deflection`).

    Parameters
    ----------
    M : array_like
        End bending moment (N m).
    L : array_like
        Strip length (m).
    EI : array_like
        Bending stiffness (N m^2).

    Returns
    -------
    (x, y) : tuple of float or ndarray
        Tip abscissa along the clamp axis and transverse coordinate (m); ``M = 0`` gives
        ``(L, 0)``.  ``x < 0`` once ``|kappa L| > pi``.
    """
    M, L, EI = _mLEI(M, L, EI)
    k = M / EI
    x = L * np.sinc(k * L / np.pi)
    x, _ = np.broadcast_arrays(x, M)
    return _out(x), tip_deflection(M, L, EI)


def _u2_over_sin2_minus_1(u):
    """``u^2/sin^2(u) - 1`` for ``u >= 0``, stable near 0, ``inf`` where ``sin u = 0``."""
    u = np.abs(np.asarray(u, dtype=float))
    small = u < 0.1
    u2 = u * u
    ser = u2 * (1.0 / 3.0 + u2 * (1.0 / 15.0 + u2 * (2.0 / 189.0 + u2 / 675.0)))
    us = np.where(small, 1.0, u)
    s = np.sin(us)
    bad = (s == 0.0) & ~small
    den = np.where(bad, 1.0, s * s)
    direct = (us - s) * (us + s) / den
    return np.where(small, ser, np.where(bad, np.inf, direct))


def small_displacement_error(M, L, EI):
    """Relative error of the small-displacement deflection, ``|w_p - w|/|w|``.

    Closed form: ``u^2/sin^2(u) - 1`` with ``u = kappa L/2``, i.e.
    ``(kappa L)^2/12 + (kappa L)^4/240 + ...``; 0 at ``M = 0``, ``inf`` where the arc closes
    (``kappa L = 2 pi n``, ``w = 0``).

    Parameters
    ----------
    M : array_like
        End bending moment (N m).
    L : array_like
        Strip length (m).
    EI : array_like
        Bending stiffness (N m^2).

    Returns
    -------
    float or ndarray
        Dimensionless relative difference (>= 0).
    """
    M, L, EI = _mLEI(M, L, EI)
    return _out(_u2_over_sin2_minus_1(0.5 * M * L / EI))


def blocking_force_small(M, L):
    """Small-displacement blocking force, ``F = 3 M/(2 L)`` (paper eq. (FP)).

    Parameters
    ----------
    M : array_like
        End bending moment (N m).
    L : array_like
        Strip length (m).

    Returns
    -------
    float or ndarray
        ``F`` (N), same sign as ``M``.
    """
    M = np.asarray(M, dtype=float)
    return _out(1.5 * M / _check_pos("L", L))


# --------------------------------------------------------------------------------------
# Large-displacement blocking force
# --------------------------------------------------------------------------------------
def _fresnel_sc(a, b):
    """``(int_0^1 sin(a t^2 + b t) dt, int_0^1 cos(a t^2 + b t) dt)`` for ``a != 0``.

    Completing the square, ``a t^2 + b t = sgn(a) [A (t + c)^2 - A c^2]`` with ``A = |a|``,
    ``c = b/(2a)``; with ``v = sqrt(2A/pi)(t + c)`` and ``d = A c^2`` the integrals are
    ``sgn(a) k [cos d dS - sin d dC]`` and ``k [cos d dC + sin d dS]``, ``k = sqrt(pi/(2A))``,
    ``dS = S(v1) - S(v0)`` (scipy's Fresnel ``S(z) = int_0^z sin(pi u^2/2) du``).
    """
    from scipy.special import fresnel  # deferred: heavy import (start-up)

    A = np.abs(a)
    sg = np.sign(a)
    c = b / (2.0 * a)
    r = np.sqrt(2.0 * A / np.pi)
    S0, C0 = fresnel(r * c)
    S1, C1 = fresnel(r * (1.0 + c))
    dS, dC = S1 - S0, C1 - C0
    d = A * c * c
    k = 1.0 / r
    cd, sd = np.cos(d), np.sin(d)
    return sg * k * (cd * dS - sd * dC), k * (cd * dC + sd * dS)


#: Gauss-Legendre nodes on [0, 1] for the branch integrals: the phase a t^2 + b t of the
#: blocking condition stays below ~66 rad on the branch (|m| <= KL_BLOCK_MAX, measured), and
#: 120 nodes integrate sin/cos of phases up to ~150 rad to ~1e-15 (n > phase/2 + ~30)
_GL_N = 120


def _gl01():
    return leggauss01(_GL_N)


#: below this many points :func:`_G_and_dG` integrates by Gauss-Legendre (no SciPy import:
#: ``estimate`` starts faster); above, the Fresnel form is cheaper (2 special functions
#: instead of 2 x _GL_N trigonometric calls per point, constant memory)
_GL_MAX_POINTS = 2048


def _G_and_dG(psi, m):
    """``G(psi, m) = int_0^1 sin(theta) dt`` and ``dG/dpsi`` for ``m != 0``.

    ``theta = a t^2 + b t``, ``a = -m psi/2``, ``b = m (psi - 1)``;
    ``dG/dpsi = m int (t - t^2/2) cos(theta) dt``.  Small inputs: Gauss-Legendre on [0, 1];
    large ones: :func:`_G_and_dG_fresnel` (the same integrals in closed form).
    """
    psi = np.asarray(psi, dtype=float)
    m = np.asarray(m, dtype=float)
    if np.broadcast(psi, m).size > _GL_MAX_POINTS:
        return _G_and_dG_fresnel(psi, m)
    t, w = _gl01()
    a = (-0.5 * m * psi)[..., None]
    b = (m * (psi - 1.0))[..., None]
    th = (a * t + b) * t
    G = np.sin(th) @ w
    dG = m * (np.cos(th) @ (w * (t - 0.5 * t * t)))
    return G, dG


def _G_and_dG_fresnel(psi, m):
    """:func:`_G_and_dG` from Fresnel integrals (``m != 0``, ``psi != 0``).

    The moments of ``cos(theta)`` follow from ``d(sin theta)/dt = (2 a t + b) cos theta`` and
    ``d(t sin theta)/dt``.
    """
    a = -0.5 * m * psi
    b = m * (psi - 1.0)
    Is, Ic = _fresnel_sc(a, b)
    s1 = np.sin(a + b)
    I1 = (s1 - b * Ic) / (2.0 * a)  # int t cos
    I2 = (s1 - Is - b * I1) / (2.0 * a)  # int t^2 cos
    return Is, m * (I1 - 0.5 * I2)


def blocking_residual(F, M, L, EI):
    """Tip deflection of the blocked strip, ``int_0^L sin[F x(2L-x)/(2EI) - M x/EI] dx``.

    Closed form with Fresnel integrals (the paper's blocking condition is ``= 0``).

    Parameters
    ----------
    F : array_like
        Transverse end force (N).
    M : array_like
        End bending moment (N m).
    L : array_like
        Strip length (m).
    EI : array_like
        Bending stiffness (N m^2).

    Returns
    -------
    float or ndarray
        ``z(L)`` (m) for the given ``F``.
    """
    M, L, EI = _mLEI(M, L, EI)
    F = np.asarray(F, dtype=float)
    a = -0.5 * F * L * L / EI
    b = (F * L - M) * L / EI
    a, b, L = np.broadcast_arrays(a, b, L)
    # Fresnel form: absolute error ~ 1e-16 (b^2/|a| + |a|^-1/2); first order in a where
    # that is smaller (error ~ a^2/10): switch at |a|^3 = 5.5e-16 (1 + b^2).
    tiny = np.abs(a) ** 3 < 5.5e-16 * (1.0 + b * b)
    aa = np.where(tiny, 1.0, a)
    bb = np.where(tiny, 0.0, b)
    Is, _ = _fresnel_sc(aa, bb)
    # a ~ 0: int_0^1 sin(b t) dt = b/2 sinc^2(b/2) (+ a * int t^2 cos(bt), kept to 1st order)
    sb = np.sinc(b / (2.0 * np.pi))
    bs = np.where(np.abs(b) < 1e-3, 1.0, b)
    t2cos = np.where(
        np.abs(b) < 1e-3,
        1.0 / 3.0 - b * b / 10.0,
        (bs * bs * np.sin(bs) + 2.0 * bs * np.cos(bs) - 2.0 * np.sin(bs)) / bs**3,
    )
    lin = 0.5 * b * sb * sb + a * t2cos
    return _out(L * np.where(tiny, lin, Is))


def _psi_series(m):
    m2 = m * m
    c = _PSI_SERIES
    return c[0] + m2 * (c[1] + m2 * (c[2] + m2 * c[3]))


def _newton(psi, m, iters=40):
    """Vectorised Newton polish of ``G(psi, m) = 0``; returns ``(psi, converged)``."""
    psi = np.array(psi, dtype=float)
    step = np.full(psi.shape, np.inf)
    for _ in range(iters):
        g, dg = _G_and_dG(psi, m)
        ok = np.isfinite(g) & np.isfinite(dg) & (dg != 0.0)
        step = np.where(ok, np.clip(g / np.where(ok, dg, 1.0), -0.05, 0.05), np.nan)
        psi = np.where(ok, psi - step, np.nan)
        # a Newton step of relative size d leaves an error ~ d^2 (quadratic convergence, no
        # fold on the branch): below 1e-9 the root is at rounding level, and a further
        # evaluation would only confirm it (measured: within 4e-16 of the root converged to
        # 1e-15)
        if np.all(~ok | (np.abs(step) <= 1e-9 * np.abs(psi))):
            break
    return psi, np.abs(step) <= 1e-9 * np.abs(psi)


#: points of the Lagrange interpolation on the branch table: 8 on steps of 0.02 give
#: psi to <= 3.3e-15 relative (measured against Newton-converged roots at 20000 random
#: kappa L; the table's own nodes are converged to ~3e-15)
_INTERP_POINTS = 8


def _interp_lagrange(x, xs, ys, q=_INTERP_POINTS):
    """``q``-point Lagrange interpolation on the uniform grid ``xs`` (``xs[0] <= x <= xs[-1]``),
    ``x`` between the two middle nodes where the grid allows; the weights by prefix and suffix
    products (3q array operations, no division by ``t - j``)."""
    h = xs[1] - xs[0]
    i = np.clip(np.floor((x - xs[0]) / h).astype(np.int64) - (q // 2 - 1), 0, xs.size - q)
    t = (x - xs[i]) / h  # nodes at 0, 1, ..., q - 1
    d = [t - j for j in range(q)]
    pre = [np.ones_like(t)]
    for j in range(1, q):
        pre.append(pre[-1] * d[j - 1])
    out = np.zeros_like(t)
    suf = np.ones_like(t)
    for j in range(q - 1, -1, -1):
        # 1 / prod_{l != j} (j - l) = (-1)^(q-1-j) / (j! (q-1-j)!)
        c = (-1.0) ** (q - 1 - j) / (math.factorial(j) * math.factorial(q - 1 - j))
        out += (c * ys[i + j]) * (pre[j] * suf)
        suf = suf * d[j]
    return out


def _branch_table_path():
    """Disk cache of the branch table, beside the Numba cache and keyed on this file."""


    with open(__file__, "rb") as fh:
        h = hashlib.sha256(fh.read()).hexdigest()[:16]
    return os.path.join(CACHE_DIR, f"beam_branch_{h}.npy")


def _compute_branch_table():
    """``(m, psi)`` on the continuous branch, ``0 <= m <= KL_BLOCK_MAX`` (continuation)."""
    n = int(math.ceil(KL_BLOCK_MAX / _TABLE_STEP)) + 1
    ms = np.linspace(0.0, KL_BLOCK_MAX, n)
    ps = np.empty(n)
    for i, m in enumerate(ms):
        if m < _SERIES_KL:
            ps[i] = _psi_series(m)
            continue
        guess = 2.0 * ps[i - 1] - ps[i - 2]  # secant predictor
        p, ok = _newton(np.array(guess), np.array(m))
        if not ok or abs(p - guess) > 1e-3:
            raise RuntimeError(f"blocking-force branch lost at kappa L = {m:.3f}")  # pragma: no cover
        ps[i] = float(p)
    return ms, ps


@functools.lru_cache(maxsize=1)
def _branch_table():
    """The branch table, computed once per installation (~0.3 s) and cached on disk.

    A damaged or foreign file is ignored and rewritten; the cache is written atomically
    (temporary file + rename), and a read-only cache directory only costs the recomputation.
    """

    path = _branch_table_path()
    n = int(math.ceil(KL_BLOCK_MAX / _TABLE_STEP)) + 1
    try:
        ps = np.load(path, allow_pickle=False)
        if ps.shape == (n,) and ps.dtype == np.float64 and np.all(np.isfinite(ps)):
            return np.linspace(0.0, KL_BLOCK_MAX, n), ps
    except (OSError, ValueError):
        pass
    ms, ps = _compute_branch_table()
    try:
        os.makedirs(os.path.dirname(path), exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=os.path.dirname(path), suffix=".tmp")
        try:
            with os.fdopen(fd, "wb") as f:
                np.save(f, ps, allow_pickle=False)
            os.replace(tmp, path)
        except BaseException:
            os.unlink(tmp)
            raise
    except OSError:
        pass
    return ms, ps


def blocking_force_ratio(kL):
    """``psi(kappa L) = F_large L / M`` on the branch continuous with ``psi(0) = 3/2``.

    Parameters
    ----------
    kL : array_like
        ``kappa L = M L/EI`` (rad).

    Returns
    -------
    float or ndarray
        ``psi`` (dimensionless, even in ``kL``); NaN where ``|kL| > KL_BLOCK_MAX`` (or ``kL``
        is NaN).  Below ``kL = 0.25`` a series, above it an 8-point interpolation of the
        branch table (<= 3.3e-15 relative, measured).
    """
    m = np.abs(np.asarray(kL, dtype=float))
    out = np.full(m.shape, np.nan)
    ser = m < _SERIES_KL
    out[ser] = _psi_series(m[ser])
    mid = (~ser) & (m <= KL_BLOCK_MAX)
    if np.any(mid):
        ms, ps = _branch_table()
        # the table's nodes are Newton-converged roots on the branch (continuation, checked
        # when it is computed); between them, 8-point interpolation is as accurate (<= 3.3e-15)
        # as a Newton polish would be, without its 2 Fresnel evaluations a point
        out[mid] = _interp_lagrange(m[mid], ms, ps)
    return _out(out)


def blocking_force_large(M, L, EI):
    """Large-displacement blocking force: root ``F`` of the paper's blocking condition.

    Solves ``int_0^L sin[F x(2L-x)/(2EI) - M x/EI] dx = 0`` on the branch continuous with
    the small-displacement value ``3M/(2L)``; written ``F = psi(M L/EI) M/L``
    (:func:`blocking_force_ratio`).  ``M = 0`` gives 0.

    Parameters
    ----------
    M : array_like
        End bending moment (N m).
    L : array_like
        Strip length (m).
    EI : array_like
        Bending stiffness (N m^2).

    Returns
    -------
    float or ndarray
        ``F`` (N), same sign as ``M``; NaN where ``|M L/EI| > KL_BLOCK_MAX`` (branch not
        tracked) or the solve failed -- :func:`solve_beam` reports such points.
    """
    M, L, EI = _mLEI(M, L, EI)
    psi = np.asarray(blocking_force_ratio(M * L / EI))
    return _out(psi * M / L)


def blocking_force_error(M, L, EI):
    """Relative difference ``|F_small - F_large|/|F_large| = |3/2 - psi|/psi``.

    Equals ``(kappa L)^2/3360 + O((kappa L)^4)``; 0 at ``M = 0``; NaN where
    :func:`blocking_force_large` is NaN.

    Parameters
    ----------
    M : array_like
        End bending moment (N m).
    L : array_like
        Strip length (m).
    EI : array_like
        Bending stiffness (N m^2).

    Returns
    -------
    float or ndarray
        Dimensionless.
    """
    M, L, EI = _mLEI(M, L, EI)
    psi = np.asarray(blocking_force_ratio(M * L / EI))
    return _out(np.abs(1.5 - psi) / psi)


def max_strain(M, EI, e):
    """Largest bending strain of the free strip, ``e |kappa| = e |M|/EI``.

    Parameters
    ----------
    M : array_like
        End bending moment (N m).
    EI : array_like
        Bending stiffness (N m^2).
    e : array_like
        HALF thickness (m) (the paper's ``e``).

    Returns
    -------
    float or ndarray
        Dimensionless strain at the faces; the model assumes it is << 1.
    """
    M = np.asarray(M, dtype=float)
    return _out(np.asarray(e, dtype=float) * np.abs(M) / _check_pos("EI", EI))


def regime(M, L, EI, tol=None):
    """Classify each point by how far the strip bends.

    Parameters
    ----------
    M : array_like
        End bending moment (N m).
    L : array_like
        Strip length (m).
    EI : array_like
        Bending stiffness (N m^2).
    tol : float, optional
        Relative tolerance on :func:`small_displacement_error` for ``"small"``
        (default :data:`DEFAULT_SMALL_TOL` = 1 %).

    Returns
    -------
    str or ndarray of str
        ``"small"`` (small-displacement deflection within ``tol`` of the arc),
        ``"large"`` (arc needed, ``|theta| <= pi/2``), ``"past-quarter-turn"``
        (``pi/2 < |theta| <= 2 pi``: the arc curls back, ``w`` not monotone in ``M``),
        ``"multi-turn"`` (``|theta| > 2 pi``: ``w`` periodic in ``M``).
    """
    return _labels(regime_code(M, L, EI, tol))


def _labels(code):
    """:data:`REGIMES` labels of integer codes: one gather; a str for a scalar code."""
    lab = np.asarray(REGIMES)[code]
    return str(lab) if lab.ndim == 0 else lab


def regime_code(M, L, EI, tol=None, _err=None):
    """:func:`regime` as indices into :data:`REGIMES` (int array; cheap to compare).
    ``_err``: :func:`small_displacement_error` if the caller has it already."""
    tol = DEFAULT_SMALL_TOL if tol is None else float(tol)
    M, L, EI = _mLEI(M, L, EI)
    th = np.abs(M * L / EI)
    err = _u2_over_sin2_minus_1(0.5 * th) if _err is None else _err
    return np.where(th > 2.0 * np.pi, 3, np.where(th > 0.5 * np.pi, 2, np.where(err <= tol, 0, 1)))


@dataclass(repr=False)
class BeamResult(ResultMixin):
    """Mechanics of the strip for given end moment(s); arrays broadcast over the inputs.

    Attributes
    ----------
    theta : float or ndarray
        Free-end rotation (rad).
    w : float or ndarray
        Large-displacement (arc) tip deflection (m).
    w_small : float or ndarray
        Small-displacement tip deflection (m).
    x_tip, y_tip : float or ndarray
        Tip coordinates of the free strip along / across the clamp axis (m); ``y_tip = w``.
    F_block : float or ndarray or None
        Large-displacement blocking force (N); where not available (see ``warnings``) NaN in an
        array, None for scalar inputs (the convention of ``evaluate``: no number, no answer).
    F_block_small : float or ndarray
        Small-displacement blocking force ``3M/(2L)`` (N).
    regime : str or ndarray of str
        See :func:`regime`.
    small_error : float or ndarray
        ``|w_small - w|/|w|``.
    block_error : float or ndarray
        ``|F_small - F_block|/|F_block|``.
    max_strain : float or ndarray or None
        ``e |M|/EI`` if the half thickness ``e`` was given.
    warnings : list of str
        One-line messages about points outside the model's comfortable range.
    regime_code : int or ndarray of int or None
        ``regime`` as indices into :data:`REGIMES`.
    """

    _result = ResultSpec("point", None, ("theta", "w", "w_small", "x_tip", "y_tip", "F_block", "F_block_small",
                                         "small_error", "block_error", "max_strain", "regime"),
                         (Panel("point", ("w", "w_small")), Panel("point", ("F_block", "F_block_small"))))

    theta: object
    w: object
    w_small: object
    x_tip: object
    y_tip: object
    F_block: object
    F_block_small: object
    regime: object
    small_error: object
    block_error: object
    max_strain: object = None
    warnings: list = field(default_factory=list)
    regime_code: object = None


def _where_msg(mask, values, n):
    """``'rotation |theta| = 2.1 rad'``-style prefix: the value if scalar, a count otherwise."""
    k = int(np.count_nonzero(mask))
    if n == 1:
        return f"{float(np.max(values[mask])):.3g}"
    return f"up to {float(np.max(values[mask])):.3g} ({k} of {n} points)"


def solve_beam(M, L, EI, *, tol=None, e=None, strain_limit=0.01) -> BeamResult:
    """All mechanical outputs of the strip for end moment(s) ``M``.

    Parameters
    ----------
    M : array_like
        End bending moment (N m).
    L : array_like
        Strip length (m).
    EI : array_like
        Bending stiffness ``E I_p`` (N m^2).
    tol : float, optional
        Tolerance for the ``"small"`` regime (default 1 %).
    e : array_like, optional
        HALF thickness (m), to report the maximum bending strain.
    strain_limit : float
        Face strain above which the small-strain assumption is said to fail in ``warnings``
        (``Material.strain_limit``; default 1 %).

    Returns
    -------
    BeamResult
        Scalars for scalar inputs, broadcast arrays otherwise.  ``warnings`` lists, one line
        each: points past a quarter turn or a full turn, large strain (> 1 %), and points
        where the large-displacement blocking force is NaN (``|kappa L| > KL_BLOCK_MAX``).
        For scalar inputs the outputs without an answer are None, as in ``evaluate``:
        ``F_block`` beyond ``KL_BLOCK_MAX``, and ``w``, ``w_small``, ``x_tip``, ``y_tip`` past a
        full turn (the arc passes through itself); arrays keep NaN / the numbers with the warning.
    """
    scalar = not any(isinstance(a, np.ndarray) or np.ndim(a) for a in (M, L, EI))
    tol_v = DEFAULT_SMALL_TOL if tol is None else float(tol)
    M, L, EI = _mLEI(M, L, EI)
    M, L, EI = np.broadcast_arrays(M, L, EI)
    theta = -M * L / EI
    ath = np.abs(theta)
    x, y = tip_position(M, L, EI)
    psi = np.asarray(blocking_force_ratio(theta))
    Fb = psi * M / L
    Fs = 1.5 * M / L
    berr = np.abs(1.5 - psi) / psi
    serr = _u2_over_sin2_minus_1(0.5 * ath)
    code = regime_code(M, L, EI, tol_v, _err=serr)
    reg = _labels(code)
    n = max(1, M.size)
    warns = []
    flat_th = ath.reshape(-1)
    multi = flat_th > 2.0 * np.pi
    quarter = (flat_th > 0.5 * np.pi) & ~multi
    if np.any(quarter):
        warns.append(
            f"rotation |theta| = {_where_msg(quarter, flat_th, n)} rad > pi/2: arc past a "
            "quarter turn (w not monotone in M); the arc formula still holds"
        )
    if np.any(multi):
        warns.append(
            f"rotation |theta| = {_where_msg(multi, flat_th, n)} rad > 2 pi: the strip winds "
            "more than a full turn; the arc passes through itself, its tip position (w) is meaningless"
        )
    beyond = flat_th > KL_BLOCK_MAX  # (M, L, EI are checked finite: the only NaN of F_block)
    if np.any(beyond):
        warns.append(
            f"F_block withheld (no answer): |kappa L| = {_where_msg(beyond, flat_th, n)} rad > "
            f"{KL_BLOCK_MAX:g}, the large-displacement blocking-force branch is not tracked"
        )
    eps = None
    if e is not None:
        eps = np.asarray(max_strain(M, EI, e))
        fe = eps.reshape(-1)
        big = fe > strain_limit
        if np.any(big):
            warns.append(
                f"max bending strain e|kappa| = {_where_msg(big, fe, max(1, fe.size))} > {strain_limit:g}: "
                "small-strain assumption questionable"
            )
        eps = _out(eps)
    tip = {"w": _out(y), "w_small": _out(-0.5 * M * L * L / EI), "x_tip": _out(x), "y_tip": _out(y)}
    if scalar and bool(multi[0]):
        tip = dict.fromkeys(tip)  # withheld past a full turn, as evaluate does
    return BeamResult(
        theta=_out(theta),
        **tip,
        F_block=None if scalar and bool(beyond[0]) else _out(Fb),
        F_block_small=_out(Fs),
        regime=reg,
        regime_code=int(code) if np.ndim(code) == 0 else code,
        small_error=_out(serr),
        block_error=_out(berr),
        max_strain=eps,
        warnings=warns,
    )
