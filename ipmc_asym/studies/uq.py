"""Uncertainty and sensitivity: a scene's ``[uncertain]`` table pushed through the model.

``run_uq(scene, samples=10**6)`` draws the uncertain inputs (Saltelli/Sobol' design of
SALib: ``N (D + 2)`` model runs for first and total indices, ``N`` a power of two as SALib
recommends), evaluates every requested output vectorised (moment kernels + beam formulas),
and returns quantiles (2.5/50/97.5 %), mean and standard deviation of each output and Sobol'
first/total indices (SALib's estimators) with 95 % confidence intervals (batch means;
SALib's bootstrap is too slow and large at 10^6 runs).

Memory does not grow with ``N``: the run is streamed.  A chunk is a range of base points
(whole Saltelli groups of ``D + 2`` rows); it generates its own rows of the design (the
scrambled Sobol' engine fast-forwarded to the range: the same design as in one piece, for
the same seed), evaluates them, and returns partial statistics, merged in order as chunks
finish (:func:`ipmc_asym.parallel.executors.imap_chunks`, also on dask):

* mean and sd: count/mean/centred sum of squares merged by Chan et al.'s pairwise update
  (:class:`ipmc_asym.base.streamstats.Moments`);
* Sobol' indices and their batch-means intervals: per batch of base points, the sums the
  estimators are made of (:class:`_GroupSums`), merged the same way; equal to the in-memory
  :func:`_sobol_indices` to rounding (tests/studies/test_uq.py);
* quantiles: a deterministic mergeable compactor sketch
  (:class:`ipmc_asym.base.streamstats.QuantileSketch`, ``k = 2^15`` items per level) that
  counts its own rank error.  Each quantile is reported with ``q*_interval``, an interval
  guaranteed to hold the exact ``np.quantile`` of the same samples, and
  ``quantile_rank_error``, the bound on the rank error as a fraction of ``n`` (0, and the
  quantiles exactly ``np.quantile``, up to ``2^15`` samples; 6.8e-5 at 1.8e6 runs).  A
  second exact pass (re-evaluating every chunk to collect the samples inside the
  intervals) would double the model runs for a gain below the sampling error of the
  quantiles themselves;
* the counts (fidelity rungs, samples outside each check, samples used) add up.

The per-sample arrays of :class:`UQResult` (``samples``, ``outputs``, ``checks``,
``valid``: the NetCDF and the histograms) hold the first ``store_samples`` runs only (whole
groups from the start of the design, a net of the Sobol' sequence; default
:data:`STORE_SAMPLES`); the statistics use every run.  Measured (tracemalloc, nominal
scene, 5 outputs, leading): peak 39.8 MB at ``N = 2^15`` and 43.8 MB at ``2^18`` base
points (ipmc_asym_bench ``uq`` section).  ``--max-samples`` of the CLI is a time cap.

Scene additions (everything else as in :mod:`ipmc_asym.studies.scenes`; one point, no ``[sweep]``)::

    outputs = ["I", "moment", "tip_deflection", "rotation", "blocking_force"]

    [uncertain]                                    # values with units, like [strip]
    thickness = {dist = "normal", mean = "200um", sd = "10um"}
    length    = {dist = "uniform", low = "1.9cm", high = "2.1cm"}
    voltage   = {dist = "triangular", low = "0.9V", mode = "1V", high = "1.1V"}
    modulus   = {dist = "lognormal", median = "130MPa", sigma = 0.1}   # sigma of ln(E)
    c_moy     = {dist = "normal", mean = 3082, sd = 50}                 # mol/m^3

Uncertain names: ``length``, ``width`` (TOTAL 2l), ``thickness`` (TOTAL 2e), ``voltage``,
``modulus``, ``c_moy``.  A normal distribution must keep a positive quantity positive: its
mean must be >= 6 sd (the 1e-9 tail is then cut by nothing; otherwise refused).

Fidelity: each sample is escalated along the compiled rungs of the registry
(``leading -> corrected -> quadrature -> exact``) until its error estimate is below the
scene's ``tolerance`` (like scenes); a sample still outside is refused with one line (the
BVP at 10^6 samples is not an option).  The
blocking force uses the small-displacement ``3M/(2L)`` where its relative deviation
``(kappa L)^2/3360`` (times 1.05 to cover the next terms for ``|kappa L| <= 2``) is within
the tolerance, the large-displacement root otherwise; the tip deflection is always the arc.

Every sample goes through the forward model :func:`ipmc_asym.forward.model.forward` and its
checks (``forward.model.CHECKS``, per sample in :attr:`UQResult.checks`).  A sample outside a
model assumption (past a quarter turn, above the strain limit, beyond the validated voltage, not
slender) is counted (:attr:`UQResult.n_outside`) and left out of the quantiles, moments and
Sobol' indices unless ``keep_invalid`` (for the Sobol' indices a whole Saltelli group of
``D + 2`` rows is left out with any of its rows, so that the design stays paired).
``C_moy`` per sample changes ``A3`` per sample, which the shared sweep driver takes as a
scalar: ``forward`` given ``c_moy`` per point uses
:func:`ipmc_asym.integral.samples.moment_samples`, the same loop with ``A3`` an array (it
calls the same compiled point kernel).

Layer rule: stdlib + numpy + the compiled kernels at import; SciPy statistics, SALib
deferred.
"""

from __future__ import annotations

import math
import os
import time
import warnings
from dataclasses import dataclass, field

import numpy as np

from ipmc_asym.base.registry import model_names
from ipmc_asym.base.results import Panel, ResultMixin, ResultSpec
from ipmc_asym.base.settings import CHUNK_ROWS
from ipmc_asym.base.streamstats import SKETCH_K, Moments, QuantileSketch
from ipmc_asym.base.units import parse_length, parse_voltage
from ipmc_asym.forward.estimate import SPREAD_NOTE
from ipmc_asym.forward.model import CHECKS, SAMPLING_FIDELITIES, assumption_warnings, forward
from ipmc_asym.io.datasets import VARIABLES
from ipmc_asym.model.parameters import ALIASES, PARAMETERS, material_value, parse_value
from ipmc_asym.model.permittivity import get_model
from ipmc_asym.model.spread import spread_of
from ipmc_asym.parallel.executors import chunk_slices, imap_chunks
from ipmc_asym.studies.scene_schema import load_scene, parse_scene

