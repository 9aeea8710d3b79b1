"""Electrode surface resistance: the strip as an RC transmission line along its length.

Each plated electrode has a sheet resistance ``R_s`` (Ohm/sq); the voltage across the thickness
then decays along the strip, and more so the faster the drive.  Along ``x`` in
``[0, L]`` (drive at the clamp ``x = 0``, open far end) the strip is a distributed line
(``derivations/line.py``):

* series resistance per length ``r = 2 R_s/(2l)``: the current still to cross the thickness
  beyond ``x`` flows out along one electrode and back along the other, so both sheets are in
  series (:func:`ipmc_asym.model.groups.electrode_line_resistance`);
* shunt admittance per length ``y(s) = 2l/Z_area(s)``, ``Z_area`` the through-thickness
  impedance per area of :func:`ipmc_asym.dynamics.circuit.frequency_response` (linearised PNP
  or the reduced circuit);
* ``g = gamma L = L sqrt(r y) = L sqrt(2 R_s/Z_area)``
  (:func:`ipmc_asym.model.groups.line_propagation`), ``V(x)/V0 = cosh(g (1 - x/L))/cosh(g)``,
  ``Z_in = Z0 coth(g)`` with ``Z0 = sqrt(r/y)``, i.e. ``Z_in = Z_u g coth g`` for the uniform
  strip's ``Z_u = Z_area/(2l L)``.

The through-thickness problem is local in ``x`` (the strip is long against its thickness) and
the polymer's own conduction along the length is neglected: its sheet resistance ``1/(kappa 2e)``
(~1.1e4 Ohm/sq at the nominal strip) is ~4500 times the measured electrode value of
:data:`ipmc_asym.model.params.SHEET_RESISTANCE_SOURCE` (2.5 Ohm/sq).

The layers' moment follows the local voltage, ``M(x, s) = H_M(s) V(x, s)``; ``H_M`` is read off
the uniform strip's tip transfer ``H_w = -L^2 H_M/(2 E I_p)`` (no electrochemistry recomputed).
Small-displacement quasi-static beam with a distributed moment: curvature ``M(x)/(E I_p)``,
``w = -int_0^L (L - x) M dx/(E I_p) = H_w^u F_w(g) V0`` and
``theta = -int_0^L M dx/(E I_p) = (2 H_w^u/L) F_theta(g) V0`` with
``F_w = 2 (g tanh g - 1 + sech g)/g^2`` and ``F_theta = tanh(g)/g`` (both 1 at ``g = 0``).
Every factor is evaluated in the overflow-free form of ``derivations/line.py`` (item 4), exact
to rounding for all ``Re g >= 0``.

For beam dynamics the modal forcing of the distributed moment, ``int_0^L M(x) phi_n''(x) dx``,
is :meth:`LineResult.modal_forcing` (any mode-shape curvature callable).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ipmc_asym.dynamics.circuit import FrequencyResult, frequency_response
from ipmc_asym.model import groups
from ipmc_asym.model.params import NAFION_LI, SHEET_RESISTANCE_SOURCE, Material, Strip, check_finite

__all__ = ["LineResult", "line_response", "line_factors", "voltage_profile", "moment_modal_integral",
           "MAX_PROFILE_POINTS"]

#: largest number of (frequency, x) values a voltage profile may hold
MAX_PROFILE_POINTS = 10**7

# below this |g| every factor is 1 to within |g|^2/3 < 1e-200 (and g^2 would underflow)
_G_TINY = 1e-100


def line_factors(g):
    """``(g coth g, tanh(g)/g, F_w(g))`` of ``derivations/line.py`` at complex ``g`` (``Re g >= 0``).

    Parameters
    ----------
    g : array_like, complex
        ``gamma L`` (dimensionless).

    Returns
    -------
    fz, fth, fw : ndarray complex
        ``Z_in/Z_u``, ``theta/theta_u``, ``w/w_u`` (each 1 where ``g = 0``).
    """
    g = np.asarray(g, dtype=complex)
    tiny = np.abs(g) < _G_TINY
    gs = np.where(tiny, 1.0, g)
    with np.errstate(over="ignore", under="ignore"):
        q = np.exp(-2.0 * gs)
        m1 = np.expm1(-gs)
        m2 = np.expm1(-2.0 * gs)
    fz = -gs * (1.0 + q) / m2
    fth = -m2 / (gs * (1.0 + q))
    fw = 2.0 * (-gs * m2 - m1 * m1) / (gs * gs * (1.0 + q))
    one = np.ones_like(g)
    return np.where(tiny, one, fz), np.where(tiny, one, fth), np.where(tiny, one, fw)


def voltage_profile(g, xi):
    """``V(x)/V0 = cosh(g (1 - xi))/cosh(g)`` (overflow-free form), broadcast over ``g`` and ``xi = x/L``."""
    g = np.asarray(g, dtype=complex)
    xi = np.asarray(xi, dtype=float)
    with np.errstate(under="ignore"):
        return (np.exp(-g * xi) + np.exp(-g * (2.0 - xi))) / (1.0 + np.exp(-2.0 * g))


# Gauss-Legendre rule per panel of the modal integral
_GL_N = 24
_GL_X, _GL_W = np.polynomial.legendre.leggauss(_GL_N)


def _panels(gmax: float, uniform: int):
    """Panel ends on [0, 1]: ``uniform`` equal panels, plus panels halving towards 0 down to
    ``0.5/|g|`` (the profile ``~ e^{-g xi}`` varies on ``1/|g|``; ``Re g >= |g|/sqrt 2``, so a panel
    ``[a, 2a]`` with ``|g| a`` large carries a negligible ``e^{-|g| a/sqrt 2}``)."""
    ends = set(np.linspace(0.0, 1.0, uniform + 1).tolist())
    if gmax > 1.0:
        a = 1.0 / uniform
        while a * gmax > 0.5:
            a *= 0.5
            ends.add(a)
    return np.array(sorted(ends))


def moment_modal_integral(curvature, g, length, *, uniform_panels: int = 4, error: bool = False):
    """``int_0^L (V(x)/V0) phi''(x) dx`` for each ``g`` (m times the unit of ``phi''``).

    Times the moment per volt ``H_M(s)`` this is the modal forcing ``int_0^L M(x) phi_n''(x) dx``
    of the distributed moment per volt.  Composite Gauss-Legendre (24 points a panel) on
    ``uniform_panels`` equal panels plus panels graded towards the clamp to the profile's decay
    length ``L/|g|``.  Measured against an independent adaptive quadrature (mpmath, 30 digits) for
    ``|g|`` up to 1300 and curvatures up to ``beta L = 30``: <= 1e-15 of ``int |V phi''| dx``.

    Parameters
    ----------
    curvature : callable
        ``phi''(x)`` (x in m, vectorised over a 1-D array of n positions), e.g. a mode shape's
        second derivative; it may return an array (k, n) for k modes at once.
    g : array_like complex
        ``gamma L`` of each frequency (:attr:`LineResult.gamma_L`).
    length : float
        ``L`` (m).
    uniform_panels : int
        Equal panels on ``[0, L]`` (24 points each resolve ~8 half waves of ``phi''``; raise it
        for modes of higher order).
    error : bool
        Also return an estimate of the quadrature error (difference with a rule of half the
        panels' order, 12 points), same shape.

    Returns
    -------
    ndarray complex, shape (len(g),) or (len(g), k)
    """
    L = float(length)
    g = np.atleast_1d(np.asarray(g, dtype=complex))
    n = int(uniform_panels)
    if n < 1 or n > 10**4:
        raise ValueError(f"uniform_panels must be an integer in 1..10000; got {uniform_panels!r}")
    ends = _panels(float(np.max(np.abs(g))) if g.size else 0.0, n)

    def rule(xg, wg):
        a, b = ends[:-1, None], ends[1:, None]
        xi = (0.5 * (b - a) * xg[None, :] + 0.5 * (a + b)).ravel()
        wt = (0.5 * (b - a) * wg[None, :]).ravel()
        c = np.asarray(curvature(xi * L), dtype=float)
        if c.shape[-1:] != xi.shape or c.ndim > 2:
            raise ValueError(f"curvature(x) must return an array of shape (n,) or (k, n) for n = {xi.size} positions")
        if not np.all(np.isfinite(c)):
            raise ValueError("curvature(x) must return finite values on [0, L]")
        return L * (voltage_profile(g[:, None], xi[None, :]) @ (wt * c).T)

    val = rule(_GL_X, _GL_W)
    if not error:
        return val
    xg, wg = np.polynomial.legendre.leggauss(_GL_N // 2)
    return val, np.abs(val - rule(xg, wg))


@dataclass
class LineResult:
    """Small-signal response of a strip whose electrodes have a sheet resistance (SI).

    Attributes
    ----------
    f : ndarray (n,)            frequency, Hz
    Z : ndarray complex         input impedance at the clamp, Ohm (``Z0 coth(gamma L)``)
    Z_area : ndarray complex    through-thickness impedance per unit area, Ohm m^2 (unchanged by R_s)
    H_w : ndarray complex       tip deflection per volt at the clamp, m/V (small displacements)
    w_amp, w_phase : ndarray    ``|H_w|`` (m/V), ``arg H_w`` (rad)
    H_theta : ndarray complex   tip rotation per volt, rad/V
    H_M : ndarray complex       layers' moment per volt of local voltage, N m/V (``M(x) = H_M V(x)``)
    gamma_L : ndarray complex   ``g = gamma L = L sqrt(2 R_s/Z_area)``
    Z0 : ndarray complex        characteristic impedance ``sqrt(r/y)``, Ohm (0 for ideal electrodes)
    sheet_resistance : float    ``R_s``, Ohm/sq (each electrode)
    length : float              ``L``, m
    x : ndarray or None         positions of the profile, m
    V_profile : ndarray complex or None   ``V(x)/V0``, shape (n, len(x))
    tau, method, model, notes   as :class:`ipmc_asym.dynamics.circuit.FrequencyResult`
    uniform : FrequencyResult   the same strip with ideal electrodes
    """

    f: np.ndarray
    Z: np.ndarray
    Z_area: np.ndarray
    H_w: np.ndarray
    w_amp: np.ndarray
    w_phase: np.ndarray
    H_theta: np.ndarray
    H_M: np.ndarray
    gamma_L: np.ndarray
    Z0: np.ndarray
    sheet_resistance: float
    length: float
    tau: float
    method: str
    model: str
    notes: list
    uniform: FrequencyResult
    x: object = None
    V_profile: object = None
    extra: dict = field(default_factory=dict)

    def modal_forcing(self, curvature, **kw):
        """``int_0^L M(x) phi''(x) dx`` per volt at the clamp, for each frequency (see
        :func:`moment_modal_integral`, whose keywords it takes; N m/V times the unit of ``phi''``
        times m); shape (n,) or (n, k) for k curvatures."""
        v = moment_modal_integral(curvature, self.gamma_L, self.length, **kw)
        if isinstance(v, tuple):
            v, err = v
            return (self.H_M * v.T).T, np.abs(self.H_M * err.T).T
        return (self.H_M * v.T).T


def line_response(f, *, strip: Strip | None = None, model="constant", material: Material | None = None,
                  sheet_resistance=None, method="pnp-linear", x=None) -> LineResult:
    """Impedance and tip transfer functions of a strip with resistive electrodes, about 0 V.

    Parameters
    ----------
    f : array_like
        Frequencies (Hz), > 0.
    strip : Strip, optional
        Geometry (``thickness`` TOTAL 2e, ``width`` TOTAL 2l, ``length`` L, m).
    model : {"constant", "linear", "affine"} or Permittivity
    material : Material, optional
    sheet_resistance : float, optional
        Sheet resistance of each electrode, Ohm/sq (>= 0); default ``material.sheet_resistance``
        (0 for the presets: ideal electrodes, exactly :func:`frequency_response`).
    method : {"pnp-linear", "circuit"}
        Through-thickness impedance, as :func:`ipmc_asym.dynamics.circuit.frequency_response`.
    x : array_like, optional
        Positions along the strip (m, in ``[0, L]``) where ``V(x)/V0`` is wanted.

    Returns
    -------
    LineResult
    """
    s = Strip() if strip is None else strip
    m = NAFION_LI if material is None else material
    Rs = m.sheet_resistance if sheet_resistance is None else sheet_resistance
    Rs = check_finite("sheet_resistance", Rs, "a finite number >= 0 Ohm/sq")
    if Rs < 0.0:
        raise ValueError(f"sheet_resistance must be a finite number >= 0 Ohm/sq; got {sheet_resistance!r}")
    u = frequency_response(f, strip=s, model=model, material=m, method=method)
    L = s.length
    g = groups.line_propagation(L, Rs, u.Z_area)
    fz, fth, fw = line_factors(g)
    Z = u.Z * fz
    Hw = u.H_w * fw
    # H_w^u = -L^2 H_M/(2 E I_p): the moment per volt of the uniform strip's own transfer
    HM = -2.0 * m.E * s.I_p * u.H_w / (L * L)
    Hth = 2.0 * u.H_w / L * fth
    prof = None
    xs = None
    if x is not None:
        xs = np.atleast_1d(np.asarray(x, dtype=float))
        if xs.ndim != 1 or not np.all(np.isfinite(xs)) or np.any(xs < 0.0) or np.any(xs > L):
            raise ValueError(f"x must be a 1-D array of positions in [0, L] = [0, {L:g}] m")
        if xs.size * g.size > MAX_PROFILE_POINTS:
            raise ValueError(f"x: {xs.size} positions x {g.size} frequencies exceed {MAX_PROFILE_POINTS} profile values")
        prof = voltage_profile(g[:, None], xs[None, :] / L)
    notes = list(u.notes) + [
        f"electrodes: sheet resistance R_s = {Rs:g} Ohm/sq each, in series along the length (r = 2 R_s/(2l)); "
        "the voltage decays along x as an RC line driven at the clamp; the moment follows the local voltage "
        "(small displacements, quasi-static beam)",
        SHEET_RESISTANCE_SOURCE,
    ]
    return LineResult(f=u.f, Z=Z, Z_area=u.Z_area, H_w=Hw, w_amp=np.abs(Hw), w_phase=np.angle(Hw), H_theta=Hth,
                      H_M=HM, gamma_L=g, Z0=u.Z * g, sheet_resistance=Rs, length=L, tau=u.tau, method=u.method,
                      model=u.model, notes=notes, uniform=u, x=xs, V_profile=prof)
