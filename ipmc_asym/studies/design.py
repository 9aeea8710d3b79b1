"""Design for a target: the strip (length, width, thickness, voltage) that maximises or
minimises an output subject to constraints on the others, and a Pareto front of two outputs.

Spec file (TOML; units as everywhere, thickness and width TOTAL)::

    model = "constant"               # a name of ipmc_asym.base.registry.MODELS
    material = "nafion-li"           # optional: a material set or a file FILE.toml
    fidelity = "corrected"           # optional: cheapest rung tried (escalation climbs from there)
    [strip]                          # fixed values
    width = "5mm"
    voltage = "1V"
    [vary]                           # design variables: [low, high], or a list of choices
    length = ["1cm", "4cm"]          # (two values: a range; three or more: choices;
    thickness = ["100um", "400um"]   #  {choices = [a, b]} for two choices, {range = [a, b], log = true})
    [objective]
    maximize = "blocking_force"      # or minimize = ...
    near_tie = 0.01                  # optional: report designs within this relative objective of the optimum
    [constraints]                    # magnitudes; min and/or max
    tip_deflection = {min = "2mm"}
    voltage = {max = "2V"}
    [pareto]                         # optional: front of two outputs (both maximised)
    x = "tip_deflection"
    y = "blocking_force"
    points = 200
    [uncertain]                      # optional (the uq schema; modulus and c_moy): robust design
    modulus = {dist = "normal", mean = "130MPa", sd = "10MPa"}
    [robust]
    probability = 0.95               # every constraint met at this probability
    confidence = 0.95                # ... with this confidence (distribution-free; samples raised to meet it)
    samples = 32

Outputs (scene-file names): ``tip_deflection`` (``|w|``, large displacement), ``blocking_force``
(``|F|``, large displacement), ``rotation`` (``|theta|``), ``moment`` (``|M_A|``), ``I``, ``work``
(``|F|`` ``|w|``, force x deflection), ``max_strain`` (``e|kappa|``); the sensing outputs
``sensitivity`` (the static short-circuit charge per tip displacement ``|Q/w|``, C/m) and
``harvested_power`` (the mean power, W, into a resistance at a frequency for a tip amplitude,
``docs/sensing.md``), set by an optional table::

    [sensing]
    support = "tip-force"            # or "free" (how the tip displacement is imposed)
    nu = 0                           # drained Poisson ratio (an assumption, default 0)
    frequency = "5mHz"               # harvested_power: needs frequency and load
    load = "1kOhm"
    amplitude = "1mm"                # peak tip displacement (default 1mm)

A candidate whose power rests on a failed assumption (the one-way coupling past its bound at that
frequency, the amplitude past the small-strain or quarter-turn limits) has no power.  Besides the
outputs, the inputs and ``footprint`` (length x width) can be constrained.  Objective and
constraints are magnitudes.

Every candidate goes through the one forward model (:func:`ipmc_asym.forward.model.forward`,
with escalation); a candidate any of whose checks withholds or flags an output the design
reads (a failed model assumption: past a quarter turn, strain above the material's limit,
beyond the validated voltage, not slender), or whose moment has no valid rung, is infeasible:
no design is chosen on an invalid number or outside the model.

Search: every combination of the listed choices x a grid of the continuous variables (one
vectorised forward call), then from the best few candidates a pattern search in the unit box
(a 3^d stencil plus seeded random directions, the step halved when nothing improves, down to
``STEP_MIN``): the search keeps the best feasible point found, so it only ever improves on the
grid.  The Pareto front (both outputs maximised): levels of ``x`` spread evenly over the
non-dominated set of a seeded uniform sample, and at each level the largest ``y`` with
``x >= level`` by the same pattern search, all levels in each forward call.
"""

from __future__ import annotations

import itertools
import math
import os
import sys
import time
from dataclasses import dataclass, field

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    import tomli as tomllib

import numpy as np

from ipmc_asym.base.inputs import read_input_text
from ipmc_asym.base.registry import fidelity_names, model_names
from ipmc_asym.base.results import Panel, ResultMixin, ResultSpec
from ipmc_asym.base.units import parse_force, parse_length, parse_quantity, parse_resistance, parse_voltage
from ipmc_asym.beam.dynamics import first_resonance
from ipmc_asym.dynamics.sensing import strip_sensing_outputs
from ipmc_asym.forward.model import CHECKS, forward
from ipmc_asym.model.electrode import beam_label
from ipmc_asym.model.materials import citations
from ipmc_asym.model.params import NOMINAL_STRIP, Material, check_positive, named_material
from ipmc_asym.studies.uq import UNCERTAIN_MATERIAL, _transform, parse_uncertain

__all__ = ["DesignSpec", "DesignResult", "design", "parse_spec", "load_spec", "OUTPUTS", "INPUTS", "CONSTRAINABLE",
           "STEP_MIN", "ACTIVE_RTOL", "MAX_COMBOS", "MAX_PARETO_POINTS", "MAX_SAMPLES"]

#: design inputs (SI; width and thickness TOTAL)
INPUTS = ("length", "width", "thickness", "voltage")
#: outputs (scene-file names) -> unit
OUTPUTS = {"tip_deflection": "m", "blocking_force": "N", "rotation": "rad", "moment": "N m", "I": "1",
           "work": "N m", "max_strain": "1", "first_resonance": "Hz", "sensitivity": "C/m", "harvested_power": "W"}
#: what a constraint may name -> unit
CONSTRAINABLE = {**OUTPUTS, "length": "m", "width": "m", "thickness": "m", "voltage": "V", "footprint": "m^2"}
#: the pattern search stops when its step (in the unit box) is below this
STEP_MIN = 1e-11
#: a constraint is reported active when its relative slack is below this
ACTIVE_RTOL = 1e-4
#: default relative tolerance of the objective within which another design is a near-tie (1 %: below
#: what the model's data pin down; an assumption, set per spec with ``[objective] near_tie``)
NEAR_TIE_RTOL = 0.01
#: levels of each continuous variable at which the near-tie profile is optimised
NEAR_TIE_LEVELS = 33
#: caps (size-like inputs): choice combinations, Pareto points, robust samples
MAX_COMBOS = 512
MAX_PARETO_POINTS = 1000
MAX_SAMPLES = 256
#: candidates of the first grid (all combinations together) and of the Pareto sample
GRID_POINTS = 32_768
PARETO_SAMPLE = 131_072
_ITER_MAX = 400
_STARTS = 4
_AREA = {"m2": 1.0, "m^2": 1.0, "cm2": 1e-4, "cm^2": 1e-4, "mm2": 1e-6, "mm^2": 1e-6}
_WORK = {"J": 1.0, "mJ": 1e-3, "uJ": 1e-6, "µJ": 1e-6, "N m": 1.0, "Nm": 1.0}
_TOP = {"name", "model", "material", "fidelity", "tolerance", "strip", "vary", "objective", "constraints", "pareto",
        "uncertain", "robust", "sensing"}