__all__ = ["UNCERTAIN", "DISTRIBUTIONS", "OUTPUT_UNITS", "UQResult", "parse_uncertain", "run_uq",
           "evaluate_samples", "uq_chunk", "uq_stream_chunk", "QUANTILES", "STORE_SAMPLES", "UNCERTAIN_MATERIAL",
           "SPREAD_STATS", "model_spread"]

#: uncertain names -> (unit, long name), as the datasets label them
UNCERTAIN = {k: VARIABLES[k] for k in ("length", "width", "thickness", "voltage", "modulus", "c_moy")}
#: the uncertain names that are material parameters (model.parameters: their aliases, units and values)
UNCERTAIN_MATERIAL = tuple(k for k in UNCERTAIN if k in PARAMETERS)
DISTRIBUTIONS = {
    "normal": ("mean", "sd"),
    "lognormal": ("median", "sigma"),
    "uniform": ("low", "high"),
    "triangular": ("low", "mode", "high"),
}
#: outputs available to UQ -> (unit, long name)
OUTPUT_UNITS = {
    "I": ("1", "moment integral I (dimensionless)"),
    "moment": ("N m", "bending moment M_A"),
    "tip_deflection": ("m", "tip deflection w (large displacement)"),
    "rotation": ("rad", "free-end rotation theta"),
    "blocking_force": ("N", "blocking force F"),
}


# ---- scene ----------------------------------------------------------------------------------
def _quantity(name, key, v):

    where = f"uncertain.{name}.{key}"
    if isinstance(v, bool) or not isinstance(v, (int, float, str)):
        raise ValueError(f"{where} must be a number or a string with units; got {v!r}")
    if key == "sigma":  # lognormal: sd of the log, dimensionless
        if isinstance(v, str):
            raise ValueError(f"{where} is the sd of ln({name}), a plain number; got {v!r}")
        return float(v)
    if name in ("length", "width", "thickness"):
        return parse_length(where, v)
    if name == "voltage":
        return parse_voltage(where, v)
    if name == "c_moy" and isinstance(v, str):
        raise ValueError(f"{where}: c_moy is a plain number in mol/m^3; got {v!r}")
    return parse_value(name, v, where)


def parse_uncertain(table) -> dict:
    """``[uncertain]`` table -> ``{name: (dist, params tuple in SI)}``; one-line errors."""
    if not isinstance(table, dict) or not table:
        raise ValueError("[uncertain] must be a non-empty table of name = {dist = ..., ...}")
    out = {}
    for name, spec in table.items():
        name = ALIASES.get(name, name) if ALIASES.get(name) in UNCERTAIN else name  # E = modulus, ...
        if name not in UNCERTAIN:
            raise ValueError(f"[uncertain]: unknown parameter {name!r}; allowed: {', '.join(UNCERTAIN)}")
        if not isinstance(spec, dict) or "dist" not in spec:
            raise ValueError(f"uncertain.{name} must be a table with dist = {'|'.join(DISTRIBUTIONS)}")
        dist = spec["dist"]
        if dist not in DISTRIBUTIONS:
            raise ValueError(f"uncertain.{name}.dist must be one of {', '.join(DISTRIBUTIONS)}; got {dist!r}")
        keys = DISTRIBUTIONS[dist]
        extra = set(spec) - set(keys) - {"dist"}
        missing = [k for k in keys if k not in spec]
        if extra or missing:
            raise ValueError(f"uncertain.{name} ({dist}) takes exactly {', '.join(keys)}"
                             + (f"; missing {', '.join(missing)}" if missing else "")
                             + (f"; unknown {', '.join(sorted(extra))}" if extra else ""))
        vals = tuple(_quantity(name, k, spec[k]) for k in keys)
        for k, v in zip(keys, vals):  # a NaN passes every comparison below: refused by name here
            if not math.isfinite(v):
                raise ValueError(f"uncertain.{name}.{k} must be a finite number; got {spec[k]!r}")
        positive = name != "voltage"
        if dist == "normal":
            mu, sd = vals
            if not sd > 0:
                raise ValueError(f"uncertain.{name}.sd must be > 0; got {spec['sd']!r}")
            if positive and mu < 6 * sd:
                raise ValueError(f"uncertain.{name}: normal with mean < 6 sd gives non-positive values; "
                                 f"use lognormal or truncate (mean {mu:g}, sd {sd:g})")
        elif dist == "lognormal":
            med, s = vals
            if not med > 0 or not s > 0:
                raise ValueError(f"uncertain.{name}: lognormal needs median > 0 and sigma > 0; got {vals}")
        elif dist == "uniform":
            lo, hi = vals
            if not lo < hi or (positive and lo <= 0):
                raise ValueError(f"uncertain.{name}: uniform needs {'0 < ' if positive else ''}low < high; got {vals}")
        else:
            lo, mode, hi = vals
            if not (lo <= mode <= hi and lo < hi) or (positive and lo <= 0):
                raise ValueError(f"uncertain.{name}: triangular needs {'0 < ' if positive else ''}low <= mode <= high, "
                                 f"low < high; got {vals}")
        out[name] = (dist, vals)
    return out


