"""The forward model, vectorised: strip -> moment integral ``I`` -> ``M_A = A5 I`` -> beam -> checks.

Every command and study that turns a strip into mechanical outputs calls :func:`forward`
(``estimate``, ``sweep``, scenes, uncertainty propagation, calibration, the transient's
quasi-static mechanics).  The chain (paper sections 3-4):

* ``I`` at the cheapest valid rung of the fidelity ladder from ``fidelity`` up
  (:func:`ipmc_asym.forward.estimate.moment_escalating`);
* ``M_A = A5 I`` with ``A5 = 6 l e^2 F |phi0| C_moy`` (:func:`ipmc_asym.model.params.moment_scale`);
* the cantilever (:func:`ipmc_asym.beam.statics.solve_beam`): ``theta = -M_A L/EI`` (eq. 12),
  the arc deflection and ``w_small = -M_A L^2/(2 EI)`` (eq. 13), ``F_small = 3 M_A/(2L)``
  (eq. 14) and the large-displacement blocking force;
* the checks of :data:`CHECKS`, of two kinds.  *Numerical validity*
  (:data:`NUMERICAL_CHECKS`: the rung's error bound, separate layers) is fixed by escalation;
  where no rung holds, the outputs are withheld (:data:`WITHHOLD`).  *Model assumptions*
  (:data:`ASSUMPTION_CHECKS`: the free strip within a quarter turn, the blocked strip within a
  quarter turn (the lever arm of eq. 15), the face strain within
  ``Material.strain_limit``, the voltage within ``settings.VALIDATED_VOLTAGE``, a slender
  strip, :mod:`ipmc_asym.model.limits`) keep the numbers and flag the row
  (:data:`FLAGS`: which outputs each concerns; :func:`assumption_warnings`: one line each,
  naming the limit and its source); only a quantity that means nothing is withheld: the free
  strip's tip position past a full turn (the arc passes through itself).

Signs as in the paper: a positive voltage gives ``M_A > 0``, ``theta < 0`` and ``w < 0``.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from ipmc_asym.base.ladder import climb, first_shown, rungs_from
from ipmc_asym.base.registry import FIDELITIES as _FIDELITY_SPECS
from ipmc_asym.base.registry import compiled_fidelities
from ipmc_asym.base.results import Panel, ResultMixin, ResultSpec
from ipmc_asym.base.settings import (
    ELECTROLYSIS_VOLTAGE,
    OUTSIDE_REGIMES,
    STRAIN_LIMIT,
    STRAIN_LIMIT_SOURCE,
    VALIDATED_VOLTAGE,
    VALIDITY_LIMIT,
)
from ipmc_asym.beam.statics import REGIMES, blocking_force_ratio, solve_beam
from ipmc_asym.forward.escalation import (
    Climb,
    Escalated,
    moment_ladder,
    rung_checks,
    rung_reason,
    where_point,
)
from ipmc_asym.forward.pressure import pressure_ladder
from ipmc_asym.integral.api import COMPILED_S, check_min_thickness, closed_model_id, run_parallel, validity_limit
from ipmc_asym.integral.samples import moment_samples
from ipmc_asym.model import groups
from ipmc_asym.model.electrode import composite_stiffness
from ipmc_asym.model.limits import slender_ok, slender_warnings
from ipmc_asym.model.params import NAFION_LI, Material, moment_scale
from ipmc_asym.model.request import Request

__all__ = ["forward", "ForwardResult", "CHECKS", "NUMERICAL_CHECKS", "ASSUMPTION_CHECKS", "FLAGS", "MOMENT_KEYS",
           "FREE_STRIP_KEYS", "MECHANICAL_KEYS", "TIP_POSITION_KEYS", "WITHHOLD", "SAMPLING_FIDELITIES",
           "ASSUMPTION_LIMITS", "distinct_pairs", "strain_reason", "regime_reason", "voltage_reason", "blocked_reason",
           "flag_mask", "assumption_warnings",
           "blocked_rotation", "model_notes", "LINEAR_SATURATION_A2"]

#: A2 = F|phi0|/(R T) from which the linear model's cathode layer is saturated: its concentration at
#: the face is within 1e-3 of 2 C_moy (B1 = 1.9991 at A2 = 7.74 on the nominal strip) and M_A within
#: 0.2 % of its limit, so neither the moment nor the charge grows with the voltage any more
LINEAR_SATURATION_A2 = 8.0


def model_notes(voltage, material, models) -> list:
    """Notes on what the model does or leaves out at this voltage (V) and ``material``, for the
    permittivity ``models`` shown: said beside the numbers, nothing flagged (the numbers are the
    model's).  The linear model's saturation (paper section 6.3) and water's electrolysis."""
    A2 = groups.A2(voltage, material)
    notes = []
    if "linear" in models and float(A2) >= LINEAR_SATURATION_A2:
        notes.append(f"linear model (eps proportional to C): from A2 = F|phi0|/(R T) ~ {LINEAR_SATURATION_A2:g} "
                     f"(here {float(A2):.3g}) its cathode layer is saturated, C = 2 C_moy at the face: its moment and "
                     "charge no longer grow with the voltage (C_diff -> 0), the paper's section 6.3, which "
                     "`ipmc-asym validate` checks")
    if abs(float(voltage)) > ELECTROLYSIS_VOLTAGE:
        notes.append(f"|phi0| = {abs(float(voltage)):g} V is above water's decomposition potential (~"
                     f"{ELECTROLYSIS_VOLTAGE:g} V): real electrodes may electrolyse the solvent there, which this "
                     "blocking-electrode model leaves out; the numbers are the model's")
    return notes

#: numerical validity: the rung's error bound on ``I`` and separate layers (escalation fixes
#: them; where no rung holds, the outputs are withheld)
NUMERICAL_CHECKS = ("electrochemistry", "layer_separation")
#: model assumptions: the free strip within a quarter turn (``beam_regime``), the blocked strip
#: within a quarter turn (``blocked_regime``: the lever arm ``L - s`` of eq. 15), the face strain
#: within ``Material.strain_limit``, ``|voltage| <= settings.VALIDATED_VOLTAGE``, a slender
#: strip (:data:`ipmc_asym.model.limits.SLENDER_LIMITS`); a failed one flags, never withholds
ASSUMPTION_CHECKS = ("beam_regime", "blocked_regime", "strain", "voltage", "slender")
#: the validity checks of a result, in the order of the chain (electrochemistry -> beam)
CHECKS = NUMERICAL_CHECKS + ASSUMPTION_CHECKS
#: outputs of the moment integral (withheld where no rung is valid)
MOMENT_KEYS = ("I", "M_A", "B1")
#: outputs of the free strip (flagged past a quarter turn)
FREE_STRIP_KEYS = ("theta", "w", "w_small", "x_tip", "y_tip")
#: every mechanical output
MECHANICAL_KEYS = FREE_STRIP_KEYS + ("F_block", "F_block_small")
#: the free strip's tip position: meaningless past a full turn (the arc passes through itself;
#: ``w`` is periodic in ``M``), withheld there
TIP_POSITION_KEYS = ("w", "w_small", "x_tip", "y_tip")
#: model assumption -> its limit and the limit's source, in one line (summaries of many rows)
ASSUMPTION_LIMITS = {
    "beam_regime": "free strip within a quarter turn, |theta| <= pi/2 (past it the arc of eq. 12 curls back: w not "
                   "monotone in M)",
    "blocked_regime": "blocked strip within a quarter turn, |kappa L| (1 - psi/2) <= pi/2 (the paper's lever arm "
                      "L - s of eq. 15)",
    "strain": f"face strain e|kappa| <= Material.strain_limit (default settings.STRAIN_LIMIT = {STRAIN_LIMIT:g}: "
              f"{STRAIN_LIMIT_SOURCE})",
    "voltage": f"|voltage| <= settings.VALIDATED_VOLTAGE = {VALIDATED_VOLTAGE:g} V (validated against the BVP; water "
               "electrolysis, ~1.23 V, is outside this blocking-electrode model)",
    "slender": "slender strip: L/2e >= 10, 2l/2e >= 10, 2l/L <= 1 (model.limits.SLENDER_LIMITS, each with its reason)",
}
#: model assumption -> the outputs it concerns (flagged where it fails, :func:`flag_mask`)
FLAGS = {"beam_regime": FREE_STRIP_KEYS, "blocked_regime": ("F_block", "F_block_small"), "strain": MECHANICAL_KEYS,
         "voltage": MOMENT_KEYS + MECHANICAL_KEYS,
         "slender": MOMENT_KEYS + MECHANICAL_KEYS}
#: the withholding rule, most severe first: (what failed, outputs withheld).  ``"moment"``: no
#: rung is valid (electrochemistry or layer separation failed at every rung tried);
#: ``"multi-turn"``: the free strip winds more than a full turn (its tip position means nothing).
#: A failed model assumption withholds nothing (:data:`FLAGS`)
WITHHOLD = (("moment", MOMENT_KEYS + MECHANICAL_KEYS), ("multi-turn", TIP_POSITION_KEYS))
_MULTI_TURN = REGIMES.index("multi-turn")
#: rungs with a compiled point kernel (those :func:`forward` climbs with per-point ``c_moy``)
SAMPLING_FIDELITIES = compiled_fidelities()
_OUTSIDE_CODES = [REGIMES.index(o) for o in OUTSIDE_REGIMES]


def _strain_source(limit) -> str:
    return (f"settings.STRAIN_LIMIT: {STRAIN_LIMIT_SOURCE}" if float(limit) == STRAIN_LIMIT
            else "given (Material.strain_limit, --strain-limit)")


def strain_reason(strain, limit=STRAIN_LIMIT) -> str:
    """One line: the strain assumption fails (``strain`` = ``e|kappa|``, ``limit`` = ``Material.strain_limit``)."""
    shown = f"{float(strain):.3g}"
    for digits in range(4, 18):  # enough digits that the value shown is not the limit's own text
        if float(shown) > float(limit):
            break
        shown = f"{float(strain):.{digits}g}"
    return (f"strain at the faces e|kappa| = {shown} > strain limit {float(limit):g} "
            f"({_strain_source(limit)}): outside the small-strain beam model; mechanical outputs kept, "
            "flagged check_strain = false")


def blocked_rotation(theta):
    """Largest rotation (rad) along the BLOCKED strip for free-strip rotation(s) ``theta`` = ``-kappa L``.

    The blocked strip's slope is ``theta_b(t) = m [psi (t - t^2/2) - t]`` (``m = kappa L``,
    ``t = s/L``, ``F = psi M/L``, paper section 3 with the lever arm ``L - s``); its extremes are
    at the tip, ``m (psi/2 - 1)``, and at ``t = 1 - 1/psi``, ``m (psi - 1)^2/(2 psi)``, smaller
    for ``1 <= psi <= 3/2``: ``|theta_b| = |m| (1 - psi/2)``, ``|m|/4`` for small ``m``.
    """
    th = np.asarray(theta, dtype=float)
    with np.errstate(all="ignore"):
        return np.abs(th) * (1.0 - 0.5 * np.asarray(blocking_force_ratio(th)))


def regime_reason(regime, theta=None) -> str:
    """One line: the free strip is past a quarter turn (what is kept, what holds)."""
    th = "" if theta is None else f", |theta| = {abs(float(theta)):.3g} rad"
    if regime == "multi-turn":
        return (f"free strip {regime}{th} > 2 pi: theta kept, flagged check_beam_regime = false; the arc passes "
                "through itself past a full turn, so its tip position means nothing: w, w_small, x_tip, y_tip withheld")
    return (f"free strip {regime}{th} > pi/2: the arc formula (paper eq. 12) still gives theta, w, x_tip, "
            "y_tip (strips do curl), kept and flagged check_beam_regime = false; w is not monotone in M; "
            "the blocking force is a separate check (blocked_regime)")


def blocked_reason(theta) -> str:
    """One line: the BLOCKED strip itself turns past a quarter turn (``theta`` = free-strip rotation)."""
    tb = float(blocked_rotation(theta))
    what = f"turns up to {tb:.3g} rad along its length" if np.isfinite(tb) else "winds beyond the tracked branch"
    return (f"blocked strip past a quarter turn: with its tip held on the axis it still {what} (> pi/2), where the "
            "paper's lever arm L - s of eq. 15 is only an approximation; F_block kept as the root of eq. 15, flagged "
            "check_blocked_regime = false")


def voltage_reason(voltage) -> str:
    """One line: the voltage is beyond the validated range."""
    return (f"|voltage| {abs(float(voltage)):g} V > {VALIDATED_VOLTAGE:g} V (settings.VALIDATED_VOLTAGE, the range "
            "validated against the BVP), and far beyond water electrolysis (~1.23 V), which this blocking-electrode "
            "model leaves out: the numbers solve the equations, not the device; kept, flagged check_voltage = false")


def flag_mask(check_of, key: str) -> np.ndarray:
    """Bool array: where output ``key`` is flagged by a failed model assumption (:data:`FLAGS`).

    ``check_of(name)`` returns the bool array of check ``name`` (``ForwardResult`` attributes,
    or the ``check_<name>`` columns of a sweep)."""
    bad = None
    for check, keys in FLAGS.items():
        if key in keys:
            b = ~np.asarray(check_of(check), bool)
            bad = b if bad is None else bad | b
    return np.zeros(np.shape(check_of("beam_regime")), bool) if bad is None else bad


@dataclass(repr=False)
class ForwardResult(ResultMixin):
    """Outputs of :func:`forward`; arrays of the broadcast input shape (0-d for scalars), SI.

    The values are computed wherever a rung is valid; where no rung is valid the moment and
    mechanical outputs are NaN (``regime`` ""), whatever the other checks.  Nothing else is
    blanked here: :meth:`withheld_mask` / :meth:`withhold` apply the rule of :data:`WITHHOLD`;
    :meth:`flag_mask` says where a model assumption flags an output.

    Attributes
    ----------
    I : ndarray      moment integral (dimensionless, signed like the voltage)
    M_A : ndarray    end moment ``A5 I`` (N m)
    theta : ndarray  free-end rotation (rad), paper eq. 12
    w, w_small : ndarray   arc and small-displacement tip deflections (m), eq. 13
    F_block, F_block_small : ndarray   large- and small-displacement blocking forces (N), eq. 14
    x_tip, y_tip : ndarray   tip coordinates of the free strip (m); ``y_tip = w``
    regime : ndarray of str   :data:`ipmc_asym.beam.statics.REGIMES` label ("" where no rung is valid)
    regime_code : ndarray of int   index into ``REGIMES``
    max_strain : ndarray   ``e |M_A|/EI`` at the faces
    small_error, block_error : ndarray   relative deviations of ``w_small`` and ``F_block_small``
        from the large-displacement values
    B1 : ndarray     cathode concentration ``C(1)/C_moy``
    error : ndarray  relative error bound of ``I`` (inf where no rung is valid)
    fidelity_used : ndarray of str   rung that produced ``I`` ("" where none)
    escalated : ndarray of bool   ``fidelity_used`` is a rung above the requested one
    electrochemistry, layer_separation, beam_regime, blocked_regime, strain, voltage, slender : ndarray of bool
        the checks (:data:`CHECKS`); also :attr:`checks_mask` ``[name]`` (the voltage itself is
        ``inputs["voltage"]``)
    moment_valid : ndarray of bool   a rung is valid (``I`` computed)
    valid : ndarray of bool   every check
    strain_limit : float   ``Material.strain_limit`` the strain check used
    message : str    why the first invalid point fails ("" if every point is valid): no valid rung, else
        its first failed model assumption in the order of :data:`CHECKS` (:func:`assumption_warnings`' line)
    moment_message : str   why the first point without a valid rung has none ("" if none)
    beam_warnings : list of str   :func:`ipmc_asym.beam.statics.solve_beam` warnings
    fidelity : str   the rung requested
    """

    _result = ResultSpec("point", None, ("inputs.length", "inputs.width", "inputs.thickness", "inputs.voltage",
                                         "I", "M_A", "theta", "w", "w_small", "F_block", "F_block_small", "x_tip",
                                         "y_tip", "max_strain", "B1", "error", "fidelity_used", "escalated",
                                         "regime", "valid"),
                         (Panel("point", ("w", "w_small")), Panel("point", ("F_block", "F_block_small"))),
                         names={f"inputs.{k}": k for k in ("length", "width", "thickness", "voltage")})

    I: np.ndarray
    M_A: np.ndarray
    theta: np.ndarray
    w: np.ndarray
    w_small: np.ndarray
    F_block: np.ndarray
    F_block_small: np.ndarray
    x_tip: np.ndarray
    y_tip: np.ndarray
    regime: np.ndarray
    regime_code: np.ndarray
    max_strain: np.ndarray
    small_error: np.ndarray
    block_error: np.ndarray
    B1: np.ndarray
    error: np.ndarray
    fidelity_used: np.ndarray
    escalated: np.ndarray
    electrochemistry: np.ndarray
    layer_separation: np.ndarray
    beam_regime: np.ndarray
    blocked_regime: np.ndarray
    strain: np.ndarray
    voltage: np.ndarray
    slender: np.ndarray
    moment_valid: np.ndarray
    valid: np.ndarray
    message: str = ""
    moment_message: str = ""
    beam_warnings: list = field(default_factory=list)
    fidelity: str = ""
    strain_limit: float = STRAIN_LIMIT
    inputs: dict = field(default_factory=dict, repr=False)

    @property
    def checks_mask(self) -> dict:
        """``{check: bool array}`` of every check of :data:`CHECKS`, in that order (the check
        booleans; ``.voltage``, ``.strain``, ... are the same arrays under the check's name)."""
        return {c: np.asarray(getattr(self, c), bool) for c in CHECKS}

    def checks(self, index=()) -> dict:
        """``{check: bool}`` of one point (``index`` into the arrays; ``()`` for 0-d results)."""
        return {c: bool(getattr(self, c)[index]) for c in CHECKS}

    def failed(self, index=()) -> str | None:
        """The most severe failure of :data:`WITHHOLD` at one point (None if nothing is withheld)."""
        if not bool(self.moment_valid[index]):
            return "moment"
        if int(self.regime_code[index]) == _MULTI_TURN:
            return "multi-turn"
        return None

    def flagged(self, index=()) -> list:
        """Names of the model assumptions (:data:`ASSUMPTION_CHECKS`) failed at one point."""
        if not bool(self.moment_valid[index]):
            return []
        return [c for c in ASSUMPTION_CHECKS if not bool(getattr(self, c)[index])]

    def flag_mask(self, key: str) -> np.ndarray:
        """Bool array: where output ``key`` is flagged by a failed model assumption (:data:`FLAGS`)."""
        return flag_mask(lambda c: getattr(self, c), key) & np.asarray(self.moment_valid, bool)

    def withheld(self, index=()) -> tuple:
        """Output names withheld at one point, by :data:`WITHHOLD` (empty if none)."""
        f = self.failed(index)
        return () if f is None else dict(WITHHOLD)[f]

    def withheld_mask(self, key: str) -> np.ndarray:
        """Bool array: where output ``key`` is withheld (False everywhere for an unaffected key)."""
        ok = {"moment": self.moment_valid, "multi-turn": np.asarray(self.regime_code) != _MULTI_TURN}
        bad = np.zeros(np.shape(self.valid), bool)
        for check, keys in WITHHOLD:
            if key in keys:
                bad |= ~ok[check]
        return bad

    def withhold(self) -> "ForwardResult":
        """A copy with every withheld output set to NaN (``regime`` kept)."""
        out = {}
        for k in MOMENT_KEYS + MECHANICAL_KEYS:
            bad = self.withheld_mask(k)
            a = getattr(self, k)
            out[k] = np.where(bad, np.nan, a) if np.any(bad) else a
        return replace(self, **out)


def assumption_warnings(r: "ForwardResult", index=None) -> list:
    """One line per failed model assumption, naming the limit and its source.

    ``index`` given: the lines of that point; None: over every point, each line at the first
    point that fails it, with the count (step time points, uq samples, sweep rows)."""
    ok_m = np.asarray(r.moment_valid, bool).reshape(-1)
    size = ok_m.size
    sel = np.ones(size, bool)
    if index is not None:  # one point
        sel[:] = False
        sel[int(np.ravel_multi_index(index, np.shape(r.valid))) if np.shape(r.valid) else 0] = True
    out = []
    for c in ASSUMPTION_CHECKS:
        bad = np.flatnonzero(sel & ok_m & ~np.asarray(getattr(r, c), bool).reshape(-1))
        if bad.size == 0:
            continue
        count = "" if index is not None else first_shown(len(bad), size)
        out += [x + count for x in _reasons(r, c, int(bad[0]))]
    return out


def _reasons(r: "ForwardResult", c: str, j: int) -> list:
    """The line(s) of the failed model assumption ``c`` at the flat point ``j`` (one per
    failed slenderness ratio); what :func:`assumption_warnings` and ``ForwardResult.message`` say."""
    def at(a):
        return np.asarray(a).reshape(-1)[j]

    if c == "strain":
        return [strain_reason(at(r.max_strain), r.strain_limit)]
    if c == "beam_regime":
        return [regime_reason(str(at(r.regime)), at(r.theta))]
    if c == "blocked_regime":
        return [blocked_reason(at(r.theta))]
    if c == "voltage":
        return [voltage_reason(at(r.inputs.get("checked_voltage", r.inputs["voltage"])))]
    q = {k: float(at(r.inputs[k])) for k in ("length", "width", "thickness")}
    return slender_warnings(q["length"], q["width"], q["thickness"])


def distinct_pairs(code):
    """``(first, inverse)``: rows holding each distinct code, and each row's distinct index;
    ``(None, None)`` when every row is distinct.

    Rows of a C-order grid whose (thickness, voltage) axes vary fastest have increasing codes:
    then nothing is sorted or gathered.
    """
    code = np.asarray(code).reshape(-1)
    if code.size < 2 or bool(np.all(code[1:] > code[:-1])):
        return None, None
    _, first, inv = np.unique(code, return_index=True, return_inverse=True)
    return first, np.asarray(inv).reshape(-1)


def _moment_per_point_material(th, v, perm, fidelity, material, c_moy, tol, escalate) -> Escalated:
    """:func:`moment_escalating` with ``C_moy`` per point (flat arrays, thickness floor held): the compiled rungs of
    :data:`SAMPLING_FIDELITIES` through :func:`ipmc_asym.integral.samples.moment_samples`,
    whose ``A3 = -rho2 Z3/(C_moy F)`` and ``lam`` are arrays.  Same validity as
    :func:`moment_escalating`: error bound <= ``min(tol, VALIDITY_LIMIT)`` and below the rung's
    ceiling, separate layers unless the rung holds at any thickness, finite ``I``."""
    if fidelity not in SAMPLING_FIDELITIES:
        raise ValueError(f"fidelity {fidelity!r} is not available with a per-point c_moy; use one of "
                         f"{', '.join(SAMPLING_FIDELITIES)}")
    limit = VALIDITY_LIMIT if tol is None else min(tol, VALIDITY_LIMIT)
    eps_core = perm.eps0 + perm.deps
    lam = groups.debye_length(th, eps_core, material, c_moy)  # core Debye length / e
    A2 = groups.A2(v, material)
    A3 = groups.A3(material, c_moy)
    rho = perm.eps0 / eps_core
    sign = np.sign(v)
    rec = Climb(th.size)

    def evaluate(f, idx):
        Ii, ei, ci = np.empty(idx.size), np.empty(idx.size), np.empty(idx.size)
        run_parallel(moment_samples, idx.size * COMPILED_S.get(f, 0.0),
                     (lam[idx], A2[idx], A3[idx], rho, closed_model_id(perm, f), _FIDELITY_SPECS[f].kernel_code,
                      sign[idx], Ii, ei, ci))
        return Ii, ei, ci

    def checks(f, r, idx):
        Ii, ei, ci = r
        e_ok, l_ok = rung_checks(Ii, ei, ci, f, limit)
        e_ok &= ei < validity_limit(f)  # the rung's own ceiling (integral.api.validity_limit)
        ok = e_ok & l_ok
        rec.take(f, idx, ok, Ii, ei, ci, e_ok, l_ok)
        if np.all(ok):
            return ok, ""
        k = int(np.flatnonzero(~ok)[0])
        return ok, rung_reason(Ii[k], ei[k], l_ok[k], min(limit, validity_limit(f)))

    lad = climb(rungs_from(SAMPLING_FIDELITIES, fidelity, escalate), evaluate, checks, th.size)
    msg = ""
    if lad.left.size:
        k = int(lad.left[0])
        msg = lad.message(where_point(th, v, perm)(k) + f", c_moy {float(c_moy[k]):.3g} mol/m^3")
    return rec.result(lad.valid, msg)


def forward(length, width, thickness, voltage, *, modulus=None, c_moy=None, material: Material = NAFION_LI,
            model="constant", fidelity="quadrature", tol=None, escalate: bool = True,
            pair_code=None, pressure_term: bool = False, checked_voltage=None) -> ForwardResult:
    """Mechanical outputs of the strip(s), with the validity checks (SI units).

    Parameters
    ----------
    length : array_like
        Strip length ``L`` (m).
    width, thickness : array_like
        TOTAL width ``2l`` and thickness ``2e`` (m).
    voltage : array_like
        Applied voltage ``phi0`` (V), any sign.
    modulus : array_like, optional
        Young's modulus (Pa), per point; default ``material.E``.
    c_moy : array_like, optional
        Mean cation concentration ``C_moy`` (mol/m^3), per point; default ``material.C_moy``.
        Given, ``I`` comes from the per-point compiled driver
        (:func:`ipmc_asym.integral.samples.moment_samples`; compiled rungs only; ``B1`` NaN).
    material : Material
    model : str or Permittivity or callable
    fidelity : str
        The cheapest rung tried; with ``escalate`` the first rung from there valid at each point.
    tol : float, optional
        Relative accuracy required of ``I``, in (0, 1) (default ``settings.VALIDITY_LIMIT``);
        also the tolerance of the "small" beam regime.
    escalate : bool
        ``False``: only ``fidelity`` (points where it is invalid fail the moment checks).
    pair_code : array_like of int, optional
        Per point: equal codes mean equal (thickness, voltage) (and, with ``c_moy``, equal
        ``c_moy``); ``I`` is then evaluated once per distinct code.
    pressure_term : bool
        Keep the pressure term of the Nernst-Planck law (paper eq. (5), which the paper drops;
        ``beta = (v1 - M1 v2/M2) C_moy`` from ``material``): ``I`` from the rungs that hold it,
        ``exact`` then ``bvp`` (:func:`ipmc_asym.forward.pressure.moment_pressure_escalating`;
        a cheaper ``fidelity`` starts there).  Default off: the paper's model.
    checked_voltage : array_like, optional
        The voltage (V) the ``voltage`` check concerns, where it is not ``voltage`` itself (a
        transient: the applied voltage, which the layers' voltage lags behind); kept in
        ``inputs["checked_voltage"]``.  Default ``voltage``.

    All inputs broadcast to one shape ``S``.

    Returns
    -------
    ForwardResult
        Arrays of shape ``S``.

    Raises
    ------
    ValueError
        Unknown fidelity, bad ``tol``, a thickness below ``settings.MIN_THICKNESS``, a
        non-positive length or stiffness (one line each).
    """
    req = Request(model, fidelity, tol, escalate, pressure_term)
    return _forward(length, width, thickness, voltage, req, modulus=modulus, c_moy=c_moy, material=material,
                    pair_code=pair_code, checked_voltage=checked_voltage, floor_checked=False)


def _forward(length, width, thickness, voltage, req: Request, *, modulus=None, c_moy=None,
             material: Material = NAFION_LI, pair_code=None, checked_voltage=None,
             floor_checked: bool = True) -> ForwardResult:
    """:func:`forward` for a checked :class:`~ipmc_asym.model.request.Request` (and, with
    ``floor_checked``, thicknesses known to be >= ``settings.MIN_THICKNESS``: a ``Strip``'s)."""
    perm, fidelity, tol, escalate, pressure_term = req.model, req.fidelity, req.tol, req.escalate, req.pressure_term
    E = material.E if modulus is None else modulus
    C = material.C_moy if c_moy is None else c_moy
    L, wd, th, v, E, C = np.broadcast_arrays(*(np.asarray(a, dtype=float) for a in
                                               (length, width, thickness, voltage, E, C)))
    shape = L.shape
    L, wd, th, v, E, C = (a.reshape(-1) for a in (L, wd, th, v, E, C))
    if not floor_checked:
        check_min_thickness(th)
    k = L.size
    A5 = moment_scale(wd, th, v, material.F, material.C_moy if c_moy is None else C)
    EI = composite_stiffness(E, wd, th, material.electrode)  # E I_p, or the section with electrode layers
    # I depends on (thickness, voltage) (and C_moy) only: each distinct pair once
    first, inv = (None, None) if pair_code is None else distinct_pairs(np.broadcast_to(pair_code, shape))

    def rows(a):  # per-distinct-pair values -> per-point values
        return a if inv is None else a[inv]

    def pairs(a):  # per-point values -> one per distinct pair
        return a if first is None else a[first]

    if pressure_term:
        if c_moy is not None:
            raise ValueError("pressure_term: a per-point c_moy is not available with the pressure term")
        r = pressure_ladder(pairs(th), pairs(v), req, material)
    elif c_moy is None:
        r = moment_ladder(pairs(th), pairs(v), req, material, progress=False).result()
    else:
        r = _moment_per_point_material(pairs(th), pairs(v), perm, fidelity, material, pairs(C), tol, escalate)
    used = rows(r.fidelity_used.reshape(-1))
    ok = rows(r.valid.reshape(-1))
    all_ok = bool(np.all(ok))
    I = rows(r.I.reshape(-1))
    Mok = A5 * I if all_ok else np.where(ok, A5 * np.where(ok, I, 0.0), 0.0)
    with np.errstate(all="ignore"):
        b = solve_beam(Mok, L, EI, tol=tol, e=0.5 * th, strain_limit=material.strain_limit)

    def masked(x, fill):  # outputs only where a rung is valid
        x = np.broadcast_to(np.asarray(x), (k,))
        return x if all_ok else np.where(ok, x, fill)

    strain = np.asarray(b.max_strain, dtype=float).reshape(-1)
    rcode = np.broadcast_to(np.asarray(b.regime_code), (k,))
    # model assumptions: checked where a rung is valid (False elsewhere: nothing to assume about)
    beam_regime = ok & ~np.isin(rcode, _OUTSIDE_CODES)  # ints, not strings
    # the blocked strip's own largest rotation |kappa L| (1 - psi/2) (blocked_rotation), with psi
    # from the beam's block_error = (3/2 - psi)/psi (psi <= 3/2 on the branch): no second
    # evaluation of psi; NaN beyond the tracked branch fails
    with np.errstate(all="ignore"):
        psi = 1.5 / (1.0 + np.asarray(b.block_error, dtype=float).reshape(-1))
        tb = np.abs(np.asarray(b.theta, dtype=float).reshape(-1)) * (1.0 - 0.5 * psi)
    blocked_ok = ok & (tb <= 0.5 * np.pi)
    strain_ok = ok & (strain <= material.strain_limit)
    cv = v if checked_voltage is None else np.broadcast_to(np.asarray(checked_voltage, float), shape).reshape(-1)
    volt_ok = ok & (np.abs(cv) <= VALIDATED_VOLTAGE)
    slender = ok & np.broadcast_to(slender_ok(L, wd, th), (k,))
    elec = rows(r.electrochemistry.reshape(-1))
    layer = rows(r.layer_separation.reshape(-1))
    valid = elec & layer & beam_regime & blocked_ok & strain_ok & volt_ok & slender
    mech = {c: masked(np.asarray(getattr(b, c), dtype=float), np.nan)
            for c in ("theta", "w", "w_small", "x_tip", "y_tip", "F_block", "F_block_small", "small_error",
                      "block_error")}
    reg = masked(np.asarray(b.regime), "")
    def rs(a):
        return np.asarray(a).reshape(shape)

    out = ForwardResult(
        I=rs(I), M_A=rs(masked(Mok, np.nan)), regime=rs(reg), regime_code=rs(rcode),
        max_strain=rs(masked(strain, np.nan)), B1=rs(rows(r.B1.reshape(-1))), error=rs(rows(r.error.reshape(-1))),
        fidelity_used=rs(used), escalated=rs((used != fidelity) & (used != "")),
        electrochemistry=rs(elec), layer_separation=rs(layer), beam_regime=rs(beam_regime),
        blocked_regime=rs(blocked_ok), strain=rs(strain_ok),
        voltage=rs(volt_ok), slender=rs(slender), moment_valid=rs(ok), valid=rs(valid),
        moment_message=r.message, beam_warnings=list(b.warnings), fidelity=fidelity,
        strain_limit=float(material.strain_limit),
        inputs={"length": rs(L), "width": rs(wd), "thickness": rs(th), "voltage": rs(v),
                **({} if checked_voltage is None else {"checked_voltage": rs(cv)})},
        **{c: rs(a) for c, a in mech.items()})
    if not bool(np.all(valid)):  # the first invalid point, its first failed check in the order of CHECKS
        j = int(np.argmin(valid))
        failed = [c for c in ASSUMPTION_CHECKS if not out.checks_mask[c].reshape(-1)[j]]
        out.message = r.message if not ok[j] else _reasons(out, failed[0], j)[0]
    return out
