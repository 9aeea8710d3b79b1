"""Reduced charging model and small-signal response.

Matched asymptotics of the transient Nernst-Planck/Gauss problem (``ipmc_asym.dynamics.transient``):
the two electrode layers stay quasi-static (each in its static state for the charge it
carries) while the neutral core carries an ohmic current.  Per unit electrode area::

    R dsigma_L/dt = phi0(t) - V(sigma_L),     V = inverse of the static sigma(phi0) (electrode.py)

plus the displacement charge of the bulk (a leaky dielectric, relaxation time ``lambda^2 e^2/D``,
instantaneous on the scale ``tau``): ``sigma = sigma_L + C_g (phi0 - V(sigma_L))``,
``C_g = eps_core/(2e)`` (``C_g/C_d(0) = lambda``; it is what a step charges at ``t = 0+``).

``R = 2e/kappa`` with the core conductivity ``kappa = phi4 F^2 D C_moy/(R T)``: the paper's
Nernst law (seed paper eq. "Nernst", solvent at rest, pressure term neglected as in §5) gives
the molar cation flux per unit area of the MATERIAL ``phi4 C V1 = -phi4 D (grad C - F C E/(R T))``
(``C`` is per unit volume of the liquid phase, a fraction ``phi4`` of the volume); in the
neutral core ``C = C_moy``, so ``j = F phi4 C V1 = kappa E``.  The porosity factor is ``phi4``
(no tortuosity factor: ``D`` is the diffusion coefficient in the liquid phase, as the paper
defines it).  Linear time constant ``tau = R C_d(0) = e lambda_D/D``.

The state is integrated as the layer voltage ``u = V(sigma)`` (``C_d(u) du/dt = (phi0 - u)/R``,
``sigma = sigma(u)`` in closed form): no inversion of ``sigma(phi0)`` is needed.  The moment
follows quasi-statically, ``M_A(t) = M_A^static(u(t))`` (the layers' state), then the beam:
``theta``, ``w``, blocking force at each instant -- NO beam inertia or damping (the beam is in
static equilibrium with the instantaneous moment).

Outside this model (stated in every dynamic output): water transport (the paper's Darcy law)
and the back-relaxation it causes; the solvent is at rest.

Small signal about ``phi0 = 0``: the exact linearised PNP impedance and moment transfer
(closed forms, ``derivations/charge.py``; the reference), and the circuit linearised,
``(R + 1/(i omega C_d(0)))/(1 + i omega R C_g)``, with its error against the reference.
"""

from __future__ import annotations

import functools
import math
import time
from dataclasses import dataclass, field

import numpy as np

from ipmc_asym.base.ladder import climb, escalation_note, rungs_from
from ipmc_asym.base.registry import check_choice
from ipmc_asym.base.results import Panel, ResultMixin, ResultSpec
from ipmc_asym.base.settings import VALIDATED_VOLTAGE
from ipmc_asym.beam.dynamics import (
    CLAMPED_OUTPUTS,
    DEFAULT_MODES,
    SUPPORTS,
    VISCOUS_MODULUS_SOURCE,
    Beam,
    ModalIntegrator,
    natural_frequencies,
    static_outputs,
    transfer,
)
from ipmc_asym.dynamics.bias import bias_reference
from ipmc_asym.dynamics.electrode import (
    capacitance_scale,
    charge,
    charge_scale,
    core_resistance,
    time_constant,
)
from ipmc_asym.dynamics.transient import solve_transient
from ipmc_asym.dynamics.waveforms import check_drive_voltage, voltage_rate
from ipmc_asym.forward.model import assumption_warnings, forward, voltage_reason
from ipmc_asym.integral.api import paper_model_id
from ipmc_asym.kernels import _generated_charge as GC
from ipmc_asym.kernels.charge import GL_W, GL_X
from ipmc_asym.kernels.charge_time import cd_hat_many, integrate_circuit
from ipmc_asym.model import groups
from ipmc_asym.model.electrode import beam_label
from ipmc_asym.model.params import (
    D_CATION_DEFAULT,
    D_CATION_SOURCE,
    NAFION_LI,
    Material,
    Strip,
    bending_stiffness,
    check_finite,
    check_finite_response,
    check_frequencies,
    check_positive,
)
from ipmc_asym.model.permittivity import Permittivity, get_model

__all__ = ["DYNAMIC_NOTES", "StepResult", "FrequencyResult", "core_resistance", "time_constant",
           "waveform", "step_response", "frequency_response", "circuit_response", "quasi_static_mechanics",
           "circuit_impedance_error", "circuit_band", "quiet_numerics",
           "layer_rates", "drive_frequency", "drive_substep", "quasi_static_forward", "check_support", "check_electrode",
           "support_notes"]

#: stated in every dynamic output
WATER_NOTE = ("water transport (the paper's Darcy law) and the back-relaxation it causes are outside this model: "
              "the solvent is at rest")
QUASI_STATIC_NOTE = "no beam inertia or damping: theta, w and the blocking force follow the moment quasi-statically"
INERTIA_NOTE = ("beam dynamics: Euler-Bernoulli strip with inertia (rho = (1 - phi4) rho3 + phi4 rho2) and Kelvin-Voigt "
                "damping (eq. (3)), modal expansion on the exact modes (free tip: w, theta; blocked tip: F_block), "
                "static limit = the quasi-static forward model; the dynamic correction is linear (small displacements)")
DYNAMIC_NOTES = (
    WATER_NOTE,
    QUASI_STATIC_NOTE,
    "the cation diffusion coefficient D is not in the paper; " + D_CATION_SOURCE,
)
BEAM_CHOICES = ("quasi-static", "dynamic")
#: said by a circuit step run without a tolerance: its error bound is a reference PNP run, 100-1000
#: times the circuit's cost (1 V step, nominal strip, to 5 tau: circuit 0.01-0.02 s CPU; with tol
#: 1e-2 1.9 s constant, 18 s affine, 1.4 s linear); ``ipmc-asym step`` runs it by default (tol "auto")
CIRCUIT_NO_TOL_NOTE = ("circuit: no error stated for sigma, current and w (no tolerance): the bound is a reference PNP "
                       "run, 100-1000 times the circuit's cost (nominal 1 V step: 1.4-18 s CPU against 0.02 s); "
                       "step and drive state it by default (--tol auto, 1e-2) or with --tol T")
DYNAMIC_W_ERROR_NOTE = ("w_error with beam dynamics: the quasi-static errors of M_A and w through the beam's modes "
                        "(each mode's impulse response bounded by its envelope): without damping (viscous modulus 0) "
                        "the bound grows like omega_1 t, as an undamped mode keeps every error it was given")
#: frequencies at which the biased circuit's error is computed against the linearised PNP at most
#: (each costs two banded solves of 10^4 - 2 10^5 nodes: 0.05 - 0.6 s CPU measured, 20 um - 1 mm)
REFERENCE_POINTS = 12
#: the beam of every command and entry unless asked otherwise: the paper's quasi-static beam (the moment
#: of the static problem bends the strip at once).  The dynamic beam adds inertia and a Kelvin-Voigt
#: damping whose viscous modulus no source gives (default 0: undamped modes that ring for ever and put
#: the poles of an exported model on the imaginary axis), so it is asked for, not assumed.
DEFAULT_BEAM = "quasi-static"


def diffusion_note(diffusion=None):
    """The note on the cation diffusion coefficient actually used.

    Parameters
    ----------
    diffusion : float, optional
        ``D`` of the run (m^2/s); ``None`` or the library default gives the default's source
        (:data:`~ipmc_asym.model.params.D_CATION_SOURCE`), any other value is said as given.
    """
    if diffusion is None or float(diffusion) == D_CATION_DEFAULT:
        return DYNAMIC_NOTES[2]
    return (f"the cation diffusion coefficient D is not in the paper; D = {float(diffusion):g} m^2/s as given "
            f"(--diffusion, the material or the fit), not the library's assumed {D_CATION_DEFAULT:g} m^2/s; "
            "every dynamic time scales as 1/D")


def dynamic_notes(beam="quasi-static", viscous_modulus=0.0, material: Material | None = None, diffusion=None):
    """The notes every dynamic output carries (water transport out of scope, beam model, the D used:
    :func:`diffusion_note`, from ``material.D`` unless ``diffusion`` is given; the composite section
    when ``material`` carries electrode layers)."""
    if diffusion is None and material is not None:
        diffusion = material.D
    check_choice("beam", beam, BEAM_CHOICES)
    notes = list(DYNAMIC_NOTES)
    notes[2] = diffusion_note(diffusion)
    if beam == "dynamic":
        notes[1] = INERTIA_NOTE + f"; viscous modulus {float(viscous_modulus):g} Pa s"
        notes.append(VISCOUS_MODULUS_SOURCE)
    elif float(viscous_modulus) != 0.0:  # said, so that a damping asked for is not silently dropped
        notes[1] += (f"; the viscous modulus {float(viscous_modulus):g} Pa s given is not used (it damps the "
                     "dynamic beam's modes: beam 'dynamic')")
    if material is not None and material.electrode.present:
        notes.append("beam: " + beam_label(material.electrode))
    return notes