def _transform(u, dist, vals):
    """Inverse CDF of ``dist`` at uniform(0, 1) ``u``."""
    from scipy import special  # deferred: heavy import (start-up)

    if dist == "normal":
        return vals[0] + vals[1] * math.sqrt(2.0) * special.erfinv(2.0 * u - 1.0)
    if dist == "lognormal":
        return vals[0] * np.exp(vals[1] * math.sqrt(2.0) * special.erfinv(2.0 * u - 1.0))
    if dist == "uniform":
        return vals[0] + (vals[1] - vals[0]) * u
    lo, mode, hi = vals
    c = (mode - lo) / (hi - lo)
    with np.errstate(invalid="ignore"):
        left = lo + np.sqrt(u * (hi - lo) * (mode - lo))
        right = hi - np.sqrt((1.0 - u) * (hi - lo) * (hi - mode))
    return np.where(u < c, left, right)


def central_value(dist, vals) -> float:
    """The nominal value of one uncertain input: the mean (normal), median (lognormal), midpoint
    (uniform) or mode (triangular), SI."""
    if dist == "normal" or dist == "lognormal":
        return float(vals[0])
    if dist == "uniform":
        return 0.5 * (vals[0] + vals[1])
    return float(vals[1])


def check_nominal(model, material, base, unc, tol, fidelity=None):
    """Refuse, before any sampling, a scene whose nominal point is outside the model.

    The nominal point is the scene's fixed inputs with each ``[uncertain]`` input at its
    :func:`central_value`; it goes through the same forward model as the samples.

    Raises
    ------
    ValueError
        One line naming the failed checks and the nominal inputs.
    """
    point = dict(base)
    for k, (dist, vals) in unc.items():
        point[k] = central_value(dist, vals)
    cols = {k: np.array([float(v)]) for k, v in point.items()}
    _, _, checks, warns = evaluate_samples(cols, (), model, material, tol, fidelity)
    failed = [c for c, ok in checks.items() if not bool(ok[0])]
    if failed:
        shown = ", ".join(f"{k} = {point[k]:.4g}" for k in unc)
        raise ValueError(f"uq: the nominal point ({shown}) is outside the model: failed check(s) {', '.join(failed)}"
                         + (f" ({warns[0]})" if warns else "") + "; move the distributions inside the model or pass "
                         "keep_invalid (--keep-invalid)")


# ---- evaluation ------------------------------------------------------------------------------
def evaluate_samples(cols: dict, outputs, model, material, tol, fidelity=None):
    """Outputs at sample columns (SI arrays of one length); returns (dict of arrays, fidelity
    counts, checks: dict check name -> bool array, warnings: list of str).

    The forward model :func:`ipmc_asym.forward.model.forward` with ``modulus`` and ``c_moy``
    per sample.  ``fidelity`` forces one rung (no escalation; samples outside its validity or
    above ``tol`` are refused); default escalates per sample along :data:`SAMPLING_FIDELITIES`.
    The blocking force is ``3M/(2L)`` (paper eq. 14) where ``1.05 (kappa L)^2/3360 <= tol`` and
    ``|kappa L| <= 2``, the large-displacement root otherwise; the tip deflection is the arc.
    """
    if fidelity and fidelity not in SAMPLING_FIDELITIES:
        raise ValueError(f"uq: fidelity {fidelity!r} is not available for sampling; use one of "
                         f"{', '.join(SAMPLING_FIDELITIES)}")
    ladder = [fidelity] if fidelity else list(SAMPLING_FIDELITIES)
    n = cols["thickness"].size
    with np.errstate(all="ignore"):
        r = forward(cols["length"], cols["width"], cols["thickness"], cols["voltage"], modulus=cols["modulus"],
                    c_moy=cols["c_moy"], material=material, model=model, fidelity=ladder[0],
                    tol=min(float(tol), 0.5), escalate=not fidelity)
    if not np.all(r.moment_valid):
        raise ValueError(f"uq: {r.moment_message}; narrow the distributions or loosen the tolerance")
    checks = {c: np.asarray(getattr(r, c), bool) for c in CHECKS}
    counts = {}
    left = n
    for fid in ladder:  # samples settled at each rung climbed
        if left == 0:
            break
        counts[fid] = int(np.count_nonzero(r.fidelity_used == fid))
        left -= counts[fid]
    out = {}
    if "I" in outputs:
        out["I"] = r.I
    if "moment" in outputs:
        out["moment"] = r.M_A
    if "rotation" in outputs:
        out["rotation"] = r.theta  # -M L/EI, paper eq. 12
    if "tip_deflection" in outputs:
        # the arc, -(kappa L^2/2) sinc^2(kappa L/2); NaN past a full turn (withheld, forward.model.WITHHOLD)
        out["tip_deflection"] = np.where(r.withheld_mask("w"), np.nan, r.w)
    if "blocking_force" in outputs:
        kL = r.theta
        big = ~((np.abs(kL) <= 2.0) & (1.05 * kL * kL / 3360.0 <= tol))
        F = np.where(big, r.F_block, r.F_block_small)
        if np.any(big) and not np.all(np.isfinite(F[big])):
            bad = int(np.count_nonzero(~np.isfinite(F[big])))
            raise ValueError(f"uq: large-displacement blocking force undefined for {bad} sample(s) "
                             f"(|kappa L| beyond the tracked branch); narrow the distributions")
        out["blocking_force"] = F
    return out, counts, checks, assumption_warnings(r)


def uq_chunk(task):
    """One chunk of samples -> outputs (module level: runs on workers)."""
    cols, outputs, model, material, tol, fidelity = task
    return evaluate_samples(cols, outputs, model, material, tol, fidelity)