_POWER = {"W": 1.0, "mW": 1e-3, "uW": 1e-6, "µW": 1e-6, "nW": 1e-9, "pW": 1e-12, "fW": 1e-15}
#: keys of the [sensing] table
SENSING_KEYS = ("support", "nu", "frequency", "load", "amplitude")


def _quantity(where: str, name: str, v) -> float:
    """A value of ``name`` (a number, SI, or a string with units)."""
    if isinstance(v, bool) or not isinstance(v, (int, float, str)):
        raise ValueError(f"{where} must be a number or a string with units; got {v!r}")
    if name in ("length", "width", "thickness", "tip_deflection"):
        return parse_length(where, v)
    if name == "voltage":
        return parse_voltage(where, v)
    if name == "blocking_force":
        return parse_force(where, v)
    if name == "footprint":
        return parse_quantity(where, v, _AREA, "area")
    if name in ("work", "moment"):
        return parse_quantity(where, v, _WORK, "work/moment (N m)")
    if name == "harvested_power":
        return parse_quantity(where, v, _POWER, "power")
    return parse_quantity(where, v, {}, f"number ({CONSTRAINABLE.get(name, '1')})")


@dataclass(frozen=True)
class DesignSpec:
    """A checked design specification (SI).

    Attributes
    ----------
    fixed : dict       input -> value (the inputs not varied)
    ranges : dict      continuous input -> (low, high, log)
    choices : dict     discrete input -> tuple of values
    objective : tuple  (output, "maximize" | "minimize")
    constraints : dict name -> (low or None, high or None), magnitudes
    pareto : tuple or None   (x, y, points)
    uncertain : dict or None the uq schema's ``{name: (dist, params)}`` (modulus, c_moy)
    probability : float      robust: each constraint met at this probability
    samples : int            robust: samples per candidate (raised to what ``confidence`` needs)
    confidence : float       robust: confidence of ``probability`` (independent samples; a constraint
                             holds at all but ``failures`` of them, the binomial tail bound)
    failures : int           robust: samples a constraint may miss (from ``samples``, ``confidence``)
    near_tie : float         relative objective tolerance of a near-tie (``[objective] near_tie``)
    sensing : dict           ``[sensing]``: support, nu, frequency (Hz), load (Ohm), amplitude (m)
    """

    name: str
    model: str
    material: Material
    fidelity: str
    tol: float | None
    fixed: dict
    ranges: dict
    choices: dict
    objective: tuple
    constraints: dict
    pareto: tuple | None = None
    uncertain: dict | None = None
    probability: float = 0.95
    samples: int = 32
    notes: list = field(default_factory=list)
    confidence: float = 0.95
    failures: int = 0
    near_tie: float = NEAR_TIE_RTOL
    sensing: dict = field(default_factory=dict)


def _check_keys(where, d, allowed):
    if not isinstance(d, dict):
        raise ValueError(f"{where} must be a table")
    for k in d:
        if k not in allowed:
            raise ValueError(f"unknown key {k!r} in {where}; allowed: {', '.join(sorted(allowed))}")


def robust_sample_size(probability, confidence, samples):
    """``(samples, failures, note)``: the independent samples and the number of them a constraint may
    miss so that meeting it implies probability ``>= probability`` with ``confidence``.

    A design whose true probability were only ``p`` would miss each sample with probability
    ``1 - p``; it passes with at most ``m`` misses out of ``n`` with probability
    ``BinomCDF(m; n, 1 - p)``, which must be ``<= 1 - confidence`` (Wilks' distribution-free
    tolerance bound).  The largest such ``m`` for the requested ``samples``; when even ``m = 0``
    does not meet it, the smallest ``n`` that does, ``ceil(ln(1 - confidence)/ln p)`` (59 at
    0.95/0.95), with a note saying so.
    """
    from scipy.stats import binom  # deferred: heavy import (start-up)

    p, c = float(probability), float(confidence)
    n = int(samples)
    ms = [m for m in range(n) if binom.cdf(m, n, 1.0 - p) <= 1.0 - c]
    if ms:
        return n, max(ms), None
    need = int(math.ceil(math.log(1.0 - c) / math.log(p)))
    if need > MAX_SAMPLES:
        raise ValueError(f"robust: probability {p:g} at confidence {c:g} needs {need} samples (> {MAX_SAMPLES}); "
                         "lower robust.probability or robust.confidence")
    return need, 0, (f"robust: samples raised from {n} to {need}: probability >= {p:g} with confidence {c:g} needs "
                     f"every one of {need} independent samples to meet the constraints")


