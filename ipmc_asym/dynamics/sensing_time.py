"""Sensing in the time domain: the tip displacement ``w(t)`` imposed, the charge, current and voltage.

What is solved (docs/sensing.md, "Time domain").  The strip is a Thevenin source (exact for the
linear one-port, ``derivations/sensing_dynamic.py``): the EMF ``V_oc`` behind the strip's own
impedance ``Z``.  Both are taken from their reduced forms:

* the EMF at leading order in ``lam = lambda_D/e`` (``derivations.sensing_dynamic:leading_order``,
  ``V_oc = (R T/F) 2 b (1 + i omega e^2/(3 D) - lam)``), i.e. in time
  ``e(t) = (R T/F) 2 [(1 - lam) b(t) + (e^2/(3 D)) db/dt]``: the static Donnan EMF plus the
  streaming potential of the water the bending moves; ``b(t) = (1 - 2 nu) e kappa_mean(t)/phi4``
  with the length-averaged curvature of the quasi-static beam (:func:`ipmc_asym.forward.sensing.
  tip_curvature`: ``kappa_mean = 2 w/L^2`` free, ``1.5 w/L^2`` tip force);
* ``Z`` the actuation's reduced circuit (:mod:`ipmc_asym.dynamics.circuit`, linearised: core
  resistance ``R``, its geometric capacitance ``C_g``, the layers' ``C_d(0)``; the admittance
  ``s C_d (1 + s R C_g)/(1 + s R C_d)``, the step circuit's charge
  ``sigma = sigma_L + C_g (v - sigma_L/C_d)``, ``R sigma_L' = v - sigma_L/C_d``).

Linear, so by superposition ``Q = -K [(1 - lam) q + (e^2/(3D)) q']`` with ``q = G b`` the charge the
circuit takes from an applied voltage ``b(t)`` (``K = 2 R T/F``, ``G = 1/(s (Z + R_load))``):
the derivative of the EMF never has to be integrated (a step in ``w`` is a delta in ``db/dt``).
``q``, ``q'`` and ``q''`` are the circuit driven by ``b``, ``b'`` and ``b''`` (``G b' = (G b)'`` from
rest; each input interpolated on its own, so no output is a difference of near-equal states over a
short time constant), integrated exactly for inputs linear between knots (the augmented matrix
exponential, :mod:`ipmc_asym.kernels.lti`); the impulses of ``b'`` and ``b''`` at the jumps of ``b``
(steps, square flips, and ``t = 0`` from rest) are kicks of the states.  The only discretisation
error is the linear interpolation, ``h^2 max|b''|/8`` (the knots refined until it is below 1e-6 of
``max|b|``; jumps are knots; the corners of ramps, triangles and measured drives are not, and the
delta of the streaming current there is not in ``I``).

The stated relative error (``error``): the circuit's impedance ``lam/2`` (the bound of
:func:`ipmc_asym.dynamics.circuit.circuit_impedance_error`, at any frequency) + the leading-order
EMF's ``max |v_lead/v_exact - 1|`` up to the fastest frequency of the run (the drive's highest for
periodic drives; ``1/(2 pi dt)`` of the output spacing for steps, ramps and measured drives) +
the interpolation's + the linearisation's (the static leading rung's ``2 |c3| b^2 (1 + lam)`` at
the peak bend).  ``error_settled``: the same for the relaxed rows, the DC values of the first two
(exponentially small in ``1/lam``) + the linearisation's.  Assumptions as :func:`ipmc_asym.sensing_response` (water instantly
redistributed; one-way coupling, rows flagged where ``|e(t)|`` exceeds ``ONE_WAY_GROWTH`` times the
static EMF of the largest bend; the static sense's strain and beam limits per row, kept and flagged).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.linalg import expm

from ipmc_asym.base.results import Panel, ResultMixin, ResultSpec
from ipmc_asym.dynamics.circuit import circuit_impedance_error
from ipmc_asym.dynamics.electrode import capacitance_scale, core_resistance
from ipmc_asym.dynamics.sensing import (
    ONE_WAY_GROWTH,
    STREAMING_NOTE,
    WATER_ASSUMPTION,
    sensing_inputs,
    voc_hat,
    voc_hat_leading,
)
from ipmc_asym.dynamics.waveforms import Waveform, parse_waveform
from ipmc_asym.forward.sensing import DEFAULT_NU, MAX_TIP_DISPLACEMENT, tip_curvature
from ipmc_asym.integral.sensing import B_LIMIT, sense_hat, strain_parameter
from ipmc_asym.kernels.lti import lti_foh
from ipmc_asym.model import groups
from ipmc_asym.model.params import Material, Strip, check_finite

__all__ = ["SensingTransient", "sensing_transient", "MAX_SENSE_POINTS", "MAX_SENSE_STEPS", "INTERP_TOL"]

#: output rows at most (the table is held in memory)
MAX_SENSE_POINTS = 1_000_000
#: internal knots at most (the interpolation of b refined to INTERP_TOL needs them)
MAX_SENSE_STEPS = 5_000_000
#: relative interpolation error of b between knots aimed at
INTERP_TOL = 1e-6
#: rows the mean power's window needs (trapezoid of a sampled period: relative error ~ (pi/n)^2/3)
MIN_POWER_ROWS = 200


@dataclass(repr=False)
class SensingTransient(ResultMixin):
    """Time series of a strip whose tip displacement follows a waveform (SI).

    Attributes
    ----------
    t : ndarray (n,)        time, s
    w : ndarray             imposed tip displacement, m
    kappa : ndarray         curvature at the clamp, 1/m
    emf : ndarray           the EMF e(t) (open-circuit voltage phi(-e) - phi(e)), V
    Q : ndarray             charge of the electrode z = -e, C (0 in open circuit)
    I : ndarray             current through the load from the electrode z = -e to z = +e, -dQ/dt, A
    V : ndarray             voltage across the load (open: the EMF; short: 0), V
    power : ndarray         instantaneous power into the load V I, W
    check_strain, check_beam_regime, check_one_way, valid : ndarray of bool   per row (values kept)
    error : float           stated relative error of Q, I, V (module docstring)
    error_circuit, error_emf, error_interp, error_linear : float   its parts
    error_settled : float   stated relative error of the relaxed rows (many ``tau`` and ``e^2/D`` after the
                            last change of ``w``): the circuit's and the EMF's DC errors + the linearisation's
    mean_power : float      time-mean of ``power`` over the last whole period (periodic drives) or the run, W
                            (NaN with fewer than MIN_POWER_ROWS rows there)
    load : str or float ; load_resistance : float (Ohm, NaN for short/open)
    support, model, waveform : str ; nu, tau, f_stream, f_top : float
    notes : list of str
    """

    _result = ResultSpec("t", "t", ("w", "kappa", "emf", "Q", "I", "V", "power", "check_strain",
                                    "check_beam_regime", "check_one_way", "valid"),
                         (Panel("t", ("w",)), Panel("t", ("Q",)), Panel("t", ("V",)), Panel("t", ("I",))),
                         ("nu", "load_resistance", "tau", "f_stream", "f_top", "error", "error_settled", "mean_power"),
                         {"w": "tip_displacement", "kappa": "curvature", "I": "I_load", "V": "V_load",
                          "power": "power_instant", "error": "error_sensing", "mean_power": "harvested_power"})
    _HEADLINE = ("model", "support", "load", "waveform")

    t: np.ndarray
    w: np.ndarray
    kappa: np.ndarray
    emf: np.ndarray
    Q: np.ndarray
    I: np.ndarray
    V: np.ndarray
    power: np.ndarray
    check_strain: np.ndarray
    check_beam_regime: np.ndarray
    check_one_way: np.ndarray
    valid: np.ndarray
    error: float
    error_circuit: float
    error_emf: float
    error_interp: float
    error_linear: float
    error_settled: float
    mean_power: float
    load: object
    load_resistance: float
    support: str
    model: str
    waveform: str
    nu: float
    tau: float
    f_stream: float
    f_top: float
    notes: list = field(default_factory=list)


def _second_derivative_scale(wave: Waveform):
    """``(max|w''|, max|w|)`` bounds of the smooth parts (sine terms; the rest is linear between corners)."""
    d2 = sum(abs(p["V"]) * (2.0 * math.pi * p["f"]) ** 2 for k, p in wave.terms if k == "sine")
    peak = sum(abs(p["V"]) if "V" in p else float(np.max(np.abs(p["v"]), initial=0.0)) for _, p in wave.terms)
    return d2, peak


def _knots(wave: Waveform, duration, points):
    """Internal knots: the output grid refined for the interpolation of ``b``, plus the jumps."""
    d2, peak = _second_derivative_scale(wave)
    h_out = duration / (points - 1)
    sub = 1
    if d2 > 0.0 and peak > 0.0:
        h_need = math.sqrt(8.0 * INTERP_TOL * peak / d2)
        sub = max(1, math.ceil(h_out / h_need))
    n = (points - 1) * sub
    if n > MAX_SENSE_STEPS:
        said = f"{n:.3g}" if n < 10**300 else "over 1e300"  # an integer count past the floats (a duration of 1e308 s)
        raise ValueError(f"waveform: the interpolation of the tip displacement to {INTERP_TOL:g} needs {said} steps "
                         f"over the duration (at most {MAX_SENSE_STEPS:g}): shorten the duration or lower the frequency")
    tj, _ = wave.jumps(0.0, duration)
    if tj.size > MAX_SENSE_STEPS:
        raise ValueError(f"waveform: more than {MAX_SENSE_STEPS:g} jumps over the duration")
    grid = np.linspace(0.0, duration, n + 1)
    knots = np.union1d(grid, tj) if tj.size else grid
    h = grid[1] - grid[0]
    interp = d2 * h * h / (8.0 * peak) if peak > 0 else 0.0
    # the output rows are every sub-th point of the grid, found among the knots by their exact values
    return knots, interp, grid[::sub]


def _segments(wave, knots, scale):
    """Start values and slopes of ``scale * w`` on each segment, from one-sided samples (right-continuous
    waveforms: a jump at a knot belongs to the segment it starts)."""
    a, c = knots[:-1], knots[1:]
    h = c - a
    eps = 1e-9 * h
    ua = scale * wave(a + eps)
    uc = scale * wave(c - eps)
    slope = (uc - ua) / (h - 2.0 * eps)
    return ua - slope * eps, slope, h


def _discretise(A, B, hs):
    """Exact first-order-hold tables (``Phi``, ``G0``, ``G1``) per distinct segment length, and ``which``."""
    n = A.shape[0]
    hr = np.round(hs / hs.max(), 12)
    uniq, which = np.unique(hr, return_inverse=True)
    Phi = np.empty((uniq.size, n, n))
    G0 = np.empty((uniq.size, n))
    G1 = np.empty((uniq.size, n))
    M = np.zeros((n + 2, n + 2))
    M[:n, :n] = A
    M[:n, n] = B
    M[n, n + 1] = 1.0
    for j, hh in enumerate(uniq * hs.max()):
        E = expm(M * hh)
        Phi[j], G0[j], G1[j] = E[:n, :n], E[:n, n], E[:n, n + 1]
    return Phi, G0, G1, which.astype(np.int64)


def sensing_transient(waveform, duration, points: int = 2001, strip: Strip | None = None, *, model="constant",
                      material: Material | None = None, load="short", nu: float = DEFAULT_NU,
                      support: str = "tip-force") -> SensingTransient:
    """Charge, current, voltage and power of a strip whose tip displacement follows ``waveform``.

    Parameters
    ----------
    waveform : str, Waveform or callable   the tip displacement ``w(t)`` in metres: the ``drive``
        grammar with lengths (``"sine:1mm@0.01Hz"``, ``"step:0.5mm"``, ``"csv:PATH"``;
        :func:`ipmc_asym.dynamics.waveforms.parse_waveform` with ``quantity="length"``)
    duration : float   s, > 0 ; points : int   output rows (2 .. MAX_SENSE_POINTS), uniform in [0, duration]
    strip, model, material, nu, support : as :func:`ipmc_asym.sensing_response`
    load : "short", "open" or a resistance (Ohm, > 0)

    Returns
    -------
    SensingTransient   (the strip at rest, relaxed and flat, before t = 0)

    Examples
    --------
    >>> import ipmc_asym as ia
    >>> r = ia.sensing_transient("step:1mm", 20.0, 101, model="linear")  # 40 tau: relaxed
    >>> static = ia.sense(tip_displacement=[1e-3], support="tip-force", model="linear").Q[0]
    >>> bool(abs(r.Q[-1] / static - 1) < r.error_settled)
    True
    """
    s, m, perm, nu, load, R_L = sensing_inputs(strip, material, model, nu, support, load)
    T = check_finite("duration", duration, "a finite time in s, > 0")
    if T <= 0.0:
        raise ValueError(f"duration must be > 0 s; got {duration!r}")
    if isinstance(points, bool) or not isinstance(points, (int, np.integer)) or not 2 <= points <= MAX_SENSE_POINTS:
        raise ValueError(f"points must be an integer in [2, {MAX_SENSE_POINTS}]; got {points!r}")
    points = int(points)
    wave = waveform if isinstance(waveform, Waveform) else parse_waveform(waveform, quantity="length")
    L, e = s.length, s.e
    # the largest bend the drive reaches: the static sense's refusal (a face losing all its water)
    _, peak = _second_derivative_scale(wave)
    if peak > MAX_TIP_DISPLACEMENT:  # the static sense's guard: kappa = 3 w/L^2 would overflow
        raise ValueError(f"waveform: a peak tip displacement of {peak:.3g} m; up to {MAX_TIP_DISPLACEMENT:g} m allowed "
                         "(a numerical guard)")
    k_peak = float(tip_curvature(peak, L, support))
    if abs(float(strain_parameter(k_peak, s.thickness, nu, m))) >= B_LIMIT:
        raise ValueError(f"waveform: a peak tip displacement of {peak:.3g} m gives (1 - 2 nu) |kappa0| e/phi4 >= 1 "
                         "(a face would lose all its water)")
    knots, interp, t = _knots(wave, T, points)
    w = wave(t)
    kappa = np.asarray(tip_curvature(w, L, support), dtype=float)

    mean_k_per_w = (2.0 if support == "free" else 1.5) / L**2
    b_per_w = float(strain_parameter(mean_k_per_w, s.thickness, nu, m))
    lam = float(groups.debye_length(s.thickness, perm.eps_moy, m))
    K = 2.0 * groups.thermal_voltage(m)
    ts = e * e / (3.0 * m.D)  # streaming time e^2/(3D): V_oc = K b (1 - lam + s ts) at leading order
    area = s.width * L
    R = float(core_resistance(s.thickness, m)) / area
    C0 = 0.5 * float(capacitance_scale(perm, m)) * area
    Cg = float(groups.geometric_capacitance(s.thickness, perm.eps_moy)) * area
    tau = R * C0
    gam = 1.0 - Cg / C0

    b = b_per_w * w
    db = b_per_w * wave.derivative(t, 1)
    d2b = b_per_w * wave.derivative(t, 2)
    emf = K * ((1.0 - lam) * b + ts * db)

    if load == "open":
        Q = np.zeros(points)
        I = np.zeros(points)
        V = emf.copy()
    else:
        # q = G b: the circuit's charge for an applied voltage b(t), zero state at t = 0 (rest)
        if load == "short":
            A = np.array([[-1.0 / tau]])
            B = np.array([1.0 / R])
        else:
            A = np.array([[-1.0 / tau, 1.0 / R],
                          [gam / (R * C0 * Cg), -(1.0 + R_L * gam / R) / (R_L * Cg)]])
            B = np.array([0.0, 1.0 / (R_L * Cg)])
        # q, q' and q'' are the circuit driven by b, b' and b'' (G b' = (G b)' from rest): each input
        # interpolated on its own, so no output is a difference of near-equal states over a short time
        # constant; the impulses of b' and b'' at the jumps of b (and at t = 0, from rest) kick the states
        n_x = A.shape[0]
        tj, dj = wave.jumps(0.0, T)
        seg_j = np.searchsorted(knots, tj)  # a jump at knot i starts segment i
        d1_0 = float(wave.derivative(np.array([0.0]), 1)[0])
        x0 = np.zeros(n_x)
        res = []
        for order in (0, 1, 2):
            fun = wave if order == 0 else (lambda tt, o=order: wave.derivative(tt, o))
            u0, us, hs = _segments(fun, knots, b_per_w)
            if order == 0:
                Phi, G0, G1, which = _discretise(A, B, hs)
            # from rest: b jumps by b(0+) and b' by b'(0+) at t = 0; later jumps of b by dj
            at, kicks = [0], [np.zeros(n_x)]
            if order == 1:
                kicks[0] = B * b_per_w * float(wave(np.array([0.0]))[0])
                at += seg_j.tolist()
                kicks += [B * b_per_w * d for d in dj]
            elif order == 2:
                kicks[0] = A @ B * b_per_w * float(wave(np.array([0.0]))[0]) + B * b_per_w * d1_0
                at += seg_j.tolist()
                kicks += [A @ B * b_per_w * d for d in dj]
            at = np.asarray(at, dtype=np.int64)
            kicks = np.asarray(kicks, dtype=float).reshape(-1, n_x)
            xs = np.zeros((hs.size, n_x))
            lti_foh(Phi, G0, G1, which, u0, us, at, kicks, x0, xs)
            xk = np.vstack([x0[None, :], xs])
            np.add.at(xk, at, kicks)  # the rows report right-limits: after the kick at their knot
            res.append(xk[np.searchsorted(knots, t)])
        ins = (b, db, d2b)
        if load == "short":
            q, dq, d2q = (gam * x[:, 0] + Cg * u for x, u in zip(res, ins))
        else:
            q, dq, d2q = (gam * x[:, 0] + Cg * x[:, 1] for x in res)
        Q = -K * ((1.0 - lam) * q + ts * dq)
        I = K * ((1.0 - lam) * dq + ts * d2q)  # -dQ/dt
        V = np.zeros(points) if load == "short" else R_L * I
    Q, I, V = Q + 0.0, I + 0.0, V + 0.0  # + 0.0: no "-0" in the rows
    power = V * I + 0.0

    # the stated error: circuit (lam/2 at any frequency), leading-order EMF up to f_top, interpolation
    periodic_only = all(k in ("sine", "square", "triangle", "dc") for k, _ in wave.terms) and wave.max_frequency > 0
    f_top = wave.max_frequency if periodic_only else 1.0 / (2.0 * math.pi * (T / (points - 1)))
    if periodic_only and any(k in ("square", "triangle") for k, _ in wave.terms):
        f_top = max(f_top, 1.0 / (2.0 * math.pi * (T / (points - 1))))  # their harmonics up to the output spacing
    fs = np.geomspace(min(1e-6, f_top), f_top, 200)
    Ws = 2.0 * math.pi * fs * e * e / m.D
    err_emf = float(np.max(np.abs(voc_hat_leading(Ws, lam) / voc_hat(Ws, lam) - 1.0)))
    err_circ = 0.5 * lam
    # linearisation: the static leading rung's bound 2 |c3| b^2 (1 + lam) at the peak clamp curvature
    # (integral/sensing.py; the nonlinear part of the relaxed response this linear circuit leaves out)
    b_peak = float(strain_parameter(k_peak, s.thickness, nu, m))
    hat = sense_hat(np.array([abs(b_peak)]), lam, perm, m, "leading", escalate=False)
    err_lin = float(max(hat.error[0], hat.error_v[0])) if b_peak != 0.0 else 0.0
    error = (err_circ + err_emf + interp + err_lin) * (1.0 + 1e-12) + 1e-15
    # the relaxed state (rows many tau and e^2/D after the last change of w): the DC parts only
    dc_circ = float(circuit_impedance_error(np.array([1e-12]), s.thickness, perm, m)[0])
    dc_emf = float(abs(voc_hat_leading(0.0, lam) / voc_hat(0.0, lam) - 1.0))
    error_settled = (dc_circ + dc_emf + err_lin) * (1.0 + 1e-12) + 1e-15

    # flags (values kept): the static sense's strain and beam limits, and the one-way coupling
    check_strain = e * np.abs(kappa) <= m.strain_limit
    check_beam = np.abs(kappa) * L <= 0.5 * math.pi
    static_peak = K * (1.0 - lam) * abs(b_per_w) * peak
    # the pressure the model leaves off the strain grows with the core field: the EMF's and the ohmic
    # drop of the current through the core (a step's streaming charge at t = 0+ makes it huge)
    core = np.maximum(np.abs(emf), np.abs(I) * R)
    check_one_way = core <= ONE_WAY_GROWTH * static_peak * (1.0 + 1e-12)
    # the stated error is the reduced forms' and is reported, not a flag (a step's f_top is conservative)
    valid = check_strain & check_beam & check_one_way

    # mean power over the last whole period of a periodic drive (else over the run)
    sel = np.ones(points, bool)
    if periodic_only and wave.max_frequency > 0:
        per = 1.0 / min(p["f"] for k, p in wave.terms if "f" in p)
        if per <= T:
            sel = t >= T - per
    # the trapezoid of the sampled power: only with enough rows in the window (else NaN, noted)
    mean_power = math.nan
    if sel.sum() >= MIN_POWER_ROWS:
        mean_power = float(np.trapezoid(power[sel], t[sel]) / (t[sel][-1] - t[sel][0]))
    f_stream = 3.0 * m.D / (2.0 * math.pi * e * e)
    notes = [WATER_ASSUMPTION, STREAMING_NOTE,
             "time domain: EMF e(t) = (R T/F) 2 [(1 - lambda) b + (e^2/(3 D)) db/dt] (leading order in lambda) behind the "
             "actuation's reduced circuit (R, C_g, C_d(0)), integrated exactly for b linear between knots; at a jump "
             "of w the streaming EMF is a delta (not in the samples; its charge is)",
             f"error = lambda/2 (circuit impedance, any frequency) {err_circ:.3g} + leading-order EMF up to "
             f"f_top = {f_top:.3g} Hz {err_emf:.3g} + interpolation {interp:.2g} + linearisation {err_lin:.2g}; "
             f"relaxed rows (many tau after the last change of w): error_settled = {error_settled:.2g}",
             f"one-way coupling: rows where the core voltage max(|e(t)|, |I| R_core) exceeds {ONE_WAY_GROWTH:g} times the "
             "static EMF of the largest bend are flagged (check_one_way; e.g. the streaming charge of a step just after it)",
             f"tip displacement imposed quasi-statically ({support}); drained Poisson ratio nu = {nu:g} (an assumption)",
             "Q: charge of the electrode z = -e; I = -dQ/dt through the load from z = -e to z = +e; V across the load "
             "(open circuit: the EMF); power = V I"]
    if not isinstance(load, str) and math.isnan(mean_power):
        notes.append(f"mean power not computed: fewer than {MIN_POWER_ROWS} rows in its window (raise points)")
    if not isinstance(load, str):
        notes.append(f"with the load the layers charge through R + R_load: time constant (R + R_load) C_d = "
                     f"{(R + R_L) * C0:.4g} s (the start-up transient; the mean power is over the last period)")
    if f_top > 0.5 * f_stream:
        notes.append(f"the drive reaches f_top = {f_top:.3g} Hz, past f_stream/2 = {0.5 * f_stream:.3g} Hz: the streaming "
                     "potential is not small there (the one-way flag says where it matters)")
    return SensingTransient(t=t, w=w, kappa=kappa, emf=emf, Q=Q, I=I, V=V, power=power, check_strain=check_strain,
                            check_beam_regime=check_beam, check_one_way=check_one_way, valid=valid, error=error,
                            error_circuit=err_circ, error_emf=err_emf, error_interp=interp, error_linear=err_lin,
                            error_settled=error_settled,
                            mean_power=mean_power,
                            load=load, load_resistance=R_L, support=support, model=perm.name,
                            waveform=getattr(wave, "spec", repr(wave)), nu=nu, tau=tau, f_stream=f_stream,
                            f_top=f_top, notes=notes)