def strip_beam(strip: Strip, material: Material, viscous_modulus=0.0, electrode=None) -> Beam:
    """The strip's beam (``E I_p``, mass per length of the hydrated membrane, ``tau_v = eta_E/E``;
    ``electrode`` the covered part ``(x1, x2)`` of the length, m, default the whole strip)."""
    return Beam.from_strip(strip.length, strip.width, strip.thickness, material, viscous_modulus, electrode)


def check_support(support):
    """``None`` (the default pair: free tip w, theta and blocked tip F_block) or one of ``SUPPORTS``."""
    if support is not None and support not in SUPPORTS:
        raise ValueError(f"support must be one of {', '.join(SUPPORTS)}; got {support!r}")
    return support


def check_electrode(electrode, length):
    """``(x1, x2)`` (m) with ``0 <= x1 < x2 <= length``, or ``None`` for the whole strip (also for ``(0, L)``)."""
    if electrode is None:
        return None
    try:
        x1, x2 = (float(v) for v in electrode)
    except (TypeError, ValueError):
        raise ValueError(f"electrode must be a pair (x1, x2) of lengths in m; got {electrode!r}") from None
    if not (math.isfinite(x1) and math.isfinite(x2) and 0.0 <= x1 < x2 <= length):
        raise ValueError(f"electrode must be (x1, x2) with 0 <= x1 < x2 <= L = {length:g} m; got {electrode!r}")
    return None if (x1 == 0.0 and x2 == length) else (x1, x2)


def support_notes(support, electrode):
    """The notes of a clamped-clamped strip or a partial electrode (what they report, what they assume)."""
    notes = []
    if electrode is not None:
        notes.append(f"partial electrode on [{electrode[0]:g}, {electrode[1]:g}] m: the active moment M_A acts there only; "
                     "the beam outputs are small-displacement (linear in M_A; the forward model's large-displacement "
                     "beam holds for a full electrode)")
    if support == "clamped-clamped":
        notes.append("clamped-clamped strip (small displacements): M_root, M_tip = bending moments at the clamps x = 0, L "
                     "(the clamps' reaction moments, the paper's sign); F_root, F_tip = transverse forces of the clamps on "
                     "the strip (+z; F_tip with the sign of F_block; statically F_root = -F_tip); w_mid = deflection at "
                     "x = L/2; with a full electrode nothing moves and M_root = M_tip = M_A")
    return notes


def _linear_statics(beam: Beam, M, support, names=None):
    """Small-displacement quasi-static outputs (dict) for the moment ``M`` (N m) on the beam's electrode."""
    return {n: v[0] * M for n, v in static_outputs(support, beam, names).items()}


#: modes kept in the time domain (with the static correction the tip deflection's tail from mode 21 on is
#: ~(f/f_21)^2 b_21^-3 ~ 1e-11 of the static value for content at the first resonance)
TIME_MODES = 20


class BeamDynamics:
    """Free tip (``w``, ``theta``) and blocked tip (``F_block``) driven by ``M_A(t)``, chunk by chunk;
    with ``clamped=True`` also the clamped-clamped strip (:meth:`advance_clamped`); ``electrode``
    ``(x1, x2)`` (m): the moment acts there only (the statics passed in are then small-displacement)."""

    def __init__(self, strip: Strip, material: Material, viscous_modulus=0.0, n_modes=TIME_MODES, electrode=None,
                 clamped=False):
        self.beam = strip_beam(strip, material, viscous_modulus, electrode)
        self.free = ModalIntegrator(self.beam, "clamped-free", n_modes)
        self.blocked = ModalIntegrator(self.beam, "clamped-pinned", n_modes)
        self.clamped = ModalIntegrator(self.beam, "clamped-clamped", n_modes) if clamped else None
        self.period = 1.0 / float(natural_frequencies("clamped-free", self.beam, 1)[0])

    def advance(self, t, M, theta, w, F_block):
        a = self.free.advance(t, M, {"w": w, "theta": theta})
        b = self.blocked.advance(t, M, {"F": F_block})
        return a["theta"], a["w"], b["F"]

    def w_error(self, t, M, M_err, w_err):
        """Bound on the error of the dynamic tip deflection :meth:`advance` gives at the times ``t`` (s,
        from 0) from bounds on the errors of the moment ``M`` (``M_err``, N m) and of the quasi-static
        deflection (``w_err``, m) at those times.

        The beam is linear in its inputs: ``w = creep(w_qs) + sum_n phi_n(L) (q_n - q_n^qs)``
        (:class:`ipmc_asym.beam.dynamics.ModalIntegrator`).  The creep filter (gain 1, a positive
        impulse response) passes at most the running maximum of ``w_err``.  Mode n's departure from its
        quasi-static value is ``c_n M`` (``c_n = phi_n(L) P_n/(rho A L omega_n^2)``, its static tip
        deflection per unit moment) through the unit-gain oscillator minus the creep filter, an impulse
        response of L1 norm at most ``1 + omega_n^2 int_0^t |h_n|``: ``|h_n(u)| <= e^{-a u}/nu_n``
        underdamped (``a = tau_v omega_n^2/2``, ``nu_n^2 = omega_n^2 - a^2``), so the integral is at
        most ``(1 - e^{-a t})/(a nu_n)`` (``t/nu_n`` undamped: an undamped mode keeps every error it was
        given, and the bound grows like ``omega_1 t``); ``h_n >= 0`` overdamped (at most ``1/omega_n^2``).
        ``M`` is held linear between the times (the integrator's first-order hold): the hold's error
        ``h^2 |M''|/8``, estimated by the second differences and counted twice (as
        :func:`deflection_error`), is added to ``M_err``; the modes past the kept ones (~1e-11 of the
        static deflection, :data:`TIME_MODES`) are covered by ``1e-10`` of it.  NaN from the first time
        whose errors are not stated.
        """
        t = np.asarray(t, dtype=float)
        M = np.asarray(M, dtype=float)
        md, b = self.free.md, self.beam
        c = np.abs(md.phi_L * md.P / (b.rhoA * b.length * md.omega**2))
        gain = np.zeros(t.size)  # sum_n c_n (1 + omega_n^2 int_0^t |h_n|), a mode at a time (memory: t only)
        for om, cn in zip(md.omega, c):
            a = 0.5 * b.tau_v * om * om
            if a < om:  # underdamped
                nu = math.sqrt(om * om - a * a)
                gain += cn * (1.0 + om * om * (-np.expm1(-a * t) / (a * nu) if a > 0.0 else t / nu))
            else:
                gain += 2.0 * cn
        hold = np.zeros(t.size)
        if t.size > 2:
            hold[1:-1] = 2.0 * np.abs(M[2:] - 2.0 * M[1:-1] + M[:-2]) / 8.0
            hold[-1] = hold[-2]
        dM = np.maximum.accumulate(np.asarray(M_err, dtype=float) + hold)
        dw = np.maximum.accumulate(np.asarray(w_err, dtype=float))
        return dw + dM * gain + 1e-10 * np.abs(M) * float(np.sum(c))

    def advance_clamped(self, t, M, statics):
        """Clamped-clamped outputs (dict, :data:`CLAMPED_OUTPUTS`) from their quasi-static values ``statics``."""
        return self.clamped.advance(t, M, statics)


def _beam_grid(t, period, cap=5_000_000):
    """``t`` refined to >= 40 points per period of the first mode (first-order hold of M_A); indices of ``t``."""
    h = period / 40.0
    dt = np.diff(t)
    k = np.maximum(1, np.ceil(dt / h)).astype(np.int64)
    if k.sum() > cap:
        raise ValueError(f"beam dynamics need >= 40 time points per period of the first mode (T1 = {period:.3g} s): "
                         f"{int(k.sum())} points exceed {cap}; shorten the duration")
    idx = np.concatenate(([0], np.cumsum(k)))
    frac = np.arange(idx[-1]) - np.repeat(idx[:-1], k)
    tf = np.concatenate((np.repeat(t[:-1], k) + np.repeat(dt / k, k) * frac, [t[-1]]))
    return tf, idx

STEP_FIDELITIES = ("circuit", "pnp")
WAVEFORMS = ("step", "ramp", "sine")
FREQ_METHODS = ("pnp-linear", "circuit")


def waveform(kind, voltage, *, ramp_time=None, frequency=None):
    """``phi0(t)`` (V, vectorised) for ``step``, ``ramp``, ``sine`` or a user callable ``f(t)``.

    ``step``: ``voltage`` for ``t >= 0``; ``ramp``: ``voltage * min(t/ramp_time, 1)``;
    ``sine``: ``voltage * sin(2 pi frequency t)``; a callable is used as given (volts).
    """
    if callable(kind) and hasattr(kind, "derivative"):  # a parsed Waveform: vectorised, checked, differentiable
        return kind
    if callable(kind):
        def user(t):
            t = np.asarray(t, dtype=float)
            try:
                v = np.asarray(kind(t), dtype=float)
                if v.shape != t.shape:  # a constant, say (the transient solver calls this per step)
                    v = np.broadcast_to(v, t.shape).astype(float)
            except Exception:  # not vectorised
                v = np.array([float(kind(x)) for x in t.ravel()]).reshape(t.shape)
            if not np.isfinite(v).all():
                raise ValueError("the voltage function phi0(t) must return finite volts")
            return v
        return user
    check_choice("waveform", kind, WAVEFORMS)
    V = check_drive_voltage("voltage", voltage)
    if kind == "step":
        return lambda t: np.full(np.shape(t), V)
    if kind == "ramp":
        tr = check_positive("ramp_time", ramp_time, "s")
        return lambda t: V * np.minimum(np.asarray(t, dtype=float) / tr, 1.0)
    f = check_positive("frequency", frequency, "Hz")
    return lambda t: V * np.sin(2.0 * math.pi * f * np.asarray(t, dtype=float))