def parse_spec(spec: dict, name: str = "design") -> DesignSpec:
    """Check a design specification (the dict of a spec file); one-line ``ValueError`` naming the key."""
    _check_keys("the design spec", spec, _TOP)
    model = spec.get("model", "constant")
    if model not in model_names():
        raise ValueError(f"model must be one of {', '.join(model_names())}; got {model!r}")
    material = spec.get("material", "nafion-li")
    material = material if isinstance(material, Material) else named_material(material)
    fidelity = spec.get("fidelity", "corrected")
    if fidelity not in fidelity_names():
        raise ValueError(f"fidelity must be one of {', '.join(fidelity_names())}; got {fidelity!r}")
    tol = spec.get("tolerance")
    if tol is not None and (isinstance(tol, bool) or not isinstance(tol, (int, float)) or not 0 < tol < 1):
        raise ValueError(f"tolerance must be a relative tolerance in (0, 1); got {tol!r}")
    strip = spec.get("strip", {})
    _check_keys("[strip]", strip, set(INPUTS))
    vary = spec.get("vary", {})
    _check_keys("[vary]", vary, set(INPUTS))
    if not vary:
        raise ValueError("[vary] must name at least one design variable (length, width, thickness, voltage)")
    fixed, ranges, choices, notes = {}, {}, {}, []
    for k in INPUTS:
        if k in strip and k in vary:
            raise ValueError(f"{k} is given both in [strip] and [vary]")
        if k in strip:
            fixed[k] = _quantity(f"strip.{k}", k, strip[k])
        elif k not in vary:
            fixed[k] = getattr(NOMINAL_STRIP, k)
            notes.append(f"{k} not given: the nominal strip's {fixed[k]:g} (SI)")
    for k, v in vary.items():
        where = f"vary.{k}"
        log = False
        if isinstance(v, dict):
            _check_keys(where, v, {"range", "choices", "log"})
            log = v.get("log", False)
            if not isinstance(log, bool):
                raise ValueError(f"{where}.log must be true or false")
            if ("range" in v) == ("choices" in v):
                raise ValueError(f"{where}: give range = [low, high] or choices = [...]")
            kind, vals = ("range", v["range"]) if "range" in v else ("choices", v["choices"])
        elif isinstance(v, list):
            kind, vals = ("range" if len(v) == 2 else "choices"), v
            if len(v) == 2:
                # a bare pair reads as [low, high]; two choices need {choices = [a, b]}
                notes.append(f"{where} = {v!r} is read as a range [low, high]; write "
                             f"{{range = [...]}} or {{choices = [...]}} to say which")
        else:
            raise ValueError(f"{where} must be [low, high] or a list of choices; got {v!r}")
        if not isinstance(vals, list) or not vals:
            raise ValueError(f"{where}: {kind} must be a non-empty list")
        xs = [_quantity(f"{where}[{i}]", k, x) for i, x in enumerate(vals)]
        for x in xs:
            if k != "voltage":
                check_positive(where, x, "m")
        if kind == "range":
            if len(xs) != 2 or not xs[0] < xs[1]:
                raise ValueError(f"{where}: a range is [low, high] with low < high; got {vals!r}")
            if log and (xs[0] <= 0):
                raise ValueError(f"{where}: a log range needs low > 0")
            ranges[k] = (xs[0], xs[1], log)
        else:
            if len(set(xs)) != len(xs):
                raise ValueError(f"{where}: the choices repeat a value")
            choices[k] = tuple(xs)
    if "thickness" in fixed:
        check_positive("strip.thickness", fixed["thickness"], "m")
    ncomb = math.prod(len(c) for c in choices.values()) if choices else 1
    if ncomb > MAX_COMBOS:
        raise ValueError(f"[vary]: {ncomb} combinations of choices; at most {MAX_COMBOS}")
    obj = spec.get("objective")
    _check_keys("[objective]", obj if obj is not None else {}, {"maximize", "minimize", "near_tie"})
    obj = dict(obj or {})
    near_tie = obj.pop("near_tie", NEAR_TIE_RTOL)
    if isinstance(near_tie, bool) or not isinstance(near_tie, (int, float)) or not 0 < near_tie < 1:
        raise ValueError(f"objective.near_tie must be a relative tolerance in (0, 1); got {near_tie!r}")
    if not obj or len(obj) != 1:
        raise ValueError("[objective] must hold exactly one of maximize = OUTPUT or minimize = OUTPUT")
    sense, out = next(iter(obj.items()))
    if out not in OUTPUTS:
        raise ValueError(f"objective.{sense} must be one of {', '.join(OUTPUTS)}; got {out!r}")
    cons = {}
    for k, c in (spec.get("constraints") or {}).items():
        if k not in CONSTRAINABLE:
            raise ValueError(f"constraints: unknown name {k!r}; allowed: {', '.join(CONSTRAINABLE)}")
        _check_keys(f"constraints.{k}", c, {"min", "max"})
        if not c:
            raise ValueError(f"constraints.{k} must give min and/or max")
        lo = _quantity(f"constraints.{k}.min", k, c["min"]) if "min" in c else None
        hi = _quantity(f"constraints.{k}.max", k, c["max"]) if "max" in c else None
        if (lo is not None and lo < 0) or (hi is not None and hi <= 0):
            raise ValueError(f"constraints.{k}: bounds are on magnitudes (min >= 0, max > 0)")
        if lo is not None and hi is not None and not lo < hi:
            raise ValueError(f"constraints.{k}: min must be below max")
        cons[k] = (lo, hi)
    pareto = None
    if "pareto" in spec:
        p = spec["pareto"]
        _check_keys("[pareto]", p, {"x", "y", "points"})
        x, y, n = p.get("x", "tip_deflection"), p.get("y", "blocking_force"), p.get("points", 200)
        for key, o in (("x", x), ("y", y)):
            if o not in OUTPUTS:
                raise ValueError(f"pareto.{key} must be one of {', '.join(OUTPUTS)}; got {o!r}")
        if x == y:
            raise ValueError("pareto.x and pareto.y must be two different outputs")
        if isinstance(n, bool) or not isinstance(n, int) or not 2 <= n <= MAX_PARETO_POINTS:
            raise ValueError(f"pareto.points must be an integer in [2, {MAX_PARETO_POINTS}]; got {n!r}")
        pareto = (x, y, n)
    unc, prob, samples, conf, fails = None, 0.95, 32, 0.95, 0
    if "uncertain" in spec:
        unc = parse_uncertain(spec["uncertain"])
        for k in unc:
            if k not in UNCERTAIN_MATERIAL:
                raise ValueError(f"uncertain.{k}: a robust design samples modulus and c_moy only "
                                 "(the strip's dimensions and voltage are the design)")
        rb = spec.get("robust", {})
        _check_keys("[robust]", rb, {"probability", "samples", "confidence"})
        prob = rb.get("probability", 0.95)
        if isinstance(prob, bool) or not isinstance(prob, (int, float)) or not 0.5 <= prob < 1:
            raise ValueError(f"robust.probability must be in [0.5, 1); got {prob!r}")
        samples = rb.get("samples", 32)
        if isinstance(samples, bool) or not isinstance(samples, int) or not 4 <= samples <= MAX_SAMPLES:
            raise ValueError(f"robust.samples must be an integer in [4, {MAX_SAMPLES}]; got {samples!r}")
        conf = rb.get("confidence", 0.95)
        if isinstance(conf, bool) or not isinstance(conf, (int, float)) or not 0.5 <= conf < 1:
            raise ValueError(f"robust.confidence must be in [0.5, 1); got {conf!r}")
        samples, fails, why = robust_sample_size(float(prob), float(conf), samples)
        if why:
            notes = list(notes) + [why]
    elif "robust" in spec:
        raise ValueError("[robust] needs an [uncertain] table (the uq schema: modulus, c_moy)")
    sensing = _parse_sensing(spec.get("sensing", {}))
    needs = {out} | set(cons) | (set(pareto[:2]) if pareto else set())
    if "harvested_power" in needs and ("frequency" not in sensing or "load" not in sensing):
        raise ValueError("harvested_power needs [sensing] frequency (e.g. \"5mHz\") and load (e.g. \"1kOhm\")")
    return DesignSpec(name=spec.get("name", name), model=model, material=material, fidelity=fidelity, tol=tol,
                      fixed=fixed, ranges=ranges, choices=choices, objective=(out, sense), constraints=cons,
                      pareto=pareto, uncertain=unc, probability=float(prob), samples=samples, notes=notes,
                      confidence=float(conf), failures=fails, near_tie=float(near_tie), sensing=sensing)


