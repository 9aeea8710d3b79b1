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

import math
from dataclasses import dataclass, field

import numpy as np

from ipmc_asym.base.registry import check_choice
from ipmc_asym.base.results import Panel, ResultMixin, ResultSpec
from ipmc_asym.beam.dynamics import DEFAULT_MODES, distributed_transfer
from ipmc_asym.dynamics.circuit import (
    BEAM_CHOICES,
    FrequencyResult,
    dynamic_notes,
    frequency_response,
    quiet_numerics,
    strip_beam,
)
from ipmc_asym.model import groups
from ipmc_asym.model.params import (
    NAFION_LI,
    SHEET_RESISTANCE_SOURCE,
    Material,
    Strip,
    bending_stiffness,
    check_finite_response,
    check_sheet_resistance,
)

__all__ = ["LineResult", "line_response", "line_factors", "voltage_profile", "moment_modal_integral",
           "ProfileQuadrature", "MAX_PROFILE_POINTS"]

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
    quad = ProfileQuadrature(g, length, uniform_panels=uniform_panels, error=error)
    return quad(curvature)


class ProfileQuadrature:
    """The composite Gauss-Legendre rule of :func:`moment_modal_integral` with the voltage profile at
    its nodes evaluated once, for several curvature callables at the same ``g`` (same arguments)."""

    def __init__(self, g, length, *, uniform_panels: int = 4, error: bool = False):
        L = float(length)
        g = np.atleast_1d(np.asarray(g, dtype=complex))
        n = int(uniform_panels)
        if n < 1 or n > 10**4:
            raise ValueError(f"uniform_panels must be an integer in 1..10000; got {uniform_panels!r}")
        ends = _panels(float(np.max(np.abs(g))) if g.size else 0.0, n)
        self.L = L
        self.rules = []
        pairs = [(_GL_X, _GL_W)] + ([np.polynomial.legendre.leggauss(_GL_N // 2)] if error else [])
        for xg, wg in pairs:
            a, b = ends[:-1, None], ends[1:, None]
            xi = (0.5 * (b - a) * xg[None, :] + 0.5 * (a + b)).ravel()
            wt = (0.5 * (b - a) * wg[None, :]).ravel()
            if g.size and float(np.max(g.real)) <= 300.0:
                # e^{-g (2 - xi)} = e^{-2g}/e^{-g xi} (no overflow for Re g <= 300), and on each panel
                # e^{-g xi} = e^{-g c} e^{-g h t} (centre c, half width h, node t): the panels of one
                # width share their e^{-g h t}, so a node costs a product, not an exponential
                c, h = (0.5 * (a + b)).ravel(), (0.5 * (b - a)).ravel()
                E = np.empty((g.size, c.size, xg.size), complex)
                ec = np.exp(-g[:, None] * c[None, :])
                for hw in np.unique(h):
                    sel = h == hw
                    E[:, sel, :] = ec[:, sel, None] * np.exp(-g[:, None] * (hw * xg))[:, None, :]
                E = E.reshape(g.size, xi.size)
                q = np.exp(-2.0 * g)
                V = (E + q[:, None] / E) / (1.0 + q)[:, None]
            else:
                V = voltage_profile(g[:, None], xi[None, :])
            # two real products (the curvatures are real): a quarter of the work of a complex one
            self.rules.append((xi, L * wt, np.ascontiguousarray(V.real), np.ascontiguousarray(V.imag)))

    def _rule(self, curvature, xi, wt, Vr, Vi):
        c = np.asarray(curvature(xi * self.L), dtype=float)
        if c.shape[-1:] != xi.shape or c.ndim > 2:
            raise ValueError(f"curvature(x) must return an array of shape (n,) or (k, n) for n = {xi.size} positions")
        if not np.all(np.isfinite(c)):
            raise ValueError("curvature(x) must return finite values on [0, L]")
        cw = np.ascontiguousarray((wt * c).T)
        return Vr @ cw + 1j * (Vi @ cw)

    def __call__(self, curvature):
        val = self._rule(curvature, *self.rules[0])
        if len(self.rules) == 1:
            return val
        return val, np.abs(val - self._rule(curvature, *self.rules[1]))


@dataclass(repr=False)
class LineResult(ResultMixin):
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
    uniform : FrequencyResult   the same strip with ideal electrodes (quasi-static beam)
    H_F : ndarray complex       blocking force per volt (blocked tip), N/V
    error : ndarray or None     circuit at 0 V: relative error of Z and H_w against the same line with
                                the linearised PNP's ``Z_area`` (computed at each frequency); None for
                                pnp-linear and about a bias
    error_max : float           largest ``error`` over the frequencies (NaN without ``error``)
    f_d, resonances, beam, voltage   as :class:`ipmc_asym.dynamics.circuit.FrequencyResult`
    beam_error : ndarray        dynamic beam: estimate of the relative error of H_w, H_theta, H_F from
                                the modal integrals (a quadrature of half the order) and the modal
                                truncation (the last kept mode's term); 0 for the quasi-static beam
    """

    _result = ResultSpec("f", "f", ("Z", "Z_area", "H_w", "w_amp", "w_phase", "H_theta", "H_M", "H_F", "gamma_L",
                                    "Z0", "error", "beam_error"),
                         (Panel("f", ("Z",), True, True), Panel("f", ("w_amp",), True, True),
                          Panel("f", ("w_phase",), True)),
                         ("sheet_resistance", "length", "tau", "f_d", "voltage"), {"error": "error_Z"})

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
    H_F: object = None
    error: object = None
    error_max: float = math.nan
    f_d: float = math.nan
    resonances: dict = field(default_factory=dict)
    beam: str = "quasi-static"
    voltage: float = 0.0
    beam_error: object = None

    @property
    def check_voltage(self) -> bool:
        """The bias within the validated range (the uniform strip's flag: one bias for both)."""
        return self.uniform.check_voltage

    def modal_forcing(self, curvature, **kw):
        """``int_0^L M(x) phi''(x) dx`` per volt at the clamp, for each frequency (see
        :func:`moment_modal_integral`, whose keywords it takes; N m/V times the unit of ``phi''``
        times m); shape (n,) or (n, k) for k curvatures."""
        v = moment_modal_integral(curvature, self.gamma_L, self.length, **kw)
        if isinstance(v, tuple):
            v, err = v
            return (self.H_M * v.T).T, np.abs(self.H_M * err.T).T
        return (self.H_M * v.T).T


def _uniform_panels(n_modes):
    """Equal panels for the modal integrals: 24 Gauss points resolve ~8 half waves of ``phi_n''``,
    mode n has ~n of them (and the kernels are cubic)."""
    return max(4, -(-int(n_modes) // 6))


def _line(u, strip: Strip, material: Material, Rs, beam, viscous_modulus, n_modes):
    """(Z, H_w, H_theta, H_F, H_M, g, beam_error) of the line over the uniform quasi-static response ``u``."""
    L = strip.length
    g = groups.line_propagation(L, Rs, u.Z_area)
    fz, fth, fw = line_factors(g)
    EI = float(bending_stiffness(material, strip.width, strip.thickness))  # composite with electrode layers
    # H_w^u = -L^2 H_M/(2 E I_p): the moment per volt of the uniform strip's own transfer
    HM = -2.0 * EI * u.H_w / (L * L)
    Z = u.Z * fz
    if beam == "quasi-static":
        Hw = u.H_w * fw
        # blocked tip, small displacements: F = 3 int (L - x) M dx/L^3 = -3 E I_p w_free/L^3
        return Z, Hw, 2.0 * u.H_w / L * fth, -3.0 * EI * Hw / L**3, HM, g, np.zeros(g.shape)
    b = strip_beam(strip, material, viscous_modulus)
    quad = ProfileQuadrature(g, L, uniform_panels=_uniform_panels(n_modes), error=True)

    def integrate(c):
        v, e = quad(c)
        return HM[:, None] * v, np.abs(HM)[:, None] * e

    from threadpoolctl import threadpool_limits  # deferred: only the modal integrals need it

    # small products (frequencies x nodes x modes): BLAS threads would only compete for the cores
    with threadpool_limits(1):
        cf = distributed_transfer(u.f, b, "clamped-free", integrate, n_modes)
        cp = distributed_transfer(u.f, b, "clamped-pinned", integrate, n_modes)
    # the estimate of the quadrature (24 against 12 points a panel) plus the modal truncation
    be = np.maximum.reduce([cf["error"]["w"], cf["error"]["theta"], cp["error"]["F"]])
    be = be + max(cf["truncation"], cp["truncation"])
    return Z, cf["w"], cf["theta"], cp["F"], HM, g, be


@quiet_numerics
def line_response(f, *, strip: Strip | None = None, model="constant", material: Material | None = None,
                  sheet_resistance=None, method="pnp-linear", x=None, beam="quasi-static", viscous_modulus=0.0,
                  n_modes=DEFAULT_MODES, voltage=0.0) -> LineResult:
    """Impedance and tip transfer functions of a strip with resistive electrodes (small signal).

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
    beam : {"quasi-static", "dynamic"}
        ``dynamic``: the distributed moment ``M(x, s) = H_M V(x, s)`` drives the strip's modes
        (inertia, Kelvin-Voigt damping; :func:`ipmc_asym.beam.dynamics.distributed_transfer`):
        free tip ``H_w``, ``H_theta``, blocked tip ``H_F`` with resonances.
    viscous_modulus : float
        ``eta_E`` (Pa s), default 0.
    n_modes : int
        Modes kept (dynamic beam).
    voltage : float
        DC bias (V), ``method="circuit"`` only: the shunt admittance per length is the small-signal
        one about the biased static state (``R``, ``C_d(V)``, ``C_g``) and ``H_M`` the forward
        model's moment slope there, as :func:`frequency_response` with ``voltage``.

    Returns
    -------
    LineResult
    """
    check_choice("beam", beam, BEAM_CHOICES)
    s = Strip() if strip is None else strip
    m = NAFION_LI if material is None else material
    Rs = m.sheet_resistance if sheet_resistance is None else sheet_resistance
    Rs = check_sheet_resistance(Rs)
    u = frequency_response(f, strip=s, model=model, material=m, method=method, voltage=voltage,
                           reference_points=0)
    L = s.length
    Z, Hw, Hth, HF, HM, g, be = _line(u, s, m, Rs, "quasi-static" if Rs == 0.0 else beam, viscous_modulus, n_modes)
    if Rs == 0.0 and beam == "dynamic":
        # ideal electrodes: exactly the uniform strip's modal response (no quadrature)
        d = frequency_response(f, strip=s, model=model, material=m, method=method, voltage=voltage, beam=beam,
                               viscous_modulus=viscous_modulus, n_modes=n_modes, reference_points=0)
        Hw, Hth, HF = d.H_w, d.H_theta, d.H_F
    err = None
    if u.error is not None:
        # the circuit's error of the line itself: against the same line on the linearised PNP's Z_area
        ref = _line(frequency_response(f, strip=s, model=model, material=m), s, m, Rs, "quasi-static",
                    viscous_modulus, n_modes)
        err = np.maximum(np.abs(Z - ref[0]) / np.abs(ref[0]),
                         np.abs(u.H_w * line_factors(g)[2] - ref[1]) / np.abs(ref[1]))
    prof = None
    xs = None
    if x is not None:
        xs = np.atleast_1d(np.asarray(x, dtype=float))
        if xs.ndim != 1 or not np.all(np.isfinite(xs)) or np.any(xs < 0.0) or np.any(xs > L):
            raise ValueError(f"x must be a 1-D array of positions in [0, L] = [0, {L:g}] m")
        if xs.size * g.size > MAX_PROFILE_POINTS:
            raise ValueError(f"x: {xs.size} positions x {g.size} frequencies exceed {MAX_PROFILE_POINTS} profile values")
        prof = voltage_profile(g[:, None], xs[None, :] / L)
    check_finite_response(u.f, {"Z": Z, "H_w": Hw, "H_theta": Hth, "H_F": HF})
    notes = dynamic_notes(beam, viscous_modulus, m) + list(u.notes[len(dynamic_notes(material=m)):]) + [
        f"electrodes: sheet resistance R_s = {Rs:g} Ohm/sq each, in series along the length (r = 2 R_s/(2l)); "
        "the voltage decays along x as an RC line driven at the clamp; the moment follows the local voltage "
        + ("(small displacements, quasi-static beam)" if beam == "quasi-static" else
           "and drives the modes through int M(x) phi_n''(x) dx (small displacements)"),
        SHEET_RESISTANCE_SOURCE,
    ]
    if err is not None:
        notes.append("circuit: 'error' is the relative error of the line's Z and H_w against the same line on the "
                     "linearised PNP (computed at each frequency)")
    if beam == "dynamic":
        notes.append(f"dynamic beam: 'beam_error' bounds the modal quadrature and truncation (largest "
                     f"{float(np.max(be)) if be.size else 0.0:.2g} relative)")
    return LineResult(f=u.f, Z=Z, Z_area=u.Z_area, H_w=Hw, w_amp=np.abs(Hw), w_phase=np.angle(Hw), H_theta=Hth,
                      H_M=HM, gamma_L=g, Z0=u.Z * g, sheet_resistance=Rs, length=L, tau=u.tau, method=u.method,
                      model=u.model, notes=notes, uniform=u, x=xs, V_profile=prof, H_F=HF, error=err,
                      error_max=float(np.max(err)) if err is not None and err.size else math.nan, f_d=u.f_d,
                      resonances=u.resonances, beam=beam, voltage=u.voltage, beam_error=be)