@dataclass(repr=False)
class StepResult(ResultMixin):
    """Time series of a charging transient (SI, per unit electrode area unless stated).

    Attributes
    ----------
    t : ndarray (n,)              time, s
    phi0 : ndarray (n,)           applied voltage, V
    sigma : ndarray (n,)          charge of the face z = -e, C/m^2
    current_density : ndarray     dsigma/dt, A/m^2
    layer_voltage : ndarray       voltage across the two electrode layers, V (circuit: V(sigma_L); pnp: phi0 - R J)
    M_A, theta, w, F_block : ndarray   moment (N m), rotation (rad), tip deflection (m),
                                  blocking force (N); quasi-static, or with beam="dynamic" the
                                  strip's inertia and damping (quasi-static values in ``extra``)
    tau : float                   linear time constant R C_d(0), s
    R : float                     core resistance per area, Ohm m^2
    C_d0 : float                  C_d(0), F/m^2
    fidelity, model : str
    notes : list of str           what the model leaves out (water transport, inertia, D source)
    success : bool ; message : str
    extra : dict                  solver details (pnp: mesh, energy balance, charge error; with ``tol``:
                                  the rung ladder and the circuit's validity window ``valid_from``, s)
    seconds : float
    checks : dict                 check name (``forward.model.CHECKS``) -> bool array (n,): the
                                  forward model's checks at each time point (a failed model
                                  assumption keeps the numbers; :attr:`warnings` says which)
    warnings : list of str        one line per failed model assumption (count of time points)
    sigma_error : ndarray         error estimate of sigma (C/m^2) at each time; NaN for the circuit
                                  without ``tol``
    current_error : ndarray       error estimate of current_density (A/m^2) at each time, stated like
                                  sigma's (pnp: Richardson; circuit with ``tol``: its difference from
                                  the reference PNP plus that run's estimate); NaN for the circuit
                                  without ``tol``
    w_error : ndarray             bound on the error of ``w`` (m) that follows from the layer voltage's
                                  (:func:`deflection_error`): circuit, from ``sigma_error`` through
                                  ``V(sigma)``; pnp, from ``current_error`` through ``phi0 - R J``;
                                  with ``beam="dynamic"`` through the beam's modes
                                  (:meth:`BeamDynamics.w_error`); NaN where no error is stated
    """

    _result = ResultSpec("t", "t", ("phi0", "sigma", "current_density", "layer_voltage", "M_A", "theta", "w",
                                    "F_block", "sigma_error"),
                         (Panel("t", ("voltage", "layer_voltage")), Panel("t", ("sigma",)), Panel("t", ("w",))),
                         ("tau", "R", "C_d0"), {"phi0": "voltage"})

    t: np.ndarray
    phi0: np.ndarray
    sigma: np.ndarray
    current_density: np.ndarray
    layer_voltage: np.ndarray
    M_A: np.ndarray
    theta: np.ndarray
    w: np.ndarray
    F_block: np.ndarray
    tau: float
    R: float
    C_d0: float
    fidelity: str
    model: str
    notes: list
    success: bool
    message: str
    extra: dict = field(default_factory=dict)
    seconds: float = 0.0
    checks: dict = field(default_factory=dict)
    warnings: list = field(default_factory=list)

    @property
    def valid(self) -> np.ndarray:
        """Bool array (n,): every check passed at each time point."""
        out = np.ones(self.t.shape, bool)
        for v in self.checks.values():
            out &= v
        return out
    sigma_error: np.ndarray | None = None
    current_error: np.ndarray | None = None
    w_error: np.ndarray | None = None


#: samples of the layer voltage's error interval on which the deflection's range is taken
W_ERROR_SAMPLES = 9


def deflection_error(u_lo, u_hi, w, strip: Strip, perm: Permittivity, material: Material):
    """Bound on ``|w(u) - w|`` for every layer voltage ``u`` in ``[u_lo, u_hi]`` (per time point).

    ``w(u)`` is not monotone in general (the arc tip deflection turns back past a half turn; the
    linear model's moment has an extremum), so the end points alone do not bound it: ``w`` is taken
    at :data:`W_ERROR_SAMPLES` equally spaced voltages of the interval, and the largest departure
    from ``w`` is increased by the bound on what lies between samples, ``h^2 max|w''|/8``, with
    ``h^2 w''`` estimated by the samples' second differences and counted twice (the margin for that
    estimate), plus the forward model's rounding (64 ulps of ``w``).  NaN where ``w``, the interval or
    a sample is not determined (withheld): the caller withholds ``w`` there.
    """
    return output_errors(u_lo, u_hi, {2: w}, strip, perm, material)[2]


def output_errors(u_lo, u_hi, values: dict, strip: Strip, perm: Permittivity, material: Material) -> dict:
    """:func:`deflection_error` for several outputs of :func:`quasi_static_mechanics` at once (its
    indices: 0 ``M_A``, 2 ``w``), from the same samples of the voltage interval; ``values`` maps an
    index to the output's value at each time point, the result an index to its bound."""
    lo = np.asarray(u_lo, dtype=float)
    hi = np.asarray(u_hi, dtype=float)
    k = np.linspace(0.0, 1.0, W_ERROR_SAMPLES)[:, None]
    U = lo[None, :] + k * (hi - lo)[None, :]
    bad = ~(np.isfinite(lo) & np.isfinite(hi))
    U = np.where(bad[None, :], 0.0, U)
    outs = quasi_static_mechanics(U.reshape(-1), strip, perm, material)
    res = {}
    for j, v in values.items():
        v = np.asarray(v, dtype=float)
        W = outs[j].reshape(U.shape)
        dev = np.max(np.abs(W - v[None, :]), axis=0)
        curv = np.max(np.abs(W[2:] - 2.0 * W[1:-1] + W[:-2]), axis=0)
        # plus the forward model's rounding (a few ulps: two evaluations at one voltage may differ by it)
        out = dev + 2.0 * curv / 8.0 + 64.0 * np.finfo(float).eps * np.max(np.abs(W), axis=0)
        # each output's bound is undetermined where that output is (not where another one is)
        out[bad | ~np.isfinite(v) | ~np.all(np.isfinite(W), axis=0)] = np.nan
        res[j] = out
    return res


def quasi_static_forward(u, strip: Strip, perm: Permittivity, material: Material, applied=None):
    """The forward model (:class:`ipmc_asym.forward.model.ForwardResult`, withheld outputs NaN)
    of the static strip at the layer voltage(s) ``u`` (V); see :func:`quasi_static_mechanics`.
    ``applied``: the drive's voltage(s) ``phi0`` (V, broadcast against ``u``); the ``voltage`` check
    then concerns the larger of the two in magnitude at each point (the layers' voltage lags behind
    the applied one, which the validated range is about too)."""
    fid = "corrected" if paper_model_id(perm) >= 0 else "quadrature"
    u = np.asarray(u, dtype=float)
    checked = None
    if applied is not None:
        applied = np.broadcast_to(np.asarray(applied, dtype=float), u.shape)
        checked = np.where(np.abs(applied) > np.abs(u), applied, u)
    with np.errstate(all="ignore"):
        return forward(strip.length, strip.width, strip.thickness, u, material=material,
                       model=perm, fidelity=fid, checked_voltage=checked).withhold()


def quasi_static_mechanics(u, strip: Strip, perm: Permittivity, material: Material):
    """``(M_A, theta, w, F_block)`` of the static strip at the layer voltage(s) ``u`` (V).

    The layers' state at a given charge is the static one at the voltage ``u = V(sigma)``
    across them: the forward model :func:`ipmc_asym.forward.model.forward` from fidelity
    ``corrected`` (``quadrature`` for a non-paper affine model), escalated per point to the
    first valid rung, then the beam (no inertia).  Arrays of the shape of ``u``: moment (N m),
    rotation (rad), arc tip deflection (m), large-displacement blocking force (N).
    """
    r = quasi_static_forward(u, strip, perm, material)
    return (np.asarray(r.M_A, dtype=float), np.asarray(r.theta, dtype=float), np.asarray(r.w, dtype=float),
            np.asarray(r.F_block, dtype=float))


#: most output times of one in-memory step response (~1 kB per time point over the integrator's
#: and the forward model's arrays: ~1 GB here; the command line's --max-points stays below)
MAX_STEP_POINTS = 10**6