def _parse_sensing(d) -> dict:
    """The ``[sensing]`` table, checked (SI); absent keys take the sensing mode's defaults."""
    _check_keys("[sensing]", d, set(SENSING_KEYS))
    out = {"support": d.get("support", "tip-force")}
    if out["support"] not in ("free", "tip-force"):
        raise ValueError(f"sensing.support must be free or tip-force; got {out['support']!r}")
    nu = d.get("nu", 0.0)
    if isinstance(nu, bool) or not isinstance(nu, (int, float)) or not 0.0 <= nu <= 0.5:
        raise ValueError(f"sensing.nu must be a drained Poisson ratio in [0, 0.5]; got {nu!r}")
    out["nu"] = float(nu)
    if "frequency" in d:
        f = parse_quantity("sensing.frequency", d["frequency"], {"Hz": 1.0, "mHz": 1e-3, "kHz": 1e3}, "frequency")
        if not f > 0:
            raise ValueError(f"sensing.frequency must be > 0 Hz; got {d['frequency']!r}")
        out["frequency"] = f
    if "load" in d:
        R = parse_resistance("sensing.load", d["load"])
        if not R > 0:
            raise ValueError(f"sensing.load must be a resistance > 0 Ohm; got {d['load']!r}")
        out["load"] = R
    amp = parse_length("sensing.amplitude", d.get("amplitude", 1e-3))
    if not amp > 0:
        raise ValueError(f"sensing.amplitude must be a tip displacement > 0 m; got {d.get('amplitude')!r}")
    out["amplitude"] = amp
    return out


def load_spec(path) -> dict:
    """Read a spec file (TOML) into a dict (``ValueError`` on an unreadable file or TOML)."""
    try:
        text = read_input_text(path, "spec file")
    except (OSError, UnicodeDecodeError) as exc:
        raise ValueError(f"spec file {os.fspath(path)!r}: cannot read ({exc.__class__.__name__}: {exc})") from None
    try:
        return tomllib.loads(text.removeprefix("\ufeff"))
    except tomllib.TOMLDecodeError as exc:
        raise ValueError(f"{path}: not valid TOML ({exc})") from None


# ---- evaluation --------------------------------------------------------------------------------
def _sensing(spec: DesignSpec, L, W, T, c_moy):
    """``sensitivity`` and ``harvested_power`` of candidates (:func:`strip_sensing_outputs`)."""
    sd = spec.sensing or {"support": "tip-force", "nu": 0.0, "amplitude": 1e-3}
    return strip_sensing_outputs(L, W, T, spec.material, spec.model, frequency=sd.get("frequency"),
                                 load=sd.get("load"), amplitude=sd["amplitude"], nu=sd["nu"], support=sd["support"],
                                 C_moy=c_moy)


