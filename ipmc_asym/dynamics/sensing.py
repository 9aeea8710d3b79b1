"""Sensing and harvesting in the frequency domain: the strip bent sinusoidally, small signal.

Derivation: ``derivations/sensing_dynamic.py`` (the linearised Nernst-Planck/Gauss problem of the
actuation's small signal, ``derivations/charge.py``, with the bending as a source: the fixed
charge per solution volume ``C_moy(z, t) = C_moy (1 + b(t) z/e)``, ``b = (1 - 2 nu) kappa e/phi4``,
from ``derivations/sensing.py``).  Per unit ``b`` and electrode area, with ``W = omega e^2/D``,
``lam = lambda_D/e``, ``k^2 = 1/lam^2 + i W``:

* the strip is exactly a Thevenin source (a linear one-port): the open-circuit voltage
  ``V_oc = (R T/F) b v(W)``, ``v = [2 i W (k^3 - 3k + 3 tanh k) + 6 k^2 (k - tanh k)]/(3 k^5 lam^2)``,
  behind the strip's own impedance ``Z`` (the actuation's ``pnp-linear``, the same admittance);
  short circuit ``Q_sc = -V_oc/(i omega Z)`` (derivation: ``sigma_sc = -Y v_oc``);
* ``W -> 0``: the static closed forms of :mod:`ipmc_asym.integral.sensing`;
* at leading order in ``lam``, ``v = 2 (1 + i W/3 - lam)``: the static Donnan EMF plus the
  streaming potential of the water that the bending moves (its cations, carried along, have to
  migrate back through the core).  The static EMF in series with ``Z`` is right only for
  ``omega << 3 D/e^2`` (relative error ``W/3``); ``method="circuit"`` uses the leading order
  (with the circuit's ``Z``) and states its error against the exact form.

Assumptions (docs/sensing.md): the water is redistributed instantly through the thickness (the
drained matrix follows the imposed bending at every instant; valid well below the poroelastic
rate ``K M/(eta e^2)``, which has no source for ``K`` in this project and is not computed), the
pressure is not fed back on the strain (one-way coupling; its relative size grows with the core
field, ``(R T C_moy/E) |V_oc(f)/V_oc(0)|``, column ``one_way_error``, flagged past
:data:`ONE_WAY_GROWTH` times its static value), Nernst-Planck without its pressure term.

The beam: a tip displacement ``w`` imposed slowly against the beam's inertia (the quasi-static
shape of :func:`ipmc_asym.forward.sensing.tip_curvature`: ``support="free"`` uniform curvature,
``"tip-force"`` the cantilever's ``kappa(x) = kappa0 (1 - x/L)``); the local sources stand in
parallel behind a uniform admittance, so ``V_oc`` is their length average and ``Q`` their sum,
exact at linear order.

A resistive load ``R`` (Ohm) across the electrodes: ``V_load = V_oc R/(R + Z)``, the current
``I_load = V_load/R`` (through the load from the electrode ``z = -e`` to ``z = +e``), the mean
power ``P = |V_oc|^2 R/(2 |R + Z|^2)`` for a tip amplitude ``w0`` (peak): largest at ``R = |Z|``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ipmc_asym.base.registry import check_choice
from ipmc_asym.base.results import Panel, ResultMixin, ResultSpec
from ipmc_asym.dynamics.circuit import FREQ_METHODS, circuit_impedance_error, frequency_response
from ipmc_asym.forward.sensing import DEFAULT_NU, SENSE_SUPPORTS, tip_curvature
from ipmc_asym.integral.sensing import B_LIMIT, strain_parameter
from ipmc_asym.model import groups
from ipmc_asym.model.params import NAFION_LI, NOMINAL_STRIP, Material, Strip, check_finite, check_frequencies
from ipmc_asym.model.permittivity import get_model

__all__ = ["SensingResponse", "sensing_response", "voc_hat", "voc_hat_leading", "SENSING_LOADS",
           "DEFAULT_AMPLITUDE", "ONE_WAY_GROWTH", "WATER_ASSUMPTION", "strip_sensing_outputs"]

#: the readings: short circuit, open circuit, or a resistance in ohms (a number)
SENSING_LOADS = ("short", "open")
#: default peak tip displacement of the load columns (m): 1 mm, within the small-strain limit of the
#: nominal strip (tip force: face strain 3 w e/L^2 = 7.5e-4)
DEFAULT_AMPLITUDE = 1e-3
#: ``check_one_way``: the one-way coupling's error estimate may grow to this many times its static
#: value (R T C_moy/E ~ 0.06, accepted by the static landing) before the point is flagged
ONE_WAY_GROWTH = 2.0
WATER_ASSUMPTION = ("water instantly redistributed through the thickness (drained matrix at every instant): valid "
                    "well below the poroelastic rate K M/(eta e^2); the permeability K has no source in this project, "
                    "so that limit is not computed")
STREAMING_NOTE = ("V_oc(f) = static Donnan EMF x (1 + i omega e^2/(3 D)) at leading order in lambda_D/e: the streaming "
                  "potential of the water the bending moves; the static EMF alone holds for f << 3 D/(2 pi e^2)")


def voc_hat(W, lam):
    """``V_oc F/(R T b)`` of the linearised PNP with the bending source (``derivations.sensing_dynamic:solve``).

    Complex, at ``W = omega e^2/D >= 0`` and ``lam = lambda_D/e``; tanh form (no overflow at
    ``k ~ 1/lam``).  ``W = 0`` gives the static ``2 (1 - lam tanh(1/lam))``.
    """
    W = np.asarray(W, dtype=float)
    k = np.sqrt(1.0 / lam**2 + 1j * W)
    th = np.tanh(k)
    # k - tanh k and k^3 - 3k + 3 tanh k lose digits only where |k| is small (thin strips, lam >~ 1);
    # |k| >= 1/lam keeps them accurate for every lam <= 0.1 the actuation side covers
    return (2j * W * (k**3 - 3.0 * k + 3.0 * th) + 6.0 * k * k * (k - th)) / (3.0 * k**5 * lam**2)


def voc_hat_leading(W, lam):
    """Leading order in ``lam``: ``2 (1 + i W/3 - lam)`` (``derivations.sensing_dynamic:leading_order``)."""
    return 2.0 * (1.0 + 1j * np.asarray(W, dtype=float) / 3.0 - lam)


@dataclass(repr=False)
class SensingResponse(ResultMixin):
    """Small-signal sensing response per tip displacement, and into a load (SI).

    Attributes
    ----------
    f : ndarray (n,)              frequency, Hz
    Q_per_w : ndarray complex     short-circuit charge of the electrode z = -e per tip displacement, C/m
    I_per_w : ndarray complex     short-circuit current ``i omega Q_per_w``, A/m
    V_oc_per_w : ndarray complex  open-circuit voltage phi(-e) - phi(e) per tip displacement, V/m
    Z : ndarray complex           impedance of the strip (electrode area 2l L), Ohm
    V_load, I_load : ndarray complex   with a resistive load: its voltage (V) and current (A) at the
                                  tip amplitude ``amplitude`` (peak); NaN without a load
    power : ndarray               mean power into the load, ``|V_load|^2/(2 R)``, W (NaN without a load)
    error : ndarray               relative error against the exact linear form (``pnp-linear``: 0;
                                  ``circuit``: the impedance's and the leading-order EMF's)
    one_way_error : ndarray       estimate of the neglected pressure feedback, (R T C_moy/E) ``|V_oc(f)/V_oc(0)|``
    check_one_way : ndarray of bool   one_way_error within ONE_WAY_GROWTH times its static value
    valid : ndarray of bool       check_one_way and the amplitude's strain and beam checks
    amplitude : float             peak tip displacement of the load columns, m
    load : str or float           "short", "open" or the load resistance (Ohm)
    load_resistance : float       Ohm (NaN for short or open)
    support, method, model : str ; nu : float
    tau : float                   the layers' charging time R C_d(0), s
    f_stream : float              3 D/(2 pi e^2), Hz: where the streaming potential equals the static EMF
    f_d : float                   dielectric relaxation frequency, Hz
    check_strain, check_beam_regime : bool   of the amplitude (face strain e kappa0 <= strain_limit,
                                  ``|kappa0|`` L <= pi/2); values kept
    notes : list of str
    """

    _result = ResultSpec("f", "f", ("Q_per_w", "I_per_w", "V_oc_per_w", "Z", "V_load", "I_load", "power", "error",
                                    "one_way_error", "check_one_way", "valid"),
                         (Panel("f", ("Q_per_w",), True, True), Panel("f", ("V_oc_per_w",), True, True)),
                         ("nu", "amplitude", "load_resistance", "tau", "f_stream", "f_d"),
                         {"error": "error_sensing", "power": "harvested_power"})
    _HEADLINE = ("model", "method", "support", "load")

    f: np.ndarray
    Q_per_w: np.ndarray
    I_per_w: np.ndarray
    V_oc_per_w: np.ndarray
    Z: np.ndarray
    V_load: np.ndarray
    I_load: np.ndarray
    power: np.ndarray
    error: np.ndarray
    one_way_error: np.ndarray
    check_one_way: np.ndarray
    valid: np.ndarray
    amplitude: float
    load: object
    load_resistance: float
    support: str
    method: str
    model: str
    nu: float
    tau: float
    f_stream: float
    f_d: float
    check_strain: bool
    check_beam_regime: bool
    notes: list = field(default_factory=list)

    def power_at(self, R):
        """Mean power (W) into resistances ``R`` (Ohm, array) at every frequency: shape ``(len(f), len(R))``."""
        R = np.atleast_1d(np.asarray(R, dtype=float))
        voc = self.V_oc_per_w[:, None] * self.amplitude
        return np.abs(voc) ** 2 * R[None, :] / (2.0 * np.abs(R[None, :] + self.Z[:, None]) ** 2)


def _load(load):
    if isinstance(load, str):
        check_choice("load", load, SENSING_LOADS)
        return load, math.nan
    if isinstance(load, bool) or not isinstance(load, (int, float, np.floating, np.integer)):
        raise ValueError(f"load must be 'short', 'open' or a resistance in ohms (> 0); got {load!r}")
    R = float(load)
    if not math.isfinite(R) or R <= 0.0:
        raise ValueError(f"load must be 'short', 'open' or a finite resistance > 0 Ohm; got {load!r}")
    return R, R


def sensing_inputs(strip, material, model, nu, support, load):
    """The checks shared by the small-signal and time-domain sensing entries, once at their top:
    ``(strip, material, perm, nu, load, R)``; ``ValueError`` naming the input."""
    check_choice("support", support, SENSE_SUPPORTS)
    load, R = _load(load)
    s = NOMINAL_STRIP if strip is None else strip
    if not isinstance(s, Strip):
        raise ValueError("strip must be an ipmc_asym.Strip")
    m = NAFION_LI if material is None else material
    if isinstance(nu, bool) or not isinstance(nu, (int, float, np.floating)) or not 0.0 <= float(nu) <= 0.5:
        raise ValueError(f"nu (drained Poisson ratio) must be a number in [0, 0.5]; got {nu!r}")
    perm = get_model(model)
    if perm.is_custom:
        raise ValueError("model: sensing needs one of the paper's permittivity models (constant, linear, affine)")
    return s, m, perm, float(nu), load, R


def sensing_response(f, strip: Strip | None = None, *, model="constant", material: Material | None = None,
                     method="pnp-linear", load="short", nu: float = DEFAULT_NU, support: str = "tip-force",
                     amplitude: float = DEFAULT_AMPLITUDE) -> SensingResponse:
    """Charge, current and voltage per tip displacement of a strip bent at frequencies ``f``; a load's power.

    Parameters
    ----------
    f : array_like (n,)   frequencies, Hz, > 0
    strip : Strip, optional   geometry (TOTAL width and thickness); default the nominal strip
    model : str   permittivity model (constant, linear, affine)
    material : Material, optional (default ``nafion-li``)
    method : {"pnp-linear", "circuit"}   ``pnp-linear``: the exact linear form (module docstring);
        ``circuit``: the circuit's ``Z`` and the leading-order EMF ``2 b (1 + i W/3 - lam)``, with its
        relative error against the exact form in ``error``
    load : "short", "open" or a resistance (Ohm, > 0)   the load columns (``V_load``, ``I_load``,
        ``power``) need a resistance; short and open say which reading the summary leads with
    nu : float   drained Poisson ratio in [0, 0.5] (default 0, an assumption: docs/sensing.md)
    support : {"free", "tip-force"}   how the tip displacement is imposed (as :func:`ipmc_asym.sense`);
        default ``tip-force``, a cantilever whose tip is moved
    amplitude : float   peak tip displacement of the load columns, m (default 1 mm)

    Returns
    -------
    SensingResponse

    Examples
    --------
    >>> import ipmc_asym as ia
    >>> r = ia.sensing_response([1e-4, 1e-2], model="linear", load=1e3)
    >>> static = ia.sense(tip_displacement=[1e-3], support="tip-force", model="linear").Q_per_w[0]
    >>> round(float(abs(r.Q_per_w[0] / static)), 3)  # 0.1 mHz: the static charge per tip displacement
    1.0
    >>> r.valid.tolist()  # 10 mHz: past the one-way coupling bound (the streaming potential)
    [True, False]
    """
    check_choice("method", method, FREQ_METHODS)
    s, m, perm, nu, load, R = sensing_inputs(strip, material, model, nu, support, load)
    w0 = check_finite("amplitude", amplitude, "a finite tip displacement in m, > 0")
    if w0 <= 0.0:
        raise ValueError(f"amplitude must be a finite tip displacement > 0 m; got {amplitude!r}")
    f = check_frequencies(f).reshape(-1)
    L, e = s.length, s.e
    # the amplitude's curvature at the clamp and its checks (the static sense's flags)
    k0 = float(tip_curvature(w0, L, support))
    if abs(float(strain_parameter(k0, s.thickness, nu, m))) >= B_LIMIT:
        raise ValueError("amplitude: (1 - 2 nu) |kappa0| e/phi4 must be < 1 (a face would lose all its water)")
    check_strain = bool(e * abs(k0) <= m.strain_limit)
    check_beam = bool(abs(k0) * L <= 0.5 * math.pi)
    # b per tip displacement, length-averaged: int kappa dx / L = (2 w/L^2 free, 1.5 w/L^2 tip force)
    mean_k_per_w = (2.0 if support == "free" else 1.5) / L**2
    b_per_w = float(strain_parameter(mean_k_per_w, s.thickness, nu, m))
    lam = float(groups.debye_length(s.thickness, perm.eps_moy, m))
    W = 2.0 * math.pi * f * e * e / m.D
    vt = groups.thermal_voltage(m)
    v_exact = voc_hat(W, lam)
    fr = frequency_response(f, strip=s, model=perm, material=m, method=method)
    Z = fr.Z
    if method == "pnp-linear":
        v = v_exact
        err = np.zeros_like(f)
    else:
        v = voc_hat_leading(W, lam)
        # the Thevenin pair's error: the impedance's (circuit_impedance_error) and the EMF's, exact
        err = (np.abs(v / v_exact - 1.0) + circuit_impedance_error(f, s.thickness, perm, m)) * (1.0 + 1e-12) + 1e-15
    voc_w = vt * b_per_w * v
    omega = 2.0 * math.pi * f
    # short circuit of the Thevenin pair: the charge that flows onto the electrode z = -e is
    # -V_oc/(i omega Z) (a positive V_oc = phi(-e) - phi(e) drives current out of that electrode)
    q_w = -voc_w / (1j * omega * Z)
    v0 = abs(2.0 * (1.0 - lam * math.tanh(1.0 / lam)))
    growth = np.abs(v_exact) / v0
    one_way = m.R * m.T * m.C_moy / m.E * growth
    check_one_way = growth <= ONE_WAY_GROWTH
    valid = check_one_way & check_strain & check_beam & (err <= 1e-2)
    nan = np.full(f.shape, complex("nan+nanj"))
    if math.isnan(R):
        v_load, i_load, power = nan, nan, np.full(f.shape, math.nan)
    else:
        v_load = voc_w * w0 * R / (R + Z)
        i_load = v_load / R
        power = np.abs(v_load) ** 2 / (2.0 * R)
    tau = float(fr.tau)
    f_stream = 3.0 * m.D / (2.0 * math.pi * e * e)
    notes = [WATER_ASSUMPTION, STREAMING_NOTE,
             f"one-way coupling: the pressure is not fed back on the strain; its estimate (R T C_moy/E) |V_oc(f)/V_oc(0)| "
             f"(one_way_error) is flagged past {ONE_WAY_GROWTH:g} times its static value {m.R * m.T * m.C_moy / m.E:.3g}",
             f"tip displacement imposed quasi-statically ({support}); drained Poisson ratio nu = {nu:g} (an assumption; "
             "the answers scale as 1 - 2 nu)",
             "Q: charge of the electrode z = -e; V_oc = phi(-e) - phi(e); I_load = V_load/R through the load from the "
             "electrode z = -e to z = +e; power = mean power at the peak tip amplitude"]
    if method == "circuit":
        notes.append("circuit: the circuit's Z with the leading-order EMF 2 b (1 + i W/3 - lambda); error = its relative "
                     "error against the exact linear form (pnp-linear)")
    return SensingResponse(f=f, Q_per_w=q_w, I_per_w=1j * omega * q_w, V_oc_per_w=voc_w, Z=Z, V_load=v_load,
                           I_load=i_load, power=power, error=err, one_way_error=one_way, check_one_way=check_one_way,
                           valid=valid, amplitude=w0, load=load, load_resistance=R, support=support, method=method,
                           model=perm.name, nu=nu, tau=tau, f_stream=f_stream, f_d=float(fr.f_d),
                           check_strain=check_strain, check_beam_regime=check_beam, notes=notes)


def strip_sensing_outputs(length, width, thickness, material: Material | None = None, model="constant", *,
                          frequency=None, load=None, amplitude: float = DEFAULT_AMPLITUDE, nu: float = DEFAULT_NU,
                          support: str = "tip-force", C_moy=None) -> dict:
    """The design outputs of sensing, vectorised over candidate strips (arrays, SI, TOTAL width and thickness).

    ``sensitivity``: the static short-circuit charge per tip displacement ``|Q/w|`` (C/m), the linear
    closed form exact in ``lam`` (:func:`ipmc_asym.forward.sensing.sense` at rung ``leading``, ``w -> 0``);
    ``harvested_power``: the mean power (W) into the resistance ``load`` (Ohm) at ``frequency`` (Hz)
    for the peak tip amplitude ``amplitude`` (m), exact linear form (``pnp-linear``), NaN when
    ``frequency`` or ``load`` is None; ``power_flag``: the candidates whose power rests on a failed
    assumption (one-way coupling past its bound, face strain above the limit, past a quarter turn).
    ``C_moy``: per-candidate override (robust designs), default the material's.
    """
    m = NAFION_LI if material is None else material
    perm = get_model(model)
    L, Wd, T = (np.asarray(a, dtype=float) for a in (length, width, thickness))
    cm = m.C_moy if C_moy is None else np.asarray(C_moy, dtype=float)
    e = 0.5 * T
    cs = 2.0 if support == "free" else 1.5  # int kappa dx / w  (free: 2 w/L, tip force: 1.5 w/L)
    S = np.sqrt(m.phi4 * cm * perm.eps_moy * m.R * m.T)  # integral.sensing.charge_scale_sensing
    lam = np.asarray(groups.debye_length(T, perm.eps_moy, m, C_moy=cm), dtype=float)
    slope = (1.0 - 2.0 * nu) * e / m.phi4  # b per curvature
    # Q/w = 2l S (coth(1/lam) - lam) (db/dkappa) int kappa dx / w (derivations.sensing:linear_solution)
    with np.errstate(over="ignore"):
        sens = Wd * S * (1.0 / np.tanh(1.0 / lam) - lam) * slope * cs / L
    out = {"sensitivity": np.abs(sens)}
    if frequency is None or load is None:
        out["harvested_power"] = np.full(np.broadcast(L, Wd, T).shape, np.nan)
        out["power_flag"] = np.zeros(out["harvested_power"].shape, bool)
        return out
    R = float(load)
    Wf = 2.0 * math.pi * float(frequency) * e * e / m.D
    k = np.sqrt(1.0 / lam**2 + 1j * Wf)
    # the actuation's impedance per area (derivations/charge.py:small_signal): (e/kappa) Zhat
    zhat = (2.0 / lam**2) * (1.0 / k**2 + (1.0 / (1j * Wf) - 1.0 / k**2) * np.tanh(k) / k)
    Z = (e / np.asarray(groups.kappa(m, C_moy=cm), dtype=float)) * zhat / (Wd * L)
    v = voc_hat(Wf, lam)
    voc = groups.thermal_voltage(m) * slope * cs / L**2 * amplitude * v
    out["harvested_power"] = np.abs(voc) ** 2 * R / (2.0 * np.abs(R + Z) ** 2)
    growth = np.abs(v) / np.abs(2.0 * (1.0 - lam * np.tanh(1.0 / lam)))
    k0 = np.asarray(tip_curvature(amplitude, L, support), dtype=float)
    bad = (growth > ONE_WAY_GROWTH) | (e * np.abs(k0) > m.strain_limit) | (np.abs(k0) * L > 0.5 * math.pi)
    bad |= np.abs(slope * k0) >= B_LIMIT
    out["power_flag"] = bad
    return out