#: the default output window, in units of the small-signal time tau: t = 0, then log-spaced from
#: DEFAULT_FIRST to DEFAULT_SPAN.  The nonlinear charging of a large step ends long before tau (affine
#: 2 V: 90 % at 0.03 tau; linear 0.5 V: at 0.09 tau), so an equally spaced grid over 5 tau would put
#: a handful of outputs in it; log spacing gives every decade from 1e-4 tau the same number of them
DEFAULT_FIRST = 1e-4
DEFAULT_SPAN = 5.0


def default_times(tau: float, points: int) -> np.ndarray:
    """The default output times of a step (s), shape (points,): 0, then log-spaced over
    ``[DEFAULT_FIRST tau, DEFAULT_SPAN tau]`` (see :data:`DEFAULT_FIRST`)."""
    _time_grid(1.0, None, points)  # the same refusal of a bad ``points``
    return np.concatenate([[0.0], np.geomspace(DEFAULT_FIRST * tau, DEFAULT_SPAN * tau, int(points) - 1)])


def _time_grid(duration, t, points):
    if t is not None:
        t = np.asarray(t, dtype=float).reshape(-1)
        if t.size > MAX_STEP_POINTS:
            raise ValueError(f"t has {t.size} times, more than {MAX_STEP_POINTS:g} (the cap bounding memory, "
                             "circuit.MAX_STEP_POINTS); stream longer runs with drive_chunks")
        if t.size < 2 or not np.all(np.isfinite(t)) or np.any(np.diff(t) <= 0) or t[0] < 0:
            raise ValueError("t must be a finite, strictly increasing array of >= 2 times >= 0 s")
        return t
    d = check_positive("duration", duration, "s")
    if isinstance(points, bool) or not isinstance(points, (int, np.integer)):
        if not (isinstance(points, (float, np.floating)) and float(points).is_integer()):
            raise ValueError(f"points must be an integer in [2, {MAX_STEP_POINTS:g}]; got {points!r}")
    if not 2 <= points <= MAX_STEP_POINTS:
        raise ValueError(f"points must be an integer in [2, {MAX_STEP_POINTS:g}] (the cap bounding memory, "
                         f"circuit.MAX_STEP_POINTS; stream longer runs with drive_chunks); got {points!r}")
    return np.linspace(0.0, d, int(points))


class CircuitStepper:
    """The reduced model integrated chunk by chunk on increasing output times (state carried over).

    ``advance(t)`` (s; the first time equal to the previous chunk's last, or 0 at the start,
    uncharged) returns ``(u, ub)``: the layer voltage ``V(sigma_L)`` and the core's voltage
    ``phi0 - u`` (V), and ``sigma`` (C/m^2, layers plus the bulk's displacement charge).
    Substeps between output times: BDF2 with ``h <= tau/200``, at least ``substeps`` on an
    interval longer than ``tau/400``.
    """

    def __init__(self, phi0_fun, strip: Strip, perm: Permittivity, material: Material, substeps: int = 2):
        self.fun, self.strip, self.perm, self.m = phi0_fun, strip, perm, material
        self.VT = groups.thermal_voltage(material)
        self.tau = float(time_constant(strip.thickness, perm, material))
        self.substeps = int(substeps)
        self.h_max = 5e-3  # the largest substep, tau/200, where the drive asks for no finer one
        self.h_sub = drive_substep(phi0_fun, self.tau, self.h_max)
        self.state = np.zeros(5)
        self.rho = perm.eps0 / perm.eps_moy
        self.mid = paper_model_id(perm)
        self.Cg = float(groups.geometric_capacitance(strip.thickness, perm.eps_moy))
        self.S = charge_scale(perm, material)
        self.t_last = 0.0
        # hull of 0 (the uncharged start) and the applied psi0 so far (R T/F): see advance
        self.ps_lo = 0.0
        self.ps_hi = 0.0

    def advance(self, t):
        t = np.asarray(t, dtype=float)
        if t[0] != self.t_last:
            raise ValueError("each chunk must start at the last time of the previous one (0 at the start)")
        tau = self.tau
        tt, idx = substep_grid(t, tau, self.h_sub, self.substeps, ("the reduced model's", SUBSTEP_ADVICE))
        ps = self.fun(drive_times(t, tt, idx, tau)) / self.VT
        A = np.empty(tt.size)
        s = np.empty(tt.size)
        integrate_circuit(tt, ps, self.rho, self.mid, GL_X, GL_W, A, s, self.state)
        # the layers charge through the core's resistance towards phi0 (ds/dt = (psi0 - A)/2 with
        # s(A) increasing), so the exact A never leaves the hull of 0 and the psi0 applied so far;
        # BDF2 is not monotone and may step past it by rounding (20.000000000004 V at a 20 V step,
        # which would flip the validity checks at their limits): the output is held in the hull
        lo = np.minimum(np.minimum.accumulate(ps), self.ps_lo)
        hi = np.maximum(np.maximum.accumulate(ps), self.ps_hi)
        self.ps_lo, self.ps_hi = float(lo[-1]), float(hi[-1])
        A = np.clip(A, lo, hi)
        A, s = A[idx], s[idx]
        u = self.VT * A
        self.t_last = float(t[-1])
        ub = self.fun(t) - u
        # the bulk is a leaky dielectric: besides the layers' charge the electrodes carry the
        # displacement charge C_g (phi0 - u) of the core, C_g = eps_core/(2e) (its relaxation time
        # R C_g = lambda^2 e^2/D is instantaneous on the scale tau); C_g/C_d(0) = lambda
        sigma = self.S * s + self.Cg * ub
        return u, ub, sigma


    def current(self, t, u):
        """The model's current density (A/m^2) at the output times ``t`` (s) where the layers hold ``u`` (V).

        From the model's own equations, not from differences over the output times:
        ``J = S ds/dt + C_g d(phi0 - u)/dt`` with ``ds/dt = (psi0 - A)/(2 tau)`` (the charging law
        integrated by :meth:`advance`) and ``du/dt = (R T/F) (ds/dt)/s'(A)`` (the layers'
        differential capacitance ``s'(A)``); ``dphi0/dt`` by
        :func:`ipmc_asym.dynamics.waveforms.voltage_rate` (a jump's impulse is not a current
        density: at a jump the output is the current just after it).
        """
        t = np.asarray(t, dtype=float)
        A = np.asarray(u, dtype=float) / self.VT
        sdot, Adot = layer_rates(A, self.fun(t) / self.VT, self.rho, self.mid, self.tau, self.h_max)
        dphi = voltage_rate(self.fun, t, 1e-3 * self.tau)
        return self.S * sdot + self.Cg * (dphi - self.VT * Adot)


def layer_rates(A, psi, rho, mid, tau, h_max):
    """``(ds/dt, dA/dt)`` (1/s) of layers at ``A`` charging towards ``psi`` (both in R T/F, any shape):
    the charging law ``ds/dt = (psi - A)/(2 tau)`` and ``dA/dt = (ds/dt)/s'(A)``, ``s'`` the layers'
    differential capacitance (``model_id`` ``mid``, ``rho`` as the kernels).

    The layers relax on ``2 s'(A) tau``; below the largest substep ``h_max`` (in tau) that relaxation
    is not resolved -- the L-stable BDF2 settles ``A`` on ``psi`` within a substep and ``psi - A`` is
    the Newton residual -- so the rate is taken over half the substep there (a saturated
    linear-model layer has ``s' ~ e^{-A}``: 1e-34 at 2 V).
    """
    cx = np.empty(A.size)
    cd_hat_many(np.ascontiguousarray(A).reshape(-1), rho, mid, GL_X, GL_W, cx)
    sdot = (psi - A) / (2.0 * tau)
    return sdot, (psi - A) / (2.0 * np.maximum(cx.reshape(A.shape), 0.5 * h_max) * tau)


#: fixed substeps per period of a waveform's fastest component (BDF2's phase error goes as
#: (2 pi/N)^2): at 100 a period a 1 kHz sine on the nominal strip was 1.4e-3 of max|sigma| off the
#: converged value and 1.4e-5 at 1000; below 1/(200 tau) Hz the tau/200 cap is the finer one
STEPS_PER_PERIOD = 400


def drive_frequency(fun) -> float:
    """The fastest component (Hz) of the drive ``fun``: a waveform's ``max_frequency``, 0 where it has
    none or ``fun`` is a bare callable (which states no frequency)."""
    return float(getattr(fun, "max_frequency", 0.0) or 0.0)


def drive_substep(fun, tau, h_max):
    """The largest substep (units of ``tau``) for the drive ``fun``: ``h_max``, or finer where its
    fastest component (:func:`drive_frequency`) needs it (:data:`STEPS_PER_PERIOD`)."""
    f = drive_frequency(fun)
    return h_max if f <= 0.0 else min(h_max, 1.0 / (STEPS_PER_PERIOD * f * tau))


#: The most fixed substeps :func:`substep_grid` lays in one chunk (the grid and the stepper's
#: arrays: ~40 bytes each)
MAX_SUBSTEPS = 5_000_000
#: what to do where a chunk would need more substeps than that
SUBSTEP_ADVICE = ("use fewer time constants, or a waveform with fewer periods in the duration "
                  f"({STEPS_PER_PERIOD} substeps a period of its fastest component)")