class _Problem:
    """The spec's variables in the unit box and one vectorised evaluation of candidates."""

    def __init__(self, spec: DesignSpec):
        self.spec = spec
        self.cont = list(spec.ranges)
        self.combos = list(itertools.product(*spec.choices.values())) if spec.choices else [()]
        self.disc = list(spec.choices)
        self.evaluations = 0
        self.samples = None
        if spec.uncertain:
            S = spec.samples
            rng = np.random.default_rng(0)
            cols = {}
            for k, (dist, vals) in spec.uncertain.items():
                # independent draws: the binomial bound of robust_sample_size holds for them
                # (stratified samples are not independent)
                u = rng.uniform(size=S)
                cols[k] = np.asarray(_transform(u, dist, vals), dtype=float)
            self.samples = cols

    def inputs(self, u: np.ndarray, combo_idx: np.ndarray) -> dict:
        """Unit-box coordinates ``u`` (n, d) and combination indices -> inputs (SI arrays)."""
        n = len(combo_idx)
        out = {k: np.full(n, v) for k, v in self.spec.fixed.items()}
        for j, k in enumerate(self.cont):
            lo, hi, log = self.spec.ranges[k]
            t = np.clip(u[:, j], 0.0, 1.0)
            out[k] = lo * (hi / lo) ** t if log else lo + (hi - lo) * t
        if self.disc:
            table = np.asarray(self.combos, dtype=float)
            for j, k in enumerate(self.disc):
                out[k] = table[combo_idx, j]
        return out

    def evaluate(self, x: dict) -> tuple[dict, np.ndarray, object]:
        """``(values, feasible, forward result)`` of candidates ``x`` (SI input arrays).

        ``values`` holds every output magnitude (robust: the median over the samples), the
        inputs and ``footprint``; NaN where an output is withheld.  ``feasible``: the outputs
        read are valid and every constraint holds (robust: at the stated probability).
        """
        spec = self.spec
        n = len(x["length"])
        self.evaluations += n
        kw = {}
        S = 1
        L, W, T, V = (x[k] for k in INPUTS)
        if self.samples is not None:
            S = spec.samples
            L, W, T, V = (np.repeat(a, S) for a in (L, W, T, V))
            for k, col in self.samples.items():
                kw[k] = np.tile(col, n)
        with np.errstate(all="ignore"):
            r = forward(L, W, T, V, material=spec.material, model=spec.model, fidelity=spec.fidelity,
                        tol=spec.tol, **kw).withhold()
            w, F = np.abs(r.w), np.abs(r.F_block)
            raw = {"tip_deflection": w, "blocking_force": F, "rotation": np.abs(r.theta), "moment": np.abs(r.M_A),
                   "I": np.abs(r.I), "work": w * F, "max_strain": np.asarray(r.max_strain, float),
                   "first_resonance": first_resonance(L, W, T, spec.material)}
            so = _sensing(spec, L, W, T, kw.get("c_moy"))
            raw["sensitivity"] = so["sensitivity"]
            raw["harvested_power"] = np.where(so["power_flag"], np.nan, so["harvested_power"])
            # a design stays inside the model: an output flagged by a failed model assumption (past a
            # quarter turn, strain above the material's limit, beyond the validated voltage, not
            # slender) counts as withheld here, so no design rests on it
            flagged = {"tip_deflection": r.flag_mask("w"), "blocking_force": r.flag_mask("F_block"),
                       "rotation": r.flag_mask("theta"), "moment": r.flag_mask("M_A"), "I": r.flag_mask("I"),
                       "work": r.flag_mask("w") | r.flag_mask("F_block")}
            raw = {k: np.where(flagged[k], np.nan, a) if k in flagged else a for k, a in raw.items()}
        used = {spec.objective[0]} | {k for k in spec.constraints if k in OUTPUTS}
        ok = np.asarray(r.moment_valid, bool).reshape(n, S).all(axis=1)
        vals = {}
        for k, a in raw.items():
            a = a.reshape(n, S)
            finite = np.isfinite(a).all(axis=1)
            if k in used:
                ok &= finite
            if S == 1:
                vals[k] = a[:, 0]
            else:
                with np.errstate(all="ignore"):
                    vals[k] = np.where(finite, np.median(np.where(finite[:, None], a, 0.0), axis=1), np.nan)
        for k in INPUTS:
            vals[k] = np.abs(x[k])
        vals["footprint"] = x["length"] * x["width"]
        feas = ok.copy()
        for k, (lo, hi) in spec.constraints.items():
            if k in OUTPUTS and S > 1:
                # a withheld sample counts as a failure of the constraint (finite sentinels: no inf - inf)
                fin = np.isfinite(raw[k])
                m = spec.failures
                if lo is not None:  # the value the constraint sees: the (m+1)-th worst sample
                    vals[f"{k}:min"] = np.sort(np.where(fin, raw[k], -1e300).reshape(n, S), axis=1)[:, m]
                    feas &= vals[f"{k}:min"] >= lo
                if hi is not None:
                    vals[f"{k}:max"] = np.sort(np.where(fin, raw[k], 1e300).reshape(n, S), axis=1)[:, S - 1 - m]
                    feas &= vals[f"{k}:max"] <= hi
                continue
            a = vals[k]
            with np.errstate(invalid="ignore"):
                if lo is not None:
                    feas &= a >= lo
                if hi is not None:
                    feas &= a <= hi
        return vals, feas, r

    def score(self, vals, feas):
        """The objective as a quantity to maximise; ``-inf`` where infeasible."""
        out, sense = self.spec.objective
        f = vals[out] if sense == "maximize" else -vals[out]
        ok = feas & np.isfinite(f)
        return np.where(ok, f, -np.inf)


def _grid_1d(m):
    return (np.arange(m) + 0.5) / m if m > 1 else np.array([0.5])


