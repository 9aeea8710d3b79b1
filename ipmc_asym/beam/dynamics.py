r"""Euler-Bernoulli strip with inertia and Kelvin-Voigt damping, driven by the electro-active moment.

Pure mechanics (no electrochemistry): the input is the moment ``M_A(t)`` that the charged layers
exert, uniform over the electrode (the paper's end moment ``M_A^p``, §3); the outputs are the
tip deflection ``w``, the tip rotation ``theta`` (free tip), the blocking force ``F`` (blocked
tip) and the clamps' reactions.

Model
-----
Small transverse displacement ``w(x, t)`` of a strip of length ``L``, clamped at ``x = 0``.
The total bending moment is ``m = EI (w'' + tau_v dw''/dt) + M_a(x, t)``: the paper's
rheological law (eq. (3), Kelvin-Voigt) reduced to a beam in uniaxial stress,
``sigma_xx = E (eps + tau_v d eps/dt)``, with the viscous modulus ``eta_E = E tau_v`` (Pa s)
(``lambda_v``, ``mu_v`` of eq. (3) in the proportion of the elastic ``lambda``, ``G``); the
active moment ``M_a = M_A(t)`` on the electrode; the sign convention of the paper (§3:
``EI dtheta/ds = F (L - s) - M``, so a positive moment bends the strip towards ``z < 0``).
Momentum balance (eq. (2) for a slender beam, rotary inertia neglected)::

    rho A d^2w/dt^2 + m'' = 0,        rho = (1 - phi4) rho3 + phi4 rho2

(the hydrated membrane: the solid, a fraction ``1 - phi4``, and the dilute solution, a
fraction ``phi4`` at the density of water, as in the paper's ``C_moy`` formula of §4).

Supports (``m = 0`` at a free or pinned end)::

    clamped-free    w(L) free      : 1 + cos(bL) cosh(bL) = 0
    clamped-pinned  w(L) = 0       : tan(bL) = tanh(bL)          (blocked tip: F(t) = -m'(L))
    clamped-clamped w = w' = 0     : cos(bL) cosh(bL) = 1

Modal expansion on the exact eigenfunctions ``phi_n`` (``int_0^L phi_n^2 dx = L``)::

    q_n'' + tau_v omega_n^2 q_n' + omega_n^2 q_n = -M_A(t) P_n/(rho A L),
    omega_n^2 = EI b_n^4/(rho A),  P_n = phi_n'(x2) - phi_n'(x1)   (electrode on [x1, x2])

(two integrations by parts of ``int phi_n m'' dx``: the boundary terms vanish for each support).
With a full electrode on a clamped-clamped strip ``P_n = 0``: the clamps take the uniform
moment, nothing moves, the reaction moments are ``M_A(t)`` and the reaction forces 0.

Mode acceleration (static correction): every output is written as its quasi-static value
plus the modal sum of ``q_n - q_n^qs``, whose terms fall off as ``omega_n^-4`` (as against the
slowly converging, for the force divergent, plain modal sum).  The quasi-static part is the
static solution passed through the creep filter ``1/(1 + s tau_v)`` (kinematic outputs) or
unfiltered (forces: ``EI (1 + s tau_v)`` cancels it); in the frequency domain it is the exact
small-displacement statics (``-M L^2/(2EI)``, ``-M L/EI``, ``3M/(2L)``); in the time domain the
caller passes the forward model's (large-displacement) static outputs, so the static limit is
the quasi-static result exactly.

Time stepping is exact for a moment linear between the given times (first-order hold): the
state of each mode is propagated by its transition matrix.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np
from numpy.polynomial import Polynomial as P

from ipmc_asym.base.settings import MAX_CREEP_TIME
from ipmc_asym.kernels.jit import jit
from ipmc_asym.model.electrode import composite_mass, membrane_share
from ipmc_asym.model.params import Material, bending_stiffness, check_positive

__all__ = ["SUPPORTS", "DEFAULT_MODES", "VISCOUS_MODULUS_SOURCE", "Beam", "Modes", "hydrated_density",
           "characteristic", "eigenvalues", "first_resonance", "mode_shape", "modes", "natural_frequencies", "transfer",
           "ModalIntegrator", "viscous_modulus_from_damping_ratio", "moment_kernels", "distributed_transfer",
           "DISTRIBUTED_OUTPUTS", "SUPPORT_OUTPUTS", "CLAMPED_OUTPUTS", "static_outputs"]

SUPPORTS = ("clamped-free", "clamped-pinned", "clamped-clamped")

#: modes kept in the sums (with the static correction the tail falls off as n^-7 for w)
DEFAULT_MODES = 60

VISCOUS_MODULUS_SOURCE = (
    "the viscous modulus eta_E = E tau_v of the paper's Kelvin-Voigt law (eq. (3): lambda_v, mu_v) has no value "
    "in the paper and none was found for hydrated Nafion/IPMC in the sources searched; default 0 (undamped "
    "beam); set it from a measured damping ratio of mode n: eta_E = 2 zeta_n E/omega_n "
    "(viscous_modulus_from_damping_ratio)"
)


def hydrated_density(material: Material) -> float:
    """``rho = (1 - phi4) rho3 + phi4 rho2`` (kg/m^3): solid and solution (dilute: water) by volume."""
    m = material
    return (1.0 - m.phi4) * m.rho3 + m.phi4 * m.rho2


@dataclass(frozen=True)
class Beam:
    """Mechanical data of the strip (SI).

    Attributes
    ----------
    length : float        L, m
    EI : float            bending stiffness E I_p, N m^2 (the composite section with electrode layers)
    rhoA : float          mass per length rho 2l 2e (+ 2 rho_m 2l t_m with layers), kg/m
    tau_v : float         Kelvin-Voigt time eta_E/E, s (>= 0)
    electrode : tuple     covered part [x1, x2] of the length, m (default the whole strip)
    """

    length: float
    EI: float
    rhoA: float
    tau_v: float = 0.0
    electrode: tuple = None

    def __post_init__(self):
        check_positive("length", self.length, "m")
        check_positive("bending stiffness EI", self.EI, "N m^2")
        check_positive("mass per length rho A", self.rhoA, "kg/m")
        if not (math.isfinite(self.tau_v) and self.tau_v >= 0.0):
            raise ValueError(f"viscous time tau_v must be a finite number >= 0 s; got {self.tau_v!r}")
        if self.electrode is not None:
            x1, x2 = (float(v) for v in self.electrode)
            if not (0.0 <= x1 < x2 <= self.length):
                raise ValueError(f"electrode must be [x1, x2] with 0 <= x1 < x2 <= length; got {self.electrode!r}")

    @classmethod
    def from_strip(cls, length, width, thickness, material: Material, viscous_modulus=0.0, electrode=None):
        """The strip of TOTAL width ``2l`` and TOTAL thickness ``2e`` (m); ``viscous_modulus`` in Pa s."""
        eta = float(viscous_modulus)
        if not (math.isfinite(eta) and eta >= 0.0):
            raise ValueError(f"viscous modulus must be a finite number >= 0 Pa s; got {viscous_modulus!r}")
        if eta / material.E > MAX_CREEP_TIME:
            raise ValueError(f"viscous modulus {eta:g} Pa s: its creep time eta_E/E = {eta / material.E:.3g} s is past "
                             f"{MAX_CREEP_TIME:g} s (settings.MAX_CREEP_TIME, a numerical guard; up to "
                             f"{MAX_CREEP_TIME * material.E:.3g} Pa s with E = {material.E:.3g} Pa: a strip far past "
                             "critical damping, which creeps 1e-4 of its way in 0.1 s there)")
        # the composite section with metal layers (material.electrode): stiffness and mass of the
        # three layers; the viscosity acts on the membrane's share E_p I_p of the stiffness only
        el = material.electrode
        EI = float(bending_stiffness(material, float(width), float(thickness)))
        rhoA = float(composite_mass(hydrated_density(material), float(width), float(thickness), el))
        tau_v = eta / material.E
        if el.present:
            tau_v = tau_v * float(membrane_share(material.E, float(width), float(thickness), el))
        return cls(float(length), EI, rhoA, tau_v, electrode)

    @property
    def omega_scale(self) -> float:
        """``sqrt(EI/(rho A L^4))`` (rad/s): ``omega_n = b_n^2`` times this (``b_n = beta_n L``)."""
        return math.sqrt(self.EI / (self.rhoA * self.length**4))


def viscous_modulus_from_damping_ratio(zeta, frequency, modulus):
    """``eta_E = 2 zeta E/omega`` (Pa s): Kelvin-Voigt gives mode n the damping ratio ``tau_v omega_n/2``."""
    z = check_positive("damping ratio", zeta)
    f = check_positive("frequency", frequency, "Hz")
    return 2.0 * z * check_positive("modulus", modulus, "Pa") / (2.0 * math.pi * f)


def _check_support(support):
    if support not in SUPPORTS:
        raise ValueError(f"support must be one of {', '.join(SUPPORTS)}; got {support!r}")


def characteristic(support, b):
    """Characteristic function (the unscaled textbook form) at ``b = beta L``; its roots are the modes."""
    _check_support(support)
    b = np.asarray(b, dtype=float)
    if support == "clamped-free":
        return 1.0 + np.cos(b) * np.cosh(b)
    if support == "clamped-pinned":
        return np.tan(b) - np.tanh(b)
    return np.cos(b) * np.cosh(b) - 1.0


def _scaled(support, b):
    """The characteristic function divided by cosh (bounded, same roots), for root finding."""
    em = math.exp(-b)
    sech = 2.0 * em / (1.0 + em * em)
    if support == "clamped-free":
        return math.cos(b) + sech
    if support == "clamped-pinned":
        return math.sin(b) - math.cos(b) * math.tanh(b)
    return math.cos(b) - sech


def eigenvalues(support, n=DEFAULT_MODES):
    """The first ``n`` roots ``b_k = beta_k L`` of the support's characteristic equation (see
    :func:`_eigenvalues`; a fresh array each call, the roots computed once per support and ``n``)."""
    _check_support(support)
    n = int(n)
    if not 1 <= n <= 2000:
        raise ValueError(f"number of modes must be an integer in [1, 2000]; got {n!r}")
    return _eigenvalues(support, n).copy()


@functools.lru_cache(maxsize=32)
def _eigenvalues(support, n):
    """The first ``n`` roots ``b_k = beta_k L`` of the support's characteristic equation.

    Bisection to the last bit on a bracket holding exactly one root: ``[(k-1) pi, k pi]``
    (clamped-free), ``[k pi, k pi + pi/2]`` (clamped-pinned), ``[k pi, (k+1) pi]`` (clamped-clamped),
    on the characteristic function divided by ``cosh b`` (no overflow).
    """
    _check_support(support)
    n = int(n)
    if not 1 <= n <= 2000:
        raise ValueError(f"number of modes must be an integer in [1, 2000]; got {n!r}")
    out = np.empty(n)
    for k in range(1, n + 1):
        if support == "clamped-free":
            a, c = (k - 1) * math.pi, k * math.pi
        elif support == "clamped-pinned":
            a, c = k * math.pi, k * math.pi + 0.5 * math.pi
        else:
            a, c = k * math.pi, (k + 1) * math.pi
        fa = _scaled(support, a)
        for _ in range(200):
            mid = 0.5 * (a + c)
            if mid in (a, c):
                break
            fm = _scaled(support, mid)
            if (fm > 0) == (fa > 0):
                a, fa = mid, fm
            else:
                c = mid
        out[k - 1] = 0.5 * (a + c)
    return out


def _sigma_terms(support, b):
    """``(sigma, (1 - sigma) e^b)`` of ``phi = cosh - cos - sigma (sinh - sin)``, both O(1), no cancellation."""
    b = np.asarray(b, dtype=float)
    em = np.exp(-b)
    sh = 0.5 * (1.0 - em * em)  # sinh(b) e^{-b}
    s, c = np.sin(b), np.cos(b)
    if support == "clamped-free":
        # sigma = (cosh + cos)/(sinh + sin); (1 - sigma) e^b = (sin - cos - e^{-b})/((sinh + sin) e^{-b})
        om_eb = (s - c - em) / (sh + s * em)
    else:
        # sigma = (cosh - cos)/(sinh - sin); (1 - sigma) e^b = (cos - sin - e^{-b})/((sinh - sin) e^{-b})
        om_eb = (c - s - em) / (sh - s * em)
    return 1.0 - om_eb * em, om_eb


def mode_shape(support, b, xi, deriv=0):
    """``d^k phi/dxi^k`` at ``xi = x/L`` in [0, 1] for the mode ``b = beta L`` (broadcast), ``k`` = 0..3.

    ``phi = cosh(b xi) - cos(b xi) - sigma (sinh(b xi) - sin(b xi))`` (``int_0^1 phi^2 dxi = 1``)
    written as ``[(1 - sigma) e^{b xi} + (1 + sigma) e^{-b xi}]/2 - cos + sigma sin`` with
    ``(1 - sigma) e^{b xi}`` formed as ``[(1 - sigma) e^{b}] e^{b (xi - 1)}``: every term O(1).
    """
    _check_support(support)
    b = np.asarray(b, dtype=float)
    xi = np.asarray(xi, dtype=float)
    sg, om_eb = _sigma_terms(support, b)
    up = 0.5 * om_eb * np.exp(b * (xi - 1.0))
    dn = 0.5 * (1.0 + sg) * np.exp(-b * xi)
    c, s = np.cos(b * xi), np.sin(b * xi)
    k = int(deriv)
    hyp = up + dn if k % 2 == 0 else up - dn
    trig = (-c + sg * s, s + sg * c, c - sg * s, -s - sg * c)[k]
    return b**k * (hyp + trig)


@dataclass
class Modes:
    """The modal data of one support (SI; derivatives with respect to x, not xi).

    Attributes
    ----------
    support : str ; b : ndarray  beta_n L ; omega : ndarray  natural angular frequencies, rad/s
    phi_L, dphi_L, d3phi_L : ndarray  phi_n, phi_n', phi_n''' at the tip x = L
    d2phi_0 : ndarray  phi_n'' at the clamp x = 0
    P : ndarray  phi_n'(x2) - phi_n'(x1), 1/m (the modal force of a unit active moment)
    """

    support: str
    b: np.ndarray
    omega: np.ndarray
    phi_L: np.ndarray
    dphi_L: np.ndarray
    d3phi_L: np.ndarray
    d2phi_0: np.ndarray
    P: np.ndarray


def modes(support, beam: Beam, n=DEFAULT_MODES) -> Modes:
    """Eigenvalues and the end values of the eigenfunctions of ``support`` for ``beam``."""
    b = eigenvalues(support, n)
    L = beam.length
    x1, x2 = (0.0, L) if beam.electrode is None else (float(beam.electrode[0]), float(beam.electrode[1]))
    d1 = lambda xi: mode_shape(support, b, xi, 1) / L  # noqa: E731
    if support == "clamped-clamped" and beam.electrode is None:
        P = np.zeros_like(b)  # phi'(L) = phi'(0) = 0 exactly: the clamps take the uniform moment
    else:
        P = d1(x2 / L) - (d1(x1 / L) if x1 > 0.0 else 0.0)
    return Modes(support=support, b=b, omega=b * b * beam.omega_scale,
                 phi_L=mode_shape(support, b, 1.0, 0), dphi_L=d1(1.0), d3phi_L=mode_shape(support, b, 1.0, 3) / L**3,
                 d2phi_0=mode_shape(support, b, 0.0, 2) / L**2, P=P)


def natural_frequencies(support, beam: Beam, n=5):
    """Undamped natural frequencies ``f_n = b_n^2 sqrt(EI/(rho A L^4))/(2 pi)`` (Hz)."""
    return eigenvalues(support, n) ** 2 * beam.omega_scale / (2.0 * math.pi)


def first_resonance(length, width, thickness, material: Material, support="clamped-free"):
    """First undamped natural frequency (Hz), vectorised over the geometry (TOTAL width and
    thickness, m): ``f1 = b1^2 sqrt(E I_p/(rho A L^4))/(2 pi)``, ``b1 = 1.8751`` for a free tip
    (:func:`eigenvalues`), the same as :func:`natural_frequencies` of :meth:`Beam.from_strip`."""
    L = np.asarray(length, dtype=float)
    EI = bending_stiffness(material, width, thickness)
    rhoA = composite_mass(hydrated_density(material), width, thickness, material.electrode)
    return float(eigenvalues(support, 1)[0]) ** 2 * np.sqrt(EI / (rhoA * L**4)) / (2.0 * math.pi)


def _static_small(support, beam: Beam):
    """Small-displacement statics per unit moment, full electrode: (w_tip, theta_tip, F_tip)."""
    L, EI = beam.length, beam.EI
    if support == "clamped-free":
        return -L * L / (2.0 * EI), -L / EI, 0.0
    if support == "clamped-pinned":
        return 0.0, -L / (4.0 * EI), 1.5 / L
    return 0.0, 0.0, 0.0


def _clamped_solution(support, part):
    """``part + c2 xi^2 + c3 xi^3``: a particular solution of a fourth-order beam problem (value and
    slope already 0 at the clamp ``xi = 0``) completed to meet the far end's conditions: second and
    third derivatives 0 (clamped-free), value and second derivative 0 (clamped-pinned)."""
    x2, x3 = P([0, 0, 1.0]), P([0, 0, 0, 1.0])
    if support == "clamped-free":
        rows = [(x2.deriv(2)(1), x3.deriv(2)(1)), (x2.deriv(3)(1), x3.deriv(3)(1))]
        rhs = [-part.deriv(2)(1), -part.deriv(3)(1)]
    else:
        rows = [(x2(1), x3(1)), (x2.deriv(2)(1), x3.deriv(2)(1))]
        rhs = [-part(1), -part.deriv(2)(1)]
    c2, c3 = np.linalg.solve(np.array(rows, dtype=float), np.array(rhs, dtype=float))
    return part + c2 * x2 + c3 * x3


def _second_static(support, beam: Beam):
    """End values of ``w2 = sum g_n phi_n/omega_n^4`` per unit moment (full electrode).

    ``w1 = sum g_n phi_n/omega_n^2`` is the static deflection (``-x^2/(2EI)``, clamped-free;
    ``(x^2/4 - x^3/(4L))/EI``, clamped-pinned; 0, clamped-clamped) and ``w2`` solves
    ``(EI/rho A) d4w2/dx4 = w1`` with the support's homogeneous conditions (the operator's
    inverse applied twice).  Returns ``(w2(L), w2'(L), w2''(0), w2'''(L))`` in SI.
    """
    L, EI = beam.length, beam.EI
    if support == "clamped-free":
        w1 = P([0.0, 0.0, -0.5]) * (L * L / EI)  # in xi = x/L
    elif support == "clamped-pinned":
        w1 = P([0.0, 0.0, 0.25, -0.25]) * (L * L / EI)
    else:
        return 0.0, 0.0, 0.0, 0.0
    part = (w1 * (beam.rhoA * L**4 / EI)).integ(4)  # zero value and slope at xi = 0: the clamp
    w2 = _clamped_solution(support, part)
    return float(w2(1)), float(w2.deriv(1)(1)) / L, float(w2.deriv(2)(0)) / L**2, float(w2.deriv(3)(1)) / L**3


#: outputs of a clamped-clamped strip: reaction moments and forces of the two clamps, midspan deflection
CLAMPED_OUTPUTS = ("M_root", "M_tip", "F_root", "F_tip", "w_mid")

#: outputs of :func:`transfer` and :class:`ModalIntegrator` for each support (any electrode)
SUPPORT_OUTPUTS = {"clamped-free": ("w", "theta"), "clamped-pinned": ("F", "theta"), "clamped-clamped": CLAMPED_OUTPUTS}

# output -> (derivative order k, position xi = x/L, force or kinematic, sign c): a kinematic output is
# d^k w/dx^k at x; a force c EI (1 + tau_v d/dt) d^k w/dx^k plus the active moment there (moments, k = 2).
# With m = EI (w'' + tau_v dw''/dt) + M_a: M_root = m(0), M_tip = m(L) (the clamps' reaction moments, the
# paper's sign), F_root = m'(0), F_tip = F = -m'(L) (the clamps' transverse forces on the strip, +z: the
# blocking force's convention; statically F_root = -F_tip)
_OUTPUT_SPEC = {"w": (0, 1.0, False, 1.0), "theta": (1, 1.0, False, 1.0), "w_mid": (0, 0.5, False, 1.0),
                "F": (3, 1.0, True, -1.0), "F_tip": (3, 1.0, True, -1.0), "F_root": (3, 0.0, True, 1.0),
                "M_root": (2, 0.0, True, 1.0), "M_tip": (2, 1.0, True, 1.0)}


def _dpow(k, d, x):
    """``d^d/dx^d x^k`` at ``x``."""
    return 0.0 if d > k else math.factorial(k) / math.factorial(k - d) * x ** (k - d)


@functools.lru_cache(maxsize=64)
def _piecewise_statics(support, beam: Beam):
    """Static deflection ``w1`` and second static ``w2`` per unit active moment, any electrode.

    ``w1``: ``EI w1'' = m - M_a`` with ``m`` linear (no load), ``M_a = 1`` on the electrode; the
    support's conditions on ``w`` and ``m`` (``m = 0`` at a free or pinned end, ``m' = 0`` at a
    free end).  ``w2``: ``(EI/rho A) d^4 w2/dx^4 = w1`` with the support's homogeneous conditions
    (the operator's inverse applied twice, as :func:`_second_static`).  Polynomials (degree 3 and
    7) on the pieces cut by the electrode's ends, joined with ``w, w', m, m'`` continuous.

    Returns ``(breaks, w1, w2, Ma)``: breaks in ``xi = x/L``, tuples of
    :class:`numpy.polynomial.Polynomial` in ``xi`` (SI values), the active moment on each piece.
    """
    L, EI = beam.length, beam.EI
    a, b = (0.0, 1.0) if beam.electrode is None else (beam.electrode[0] / L, beam.electrode[1] / L)
    brk = sorted({0.0, float(a), float(b), 1.0})
    ns = len(brk) - 1
    Ma = [1.0 if (brk[j] >= a and brk[j + 1] <= b) else 0.0 for j in range(ns)]
    end = {"clamped-free": (2, 3), "clamped-pinned": (0, 2), "clamped-clamped": (0, 1)}[support]

    def solve(q, s):
        # w_j = part_j + sum_k c_jk xi^k; continuity of w, w', w'' + s M_a (the moment), w''' at the breaks
        part = [qj.integ(4) for qj in q]
        A = np.zeros((4 * ns, 4 * ns))
        r = np.zeros(4 * ns)

        def cond(row, j, d, x, coef):
            A[row, 4 * j:4 * j + 4] += [coef * _dpow(k, d, x) for k in range(4)]
            return -coef * part[j].deriv(d)(x)

        row = 0
        for d in (0, 1):  # the clamp at x = 0
            r[row] = cond(row, 0, d, 0.0, 1.0)
            row += 1
        for j in range(1, ns):
            for d in range(4):
                r[row] = cond(row, j - 1, d, brk[j], 1.0) + cond(row, j, d, brk[j], -1.0)
                if d == 2:
                    r[row] += s * (Ma[j] - Ma[j - 1])
                row += 1
        for d in end:
            r[row] = cond(row, ns - 1, d, 1.0, 1.0) - (s * Ma[-1] if d == 2 else 0.0)
            row += 1
        c = np.linalg.solve(A, r)
        return tuple(part[j] + P(c[4 * j:4 * j + 4]) for j in range(ns))

    w1 = solve([P([0.0])] * ns, L * L / EI)
    w2 = solve([w * (beam.rhoA * L**4 / EI) for w in w1], 0.0)
    return tuple(brk), w1, w2, tuple(Ma)


def _piece(brk, xi):
    """Index of the piece holding ``xi`` (the first one at a break: 0 at the clamp, the last at the tip)."""
    for j in range(len(brk) - 1):
        if brk[j] <= xi <= brk[j + 1]:
            return j
    raise ValueError(f"xi = {xi!r} outside [0, 1]")


def static_outputs(support, beam: Beam, names=None):
    """Small-displacement static outputs and second statics per unit active moment, any electrode.

    Parameters
    ----------
    support : str ; beam : Beam (its ``electrode``, default the whole strip)
    names : iterable of str, optional   default :data:`SUPPORT_OUTPUTS` of the support

    Returns
    -------
    dict  name -> ``(O1, O2)``: ``O1`` the static value (m, rad, N or N m per N m of active moment),
          ``O2`` the second static ``d^k w2/dx^k`` at the output's point (the sum over all modes of
          ``g_n phi_n^(k)/omega_n^4``, see :func:`transfer`)
    """
    _check_support(support)
    brk, w1, w2, Ma = _piecewise_statics(support, beam)
    L, EI = beam.length, beam.EI
    out = {}
    for n in (SUPPORT_OUTPUTS[support] if names is None else names):
        k, xi, force, c = _OUTPUT_SPEC[n]
        j = _piece(brk, xi)
        o1 = float(w1[j].deriv(k)(xi)) / L**k
        o2 = float(w2[j].deriv(k)(xi)) / L**k
        if force:
            o1 = c * EI * o1 + (Ma[j] if k == 2 else 0.0)
        out[n] = (o1, o2)
    return out


def _general_transfer(f, beam: Beam, support, n_modes):
    """:func:`transfer` for any electrode and the outputs of :data:`SUPPORT_OUTPUTS` (the same expansion)."""
    md = modes(support, beam, n_modes)
    L, EI = beam.length, beam.EI
    s = 2j * math.pi * f[..., None]
    kv = 1.0 + s * beam.tau_v
    Dn = md.omega**2 * kv + s * s
    g = -md.P / (beam.rhoA * L)
    rem = g * s**4 / (md.omega**4 * kv * kv * Dn)
    k0, s0 = kv[..., 0], s[..., 0]
    st = static_outputs(support, beam)
    out = {"static": {n: v[0] for n, v in st.items()}}
    trunc = 0.0
    for n, (o1, o2) in st.items():
        k, xi, force, c = _OUTPUT_SPEC[n]
        ph = mode_shape(support, md.b, xi, k) / L**k
        if force:  # c EI (1 + s tau_v) w^(k) (+ M_a): the static unfiltered, the second static once
            t = c * EI * kv * rem * ph
            out[n] = o1 - c * EI * s0 * s0 * o2 / k0 + t.sum(axis=-1)
        else:
            t = rem * ph
            out[n] = o1 / k0 - s0 * s0 * o2 / k0**2 + t.sum(axis=-1)
        if f.size:
            trunc = max(trunc, float(np.max(np.abs(t[..., -1]) / np.maximum(np.abs(out[n]), 1e-300))))
    out["dynamic_factor"] = {k: out[k] / v for k, v in out["static"].items() if v != 0.0}
    out["truncation"] = trunc
    out["modes"] = md
    return out


def transfer(f, beam: Beam, support="clamped-free", n_modes=DEFAULT_MODES):
    """Tip responses per unit active moment at frequencies ``f`` (Hz), small displacements.

    Exact up to the modal tail: with ``k = 1 + s tau_v`` and ``D_n = omega_n^2 k + s^2``,
    ``1/D_n = 1/(omega_n^2 k) - s^2/(omega_n^4 k^2) + s^4/(omega_n^4 k^2 D_n)``; the first two
    sums over ALL modes are the statics ``w1`` and the second static ``w2``
    (:func:`_second_static`, closed form), so only the last, falling off as ``b_n^-8`` (force)
    or faster, is summed over the kept modes.

    Returns
    -------
    dict of complex ndarrays and floats
        clamped-free: ``w`` (m/(N m)), ``theta`` (rad/(N m)); clamped-pinned: ``F`` (N/(N m),
        the blocking force), ``theta``; clamped-clamped: ``M_root`` (the reaction moment at the
        clamp x = 0 per unit moment) and ``M_tip``, ``F_root``, ``F_tip``, ``w_mid``
        (:data:`SUPPORT_OUTPUTS`).  A partial electrode (``beam.electrode``) takes the statics of
        :func:`static_outputs` in the same expansion.  ``static``: the same at f = 0 (exact small-displacement
        statics); ``dynamic_factor``: each divided by its static value (where that is not 0);
        ``truncation``: relative size of the last kept mode's term (the tail is smaller).
    """
    _check_support(support)
    f = np.asarray(f, dtype=float)
    if not np.all(np.isfinite(f)) or np.any(f < 0):
        raise ValueError("frequencies must be finite and >= 0 Hz")
    if beam.electrode is not None or support == "clamped-clamped":
        return _general_transfer(f, beam, support, n_modes)
    md = modes(support, beam, n_modes)
    s = 2j * math.pi * f[..., None]
    kv = 1.0 + s * beam.tau_v
    Dn = md.omega**2 * kv + s * s
    g = -md.P / (beam.rhoA * beam.length)
    rem = g * s**4 / (md.omega**4 * kv * kv * Dn)  # third term per mode, per unit c_n
    w_s, th_s, F_s = _static_small(support, beam)
    w2L, dw2L, d2w20, d3w2L = _second_static(support, beam)
    k0 = kv[..., 0]
    s0 = s[..., 0]
    EI = beam.EI
    out = {"static": {}}
    if support == "clamped-free":
        terms = {"w": rem * md.phi_L, "theta": rem * md.dphi_L}
        base = {"w": w_s / k0 - s0 * s0 * w2L / k0**2, "theta": th_s / k0 - s0 * s0 * dw2L / k0**2}
        out["static"] = {"w": w_s, "theta": th_s}
    elif support == "clamped-pinned":
        # F = -EI (1 + s tau_v) w'''(L)
        terms = {"F": -EI * kv * rem * md.d3phi_L, "theta": rem * md.dphi_L}
        base = {"F": F_s + EI * s0 * s0 * d3w2L / k0, "theta": th_s / k0 - s0 * s0 * dw2L / k0**2}
        out["static"] = {"F": F_s, "theta": th_s}
    else:
        terms = {"M_root": EI * kv * rem * md.d2phi_0}
        base = {"M_root": np.ones(f.shape, dtype=complex) - EI * s0 * s0 * d2w20 / k0}
        out["static"] = {"M_root": 1.0}
    trunc = 0.0
    for k, t in terms.items():
        out[k] = base[k] + t.sum(axis=-1)
        if f.size:
            scale = np.maximum(np.abs(out[k]), 1e-300)
            trunc = max(trunc, float(np.max(np.abs(t[..., -1]) / scale)))
    out["dynamic_factor"] = {k: out[k] / v for k, v in out["static"].items() if v != 0.0}
    out["truncation"] = trunc
    out["modes"] = md
    return out


#: outputs of :func:`distributed_transfer` for each support
DISTRIBUTED_OUTPUTS = {"clamped-free": ("w", "theta"), "clamped-pinned": ("F", "theta")}


def moment_kernels(support, beam: Beam):
    """Curvature kernels of the statics under a distributed active moment ``M_a(x)`` (full electrode).

    Each output is a linear functional of ``M_a``: ``O_j = int_0^L M_a(x) kappa_j(x) dx`` for the
    static part ``O_1`` and the second static ``O_2`` of :func:`transfer` (the sums over ALL modes
    of ``g_n out(phi_n)/omega_n^{2j}``, ``g_n = -int M_a phi_n'' dx/(rho A L)``).  With the Green
    function ``G`` of ``d^4/dx^4`` under the support's conditions and ``u(x) = out_y G(y, x)``
    (the field of the output's dual load): ``kappa_1 = -u''/EI`` and ``kappa_2 = -(rho A/EI^2) U''``
    with ``d^4U/dx^4 = u`` under the same conditions (the operator's inverse applied twice, as in
    :func:`_second_static`).  ``u`` per output, ``xi = x/L``: clamped-free ``w(L)``:
    ``L^3 (3 xi^2 - xi^3)/6`` (tip force), ``theta(L)``: ``L^2 xi^2/2`` (tip couple); clamped-pinned
    ``theta(L)``: ``L^2 (xi^3 - xi^2)/4``, ``w'''(L)``: ``(3 xi^2 - xi^3)/2`` (the prop's influence
    line), and the blocking force ``F = -EI w'''(L)``.  For a uniform moment the integrals are the
    closed forms of :func:`_static_small` and :func:`_second_static` (tested).

    Returns
    -------
    dict  output -> (kappa_1, kappa_2), each a :class:`numpy.polynomial.Polynomial` in ``xi = x/L``
          whose value is the kernel in SI (output unit per N m, per m)
    """
    return dict(_moment_kernels(support, beam))


@functools.lru_cache(maxsize=64)
def _moment_kernels(support, beam: Beam):
    _check_support(support)
    if support not in DISTRIBUTED_OUTPUTS:
        raise ValueError(f"a distributed moment is supported on {', '.join(DISTRIBUTED_OUTPUTS)}; got {support!r}")
    L, EI, rhoA = beam.length, beam.EI, beam.rhoA
    if support == "clamped-free":
        duals = {"w": P([0, 0, 3.0, -1.0]) * (L**3 / 6.0), "theta": P([0, 0, 0.5]) * L**2}
    else:
        duals = {"F": P([0, 0, 1.5, -0.5]), "theta": P([0, 0, -0.25, 0.25]) * L**2}
    out = {}
    for k, u in duals.items():
        part = (u * L**4).integ(4)  # d^4/dxi^4 = L^4 d^4/dx^4; zero value and slope at the clamp
        U = _clamped_solution(support, part)
        k1 = -u.deriv(2) / (EI * L * L)
        k2 = -U.deriv(2) * (rhoA / (EI * EI * L * L))
        if k == "F":  # F = -EI w'''(L)
            k1, k2 = -EI * k1, -EI * k2
        out[k] = (k1, k2)
    return out


def distributed_transfer(f, beam: Beam, support, integrate, n_modes=DEFAULT_MODES):
    """Tip responses to a distributed active moment ``M_a(x, s)`` at frequencies ``f`` (Hz).

    The moment enters the modes through ``Q_n = int_0^L M_a phi_n'' dx`` (the two integrations by
    parts of the module docstring; the boundary terms vanish at a clamp, a free or a pinned end)
    in place of ``M_A P_n``; the static and second static parts are the integrals of
    :func:`moment_kernels`, so the expansion of :func:`transfer` holds with the same tail.

    Parameters
    ----------
    f : array_like   frequencies, Hz (>= 0)
    beam : Beam      full electrode
    support : {"clamped-free", "clamped-pinned"}
    integrate : callable
        ``integrate(c)`` -> complex array (len(f), k), or a pair (values, error estimates):
        ``int_0^L M_a(x, s) c_i(x) dx`` at each frequency, for ``c(x)`` returning k curvatures (k, n) at n positions x (m), e.g.
        :meth:`ipmc_asym.dynamics.line.LineResult.modal_forcing` (N m/V times m/m^2 per volt).
    n_modes : int

    Returns
    -------
    dict  clamped-free: ``w`` (m), ``theta`` (rad); clamped-pinned: ``F`` (N), ``theta``; complex
          (len(f),) per unit of ``M_a``; ``truncation``: relative size of the last kept mode's term;
          ``error`` (when ``integrate`` returns ``(values, errors)``, the errors >= 0 of its integrals):
          dict output -> relative error bound of that output from the integrals' errors.
    """
    f = np.asarray(f, dtype=float)
    if not np.all(np.isfinite(f)) or np.any(f < 0):
        raise ValueError("frequencies must be finite and >= 0 Hz")
    if beam.electrode is not None:
        raise ValueError("a distributed moment with a partial electrode is not supported: give the moment on [0, L]")
    ker = moment_kernels(support, beam)
    names = list(ker)
    md = modes(support, beam, n_modes)
    L = beam.length
    b = md.b

    def curv(x):
        xi = np.asarray(x, dtype=float) / L
        k = [ker[n][j](xi) for n in names for j in (0, 1)]
        return np.vstack(k + list(mode_shape(support, b[:, None], xi[None, :], 2) / (L * L)))

    got = integrate(curv)
    vals, errs = (np.asarray(got[0]), np.asarray(got[1])) if isinstance(got, tuple) else (np.asarray(got), None)
    if vals.shape != (f.size, 2 * len(names) + b.size):
        raise ValueError(f"integrate(c) must return an array (len(f), k) = ({f.size}, {2 * len(names) + b.size})")
    nk = 2 * len(names)
    s = 2j * math.pi * f[:, None]
    kv = 1.0 + s * beam.tau_v
    Dn = md.omega**2 * kv + s * s
    coef = -s**4 / (beam.rhoA * L * md.omega**4 * kv * kv * Dn)  # of Q_n in each mode's remainder
    k0, s0 = kv[:, 0], s[:, 0]
    out = {}
    trunc = 0.0
    for i, n in enumerate(names):
        # each output: a1 int(M kappa_1) + a2 int(M kappa_2) + sum_n c_n Q_n
        if n == "F":  # -EI (1 + s tau_v) w'''(L): the static is not filtered, the second static once
            a1, a2, cn = np.ones_like(k0), -s0 * s0 / k0, -beam.EI * kv * coef * md.d3phi_L
        else:
            a1, a2, cn = 1.0 / k0, -s0 * s0 / k0**2, coef * (md.phi_L if n == "w" else md.dphi_L)
        t = cn * vals[:, nk:]
        out[n] = a1 * vals[:, 2 * i] + a2 * vals[:, 2 * i + 1] + t.sum(axis=-1)
        if errs is not None:
            # the integrals' error estimates carried through the same linear map, in absolute values
            bound = (np.abs(a1) * errs[:, 2 * i] + np.abs(a2) * errs[:, 2 * i + 1]
                     + np.sum(np.abs(cn) * errs[:, nk:], axis=-1))
            out.setdefault("error", {})[n] = bound / np.maximum(np.abs(out[n]), 1e-300)
        if f.size:
            trunc = max(trunc, float(np.max(np.abs(t[:, -1]) / np.maximum(np.abs(out[n]), 1e-300))))
    out["truncation"] = trunc
    return out


@jit
def _propagate(t, M, S, omega, tau_v, P, rhoAL, q0, v0, y0, ys0, out_q, out_dq, out_y, out_ys):
    """Exact first-order-hold propagation of every mode and of the creep filter.

    Mode n: ``q'' + tau_v w_n^2 q' + w_n^2 q = -M(t) P_n/(rho A L)``; creep filter
    ``tau_v y' + y = M`` (moment) and ``tau_v ys' + ys = S`` (the static outputs, columns of S).
    ``M`` and ``S`` linear between the times ``t``.  Writes ``q_n(t_k)`` minus its quasi-static
    part ``-y(t_k) P_n/(rho A L w_n^2)`` in ``out_q``, its time derivative in ``out_dq`` and the
    filtered statics in ``out_ys``.
    """
    nm = omega.shape[0]
    ns = S.shape[1]
    q = q0.copy()
    v = v0.copy()
    y = y0
    ys = ys0.copy()
    h_prev = -1.0
    p11 = np.empty(nm)
    p12 = np.empty(nm)
    p21 = np.empty(nm)
    p22 = np.empty(nm)
    ef = 0.0
    gw = np.empty(nm)
    for n in range(nm):
        gw[n] = -P[n] / (rhoAL * omega[n] * omega[n])
    for n in range(nm):
        out_q[0, n] = q[n] - gw[n] * y
        out_dq[0, n] = v[n]
    out_y[0] = y
    for j in range(ns):
        out_ys[0, j] = ys[j]
    for k in range(1, t.shape[0]):
        h = t[k] - t[k - 1]
        # an equally spaced grid differs in the last bits only: keep its transition matrices
        if abs(h - h_prev) > 1e-13 * h:
            for n in range(nm):
                w = omega[n]
                a = 0.5 * tau_v * w * w
                mu2 = a * a - w * w
                if mu2 < 0.0:
                    nu = math.sqrt(-mu2)
                    C = math.cos(nu * h)
                    Sx = math.sin(nu * h) / nu
                    ea = math.exp(-a * h)
                    C *= ea
                    Sx *= ea
                else:
                    mu = math.sqrt(mu2)
                    if mu * h >= 1e-4:
                        # overdamped: the roots s2 = -(a + mu) and s1 = w^2/s2 (their product is w^2);
                        # mu - a would cancel where a >> w (a heavy viscous modulus: 0 for the upper
                        # modes, which would then never creep)
                        s2 = -(a + mu)
                        s1 = w * w / s2
                        e1 = math.exp(s1 * h)
                        e2 = math.exp(s2 * h)
                        d = 1.0 / (s1 - s2)
                        p11[n] = (s1 * e2 - s2 * e1) * d
                        p12[n] = (e1 - e2) * d
                        p21[n] = -w * w * p12[n]
                        p22[n] = (s1 * e1 - s2 * e2) * d
                        continue
                    ea = math.exp(-a * h)
                    C = ea * (1.0 + 0.5 * mu2 * h * h)
                    Sx = ea * h * (1.0 + mu2 * h * h / 6.0)
                p11[n] = C + a * Sx
                p12[n] = Sx
                p21[n] = -w * w * Sx
                p22[n] = C - a * Sx
            ef = math.exp(-h / tau_v) if tau_v > 0.0 else 0.0
            h_prev = h
        # creep filter, first-order hold: y = x - tau b + e^{-h/tau} (y_k - x_k + tau b)
        bM = (M[k] - M[k - 1]) / h
        if tau_v > 0.0:
            y_new = M[k] - tau_v * bM + ef * (y - M[k - 1] + tau_v * bM)
            for j in range(ns):
                bS = (S[k, j] - S[k - 1, j]) / h
                ys[j] = S[k, j] - tau_v * bS + ef * (ys[j] - S[k - 1, j] + tau_v * bS)
        else:
            y_new = M[k]
            for j in range(ns):
                ys[j] = S[k, j]
        for n in range(nm):
            # particular solution of q'' + c q' + w2 q = g (M_k + bM s): qp = gw (M_k - cw bM) + gw bM s,
            # gw = g/w2, cw = c/w2 = tau_v
            yq = q[n] - gw[n] * (M[k - 1] - tau_v * bM)
            vp = gw[n] * bM
            yv = v[n] - vp
            q[n] = gw[n] * (M[k] - tau_v * bM) + p11[n] * yq + p12[n] * yv
            v[n] = vp + p21[n] * yq + p22[n] * yv
            out_q[k, n] = q[n] - gw[n] * y_new
            # d/dt of the quasi-static part: gw y', y' = (M - y)/tau_v (0 without creep: not used then)
            out_dq[k, n] = v[n] - (gw[n] * (M[k] - y_new) / tau_v if tau_v > 0.0 else 0.0)
        y = y_new
        out_y[k] = y
        for j in range(ns):
            out_ys[k, j] = ys[j]
    return q, v, y, ys


class ModalIntegrator:
    """Time response of one support to the active moment, chunk by chunk (state carried over).

    ``advance(t, M, statics)`` takes output times ``t`` (s, increasing; the first equal to the
    last time of the previous chunk, or 0 at the start, at rest), the moment ``M_A(t)`` (N m) and
    the quasi-static outputs at those times (dict name -> array: ``w``, ``theta``, ``F``,
    ``M_root``, from the static model; for a clamped-clamped strip also ``M_tip``, ``F_root``,
    ``F_tip``, ``w_mid``, e.g. :func:`static_outputs` times the moment), and returns the dynamic outputs: the quasi-static values
    through the creep filter (forces unfiltered) plus the modal sums of ``q_n - q_n^qs``.
    """

    def __init__(self, beam: Beam, support="clamped-free", n_modes=DEFAULT_MODES):
        self.beam = beam
        self.support = support
        self.md = modes(support, beam, n_modes)
        nm = self.md.b.size
        self.q = np.zeros(nm)
        self.v = np.zeros(nm)
        self.y = 0.0
        self.ys = None
        self.t_last = None
        self.hist_t = np.zeros(0)
        self.hist_y = np.zeros(0)
        md = self.md
        g = -md.P / (beam.rhoA * beam.length)
        _, _, d2w20, d3w2L = _second_static(support, beam) if beam.electrode is None else (0.0, 0.0, 0.0, 0.0)
        self.tail_F = d3w2L - float(np.sum(g * md.d3phi_L / md.omega**4))
        self.tail_M = d2w20 - float(np.sum(g * md.d2phi_0 / md.omega**4))
        # any electrode, every output of the support: the mode values at its point and the force tail
        self.spec = {}
        st = static_outputs(support, beam, tuple(_OUTPUT_SPEC))
        for n, (k, xi, force, c) in _OUTPUT_SPEC.items():
            ph = mode_shape(support, md.b, xi, k) / beam.length**k
            self.spec[n] = (ph, force, c, st[n][1] - float(np.sum(g * ph / md.omega**4)))
        if beam.electrode is not None:
            self.tail_F, self.tail_M = self.spec["F"][3], self.spec["M_root"][3]

    def advance(self, t, M, statics):
        t = np.ascontiguousarray(t, dtype=float)
        M = np.ascontiguousarray(M, dtype=float)
        names = list(statics)
        S = np.ascontiguousarray(np.column_stack([np.asarray(statics[k], dtype=float) for k in names])
                                 if names else np.zeros((t.size, 0)))
        if self.ys is None:
            self.ys = S[0].copy()  # at rest at the first time: the filter starts at the static value
            self.y = float(M[0])
        elif self.t_last is not None and t[0] != self.t_last:
            raise ValueError("each chunk must start at the last time of the previous one")
        md, b = self.md, self.beam
        oq = np.empty((t.size, md.b.size))
        odq = np.empty((t.size, md.b.size))
        oy = np.empty(t.size)
        oys = np.empty((t.size, len(names)))
        self.q, self.v, self.y, ys = _propagate(t, M, S, md.omega, b.tau_v, md.P, b.rhoA * b.length, self.q, self.v,
                                                self.y, self.ys, oq, odq, oy, oys)
        self.ys = np.asarray(ys)
        self.t_last = float(t[-1])
        # forces: the modes past the kept ones add EI (w2''' - sum_kept) d^2y/dt^2 (y the moment through the
        # creep filter), the second static of transfer(); the kinematic outputs' tail is below rounding.
        # d^2y/dt^2 by the backward second difference, carried over chunks (causal, the same split or not)
        th = np.concatenate((self.hist_t, t[1:] if self.hist_t.size else t))
        yh = np.concatenate((self.hist_y, oy[1:] if self.hist_y.size else oy))
        ydd_all = np.zeros(th.size)
        if th.size > 2:
            h1 = th[2:] - th[1:-1]
            h0 = th[1:-1] - th[:-2]
            ydd_all[2:] = 2.0 * ((yh[2:] - yh[1:-1]) / h1 - (yh[1:-1] - yh[:-2]) / h0) / (h0 + h1)
        ydd = ydd_all[th.size - t.size:]
        self.hist_t, self.hist_y = th[-2:], yh[-2:]
        out = {}
        for j, k in enumerate(names):
            if k == "w":
                out[k] = oys[:, j] + oq @ md.phi_L
            elif k == "theta":
                out[k] = oys[:, j] + oq @ md.dphi_L
            elif k == "F":
                # -EI (1 + tau_v d/dt) sum d_n phi_n'''(L); the derivative of d_n from the same modal state
                dd = oq + b.tau_v * odq if b.tau_v > 0.0 else oq
                out[k] = S[:, j] - b.EI * (dd @ md.d3phi_L) + b.EI * self.tail_F * ydd
            elif k == "M_root":
                dd = oq + b.tau_v * odq if b.tau_v > 0.0 else oq
                out[k] = S[:, j] + b.EI * (dd @ md.d2phi_0) - b.EI * self.tail_M * ydd
            elif k in self.spec:
                ph, force, c, tail = self.spec[k]
                if force:  # c EI (1 + tau_v d/dt) w^(k) plus the unfiltered static (with the active moment)
                    dd = oq + b.tau_v * odq if b.tau_v > 0.0 else oq
                    out[k] = S[:, j] + c * b.EI * (dd @ ph) - c * b.EI * tail * ydd
                else:
                    out[k] = oys[:, j] + oq @ ph
            else:
                raise ValueError(f"unknown output {k!r}; allowed: {', '.join(_OUTPUT_SPEC)}")
        return out