def substep_grid(t, tau, h_max, substeps, too_long):
    """Fixed substeps between the output times ``t`` (s): each interval of ``dt`` (in ``tau``) split
    into ``max(ceil(dt/h_max), substeps)`` equal steps (1 where ``dt <= h_max/2``).

    Returns ``(grid, idx)``: the substep times in units of ``tau`` and the index of each output
    time in the grid.  ``too_long`` = (whose substeps, what to do) for the refusal where the grid
    would pass :data:`MAX_SUBSTEPS`; the refusal states the longest chunk in tau and in seconds.
    """
    # counted in floating point first: a duration of 1e30 s would overflow the integer count, and
    # one of 1e308 s overflows the float count to inf, which the refusal below names
    with np.errstate(over="ignore", invalid="ignore"):
        dt = np.diff(t) / tau
        kf = np.maximum(np.ceil(dt / h_max), np.where(dt <= 0.5 * h_max, 1, substeps))
        total = kf.sum()
    if not np.all(np.isfinite(kf)) or total > MAX_SUBSTEPS:
        span = MAX_SUBSTEPS * h_max
        whose, advice = too_long
        raise ValueError(f"duration is too long for {whose} fixed substeps (at most {MAX_SUBSTEPS:.0e} of at most "
                         f"{h_max:.3g} tau in one chunk: {span:.3g} tau = {span * tau:.3g} s here); {advice}")
    k = kf.astype(np.int64)
    idx = np.concatenate(([0], np.cumsum(k)))
    frac = np.arange(idx[-1]) - np.repeat(idx[:-1], k)
    return np.concatenate((np.repeat(t[:-1] / tau, k) + np.repeat(dt / k, k) * frac, [t[-1] / tau])), idx


def drive_times(t, tt, idx, tau):
    """The times (s) at which a stepper samples ``phi0`` on the grid ``(tt, idx)`` of
    :func:`substep_grid`: the substeps, and at each output time ``t`` the instant just before it.
    The layers are integrated up to an output time with phi0's value before it: at a jump there (a
    step after 0, a square wave's flip) the layer charge is continuous and the output is the state
    just after the jump (the core's displacement charge and the current take ``phi0(t)``); and
    ``(t/tau) tau``, rounded past a jump at ``t``, would let the layers respond to it early."""
    tp = tt * tau
    tp[idx] = np.where(t > 0.0, np.nextafter(t, -np.inf), t)
    return tp


def circuit_response(t, phi0_fun, strip: Strip, perm: Permittivity, material: Material, substeps: int = 2):
    """Integrate the reduced model on the time grid ``t`` (s); returns ``(sigma, u, J)``."""
    stepper = CircuitStepper(phi0_fun, strip, perm, material, substeps)
    u, ub, sigma = stepper.advance(t)
    return sigma, u, stepper.current(t, u)


def _applied_hull(tgrid, fun):
    """``(lo, hi)`` per output time: the hull of 0 and the voltages applied so far (V), sampled finely
    between the output times (a coarse grid may miss a peak)."""
    tf = np.union1d(tgrid, np.linspace(0.0, tgrid[-1], 20001))
    af = fun(tf)
    k = np.searchsorted(tf, tgrid)
    return np.minimum.accumulate(np.minimum(af, 0.0))[k], np.maximum.accumulate(np.maximum(af, 0.0))[k]


def _pnp_layer_voltage(tgrid, fun, J, strip, material):
    """The PNP's layer voltage ``phi0 - R J`` (V) at the output times."""
    # the voltage left across the layers: phi0 minus the ohmic drop of the core (exact at
    # t = 0+ and t -> infinity; the bulk's displacement current is O(lambda) of J)
    u = fun(tgrid) - core_resistance(strip.thickness, material) * J
    # t = 0 is the run's uncharged initial state: the layers hold no charge, so no voltage (phi0 - R J
    # there evaluates the step's discontinuity, and its current is the rate at a jump)
    u = np.where(tgrid == 0.0, 0.0, u)
    # and, as in the circuit (CircuitStepper.advance), within the hull of 0 and the voltages applied
    # so far: the current's rounding noise once charged (~1e-5 of J(0), either sign) would put
    # phi0 - R J past phi0 and flip the checks at their limits
    lo, hi = _applied_hull(tgrid, fun)
    return np.clip(u, lo, hi)


def _pnp_output_errors(tgrid, fun, u, cur_err, M, w, strip, perm, material):
    """Bounds ``(M_A, w)`` on the errors of the PNP's ``M_A``, ``w`` at ``phi0 - R J`` from its current's
    error (V = R dJ; none at t = 0, the uncharged state), the voltage interval held in the hull of 0 and
    the applied voltages."""
    du = np.where(tgrid == 0.0, 0.0, core_resistance(strip.thickness, material) * np.asarray(cur_err, dtype=float))
    lo, hi = _applied_hull(tgrid, fun)
    e = output_errors(np.clip(u - du, lo, hi), np.clip(u + du, lo, hi), {0: M, 2: w}, strip, perm, material)
    return e[0], e[2]


