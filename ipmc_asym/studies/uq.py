"""Uncertainty and sensitivity: a scene's ``[uncertain]`` table pushed through the model.

``run_uq(scene, samples=10**6)`` draws the uncertain inputs (Saltelli/Sobol' design of
SALib: ``N (D + 2)`` model runs for first and total indices, ``N`` a power of two as SALib
recommends), evaluates every requested output vectorised (moment kernels + beam formulas,
in chunks of bounded memory), and returns quantiles (2.5/50/97.5 %), mean and standard
deviation of each output and Sobol' first/total indices (SALib's estimators) with 95 %
confidence intervals (batch means; SALib's bootstrap is too slow and large at 10^6 runs).

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
from dataclasses import dataclass, field

import numpy as np

from ipmc_asym.base.settings import CHUNK_ROWS
from ipmc_asym.base.units import parse_length, parse_pressure, parse_voltage
from ipmc_asym.forward.model import CHECKS, SAMPLING_FIDELITIES, assumption_warnings, forward
from ipmc_asym.io.datasets import VARIABLES
from ipmc_asym.model.permittivity import get_model
from ipmc_asym.parallel.executors import chunk_slices, run_chunks
from ipmc_asym.studies.scene_schema import load_scene, parse_scene

__all__ = ["UNCERTAIN", "DISTRIBUTIONS", "OUTPUT_UNITS", "UQResult", "parse_uncertain", "run_uq",
           "evaluate_samples", "uq_chunk"]

#: uncertain names -> (unit, long name), as the datasets label them
UNCERTAIN = {k: VARIABLES[k] for k in ("length", "width", "thickness", "voltage", "modulus", "c_moy")}
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
    if name == "modulus":
        return parse_pressure(where, v)
    if isinstance(v, str):
        raise ValueError(f"{where}: c_moy is a plain number in mol/m^3; got {v!r}")
    return float(v)


def parse_uncertain(table) -> dict:
    """``[uncertain]`` table -> ``{name: (dist, params tuple in SI)}``; one-line errors."""
    if not isinstance(table, dict) or not table:
        raise ValueError("[uncertain] must be a non-empty table of name = {dist = ..., ...}")
    out = {}
    for name, spec in table.items():
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
@dataclass
class UQResult:
    """Outcome of :func:`run_uq`.

    Attributes
    ----------
    summary : dict
        output -> ``{"unit", "mean", "sd", "q2.5", "q50", "q97.5"}`` (SI).
    sobol : dict
        output -> parameter -> ``{"S1", "S1_conf", "ST", "ST_conf"}`` (conf: half-width of
        the 95 % interval, batch means, :func:`_sobol_indices`); ``None`` for an output
        with zero variance.
    inputs : dict   name -> (dist, params) in SI
    samples : dict  name -> array (n_samples,) of the inputs
    outputs : dict  name -> array (n_samples,)
    n_samples, base_n : int
    fidelity : dict  rung -> number of samples settled there
    checks : dict  check name (``forward.model.CHECKS``) -> bool array (n_samples,)
    valid : ndarray of bool (n_samples,)   every check passed
    n_outside : int   samples outside a model assumption (``~valid``)
    keep_invalid : bool   the statistics include the samples outside (else they are left out)
    n_used : int   samples in the quantiles and moments
    n_sobol : int  Saltelli base points (groups of D + 2 rows) in the Sobol' indices
    warnings : list of str   one line per failed model assumption (with its count)
    """

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

    def as_dict(self) -> dict:
        return {"scene": self.scene, "model": self.model, "tolerance": self.tolerance,
                "n_samples": self.n_samples, "base_n": self.base_n, "fidelity": self.fidelity,
                "n_outside_model": self.n_outside, "keep_invalid": self.keep_invalid, "n_used": self.n_used,
                "n_sobol_base_points": self.n_sobol, "seed": self.seed,
                "outside_by_check": {c: int(np.count_nonzero(~v)) for c, v in self.checks.items()},
                "warnings": self.warnings,
                "inputs": {k: {"dist": d, "params": list(p), "unit": UNCERTAIN[k][0]}
                           for k, (d, p) in self.inputs.items()},
                "summary": self.summary, "sobol": self.sobol, "seconds": self.seconds, "timings": self.timings,
                "thickness_note": "thickness is the TOTAL thickness 2e"}


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
    base["modulus"] = material.E
    base["c_moy"] = material.C_moy
    return name, model, material, base, unc, outputs, tol


def _saltelli(D, N, seed):
    """Saltelli design for first/total indices in SALib's row layout (``N (D+2)`` x ``D``).

    Rows per base point: ``A, AB_1 .. AB_D, B`` (``AB_j`` = ``A`` with column ``j`` from
    ``B``), exactly what ``SALib.sample.sobol.sample(..., calc_second_order=False)`` lays
    out and ``SALib.analyze.sobol.separate_output_values`` reads; built with numpy from a
    scrambled Sobol' sequence of dimension ``2D`` (``scipy.stats.qmc``) because SALib's
    sampler loops in Python (4 s at 10^6 rows).  Values kept strictly inside (0, 1).
    """
    from scipy.stats import qmc  # deferred: heavy import (start-up)

    base = qmc.Sobol(d=2 * D, scramble=True, seed=seed).random_base2(int(round(math.log2(N))))
    A, B = base[:, :D], base[:, D:]
    U = np.empty((N, D + 2, D))
    U[:, 0] = A
    U[:, D + 1] = B
    for j in range(D):
        U[:, j + 1] = A
        U[:, j + 1, j] = B[:, j]
    U = U.reshape(N * (D + 2), D)
    eps = 0.25 / N
    return np.clip(U, eps, 1.0 - eps)


#: rough cost of one sample (moment + beam) by fidelity, s: sizes scheduler chunks (>= 100 ms);
#: None = per-sample escalation (mostly leading/corrected)
_SECONDS_PER_SAMPLE = {"leading": 2e-7, "corrected": 2.5e-7, "quadrature": 2e-6, "exact": 2e-5, None: 5e-7}


#: batches of the batch-means confidence interval of the Sobol' indices
SOBOL_BATCHES = 32


def _sobol_indices(y, names, N, batches=SOBOL_BATCHES):
    """First/total indices (SALib's Saltelli 2010 / Jansen estimators) and 95 % intervals.

    SALib's own ``sobol.analyze`` bootstraps with an ``N x 100`` index matrix per output
    (minutes and ~200 MB at 10^6 runs); the point estimates here are SALib's estimator
    functions on all ``N`` rows, and the interval is by batch means: the rows split into
    ``batches`` interleaved groups, the estimator applied to each, half-width
    ``t_{0.975, K-1} sd / sqrt(K)`` -- the same estimator's sampling spread, O(N D).
    """
    from SALib.analyze.sobol import separate_output_values  # deferred: heavy import (start-up)
    from scipy import stats  # deferred: heavy import (start-up)

    D = len(names)
    y = np.asarray(y, float)
    # centred and scaled as SALib's analyze does: the Saltelli first-order estimator is not
    # shift invariant in its variance (an output with a large mean would swamp it)
    y = (y - y.mean()) / y.std()
    A, B, AB, _ = separate_output_values(y, D, N, False)
    K = batches if N >= 4 * batches else max(2, N // 4)
    m = (N // K) * K
    tq = float(stats.t.ppf(0.975, K - 1))
    # SALib's first_order / total_order (Saltelli 2010 CPC; Jansen), written out so that the
    # variance of [A, B] is computed once for all parameters and batches (the functions
    # recompute it per call); tests/studies/test_uq.py checks equality with SALib's functions.
    def est(a, b, ab):  # a, b: (n, ...); ab: (n, ..., D) -> S1, ST of shape (..., D)
        v = np.var(np.concatenate([a, b], axis=0), axis=0)[..., None]
        s1 = np.mean(b[..., None] * (ab - a[..., None]), axis=0) / v
        st = 0.5 * np.mean((a[..., None] - ab) ** 2, axis=0) / v
        return s1, st

    with np.errstate(all="ignore"):
        s1, st = est(A, B, AB)
        nb = m // K
        # contiguous blocks of a Sobol' sequence are nets (representative); strided subsets are not
        s1b, stb = est(A[:m].reshape(K, nb).T, B[:m].reshape(K, nb).T, AB[:m].reshape(K, nb, D).transpose(1, 0, 2))
    h1 = tq * np.std(s1b, axis=0, ddof=1) / math.sqrt(K)
    ht = tq * np.std(stb, axis=0, ddof=1) / math.sqrt(K)
    out = {k: {"S1": float(s1[j]), "S1_conf": float(h1[j]), "ST": float(st[j]), "ST_conf": float(ht[j])}
           for j, k in enumerate(names)}
    return out


def run_uq(scene, samples: int = 10**6, *, seed: int = 0, fidelity: str | None = None, scheduler=None,
           chunk_rows: int | None = None, keep_invalid: bool = False) -> UQResult:
    """Quantiles, moments and Sobol' indices of a scene's outputs under its ``[uncertain]`` inputs.

    Parameters
    ----------
    scene : path or dict
        A scene (see module docstring) with an ``[uncertain]`` table.
    samples : int
        Model runs wanted; ``N (D+2)`` are run with ``N`` the power of two at or above
        ``samples/(D+2)`` (SALib's Sobol' design for first and total indices).
    seed : int
        Seed of the scrambled Sobol' sequence and of the bootstrap (reproducible).
    fidelity : str, optional
        Force one rung (e.g. ``"leading"``); default: per-sample escalation by tolerance.
    scheduler : None, "local", "tcp://HOST:PORT" or Client
        Where the chunks run (:func:`ipmc_asym.parallel.executors.run_chunks`); results identical.
    chunk_rows : int, optional
        Samples per chunk.  Default: ``settings.CHUNK_ROWS`` in this process (bounds the
        memory of the temporaries); on a scheduler, chunks of >= 100 ms of work (at most
        4 per worker, at most 2^20 rows) by :func:`ipmc_asym.parallel.executors.chunk_slices`.
    keep_invalid : bool
        Keep the samples outside a model assumption in the statistics (default: left out,
        counted in ``n_outside``; the per-sample checks are in ``checks`` either way).

    Returns
    -------
    UQResult

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
    name, model, material, base, unc, outputs, tol = _scene_parts(scene)
    names = list(unc)
    D = len(names)
    base_n = 1 << max(1, math.ceil(math.log2(max(samples / (D + 2), 2))))
    U = _saltelli(D, base_n, seed)
    t_sample = time.perf_counter()
    n = U.shape[0]
    cols = {}
    for j, k in enumerate(names):
        cols[k] = _transform(U[:, j], *unc[k])
    del U
    for k in base:
        if k not in cols:
            cols[k] = np.full(n, base[k])
    for k in ("length", "width", "thickness", "modulus", "c_moy"):
        if np.any(cols[k] <= 0):
            raise ValueError(f"uq: sampled {k} <= 0 ({int(np.sum(cols[k] <= 0))} samples); narrow its distribution")

    if chunk_rows is not None:
        slices = [slice(a, min(a + int(chunk_rows), n)) for a in range(0, n, int(chunk_rows))]
    elif scheduler is None:
        slices = [slice(a, min(a + CHUNK_ROWS, n)) for a in range(0, n, CHUNK_ROWS)]
    else:

        slices = chunk_slices(n, _SECONDS_PER_SAMPLE.get(fidelity, 1e-6), os.cpu_count() or 1, max_items=2**20)
    tasks = [({k: cols[k][sl] for k in cols}, tuple(outputs), model, material, tol, fidelity) for sl in slices]

    t_eval0 = time.perf_counter()
    parts = run_chunks(uq_chunk, tasks, scheduler=scheduler)
    t_eval1 = time.perf_counter()
    outs = {o: np.concatenate([p[0][o] for p in parts]) for o in outputs}
    counts = {}
    for p in parts:
        for k, c in p[1].items():
            counts[k] = counts.get(k, 0) + c
    checks = {c: np.concatenate([p[2][c] for p in parts]) for c in CHECKS}
    valid = np.ones(n, bool)
    for v in checks.values():
        valid &= v
    n_out = int(np.count_nonzero(~valid))
    warns = []
    for p in parts:  # one line per failed assumption (the first chunk's wording), total counts below
        for w in p[3]:
            head = w.split(" [")[0]
            if not any(x.startswith(head[:40]) for x in warns):
                warns.append(head)
    # samples inside every model assumption (unless kept); whole Saltelli groups for the indices
    use = np.ones(n, bool) if keep_invalid else valid
    groups_ok = use.reshape(base_n, D + 2).all(axis=1)
    n_sobol = int(np.count_nonzero(groups_ok))
    summary, sob = {}, {}
    for o in outputs:
        y = outs[o][use & np.isfinite(outs[o])]
        if y.size < 2:
            raise ValueError(f"uq: {y.size} sample(s) of {o} inside the model ({n_out} of {n} outside a model "
                             "assumption); narrow the distributions or pass keep_invalid (--keep-invalid)")
        q = np.quantile(y, [0.025, 0.5, 0.975])
        summary[o] = {"unit": OUTPUT_UNITS[o][0], "mean": float(np.mean(y)), "sd": float(np.std(y, ddof=1)),
                      "q2.5": float(q[0]), "q50": float(q[1]), "q97.5": float(q[2]), "n": int(y.size)}
        yg = outs[o].reshape(base_n, D + 2)[groups_ok & np.all(np.isfinite(outs[o].reshape(base_n, D + 2)), axis=1)]
        if yg.shape[0] < 2 or not np.ptp(yg) > 0:
            sob[o] = None
            continue
        sob[o] = _sobol_indices(yg.reshape(-1), names, yg.shape[0])

    return UQResult(summary=summary, sobol=sob, inputs=unc, samples={k: cols[k] for k in names}, outputs=outs,
                    n_samples=n, base_n=base_n, fidelity=counts, model=get_model(model).name, tolerance=tol,
                    seconds=time.perf_counter() - t0, scene=name, base=base, material=material,
                    timings={"sampling": t_sample - t0, "evaluation": t_eval1 - t_eval0,
                             "analysis": time.perf_counter() - t_eval1},
                    checks=checks, valid=valid, n_outside=n_out, keep_invalid=bool(keep_invalid),
                    n_used=int(np.count_nonzero(use)), n_sobol=n_sobol, warnings=warns, seed=int(seed))