# ---- driver ----------------------------------------------------------------------------------
@dataclass(repr=False)
class UQResult(ResultMixin):
    """Outcome of :func:`run_uq`.

    Attributes
    ----------
    summary : dict
        output -> ``{"unit", "mean", "sd", "q2.5", "q50", "q97.5", "n"}`` (SI), with each
        quantile's guaranteed interval ``"q2.5_interval"``, ... ``[low, high]`` (the exact
        ``np.quantile`` of the same samples lies in it; a single point while the sketch
        holds every value) and ``"quantile_rank_error"`` (the sketch's rank-error bound,
        a fraction of ``n``; 0 when exact).
    sobol : dict
        output -> parameter -> ``{"S1", "S1_conf", "ST", "ST_conf"}`` (conf: half-width of
        the 95 % interval, batch means, :func:`_sobol_indices`); ``None`` for an output
        with zero variance.
    inputs : dict   name -> (dist, params) in SI
    samples : dict  name -> array (n_stored,) of the inputs: the first ``n_stored`` runs
        (whole Saltelli groups, at most ``store_samples`` of :func:`run_uq`)
    outputs : dict  name -> array (n_stored,)
    n_samples, base_n : int
    fidelity : dict  rung -> number of samples settled there
    checks : dict  check name (``forward.model.CHECKS``) -> bool array (n_stored,)
    valid : ndarray of bool (n_stored,)   every check passed
    n_stored : int  runs kept per sample (``n_samples`` when ``store_samples`` allows)
    model_spread : dict or None
        With ``run_uq(..., spread=True)``: the same study run with each of the three
        permittivity models, and for each output and each of :data:`SPREAD_STATS` the range
        over them (:func:`model_spread`); None otherwise (and absent from :meth:`as_dict`).
    outside_by_check : dict  check name -> samples (of all ``n_samples``) failing it
    n_outside : int   samples outside a model assumption (of all ``n_samples``)
    keep_invalid : bool   the statistics include the samples outside (else they are left out)
    n_used : int   samples in the quantiles and moments
    n_sobol : int  Saltelli base points (groups of D + 2 rows) in the Sobol' indices
    warnings : list of str   one line per failed model assumption (with its count)
    """

    _result = ResultSpec("sample", None, ())

    def _arrays(self):
        """The stored runs: inputs and outputs (scene names) per sample, and the checks' verdict."""
        out = {k: np.asarray(v) for k, v in {**self.samples, **self.outputs}.items()}
        if self.valid is not None:
            out["valid"] = np.asarray(self.valid)
        return "sample", None, out

    def _panels(self, arrays):
        return tuple(Panel("sample", (o,), kind="hist") for o in self.outputs)

    summary: dict
    sobol: dict
    inputs: dict
    samples: dict = field(repr=False)
    outputs: dict = field(repr=False)
    n_samples: int = 0
    base_n: int = 0
    fidelity: dict = field(default_factory=dict)
    model: str = ""
    tolerance: float = 0.0
    seconds: float = 0.0
    scene: str = ""
    base: dict = field(default_factory=dict)
    material: object = None
    timings: dict = field(default_factory=dict)
    checks: dict = field(default_factory=dict, repr=False)
    valid: np.ndarray = field(default=None, repr=False)
    n_outside: int = 0
    keep_invalid: bool = False
    n_used: int = 0
    n_sobol: int = 0
    warnings: list = field(default_factory=list)
    seed: int = 0
    outside_by_check: dict = field(default_factory=dict)
    n_stored: int = 0
    model_spread: dict = None

    def as_dict(self) -> dict:
        out = {"scene": self.scene, "model": self.model, "tolerance": self.tolerance,
                "n_samples": self.n_samples, "base_n": self.base_n, "fidelity": self.fidelity,
                "n_outside_model": self.n_outside, "keep_invalid": self.keep_invalid, "n_used": self.n_used,
                "n_sobol_base_points": self.n_sobol, "seed": self.seed,
                "n_samples_stored": self.n_stored,
                "outside_by_check": {c: int(v) for c, v in self.outside_by_check.items()},
                "warnings": self.warnings,
                "inputs": {k: {"dist": d, "params": list(p), "unit": UNCERTAIN[k][0]}
                           for k, (d, p) in self.inputs.items()},
                "summary": self.summary, "sobol": self.sobol, "seconds": self.seconds, "timings": self.timings,
                "thickness_note": "thickness is the TOTAL thickness 2e"}
        if self.model_spread is not None:
            out["model_spread"] = self.model_spread
        return out


def _scene_parts(scene):

    if not isinstance(scene, dict):
        scene = load_scene(scene)
    scene = dict(scene)
    if "uncertain" not in scene:
        raise ValueError("uq: the scene has no [uncertain] table")
    unc = parse_uncertain(scene.pop("uncertain"))
    if "sweep" in scene or "voltages" in scene:
        raise ValueError("uq: a scene with [uncertain] describes one nominal point; remove [sweep]/voltages")
    for k in unc:
        if k in ("length", "width", "thickness") and k in scene.get("strip", {}):
            raise ValueError(f"uq: {k} given both in [strip] and [uncertain]")
    if "voltage" in unc and "voltage" not in scene:
        scene["voltage"] = 1.0  # placeholder for the parser; the samples replace it
    sc = parse_scene(scene)
    name, model, material, pts, outputs, tol = sc.name, sc.model, sc.material, sc.points, sc.outputs, sc.tolerance
    if not isinstance(model, str):
        raise ValueError("uq: model must be constant, linear or affine")
    for o in outputs:
        if o not in OUTPUT_UNITS:
            raise ValueError(f"uq: output {o!r} is not available for sampling; use {', '.join(OUTPUT_UNITS)}")
    base = {k: float(pts[k][0]) for k in ("length", "width", "thickness", "voltage")}
    for k in UNCERTAIN_MATERIAL:
        base[k] = material_value(material, k)
    return name, model, material, base, unc, outputs, tol