def step_response(voltage=1.0, duration=None, *, strip: Strip | None = None, model="constant",
                  fidelity="circuit", material: Material | None = None, t=None, points: int = 1000,
                  waveform_kind="step", ramp_time=None, frequency=None, pnp_options=None, beam="quasi-static",
                  viscous_modulus=0.0, n_modes=TIME_MODES, tol: float | None = None,
                  notice=None) -> StepResult:
    """Charging transient of the strip under an imposed ``phi0(t)`` (starting uncharged at t = 0).

    Parameters
    ----------
    voltage : float
        Amplitude (V) of the step / ramp plateau / sine (ignored for a callable waveform).
    duration : float, optional
        End time (s) of ``points`` equally spaced output times.  Default: ``5 tau``; for a step,
        with the times :func:`default_times` (0, then log-spaced from ``1e-4 tau``: the nonlinear
        charging of a large step ends well before ``tau``).  Ignored when ``t`` is given.
    strip : Strip, optional
        Geometry (``thickness`` TOTAL 2e, ``width`` TOTAL 2l, ``length``); its voltage is unused.
    model : {"constant", "linear", "affine"} or Permittivity
    fidelity : {"circuit", "pnp"}
        ``circuit``: the reduced nonlinear-capacitor model; ``pnp``: the transient
        Nernst-Planck/Gauss solver (:mod:`ipmc_asym.dynamics.transient`).
    material : Material, optional (``D`` = cation diffusion coefficient)
    t : array_like, optional
        Output times (s), increasing, from 0.
    points : int
        Number of output times when ``t`` is not given (default 1000).
    waveform_kind : {"step", "ramp", "sine"} or callable ``phi0(t)`` (V)
    ramp_time, frequency : float
        For ``ramp`` (s) and ``sine`` (Hz).
    pnp_options : dict, optional
        Passed to :func:`ipmc_asym.dynamics.transient.solve_transient` (``cells_per_debye``, ``rtol``, ...).
    beam : {"quasi-static", "dynamic"}
        ``dynamic``: the strip's inertia and Kelvin-Voigt damping (:mod:`ipmc_asym.beam.dynamics`)
        on top of the quasi-static outputs (kept in ``extra``); the time grid is refined to 40
        points per period of the first mode for the mechanics.
    viscous_modulus : float
        ``eta_E`` (Pa s) of the Kelvin-Voigt law; default 0 (no source gives a value).
    n_modes : int
        Modes kept (the static correction makes the tail negligible).
    tol : float, optional
        Relative tolerance on ``sigma`` (relative to ``max |sigma|`` over the times), in [1e-8, 0.5).
        Picks the cheapest rung that meets it at every output time, starting at ``fidelity``
        (circuit, then pnp): the circuit's error is bounded by comparison with a PNP run whose own
        (Richardson) error estimate is ``tol/10`` on a coarse mesh, ``|sigma_c - sigma_pnp| +
        error_pnp``; when it fails, the PNP at ``tol`` is returned (``fidelity`` says which).
        Without ``tol`` the circuit carries no error estimate (``sigma_error`` NaN) and the
        PNP its default tolerance (1e-6).
    notice : callable, optional
        Called with no argument once, just before the PNP solver starts (the reference run or the
        pnp rung: the long part), after the checks and the circuit's own run: a line saying what
        runs is not printed ahead of a refusal.

    Returns
    -------
    StepResult
    """
    t0 = time.perf_counter()
    check_choice("fidelity", fidelity, STEP_FIDELITIES)
    s = Strip() if strip is None else strip
    m = NAFION_LI if material is None else material
    perm = get_model(model)
    if perm.is_custom:
        raise ValueError("dynamic models need an affine permittivity (constant, linear, affine or a "
                         "Permittivity); a custom eps(C) callable is not supported")
    fun = waveform(waveform_kind, voltage, ramp_time=ramp_time, frequency=frequency)
    tau = float(time_constant(s.thickness, perm, m))
    if duration is None and t is None and isinstance(waveform_kind, str) and waveform_kind == "step":
        tgrid = default_times(tau, points)
    else:
        tgrid = _time_grid(5.0 * tau if duration is None and t is None else duration, t, points)
    R = float(core_resistance(s.thickness, m))
    notes = dynamic_notes(beam, viscous_modulus, m)
    extra = {}
    dyn = BeamDynamics(s, m, viscous_modulus, n_modes) if beam == "dynamic" else None
    tout = tgrid
    if dyn is not None:
        tgrid, keep = _beam_grid(tgrid, dyn.period)
    sig_err = np.full(tgrid.size, np.nan)
    cur_err = np.full(tgrid.size, np.nan)
    opts = dict(pnp_options or {})
    if tol is not None:
        tol = check_finite("tol", tol, "a relative tolerance in [1e-8, 0.5)")
        if not 1e-8 <= tol < 0.5:
            raise ValueError(f"tol must be in [1e-8, 0.5) (relative on sigma); got {tol!r}")
        opts["tol"] = min(tol, 9e-3)
    pnp_ref = []  # the PNP run that bounds the circuit's error: also the pnp rung

    def evaluate(f, idx):
        if f == "circuit":
            sigma, u, J = circuit_response(tgrid, fun, s, perm, m)
            err = sig_err
            if tol is not None:
                if notice is not None:
                    notice()
                r, err = _circuit_error(sigma, tgrid, fun, s, perm, m, opts)
                pnp_ref.append(r)
            return sigma, u, J, err
        if pnp_ref:  # the reference run is the pnp rung: no second run, no second notice
            return pnp_ref[0]
        if notice is not None:
            notice()
        return solve_transient(tgrid, fun, s, perm, m, **opts)

    def checks(f, r, idx):
        if f == "pnp":
            return bool(r.success), f"transient PNP solver failed: {r.message}"
        if tol is None:  # no error bound: the circuit is taken as it is
            return True, ""
        err = r[3]
        scale = float(np.max(np.abs(r[0])))
        bad = err > tol * scale
        # validity window: from the first output time after which every later one meets tol
        extra["valid_from"] = (float(tgrid[0]) if not bad.any() else
                               float(tgrid[np.nonzero(bad)[0][-1] + 1]) if not bad[-1] else None)
        # 0 V: nothing charges, sigma is 0 to the bit and so is a bound that holds
        emax = float(np.max(err))
        extra["circuit_error_max_rel"] = emax / scale if scale > 0.0 else (0.0 if emax == 0.0 else math.inf)
        return not bad.any(), (f"the circuit's error bound {extra['circuit_error_max_rel']:.2g} (relative) exceeds "
                               f"tol = {tol:g}")

    lad = climb(rungs_from(STEP_FIDELITIES, fidelity), evaluate, checks)
    if lad.left.size:
        raise RuntimeError(lad.message(f"thickness (total 2e) {s.thickness:.3g} m, voltage {float(voltage):.3g} V "
                                       f"(model {perm.name})"))
    for a, b in zip(lad.steps, lad.steps[1:]):
        notes.append(escalation_note(a.rung, b.rung, lad.why[lad.steps.index(a)]))
    fidelity = lad.last.rung
    if fidelity == "circuit":
        sigma, u, J, sig_err = lad.last.result
        success, message = True, "reduced model integrated (variable-step BDF2, 2 substeps per output interval)"
        if pnp_ref:  # tol given: the reference PNP run bounds the circuit's current too
            cur_err = np.abs(J - pnp_ref[0].current_density) + pnp_ref[0].current_error
        else:
            notes.append(CIRCUIT_NO_TOL_NOTE)
    else:
        r = lad.last.result
        sig_err, cur_err = r.sigma_error, r.current_error
        sigma, J = r.sigma, r.current_density
        u = _pnp_layer_voltage(tgrid, fun, J, s, m)
        success, message = r.success, r.message
        extra = dict(extra, **r.extra)
        notes.append("pnp: M_A(t) is the layers' quasi-static moment at the layer voltage phi0 - R J; the moment of the transient "
                     "profiles (p' = (C + A3) E, which adds the pressure gradient of the ohmic core field) is in "
                     "extra['M_A_profiles']")
        extra = dict(extra, M_A_profiles=r.M_A_profiles)
    # every time point through the forward model and its checks (the same as estimate's)
    applied = fun(tgrid)
    fr = quasi_static_forward(u, s, perm, m, applied=applied)
    checks = {c: a.reshape(-1) for c, a in fr.checks_mask.items()}
    warns = assumption_warnings(fr)
    M, th, w, Fb = (np.asarray(getattr(fr, k), dtype=float) for k in ("M_A", "theta", "w", "F_block"))
    w_err = np.full(tgrid.size, np.nan)
    M_err = np.full(tgrid.size, np.nan)
    stated = np.isfinite(np.asarray(sig_err, dtype=float))
    if stated.any():
        # the deflection's (and the moment's) error from the layer voltage's, the voltage the beam was given
        if fidelity == "circuit":
            # as sigma's: the difference from the reference PNP run's plus that one's error (the circuit's
            # charge also holds the core's displacement charge, so V(sigma) is not its layer voltage: the
            # bound is taken on w and M_A themselves)
            ref = pnp_ref[0]
            u_r = _pnp_layer_voltage(tgrid, fun, ref.current_density, s, m)
            M_r, _, w_r, _ = quasi_static_mechanics(u_r, s, perm, m)
            eM, ew = _pnp_output_errors(tgrid, fun, u_r, ref.current_error, M_r, w_r, s, perm, m)
            w_err = np.abs(w - w_r) + ew
            M_err = np.abs(M - M_r) + eM
        else:
            M_err, w_err = _pnp_output_errors(tgrid, fun, u, cur_err, M, w, s, perm, m)
        w_err = np.where(stated, w_err, np.nan)
        M_err = np.where(stated, M_err, np.nan)
    if dyn is None and stated.any():
        lost = stated & np.isfinite(w) & ~np.isfinite(w_err)
        if lost.any():  # the error interval reaches where w is not determined: w is withheld, not printed
            w = np.where(lost, np.nan, w)
            notes.append(f"w withheld at {int(lost.sum())} of {lost.size} times: its error interval reaches a "
                         f"layer voltage where w is not determined")
    # a current whose error is stated as not determined (the PNP's rate at the step's jump, t = 0,
    # diverges with the mesh) is withheld, not printed without its error
    lost_j = stated & ~np.isfinite(np.asarray(cur_err, dtype=float))
    if lost_j.any():
        J = np.where(lost_j, np.nan, J)
        notes.append(f"current withheld at {int(lost_j.sum())} of {lost_j.size} times: the PNP's current there "
                     f"(the rate at the step's jump) does not converge with the mesh")
    if dyn is not None:
        thd, wd, Fd = dyn.advance(tgrid, M, th, w, Fb)
        if stated.any():  # the quasi-static errors through the beam's dynamics
            w_err = dyn.w_error(tgrid, M, M_err, w_err)
            notes.append(DYNAMIC_W_ERROR_NOTE)
        extra = dict(extra, theta_quasi_static=th[keep], w_quasi_static=w[keep], F_block_quasi_static=Fb[keep],
                     beam_frequencies={"clamped-free": natural_frequencies("clamped-free", dyn.beam, 3).tolist(),
                                       "clamped-pinned": natural_frequencies("clamped-pinned", dyn.beam, 3).tolist()})
        sigma, J, u, M, th, w, Fb, applied, sig_err, cur_err, w_err = (
            a[keep] for a in (sigma, J, u, M, thd, wd, Fd, applied, np.asarray(sig_err), np.asarray(cur_err), w_err))
        checks = {c: v[keep] for c, v in checks.items()}
        tgrid = tout
    return StepResult(t=tgrid, phi0=applied, sigma=sigma, current_density=J, layer_voltage=u, M_A=M,
                      theta=th, w=w, F_block=Fb, tau=tau, R=R, C_d0=0.5 * capacitance_scale(perm, m),
                      fidelity=fidelity, model=perm.name, notes=notes, success=success, message=message,
                      extra=extra, seconds=time.perf_counter() - t0, checks=checks, warnings=warns,
                      sigma_error=sig_err, current_error=cur_err, w_error=w_err)


def quiet_numerics(fn):
    """``fn`` run with NumPy's floating-point warnings off: its outputs are checked finite at its end
    (:func:`~ipmc_asym.model.params.check_finite_response`), which says in one line what did not hold, where the warnings
    would print lines of NumPy's internals before it."""
    @functools.wraps(fn)
    def quiet(*args, **kwargs):
        with np.errstate(all="ignore"):
            return fn(*args, **kwargs)

    return quiet