def _grid(problem: _Problem, total: int):
    """A grid of the continuous variables x every combination (about ``total`` candidates)."""
    d = len(problem.cont)
    nc = len(problem.combos)
    per = max(1, total // nc)
    m = max(2, int(round(per ** (1.0 / d)))) if d else 1
    axes = [np.linspace(0.0, 1.0, m) for _ in range(d)]
    U = np.stack(np.meshgrid(*axes, indexing="ij"), -1).reshape(-1, d) if d else np.zeros((1, 0))
    u = np.tile(U, (nc, 1))
    c = np.repeat(np.arange(nc), len(U))
    return u, c, (1.0 / (m - 1) if d and m > 1 else 0.0)


def _search(problem: _Problem, u0, c0, s0, step0, score=None, step_min=STEP_MIN):
    """Pattern search from the rows (``u0``, ``c0``, score ``s0``), all rows in each forward call.

    Each iteration tries, around each row's best point, the ``3^d - 1`` stencil and ``2 d + 8``
    seeded random directions at the current step; a row whose best does not improve halves its
    step.  ``score(vals, feas, rows)`` (default: the objective) scores candidates of the given
    rows (``-inf`` where infeasible).  Returns the improved ``(u, s)``.
    """
    d = u0.shape[1]
    if d == 0:
        return u0, s0
    score = score or (lambda vals, feas, rows: problem.score(vals, feas))
    rng = np.random.default_rng(1)
    sten = np.array([p for p in itertools.product((-1.0, 0.0, 1.0), repeat=d) if any(p)])
    nr = 2 * d + 8
    u, s = u0.copy(), s0.copy()
    step = np.full(len(u), step0)
    active = np.isfinite(s)
    for _ in range(_ITER_MAX):
        rows = np.flatnonzero(active & (step > step_min))
        if rows.size == 0:
            break
        rnd = rng.normal(size=(nr, d))
        rnd /= np.linalg.norm(rnd, axis=1, keepdims=True)
        dirs = np.vstack([sten, rnd])
        k = len(dirs)
        cand = (u[rows][:, None, :] + step[rows][:, None, None] * dirs[None]).reshape(-1, d)
        cand = np.clip(cand, 0.0, 1.0)
        cc = np.repeat(c0[rows], k)
        vals, feas, _ = problem.evaluate(problem.inputs(cand, cc))
        sc = score(vals, feas, np.repeat(rows, k)).reshape(len(rows), k)
        j = np.argmax(sc, axis=1)
        best = sc[np.arange(len(rows)), j]
        better = best > s[rows]
        ib = rows[better]
        u[ib] = cand.reshape(len(rows), k, d)[better, j[better]]
        s[ib] = best[better]
        step[rows[~better]] *= 0.5
    return u, s


class _Pinned:
    """The problem with continuous coordinate ``j`` held at ``value`` (unit box)."""

    def __init__(self, problem, j, value):
        self.problem, self.j, self.value = problem, j, value

    def inputs(self, u, combo_idx):
        u = np.array(u, dtype=float)
        u[:, self.j] = self.value
        return self.problem.inputs(u, combo_idx)

    def __getattr__(self, name):
        return getattr(self.problem, name)


def _polish_bounds(problem, u, c, s, step, near=0.02, n=512):
    """The optimum on a variable's bound when the search stopped short of it.

    A pattern search along a constraint ridge that ends on a bound stalls near it (the blocking-force
    example: 398.5 um of the 400 um bound).  For each continuous variable within ``near`` (unit box)
    of a bound: the best feasible of ``n`` seeded points with it held there, refined by the same
    search; kept where it scores higher.  Returns ``(u, s)``.
    """
    rng = np.random.default_rng(2)
    for j in range(u.size):
        for bound in (0.0, 1.0):
            if abs(u[j] - bound) > near or u[j] == bound:
                continue
            pin = _Pinned(problem, j, bound)
            cand = np.vstack([u, rng.uniform(size=(n, u.size))])
            cand[:, j] = bound
            cc = np.full(len(cand), c)
            vals, feas, _ = problem.evaluate(pin.inputs(cand, cc))
            sc = problem.score(vals, feas)
            if not np.isfinite(sc).any():
                continue
            top = np.argsort(-sc)[:2]
            top = top[np.isfinite(sc[top])]
            up, sp_ = _search(pin, cand[top], cc[top], sc[top], step)
            k = int(np.argmax(sp_))
            if sp_[k] > s:
                u, s = up[k].copy(), float(sp_[k])
                u[j] = bound
    return u, s


class _PinnedRows:
    """The problem with continuous coordinate ``j`` held at a level per row: the search's
    "combination index" of a row is its row number, mapped to the level and the real combination."""

    def __init__(self, problem, j, levels, combos):
        self.problem, self.j, self.levels, self.real = problem, j, np.asarray(levels), np.asarray(combos)

    def inputs(self, u, combo_idx):
        u = np.array(u, dtype=float)
        u[:, self.j] = self.levels[combo_idx]
        return self.problem.inputs(u, self.real[combo_idx])

    def __getattr__(self, name):
        return getattr(self.problem, name)


def _near_ties(problem, ub, cb, sb, grid, rtol, n=NEAR_TIE_LEVELS):
    """Designs whose objective is within ``rtol`` of the optimum's, along each continuous variable.

    For each continuous variable: at ``n`` levels across its range, the best objective with the
    variable held there and the others re-optimised (the same pattern search, from the optimum and
    from the best grid point of that level's column, whichever is better); the near-tie span is
    the range of levels whose best is within ``rtol`` of the optimum (a flat ridge shows as a wide
    span).  ``grid`` is the first grid's ``(u, c, score)``.

    Returns
    -------
    dict
        ``{"rtol", "levels", "variables": {name: {"low", "high", "objective_low", "objective_high",
        "profile": [[value, objective or None], ...]}}}`` (SI); the objective as reported (a
        magnitude; ``None`` where no feasible design has that level).
    """
    spec = problem.spec
    out_name, sense = spec.objective
    u_g, c_g, s_g = grid
    sgn = 1.0 if sense == "maximize" else -1.0
    thr = sb - rtol * abs(sb)
    res = {"rtol": rtol, "levels": n, "variables": {}}
    for j, name in enumerate(problem.cont):
        lv = np.linspace(0.0, 1.0, n)
        starts = np.tile(ub, (2 * n, 1))
        for i, t in enumerate(lv):  # the best grid point of the nearest column, as the second start
            col = np.abs(u_g[:, j] - t) <= 0.5 / (n - 1) + 1e-12
            col &= c_g == cb
            if col.any() and np.isfinite(s_g[col]).any():
                starts[n + i] = u_g[col][int(np.argmax(s_g[col]))]
        levels = np.concatenate([lv, lv])
        pin = _PinnedRows(problem, j, levels, np.full(2 * n, cb))
        rows = np.arange(2 * n)
        vals, feas, _ = problem.evaluate(pin.inputs(starts, rows))
        s0 = problem.score(vals, feas)
        uu, ss = _search(pin, starts, rows, s0, 0.05, step_min=1e-7)
        best = np.maximum(ss[:n], ss[n:])
        x = problem.inputs(np.column_stack([lv] * len(problem.cont)), np.full(n, cb))[name]
        tie = best >= thr
        prof = [[float(x[i]), float(sgn * best[i]) if np.isfinite(best[i]) else None] for i in range(n)]
        if tie.any():
            k = np.flatnonzero(tie)
            lo, hi = int(k[0]), int(k[-1])
            res["variables"][name] = {"low": float(x[lo]), "high": float(x[hi]),
                                      "objective_low": float(sgn * best[lo]), "objective_high": float(sgn * best[hi]),
                                      "profile": prof}
        else:
            res["variables"][name] = {"low": None, "high": None, "objective_low": None, "objective_high": None,
                                      "profile": prof}
    return res


@dataclass(repr=False)
class DesignResult(ResultMixin):
    """The answer of :func:`design` (``as_dict()`` is the ``--json`` object).

    Attributes
    ----------
    optimum : dict   {"inputs", "outputs", "checks"} of the chosen design (SI; outputs signed as
                     the forward model gives them, scene-file names)
    active_constraints : list of dict   {"name", "bound", "limit", "value"} at the optimum
    pareto : list of dict   {"inputs", "outputs"} along the front (empty without [pareto])
    near_ties : dict   designs within ``rtol`` of the optimum's objective along each continuous
                       variable (:func:`_near_ties`: ``{"rtol", "levels", "variables": {name: {"low",
                       "high", "objective_low", "objective_high", "profile"}}}``, SI)
    objective : dict, material : str, sources : list, evaluations : int, seconds : float
    """

    _result = ResultSpec("point", None, ())

    def _arrays(self):
        """Inputs and outputs along the Pareto front (the optimum alone without one)."""
        pts = self.pareto or [self.optimum]
        keys = [*pts[0]["inputs"], *pts[0]["outputs"]]
        vals = {k: [{**p["inputs"], **p["outputs"]}.get(k) for p in pts] for k in keys}
        return "point", None, {k: np.array([np.nan if x is None else x for x in v], float) for k, v in vals.items()}

    def _panels(self, arrays):
        outs = list(self.pareto[0]["outputs"] if self.pareto else self.optimum["outputs"])
        return (Panel(outs[0], tuple(outs[1:2])),) if len(outs) > 1 else (Panel("point", tuple(outs)),)

    optimum: dict
    active_constraints: list
    pareto: list
    objective: dict
    spec: DesignSpec
    evaluations: int
    seconds: float
    robust: dict | None = None
    notes: list = field(default_factory=list)
    near_ties: dict | None = None

    def as_dict(self) -> dict:
        m = self.spec.material
        d = {"optimum": self.optimum, "active_constraints": self.active_constraints, "pareto": self.pareto,
             "objective": self.objective, "model": self.spec.model, "fidelity": self.spec.fidelity,
             "material": m.name, "material_sources": list(citations(m)),
             "constraints": {k: {"min": lo, "max": hi, "unit": CONSTRAINABLE[k]}
                             for k, (lo, hi) in self.spec.constraints.items()},
             "evaluations": self.evaluations, "seconds": self.seconds, "notes": self.notes,
             "units": {**CONSTRAINABLE}, "thickness_is": "TOTAL 2e", "width_is": "TOTAL 2l"}
        if self.robust is not None:
            d["robust"] = self.robust
        if self.near_ties is not None:
            d["near_ties"] = self.near_ties
        if m.electrode.present:  # the composite beam (the bare membrane is the paper's)
            d["beam"] = beam_label(m.electrode)
        return d


def _point_report(problem: _Problem, x: dict) -> tuple[dict, dict, dict]:
    """Inputs, signed outputs and checks of one candidate (``x``: 1-element arrays)."""
    spec = problem.spec
    r = forward(*(x[k] for k in INPUTS), material=spec.material, model=spec.model, fidelity=spec.fidelity,
                tol=spec.tol).withhold()

    def num(a):
        v = float(np.asarray(a).reshape(-1)[0])
        return v if math.isfinite(v) else None

    w, F = num(r.w), num(r.F_block)
    outputs = {"tip_deflection": w, "blocking_force": F, "rotation": num(r.theta), "moment": num(r.M_A),
               "I": num(r.I), "work": (abs(w) * abs(F)) if w is not None and F is not None else None,
               "max_strain": num(r.max_strain), "footprint": float(x["length"][0] * x["width"][0]),
               "first_resonance": num(first_resonance(*(x[k] for k in INPUTS[:3]), spec.material))}
    so = _sensing(spec, *(x[k] for k in INPUTS[:3]), None)
    outputs["sensitivity"] = num(so["sensitivity"])
    outputs["harvested_power"] = None if bool(np.asarray(so["power_flag"]).reshape(-1)[0]) else num(so["harvested_power"])
    checks = {c: bool(np.asarray(getattr(r, c)).reshape(-1)[0]) for c in CHECKS}
    checks["valid"] = bool(np.asarray(r.valid).reshape(-1)[0])
    checks["fidelity_used"] = str(np.asarray(r.fidelity_used).reshape(-1)[0])
    checks["escalated"] = bool(np.asarray(r.escalated).reshape(-1)[0])
    return {k: float(x[k][0]) for k in INPUTS}, outputs, checks


def _violation(problem, vals):
    """The smallest total relative violation of the constraints among candidates (for the refusal)."""
    spec = problem.spec
    tot = np.zeros(len(vals["length"]))
    worst = {}
    for k, (lo, hi) in spec.constraints.items():
        a = vals[k]
        v = np.zeros_like(a)
        with np.errstate(invalid="ignore", divide="ignore"):
            if lo is not None:
                v = np.maximum(v, (lo - a) / max(lo, 1e-300))
            if hi is not None:
                v = np.maximum(v, (a - hi) / hi)
        v = np.where(np.isfinite(v), v, np.inf)
        tot += v
        worst[k] = v
    i = int(np.argmin(tot))
    parts = [f"{k} {vals[k][i]:.3g} {CONSTRAINABLE[k]} (min {lo}, max {hi})" for k, (lo, hi) in spec.constraints.items()
             if worst[k][i] > 0]
    return "; ".join(parts) if math.isfinite(tot[i]) else "no candidate has a valid result"


def _front(xs, ys, idx):
    """Indices (of ``idx``) of the non-dominated points, both maximised, x ascending."""
    order = idx[np.lexsort((-ys[idx], -xs[idx]))]  # x descending, then y descending
    best_y = -np.inf
    front = []
    for i in order:
        if ys[i] > best_y:
            front.append(i)
            best_y = ys[i]
    return np.array(front[::-1], dtype=int)


def _pareto(problem: _Problem, x_name: str, y_name: str, n_points: int) -> list:
    """``n_points`` of the front of (x, y), both maximised: levels of x evenly spread over the
    front of a seeded uniform sample, and at each level the largest y with ``x >= level``
    (epsilon-constraint), by the pattern search from the best sample point at that level."""
    rng = np.random.default_rng(2)
    nc, d = len(problem.combos), len(problem.cont)
    n_s = max(4096, PARETO_SAMPLE // 8)
    u = rng.uniform(size=(n_s, d))
    c = rng.integers(0, nc, n_s)
    vals, feas, _ = problem.evaluate(problem.inputs(u, c))
    xs, ys = vals[x_name], vals[y_name]
    idx = np.flatnonzero(feas & np.isfinite(xs) & np.isfinite(ys))
    if idx.size == 0:
        return []
    f = _front(xs, ys, idx)
    levels = np.linspace(xs[f[0]], xs[f[-1]], n_points)
    # start of each level: the front point with the largest y among those with x >= level
    start = f[np.searchsorted(xs[f], levels).clip(0, len(f) - 1)]
    u0, c0, s0 = u[start], c[start], ys[start]

    def score(v, ok, rows):
        good = ok & np.isfinite(v[y_name]) & (v[x_name] >= levels[rows])
        return np.where(good, v[y_name], -np.inf)

    uu, _ = _search(problem, u0, c0, s0.copy(), 0.05, score=score, step_min=1e-7)
    x_in = problem.inputs(uu, c0)
    v, ok, _ = problem.evaluate(x_in)
    xs2, ys2 = v[x_name], v[y_name]
    keep = _front(xs2, ys2, np.flatnonzero(ok & np.isfinite(xs2) & np.isfinite(ys2)))
    return [{"inputs": {k: float(x_in[k][i]) for k in INPUTS},
             "outputs": {x_name: float(xs2[i]), y_name: float(ys2[i])}} for i in keep]


def design(spec, *, pareto: bool = True) -> DesignResult:
    """Choose length, width, thickness and voltage within bounds to optimise an output.

    Parameters
    ----------
    spec : dict or str or path
        A design specification (module docstring) or the path of its TOML file.
    pareto : bool
        Compute the Pareto front when the spec has ``[pareto]``.

    Returns
    -------
    DesignResult
        ``as_dict()``: ``{"optimum": {"inputs", "outputs", "checks"}, "active_constraints",
        "pareto", "near_ties", ...}`` (SI; thickness and width TOTAL); ``near_ties``: along each
        continuous variable, the span over which the objective stays within ``[objective] near_tie``
        (default :data:`NEAR_TIE_RTOL`) of the optimum, the other variables re-optimised.

    Raises
    ------
    ValueError
        A bad spec (one line naming the key), or no candidate in the bounds meets the
        constraints with a valid result (one line with the closest candidate's violation).

    Examples
    --------
    >>> import ipmc_asym as ia
    >>> r = ia.design({"strip": {"width": "5mm", "voltage": "1V"},
    ...                "vary": {"length": ["1cm", "4cm"], "thickness": ["100um", "400um"]},
    ...                "objective": {"maximize": "blocking_force"},
    ...                "constraints": {"tip_deflection": {"min": "2mm"}}})
    >>> [a["name"] for a in r.active_constraints]  # the optimum lies on the thickness bound
    ['tip_deflection', 'thickness']
    """
    t0 = time.perf_counter()
    if isinstance(spec, DesignSpec):
        sp = spec
    elif isinstance(spec, dict):
        sp = parse_spec(spec, "design")
    else:
        path = os.fspath(spec)
        sp = parse_spec(load_spec(path), os.path.basename(path).removesuffix(".toml"))
    problem = _Problem(sp)
    S = sp.samples if sp.uncertain else 1
    u, c, step = _grid(problem, max(512, GRID_POINTS // S))
    vals, feas, _ = problem.evaluate(problem.inputs(u, c))
    s = problem.score(vals, feas)
    if not np.isfinite(s).any():
        raise ValueError("no design within the bounds meets the constraints with a valid result; closest: "
                         + _violation(problem, vals))
    # the best few distinct starts (best first), refined together
    order = np.argsort(-s)
    starts = []
    for i in order:
        if not np.isfinite(s[i]) or len(starts) >= _STARTS:
            break
        if all(c[i] != c[j] or np.max(np.abs(u[i] - u[j])) > 2 * step for j in starts):
            starts.append(i)
    starts = np.array(starts)
    uu, ss = _search(problem, u[starts], c[starts], s[starts], max(step, 1e-3))
    b = int(np.argmax(ss))
    ub, cb, sb = uu[b].copy(), c[starts][b], float(ss[b])
    ub, sb = _polish_bounds(problem, ub, cb, sb, max(step, 1e-3))
    xb = problem.inputs(ub[None, :], np.array([cb]))
    vb, fb, _ = problem.evaluate(xb)
    if not bool(fb[0]):  # the search only keeps feasible points; this re-check is the contract
        raise ValueError("design: the optimum failed its re-evaluation")
    inputs, outputs, checks = _point_report(problem, xb)
    active = []
    for k, (lo, hi) in sp.constraints.items():
        for bound, lim in (("min", lo), ("max", hi)):
            a = float(vb.get(f"{k}:{bound}", vb[k])[0])  # robust: the order statistic the constraint holds at
            if lim is not None and abs(a - lim) <= ACTIVE_RTOL * abs(lim):
                active.append({"name": k, "bound": bound, "limit": lim, "value": a})
    for k, (lo, hi, _log) in sp.ranges.items():
        a = float(xb[k][0])
        for bound, lim in (("min", lo), ("max", hi)):
            if abs(a - lim) <= ACTIVE_RTOL * abs(hi - lo):
                active.append({"name": k, "bound": bound, "limit": lim, "value": a, "kind": "variable bound"})
    # model-validity limits the optimum sits on (the checks withhold outputs beyond them)
    sl = sp.material.strain_limit
    if outputs["max_strain"] is not None and abs(outputs["max_strain"] - sl) <= ACTIVE_RTOL * sl:
        active.append({"name": "max_strain", "bound": "max", "limit": sl, "value": outputs["max_strain"],
                       "kind": "model validity: the material's strain limit (small-strain beam)"})
    if outputs["rotation"] is not None and abs(abs(outputs["rotation"]) - math.pi / 2) <= ACTIVE_RTOL * math.pi / 2:
        active.append({"name": "rotation", "bound": "max", "limit": math.pi / 2, "value": abs(outputs["rotation"]),
                       "kind": "model validity: free strip within a quarter turn (beam regime)"})
    out, sense = sp.objective
    robust = None
    if sp.uncertain:
        robust = {"probability": sp.probability, "samples": sp.samples, "confidence": sp.confidence,
                  "failures_allowed": sp.failures,
                  "uncertain": {k: {"dist": d, "params": list(p)} for k, (d, p) in sp.uncertain.items()},
                  "median_outputs": {k: float(vb[k][0]) for k in OUTPUTS},
                  "constraint_quantiles": {k: float(v[0]) for k, v in vb.items() if ":" in k},
                  "note": (f"each constraint met at all but {sp.failures} of {sp.samples} independent samples: probability "
                           f">= {sp.probability:g} with confidence {sp.confidence:g} (binomial tail, distribution-free); "
                           "objective = median; optimum.outputs are at the nominal material")}
    front = _pareto(problem, *sp.pareto[:2], sp.pareto[2]) if (pareto and sp.pareto) else []
    ties = _near_ties(problem, ub, cb, sb, (u, c, s), sp.near_tie) if sp.ranges else None
    tie_notes = []
    for name, t in (ties or {"variables": {}})["variables"].items():
        lo, hi, _log = sp.ranges[name]
        if t["low"] is not None and t["high"] - t["low"] > 0.05 * (hi - lo):  # a ridge, not the optimum's neighbourhood
            tie_notes.append(f"near-tie: {name} from {t['low']:.4g} to {t['high']:.4g} {CONSTRAINABLE[name]} keeps the "
                             f"objective within {sp.near_tie:.0%} of the optimum (the other variables re-optimised)")
    res = DesignResult(optimum={"inputs": inputs, "outputs": outputs, "checks": checks},
                       active_constraints=active, pareto=front,
                       objective={"name": out, "sense": sense, "value": float(vb[out][0]), "unit": OUTPUTS[out]},
                       spec=sp, evaluations=problem.evaluations, seconds=0.0, robust=robust,
                       notes=list(sp.notes) + tie_notes, near_ties=ties)
    res.seconds = time.perf_counter() - t0
    return res