def _design_rows(D, N, seed, g0, g1):
    """Rows of the Saltelli design of base points ``g0 .. g1-1`` (``(g1-g0)(D+2)`` x ``D``).

    Rows per base point: ``A, AB_1 .. AB_D, B`` (``AB_j`` = ``A`` with column ``j`` from
    ``B``), exactly what ``SALib.sample.sobol.sample(..., calc_second_order=False)`` lays
    out and ``SALib.analyze.sobol.separate_output_values`` reads; built with numpy from a
    scrambled Sobol' sequence of dimension ``2D`` (``scipy.stats.qmc``) because SALib's
    sampler loops in Python (4 s at 10^6 rows).  The engine is fast-forwarded to ``g0``, so
    a range is the same rows as in the whole design of ``N`` base points (the scrambling is
    drawn from ``seed`` alone).  Values kept strictly inside (0, 1) with the margin
    ``0.25/N`` of the whole design.
    """
    from scipy.stats import qmc  # deferred: heavy import (start-up)

    eng = qmc.Sobol(d=2 * D, scramble=True, seed=seed)
    if g0:
        eng.fast_forward(int(g0))
    with warnings.catch_warnings():
        # the balance warning is about one call; the whole design is N = 2^m points
        warnings.simplefilter("ignore", UserWarning)
        base = eng.random(int(g1 - g0))
    A, B = base[:, :D], base[:, D:]
    n = base.shape[0]
    U = np.empty((n, D + 2, D))
    U[:, 0] = A
    U[:, D + 1] = B
    for j in range(D):
        U[:, j + 1] = A
        U[:, j + 1, j] = B[:, j]
    U = U.reshape(n * (D + 2), D)
    eps = 0.25 / N
    return np.clip(U, eps, 1.0 - eps)


def _saltelli(D, N, seed):
    """The whole Saltelli design of ``N`` base points (``N (D+2)`` x ``D``), :func:`_design_rows`."""
    return _design_rows(D, N, seed, 0, N)


#: rough cost of one sample (moment + beam) by fidelity, s: sizes scheduler chunks (>= 100 ms);
#: None = per-sample escalation (mostly leading/corrected)
_SECONDS_PER_SAMPLE = {"leading": 2e-7, "corrected": 2.5e-7, "quadrature": 2e-6, "exact": 2e-5, None: 5e-7}


#: batches of the batch-means confidence interval of the Sobol' indices
SOBOL_BATCHES = 32
#: model runs kept per sample in UQResult.samples/outputs/checks/valid (and the NetCDF): the
#: first whole Saltelli groups of the design; the statistics use every run
STORE_SAMPLES = 2**17
#: probability levels of the reported quantiles (keys q2.5, q50, q97.5)
QUANTILES = {"q2.5": 0.025, "q50": 0.5, "q97.5": 0.975}