def circuit_impedance_error(f, thickness, perm: Permittivity, material: Material):
    """Relative error of the circuit's impedance against the linearised PNP, per frequency.

    The linearised Nernst-Planck/Gauss impedance about 0 V (``derivations/charge.py``) is
    ``Z = [R + g/(i omega C_d(0))]/(1 + i omega R C_g)`` with the layers' exact factor
    ``g = tanh(k e)/(k lambda_D)``, ``(k lambda_D)^2 = 1 + i omega lambda_D^2/D``; the circuit has
    ``g = 1`` (layers in equilibrium with their charge).  Hence, exactly,
    ``|Z_circuit - Z_pnp|/|Z_pnp| = |1 - g|/|i omega tau + g|``: ``(Omega/2)/|1 + i omega tau|``
    well below the dielectric relaxation frequency ``f_d = D/(2 pi lambda_D^2)`` (``Omega = f/f_d``,
    ``omega tau = Omega/lambda``), at most ``lambda/2`` (``lambda = lambda_D/e``) at any frequency
    (checked on 20 um - 1 mm, three models, 1 mHz - 100 MHz).

    Parameters
    ----------
    f : array_like   frequencies, Hz
    thickness : float   TOTAL thickness 2e, m
    perm : Permittivity ; material : Material

    Returns
    -------
    ndarray   relative error of ``Z`` (and, to first order, of ``H_w``)
    """
    m = material
    lam = float(groups.debye_length(thickness, perm.eps_moy, m))
    lD = lam * 0.5 * thickness
    omega = 2.0 * math.pi * np.asarray(f, dtype=float)
    q = np.sqrt(1.0 + 1j * omega * lD * lD / m.D)
    g = np.tanh(q / lam) / q
    tau = float(time_constant(thickness, perm, m))
    return np.abs(1.0 - g) / np.abs(1j * omega * tau + g)


def _bias_error(f, Za, C0, bias, strip, perm, material, points):
    """The biased circuit's relative error of ``Z`` and ``H_w`` against the PNP linearised about the bias.

    ``(error, note)``: ``error`` (n,) NaN where the reference was not computed, or None (with the
    reason in ``note``) where it refuses.  ``H_w`` of either model is ``h0 sigma/C_d`` (the layers'
    moment at their charge; ``h0`` shared), so its relative error is that of ``C_d Z``: the circuit's
    ``C_d`` (``corrected`` rung) against the exact one the reference meets at low frequency.  With
    the reference's stated error ``eps``: ``(|x_c - x_r|/|x_r| + eps)/(1 - eps)`` bounds ``|x_c - x|/|x|``.
    """
    if points <= 0:
        return None, "no error stated against the PNP linearised about the bias (reference_points=0)"
    n = f.size
    idx = np.arange(n) if n <= points else np.unique(np.round(np.linspace(0, n - 1, points)).astype(int))
    try:
        ref = bias_reference(f[idx], bias, strip, perm, material)
    except RuntimeError as exc:
        return None, f"no error stated: {exc}"
    eps = ref.error
    eZ = np.abs(Za[idx] - ref.Z_area) / np.abs(ref.Z_area)
    eH = np.abs(C0 * Za[idx] / (ref.C_diff * ref.Z_area) - 1.0)
    err = np.full(n, np.nan)
    err[idx] = (np.maximum(eZ, eH) + eps) / (1.0 - eps)
    where = "every frequency" if idx.size == n else f"{idx.size} of the {n} frequencies (the others: NaN)"
    return err, (f"circuit: relative error of Z and H_w against the PNP linearised about the static state at {bias:g} V "
                 f"(collocation on a graded mesh, its own error <= {float(eps.max()):.2g} included) in 'error', at {where}")


def circuit_band(f, error, tol):
    """``[f_lo, f_hi]`` intervals of the sampled ``f`` (Hz) where ``error <= tol`` (list of pairs)."""
    ok = np.asarray(error) <= tol
    out = []
    i = 0
    while i < ok.size:
        if ok[i]:
            j = i
            while j + 1 < ok.size and ok[j + 1]:
                j += 1
            out.append([float(f[i]), float(f[j])])
            i = j + 1
        else:
            i += 1
    return out


class ReferenceFailed(RuntimeError):
    """The reference PNP run that bounds the circuit's error failed; ``over_budget``: it was stopped by
    its cap on work (``pnp_options["max_work"]``), not by the problem."""

    def __init__(self, message, over_budget=False):
        super().__init__(message)
        self.over_budget = over_budget


def _circuit_error(sigma_c, t, fun, strip, perm, material, opts):
    """Bound on the circuit's sigma error at each time: ``|sigma_c - sigma_pnp| + error_pnp``.

    The reference is the PNP solver at a tenth of the tolerance, its mesh ladder started coarse
    (``refine`` 1/4; its own Richardson estimate refines it when that is not enough); it is
    also the pnp rung when the circuit fails.  Returns ``(pnp result, bound)``.
    """
    o = dict(opts)
    o["tol"] = 0.1 * o["tol"]
    o.setdefault("refine", 0.25)
    o.setdefault("rtol", 1e-8)  # the 1 % allowance below was measured with this time integration
    r = solve_transient(t, fun, strip, perm, material, **o)
    if not r.success:
        raise ReferenceFailed(f"transient PNP solver failed (the reference for the circuit's error): {r.message}",
                              over_budget=bool(r.extra.get("over_budget")))
    # the reference's Richardson estimate covers its mesh; its time integration, controlled to a
    # fraction of its tol, is covered by 1 % of that tol over the run (the excess measured against a
    # PNP run at 1e-6: 3e-5 of it, constant model, 2e = 1 mm, 0.05 V)
    return r, np.abs(sigma_c - r.sigma) + r.sigma_error + 1e-2 * o["tol"] * float(np.max(np.abs(r.sigma)))


@dataclass(repr=False)
class FrequencyResult(ResultMixin):
    """Small-signal response about ``phi0 = 0`` (SI).

    Attributes
    ----------
    f : ndarray (n,)          frequency, Hz
    Z : ndarray complex (n,)  impedance of the strip (electrode area 2l L), Ohm
    Z_area : ndarray complex  impedance per unit area, Ohm m^2
    H_w : ndarray complex     tip deflection per volt (small displacements), m/V
    w_amp, w_phase : ndarray  ``|H_w|`` (m/V), ``arg H_w`` (rad; w < 0 for phi0 > 0 gives phase pi at DC);
                              H_w is the layers' (quasi-static) moment at the layer voltage V(sigma)
    tau : float ; method : str ; model : str ; notes : list
    H_w_profiles : ndarray complex or None   pnp-linear only: transfer of the full profile moment
    error : ndarray or None   circuit: relative error of Z (and H_w) against the linearised PNP
                              (:func:`circuit_impedance_error`); None for the reference pnp-linear
    f_d : float               dielectric relaxation frequency D/(2 pi lambda_D^2), Hz
    error_max : float         circuit: bound lambda/2 on ``error`` over all frequencies (0 V)
    H_theta : ndarray complex tip rotation per volt (free tip), rad/V
    H_F : ndarray complex     blocking force per volt (blocked tip), N/V
    resonances : dict         first three natural frequencies (Hz) of the free and the blocked strip
                              (and of the clamped-clamped one with ``support="clamped-clamped"``)
    beam : str ; voltage : float  (DC bias, V)
    support : str or None     the requested support (None: the default pair, free and blocked tip)
    electrode : tuple or None covered part (x1, x2) of the length, m (None: the whole strip)
    H_clamped : dict          clamped-clamped only: output (:data:`CLAMPED_OUTPUTS`) -> complex array per
                              volt: ``M_root``, ``M_tip`` (N m/V), ``F_root``, ``F_tip`` (N/V), ``w_mid`` (m/V)
    """

    _result = ResultSpec("f", "f", ("Z", "Z_area", "H_w", "w_amp", "w_phase", "H_theta", "H_F", "error"),
                         (Panel("f", ("Z",), True, True), Panel("f", ("w_amp",), True, True),
                          Panel("f", ("w_phase",), True)), ("tau", "f_d", "voltage"), {"error": "error_Z"})

    f: np.ndarray
    Z: np.ndarray
    Z_area: np.ndarray
    H_w: np.ndarray
    w_amp: np.ndarray
    w_phase: np.ndarray
    tau: float
    method: str
    model: str
    notes: list
    H_w_profiles: object = None
    error: object = None
    f_d: float = math.nan
    error_max: float = math.nan
    H_theta: object = None
    H_F: object = None
    resonances: dict = field(default_factory=dict)
    beam: str = "quasi-static"
    voltage: float = 0.0
    support: str | None = None
    electrode: tuple | None = None
    H_clamped: dict = field(default_factory=dict)
    check_voltage: bool = True