def _n_batches(base_n, batches=SOBOL_BATCHES):
    """Batches of the batch-means interval for ``base_n`` base points (a power of two)."""
    return batches if base_n >= 4 * batches else max(2, base_n // 4)


def _sobol_indices(y, names, N, batches=SOBOL_BATCHES, groups=None, base_n=None):
    """First/total indices (SALib's Saltelli 2010 / Jansen estimators) and 95 % intervals.

    SALib's own ``sobol.analyze`` bootstraps with an ``N x 100`` index matrix per output
    (minutes and ~200 MB at 10^6 runs); the point estimates here are SALib's estimator
    functions on all ``N`` groups, and the interval is by batch means: the groups split into
    ``K`` batches of contiguous base points of the design (``groups``: the design index of
    each of the ``N`` groups, default ``0 .. N-1``, of ``base_n`` in all, default ``N``),
    the estimator applied to each non-empty batch, half-width ``t_{0.975, K-1} sd / sqrt(K)``
    -- the same estimator's sampling spread, O(N D).  In-memory form; :func:`run_uq`
    accumulates the same sums chunk by chunk (:class:`_SobolSums`).
    """
    from SALib.analyze.sobol import separate_output_values  # deferred: heavy import (start-up)

    D = len(names)
    y = np.asarray(y, float)
    # centred and scaled as SALib's analyze does: the Saltelli first-order estimator is not
    # shift invariant in its variance (an output with a large mean would swamp it)
    y = (y - y.mean()) / y.std()
    A, B, AB, _ = separate_output_values(y, D, N, False)
    base_n = N if base_n is None else int(base_n)
    g = np.arange(N) if groups is None else np.asarray(groups)
    K = _n_batches(base_n, batches)
    # contiguous blocks of a Sobol' sequence are nets (representative); strided subsets are not
    label = g // (base_n // K)

    # SALib's first_order / total_order (Saltelli 2010 CPC; Jansen), written out so that the
    # variance of [A, B] is computed once for all parameters (the functions recompute it per
    # call); tests/studies/test_uq.py checks equality with SALib's functions.
    def est(a, b, ab):  # a, b: (n,); ab: (n, D) -> S1, ST of shape (D,)
        v = np.var(np.concatenate([a, b]))
        s1 = np.mean(b[:, None] * (ab - a[:, None]), axis=0) / v
        st = 0.5 * np.mean((a[:, None] - ab) ** 2, axis=0) / v
        return s1, st

    with np.errstate(all="ignore"):
        s1, st = est(A, B, AB)
        parts = [est(A[label == b], B[label == b], AB[label == b]) for b in range(K) if np.any(label == b)]
    return _indices_dict(names, s1, st, np.array([p[0] for p in parts]), np.array([p[1] for p in parts]))


def _indices_dict(names, s1, st, s1b, stb):
    """Point estimates and batch-means half-widths -> ``{name: {S1, S1_conf, ST, ST_conf}}``."""
    from scipy import stats  # deferred: heavy import (start-up)

    K = s1b.shape[0]
    if K >= 2:
        tq = float(stats.t.ppf(0.975, K - 1))
        h1 = tq * np.std(s1b, axis=0, ddof=1) / math.sqrt(K)
        ht = tq * np.std(stb, axis=0, ddof=1) / math.sqrt(K)
    else:
        h1 = ht = np.full(len(names), math.nan)
    return {k: {"S1": float(s1[j]), "S1_conf": float(h1[j]), "ST": float(st[j]), "ST_conf": float(ht[j])}
            for j, k in enumerate(names)}


class _GroupSums:
    """Mergeable sums of the Saltelli estimators over a set of groups (rows ``A, AB_1..AB_D, B``).

    With ``d_j = AB_j - A``: group count ``n``; mean of every row ``m_all``; mean and centred
    second moment of ``[A, B]`` (``m_ab``, ``M2_ab``); means ``m_b``, ``m_d``; co-moment
    ``c_bd = sum (B - m_b)(d_j - m_d_j)``; ``s_d2 = sum d_j^2``.  Merged by Chan et al.'s
    pairwise update, so any split into chunks gives the in-memory sums to rounding.
    """

    __slots__ = ("n", "m_all", "ab", "m_b", "m_d", "c_bd", "s_d2")

    @classmethod
    def of(cls, Y):
        """Sums of the groups ``Y`` (n, D+2)."""
        s = cls()
        D = Y.shape[1] - 2
        A, B = Y[:, 0], Y[:, D + 1]
        d = Y[:, 1:D + 1] - A[:, None]
        s.n = Y.shape[0]
        s.m_all = float(Y.mean())
        s.ab = Moments.of(np.concatenate([A, B]))
        s.m_b = float(B.mean())
        s.m_d = d.mean(axis=0)
        s.c_bd = ((B - s.m_b)[:, None] * (d - s.m_d)).sum(axis=0)
        s.s_d2 = (d * d).sum(axis=0)
        return s

    def copy(self):
        c = _GroupSums()
        c.n, c.m_all, c.m_b, c.m_d, c.c_bd, c.s_d2 = self.n, self.m_all, self.m_b, self.m_d, self.c_bd, self.s_d2
        c.ab = Moments(self.ab.n, self.ab.mean, self.ab.m2)
        return c

    def merge(self, o):
        n = self.n + o.n
        f = o.n / n
        db, dd = o.m_b - self.m_b, o.m_d - self.m_d
        self.c_bd = self.c_bd + o.c_bd + db * dd * (self.n * o.n / n)
        self.m_all = self.m_all + (o.m_all - self.m_all) * f
        self.ab.merge(o.ab)
        self.m_b = self.m_b + db * f
        self.m_d = self.m_d + dd * f
        self.s_d2 = self.s_d2 + o.s_d2
        self.n = n
        return self

    def indices(self, mu):
        """S1, ST of these groups with the outputs centred on ``mu`` (the mean of every group's
        rows, as :func:`_sobol_indices` centres; the scale cancels in the ratios)."""
        v = self.ab.m2 / self.ab.n  # np.var of [A, B]
        s1 = (self.c_bd + self.n * (self.m_b - mu) * self.m_d) / self.n / v
        st = 0.5 * self.s_d2 / self.n / v
        return s1, st


class _SobolSums:
    """Per-batch :class:`_GroupSums` of one output, and the range of its values (a constant
    output has no indices)."""

    __slots__ = ("batches", "min", "max")

    def __init__(self, K):
        self.batches = [None] * K
        self.min, self.max = math.inf, -math.inf

    def add(self, Y, label):
        """Groups ``Y`` (n, D+2) in batches ``label`` (n,)."""
        if Y.shape[0] == 0:
            return self
        self.min = min(self.min, float(Y.min()))
        self.max = max(self.max, float(Y.max()))
        for b in np.unique(label):
            self._put(int(b), _GroupSums.of(Y[label == b]))
        return self

    def _put(self, b, s):
        self.batches[b] = s if self.batches[b] is None else self.batches[b].merge(s)

    def merge(self, o):
        self.min, self.max = min(self.min, o.min), max(self.max, o.max)
        for b, s in enumerate(o.batches):
            if s is not None:
                self._put(b, s)
        return self

    @property
    def n(self):
        return sum(s.n for s in self.batches if s is not None)

    def result(self, names):
        parts = [s for s in self.batches if s is not None]
        if self.n < 2 or not self.max - self.min > 0:
            return None
        tot = parts[0].copy()
        for s in parts[1:]:
            tot.merge(s)
        with np.errstate(all="ignore"):
            s1, st = tot.indices(tot.m_all)
            per = [s.indices(tot.m_all) for s in parts]
        return _indices_dict(names, s1, st, np.array([p[0] for p in per]), np.array([p[1] for p in per]))


@dataclass
class _Spec:
    """What every chunk needs (small: sent to the workers with each range of groups)."""

    names: list
    unc: dict
    base: dict
    base_n: int
    seed: int
    outputs: tuple
    model: str
    material: object
    tol: float
    fidelity: str | None
    keep_invalid: bool
    store_groups: int
    sketch_k: int


def _columns(spec, g0, g1):
    """Sampled input columns (SI) of the design's base points ``g0 .. g1-1``."""
    D = len(spec.names)
    U = _design_rows(D, spec.base_n, spec.seed, g0, g1)
    n = U.shape[0]
    cols = {k: _transform(U[:, j], *spec.unc[k]) for j, k in enumerate(spec.names)}
    for k, v in spec.base.items():
        if k not in cols:
            cols[k] = np.full(n, v)
    for k in ("length", "width", "thickness", "modulus", "c_moy"):
        bad = int(np.count_nonzero(cols[k] <= 0))
        if bad:
            raise ValueError(f"uq: sampled {k} <= 0 ({bad} samples among base points {g0}..{g1 - 1}); "
                             "narrow its distribution")
    return cols


def uq_stream_chunk(task):
    """Base points ``g0`` to ``g1 - 1`` of the design -> their partial statistics (module level: runs on
    workers); the design rows are generated here, so a task is a few numbers."""
    spec, g0, g1 = task
    t0 = time.perf_counter()
    D = len(spec.names)
    cols = _columns(spec, g0, g1)
    t1 = time.perf_counter()
    outs, counts, checks, warns = evaluate_samples(cols, spec.outputs, spec.model, spec.material, spec.tol,
                                                   spec.fidelity)
    t2 = time.perf_counter()
    n = cols["thickness"].size
    valid = np.ones(n, bool)
    for v in checks.values():
        valid &= v
    use = np.ones(n, bool) if spec.keep_invalid else valid
    groups_use = use.reshape(-1, D + 2).all(axis=1)
    K = _n_batches(spec.base_n)
    label = np.arange(g0, g1) // (spec.base_n // K)
    part = {"counts": counts, "warnings": warns, "n": n, "n_outside": int(np.count_nonzero(~valid)),
            "outside_by_check": {c: int(np.count_nonzero(~v)) for c, v in checks.items()},
            "n_used": int(np.count_nonzero(use)), "n_sobol": int(np.count_nonzero(groups_use)),
            "moments": {}, "sketch": {}, "sobol": {}, "stored": None}
    for o in spec.outputs:
        y = outs[o]
        fin = np.isfinite(y)
        yu = y[use & fin]
        part["moments"][o] = Moments.of(yu)
        part["sketch"][o] = QuantileSketch(spec.sketch_k).add(yu)
        Yg = y.reshape(-1, D + 2)
        ok = groups_use & fin.reshape(-1, D + 2).all(axis=1)
        part["sobol"][o] = _SobolSums(K).add(Yg[ok], label[ok])
    if g0 < spec.store_groups:
        r = (min(g1, spec.store_groups) - g0) * (D + 2)
        # copies: a view would keep the whole chunk's arrays alive
        part["stored"] = ({k: cols[k][:r].copy() for k in spec.names}, {o: outs[o][:r].copy() for o in spec.outputs},
                          {c: checks[c][:r].copy() for c in CHECKS}, valid[:r].copy())
    part["timings"] = {"sampling": t1 - t0, "evaluation": t2 - t1, "analysis": time.perf_counter() - t2}
    return part


#: the statistics of each output whose range over the permittivity models ``spread=True`` reports
SPREAD_STATS = ("mean", "sd", "q2.5", "q50", "q97.5")


def model_spread(results: dict, refused: dict | None = None) -> dict:
    """The model-form spread of a study: ``results`` (model name -> :class:`UQResult` of the same
    scene, seed and samples) -> ``{"over", "quantities": {output: {stat: spread_of(...)}},
    "refused": {model: reason}, "note"}``; ``spread_of`` (forward.estimate) gives ``min``,
    ``max``, ``ratio``, ``values`` per model (None for a model that refused the scene)."""
    refused = dict(refused or {})
    first = next(iter(results.values()))
    labels = list(results) + [m for m in refused if m not in results]
    q = {}
    for o, s0 in first.summary.items():
        q[o] = {"unit": s0["unit"]}
        for st in SPREAD_STATS:
            q[o][st] = spread_of({m: (results[m].summary[o][st] if m in results else None) for m in labels})
    return {"over": "permittivity model: " + ", ".join(labels), "quantities": q, "refused": refused,
            "note": SPREAD_NOTE}


def run_uq(scene, samples: int = 10**6, *, seed: int = 0, fidelity: str | None = None, scheduler=None,
           chunk_rows: int | None = None, keep_invalid: bool = False, store_samples: int = STORE_SAMPLES,
           sketch_k: int = SKETCH_K, spread: bool = False, _model: str | None = None) -> UQResult:
    """Quantiles, moments and Sobol' indices of a scene's outputs under its ``[uncertain]`` inputs.

    Streams: the design is generated, evaluated and reduced chunk by chunk (whole Saltelli
    groups), so memory does not grow with ``samples`` (module docstring).

    Parameters
    ----------
    scene : path or dict
        A scene (see module docstring) with an ``[uncertain]`` table.
    samples : int
        Model runs wanted; ``N (D+2)`` are run with ``N`` the power of two at or above
        ``samples/(D+2)`` (SALib's Sobol' design for first and total indices).
    seed : int
        Seed of the scrambled Sobol' sequence (reproducible).
    fidelity : str, optional
        Force one rung (e.g. ``"leading"``); default: per-sample escalation by tolerance.
    scheduler : None, "local", "tcp://HOST:PORT" or Client
        Where the chunks run (:func:`ipmc_asym.parallel.executors.imap_chunks`); their partial
        statistics are merged in order as they arrive.
    chunk_rows : int, optional
        Samples per chunk (rounded down to whole groups of ``D + 2``, at least one group).
        Default: ``settings.CHUNK_ROWS`` in this process (bounds the memory of the
        temporaries); on a scheduler, chunks of >= 100 ms of work (at most 4 per worker, at
        most 2^20 rows) by :func:`ipmc_asym.parallel.executors.chunk_slices`.  The same
        ``chunk_rows`` gives the same result on every scheduler.
    keep_invalid : bool
        Keep the samples outside a model assumption in the statistics (default: left out,
        counted in ``n_outside``; the per-sample checks are in ``checks`` either way).
    store_samples : int
        Runs kept per sample in ``samples``, ``outputs``, ``checks``, ``valid`` (the first
        whole groups of the design; >= 0); the statistics use every run.
    sketch_k : int
        Items per level of the quantile sketch (:class:`ipmc_asym.base.streamstats.QuantileSketch`).
    spread : bool
        Also run the study (same design and seed) with the other two permittivity models and
        report the range of each output's statistics over the three
        (:attr:`UQResult.model_spread`): the model-form spread beside the sampling error.
        Three times the work.

    Returns
    -------
    UQResult
        ``timings``: seconds of sampling, evaluation and analysis summed over the chunks
        (on a scheduler, worker time; the merges count as analysis) and ``wall``.

    Examples
    --------
    >>> scene = {"name": "demo", "model": "constant", "voltage": "1V", "outputs": ["I"],
    ...          "uncertain": {"thickness": {"dist": "normal", "mean": "200um", "sd": "8um"}}}
    >>> res = run_uq(scene, 64, fidelity="leading")
    >>> res.n_samples, sorted(res.summary)
    (96, ['I'])
    """
    t0 = time.perf_counter()
    if isinstance(samples, bool) or not isinstance(samples, (int, np.integer)) or samples < 1:
        raise ValueError(f"--samples must be an integer >= 1; got {samples!r}")
    if isinstance(store_samples, bool) or not isinstance(store_samples, (int, np.integer)) or store_samples < 0:
        raise ValueError(f"store_samples must be an integer >= 0; got {store_samples!r}")
    if chunk_rows is not None and (isinstance(chunk_rows, bool) or not isinstance(chunk_rows, (int, np.integer))
                                   or chunk_rows < 1):
        raise ValueError(f"chunk_rows must be an integer >= 1; got {chunk_rows!r}")
    if isinstance(sketch_k, bool) or not isinstance(sketch_k, (int, np.integer)) or sketch_k < 2:
        raise ValueError(f"sketch_k must be an integer >= 2; got {sketch_k!r}")
    name, model, material, base, unc, outputs, tol = _scene_parts(scene)
    if _model is not None:  # one run of a spread: the scene with another permittivity model
        model = _model
    if spread:
        kw = dict(samples=samples, seed=seed, fidelity=fidelity, scheduler=scheduler, chunk_rows=chunk_rows,
                  keep_invalid=keep_invalid, store_samples=store_samples, sketch_k=sketch_k)
        own = run_uq(scene, **kw, _model=model)
        runs, refused = {}, {}
        for m in model_names():
            if m == own.model:
                runs[m] = own
                continue
            try:
                runs[m] = run_uq(scene, **kw, _model=m)
            except ValueError as e:  # e.g. the nominal point past a quarter turn for this law
                refused[m] = str(e)
        own.model_spread = model_spread(runs, refused)
        return own
    if not keep_invalid:  # minutes of sampling would end in a refusal: say so first
        check_nominal(model, material, base, unc, tol, fidelity)
    names = list(unc)
    D = len(names)
    base_n = 1 << max(1, math.ceil(math.log2(max(samples / (D + 2), 2))))
    n = base_n * (D + 2)
    spec = _Spec(names=names, unc=unc, base=base, base_n=base_n, seed=int(seed), outputs=tuple(outputs),
                 model=model, material=material, tol=tol, fidelity=fidelity, keep_invalid=bool(keep_invalid),
                 store_groups=min(base_n, int(store_samples) // (D + 2)), sketch_k=int(sketch_k))
    if chunk_rows is not None:
        rows = int(chunk_rows)
    elif scheduler is None:
        rows = CHUNK_ROWS
    else:
        sl = chunk_slices(n, _SECONDS_PER_SAMPLE.get(fidelity, 1e-6), os.cpu_count() or 1, max_items=2**20)
        rows = sl[0].stop - sl[0].start
    per = max(1, rows // (D + 2))
    tasks = ((spec, g, min(g + per, base_n)) for g in range(0, base_n, per))

    K = _n_batches(base_n)
    counts, warns, outside = {}, [], dict.fromkeys(CHECKS, 0)
    n_out = n_used = n_sobol = 0
    moments = {o: Moments() for o in outputs}
    sketches = {o: QuantileSketch(spec.sketch_k) for o in outputs}
    sobols = {o: _SobolSums(K) for o in outputs}
    stored = []
    timings = {"sampling": 0.0, "evaluation": 0.0, "analysis": 0.0}
    for p in imap_chunks(uq_stream_chunk, tasks, scheduler=scheduler):
        for k, c in p["counts"].items():
            counts[k] = counts.get(k, 0) + c
        for w in p["warnings"]:  # one line per failed assumption (the first chunk's wording)
            head = w.split(" [")[0]
            if not any(x.startswith(head[:40]) for x in warns):
                warns.append(head)
        for c, v in p["outside_by_check"].items():
            outside[c] += v
        n_out += p["n_outside"]
        n_used += p["n_used"]
        n_sobol += p["n_sobol"]
        for o in outputs:
            moments[o].merge(p["moments"][o])
            sketches[o].merge(p["sketch"][o])
            sobols[o].merge(p["sobol"][o])
        if p["stored"] is not None:
            stored.append(p["stored"])
        for k, v in p["timings"].items():
            timings[k] += v
    t_eval1 = time.perf_counter()

    summary, sob = {}, {}
    for o in outputs:
        m = moments[o]
        if m.n < 2:
            raise ValueError(f"uq: {m.n} sample(s) of {o} inside the model ({n_out} of {n} outside a model "
                             "assumption); narrow the distributions or pass keep_invalid (--keep-invalid)")
        q, lo, hi = sketches[o].quantiles(list(QUANTILES.values()))
        s = {"unit": OUTPUT_UNITS[o][0], "mean": float(m.mean), "sd": float(math.sqrt(m.var(ddof=1)))}
        s.update({key: float(q[i]) for i, key in enumerate(QUANTILES)})
        s["n"] = int(m.n)
        # the exact sample quantile (np.quantile of the same samples) lies in this interval
        s.update({key + "_interval": [float(lo[i]), float(hi[i])] for i, key in enumerate(QUANTILES)})
        s["quantile_rank_error"] = float(sketches[o].rank_error)
        summary[o] = s
        sob[o] = sobols[o].result(names)

    def cat(i, k):
        return np.concatenate([s[i][k] for s in stored]) if stored else np.empty(0, bool if i == 2 else float)

    samples_kept = {k: cat(0, k) for k in names}
    outs_kept = {o: cat(1, o) for o in outputs}
    checks_kept = {c: cat(2, c) for c in CHECKS}
    valid_kept = np.concatenate([s[3] for s in stored]) if stored else np.empty(0, bool)
    timings["analysis"] += time.perf_counter() - t_eval1
    timings["wall"] = time.perf_counter() - t0
    return UQResult(summary=summary, sobol=sob, inputs=unc, samples=samples_kept, outputs=outs_kept,
                    n_samples=n, base_n=base_n, fidelity=counts, model=get_model(model).name, tolerance=tol,
                    seconds=time.perf_counter() - t0, scene=name, base=base, material=material,
                    timings=timings, checks=checks_kept, valid=valid_kept, n_outside=n_out,
                    keep_invalid=bool(keep_invalid), n_used=n_used, n_sobol=n_sobol, warnings=warns, seed=int(seed),
                    outside_by_check=outside, n_stored=int(valid_kept.size))