@quiet_numerics
def frequency_response(f, *, strip: Strip | None = None, model="constant", material: Material | None = None,
                       method="pnp-linear", beam="quasi-static", viscous_modulus=0.0, n_modes=DEFAULT_MODES,
                       voltage=0.0, support=None, electrode=None,
                       reference_points=REFERENCE_POINTS) -> FrequencyResult:
    """Impedance and tip-deflection/voltage transfer function about zero volts or a DC bias.

    Parameters
    ----------
    f : array_like
        Frequencies (Hz), > 0.
    strip : Strip, optional ; model : str or Permittivity ; material : Material, optional
    method : {"pnp-linear", "circuit"}
        ``pnp-linear`` (the reference): exact closed form of the linearised Nernst-Planck/Gauss
        equations (constant core permittivity: at 0 V every affine model linearises about
        ``eps_core``); ``circuit``: the step circuit linearised, ``Z = (R + 1/(i omega C_d(0)))/
        (1 + i omega R C_g)`` (core resistance in parallel with the bulk capacitance ``C_g``, in
        series with the layers), with its error against the reference per frequency
        (:func:`circuit_impedance_error`; at most ``lambda/2``).
    beam : {"quasi-static", "dynamic"}
        ``dynamic``: the strip's inertia and Kelvin-Voigt damping (resonances;
        :func:`ipmc_asym.beam.dynamics.transfer`; asked for, as by ``ipmc-asym freq --beam dynamic``);
        ``quasi-static`` (default): the beam follows the moment.
    viscous_modulus : float
        ``eta_E`` (Pa s), default 0.
    n_modes : int
    voltage : float
        DC bias (V): small signal about the biased static state (``method="circuit"`` only:
        ``R`` in series with the layers' differential capacitance ``C_d(V)``, ``C_g`` across the
        core; the moment slope ``dM_A/dV`` of the forward model).  Its error is stated against
        the PNP linearised about the biased static state (:func:`ipmc_asym.dynamics.bias.bias_reference`)
        on at most ``reference_points`` of the frequencies (all of them when there are no more;
        else equally spaced in index, the others' ``error`` NaN); ``reference_points=0``, or a
        reference that refuses, states none (a note says why).
    support : {None, "clamped-free", "clamped-pinned", "clamped-clamped"}
        ``None`` (default), ``clamped-free`` or ``clamped-pinned``: the free tip (``H_w``,
        ``H_theta``) and the blocked tip (``H_F``), as always reported together;
        ``clamped-clamped`` adds ``H_clamped`` (reaction moments and forces of both clamps,
        midspan deflection; :data:`ipmc_asym.beam.dynamics.CLAMPED_OUTPUTS`) and its resonances.
    electrode : (x1, x2), optional
        Covered part of the length (m, ``0 <= x1 < x2 <= L``; default the whole strip): the
        moment acts there only (modal force ``phi_n'(x2) - phi_n'(x1)``); all beam outputs are
        then small-displacement (:func:`ipmc_asym.beam.dynamics.static_outputs`).

    Returns
    -------
    FrequencyResult
    """
    check_choice("method", method, FREQ_METHODS)
    check_choice("beam", beam, BEAM_CHOICES)
    s = Strip() if strip is None else strip
    m = NAFION_LI if material is None else material
    perm = get_model(model)
    if perm.is_custom:
        raise ValueError("frequency_response needs an affine permittivity (constant, linear, affine)")
    f = check_frequencies(f)
    bias = check_drive_voltage("voltage (DC bias)", voltage)
    support = check_support(support)
    el = check_electrode(electrode, s.length)
    if bias != 0.0 and method != "circuit":
        raise ValueError("voltage: a DC bias needs method 'circuit' (pnp-linear is the linearisation about 0 V)")
    if isinstance(reference_points, bool) or not isinstance(reference_points, (int, np.integer)) or reference_points < 0:
        raise ValueError(f"reference_points must be an integer >= 0; got {reference_points!r}")
    e = s.e
    lam = float(groups.debye_length(s.thickness, perm.eps_moy, m))
    kappa = float(groups.kappa(m))
    A3 = float(groups.A3(m))
    omega = 2.0 * math.pi * f
    tau = float(time_constant(s.thickness, perm, m))
    # tip deflection per volt, small displacements: w = -M L^2/(2 E I_p),
    # M per volt = A5(1 V) (1 + A3) * (moment transfer), A5(1 V) = 6 l e^2 C_moy F (N m/V)
    w_per_M = -s.length**2 / (2.0 * float(bending_stiffness(m, s.width, s.thickness)))
    k_w = w_per_M * float(groups.A5(s.width, s.thickness, 1.0, m)) * (1.0 + A3)
    R = float(core_resistance(s.thickness, m))
    C0 = 0.5 * capacitance_scale(perm, m)
    # DC transfer: the static moment slope at 0 V, I(0+) = (1 + A3)(lam coth(1/lam) - lam^2)
    h0 = k_w * float(GC.moment_transfer_hat(np.array([1e-12]), lam)[0].real)
    err = None
    if bias != 0.0:
        # about the biased static state: the layers' differential capacitance C_d(V) and the
        # forward model's moment slope dM_A/dV (central difference, step 1e-4 R T/F)
        C0 = float(charge(s.thickness, bias, perm, "corrected", material=m).C_diff)
        tau = R * C0
        dv = 1e-4 * groups.thermal_voltage(m)
        Mp, Mm = (quasi_static_mechanics(np.array([bias + d]), s, perm, m)[0][0] for d in (dv, -dv))
        h0 = w_per_M * (Mp - Mm) / (2.0 * dv)
    if method == "pnp-linear":
        W = omega * e * e / m.D
        Za = (e / kappa) * GC.impedance_hat(W, lam)
        Hprof = k_w * GC.moment_transfer_hat(W, lam)
    else:
        # the step circuit (circuit_response) linearised: layers C_d in series with the core,
        # the core's resistance R in parallel with its geometric capacitance C_g (a leaky dielectric)
        Cg = float(groups.geometric_capacitance(s.thickness, perm.eps_moy))
        Za = (R + 1.0 / (1j * omega * C0)) / (1.0 + 1j * omega * R * Cg)
        Hprof = None
        if bias == 0.0:
            err = circuit_impedance_error(f, s.thickness, perm, m)
        else:
            err, bias_note = _bias_error(f, Za, C0, bias, s, perm, m, reference_points)
    # the layers' moment follows their charge: u = V(sigma) = sigma/C_d = J/(i omega C_d)
    Hw = h0 / (1j * omega * C0 * Za)
    HM = Hw / w_per_M  # moment per volt, N m/V
    b = strip_beam(s, m, viscous_modulus, el)
    if beam == "dynamic":
        cf = transfer(f, b, "clamped-free", n_modes)
        cp = transfer(f, b, "clamped-pinned", n_modes)
        Hw = HM * cf["w"]
        Htheta = HM * cf["theta"]
        HF = HM * cp["F"]
    elif el is None:
        Htheta = HM * (-s.length / b.EI)
        HF = HM * (1.5 / s.length)
    else:  # the moment on [x1, x2] only: the small-displacement statics of that load
        Hw = _linear_statics(b, HM, "clamped-free", ("w",))["w"]
        Htheta = _linear_statics(b, HM, "clamped-free", ("theta",))["theta"]
        HF = _linear_statics(b, HM, "clamped-pinned", ("F",))["F"]
    Hcc = {}
    if support == "clamped-clamped":
        if beam == "dynamic":
            cc = transfer(f, b, "clamped-clamped", n_modes)
            Hcc = {n: HM * cc[n] for n in CLAMPED_OUTPUTS}
        else:
            Hcc = _linear_statics(b, HM, "clamped-clamped")
    sups = ("clamped-free", "clamped-pinned") + (("clamped-clamped",) if support == "clamped-clamped" else ())
    resonances = {sup: natural_frequencies(sup, b, 3).tolist() for sup in sups}
    area = s.width * s.length
    notes = dynamic_notes(beam, viscous_modulus, m) + support_notes(support, el)
    if bias != 0.0:
        notes.append(f"small signal about the static state at {bias:g} V (circuit: R, C_d({bias:g} V), C_g; "
                     "dM_A/dV of the forward model)")
        notes.append(bias_note)  # a bias is refused above with any method but the circuit
        if not abs(bias) <= VALIDATED_VOLTAGE:  # a model assumption: the number kept, flagged
            notes.append("warning: " + voltage_reason(bias))
    f_d = m.D / (2.0 * math.pi * (lam * e) ** 2)
    if Hprof is not None:
        notes.append("H_w_profiles: the moment of the linearised profiles, p' = (C + A3) E, which adds the pressure "
                     "gradient of the ohmic core field (-> (1 + A3)/3 per unit psi0 at high frequency, ~1/(3 lambda) "
                     "times the static slope); with the solvent at rest nothing relaxes it -- water flow would")
    elif bias == 0.0:  # the closed-form error is that of the linearisation about 0 V
        notes.append(f"circuit: relative error of Z and H_w against the linearised PNP (the reference) in 'error', "
                     f"~(f/(2 f_d))/|1 + i omega tau| below the dielectric relaxation frequency f_d = {f_d:.4g} Hz, at most "
                     f"lambda/2 = {0.5 * lam:.3g} at any frequency")
    check_finite_response(f, {"Z": Za, "H_w": Hw, "H_theta": Htheta, "H_F": HF, **Hcc})
    return FrequencyResult(f=f, Z=Za / area, Z_area=Za, H_w=Hw, w_amp=np.abs(Hw), w_phase=np.angle(Hw), tau=tau,
                           method=method, model=perm.name, notes=notes, H_w_profiles=Hprof, error=err, f_d=f_d,
                           error_max=(math.nan if err is None else 0.5 * lam if bias == 0.0
                                      else float(np.nanmax(err))), H_theta=Htheta, H_F=HF,
                           resonances=resonances, beam=beam, voltage=bias, support=support, electrode=el,
                           H_clamped=Hcc, check_voltage=bool(abs(bias) <= VALIDATED_VOLTAGE))
