"""Response to any voltage waveform, computed and handed out in chunks (memory independent of the length).

The reduced circuit (:class:`ipmc_asym.dynamics.circuit.CircuitStepper`), the quasi-static
mechanics of each time point from the one forward model and its checks
(:func:`ipmc_asym.dynamics.circuit.quasi_static_forward`; ``check_*`` and ``valid`` columns,
one ``warnings`` list per chunk) and, with ``beam="dynamic"``, the
strip's inertia and damping (:class:`ipmc_asym.dynamics.circuit.BeamDynamics`), each carrying
its state from one chunk to the next: the rows are those of one run over the whole grid (the
current's displacement part uses the same central differences, a row is handed out once its
successor is known).
"""

from __future__ import annotations

import math

import numpy as np

from ipmc_asym.base.registry import check_choice
from ipmc_asym.base.settings import VALIDATED_VOLTAGE
from ipmc_asym.beam.dynamics import natural_frequencies
from ipmc_asym.dynamics.circuit import (
    BEAM_CHOICES,
    TIME_MODES,
    BeamDynamics,
    CircuitStepper,
    dynamic_notes,
    quasi_static_forward,
    waveform,
)
from ipmc_asym.dynamics.electrode import core_resistance, time_constant
from ipmc_asym.dynamics.waveforms import Waveform, parse_waveform
from ipmc_asym.forward.model import CHECKS, assumption_warnings, voltage_reason
from ipmc_asym.model.params import NAFION_LI, Material, Strip, check_positive
from ipmc_asym.model.permittivity import get_model

__all__ = ["DRIVE_COLUMNS", "CHECK_COLUMNS", "MAX_DRIVE_POINTS", "drive_info", "drive_chunks", "drive_response"]

DRIVE_COLUMNS = ("t", "phi0", "sigma", "current_density", "layer_voltage", "M_A", "theta", "w", "F_block")
#: the forward model's checks at each time point (1 passed, 0 failed), as in step and estimate
CHECK_COLUMNS = tuple(f"check_{c}" for c in CHECKS) + ("valid",)

#: cap on the number of output times of one run (each row is ~9 numbers; streamed to a file)
MAX_DRIVE_POINTS = 100_000_000


def _resolve(wave):
    if isinstance(wave, str):
        return parse_waveform(wave)
    if isinstance(wave, Waveform) or callable(wave):
        return waveform(wave, 0.0)
    raise ValueError("waveform must be a SPEC string (e.g. 'sine:1V@10Hz') or a callable phi0(t) in volts")


def drive_info(strip: Strip, model, material: Material, beam="dynamic", viscous_modulus=0.0):
    """Header of a run: time constant, R, resonances, notes (what is modelled and what is not)."""
    perm = get_model(model)
    info = {"tau": float(time_constant(strip.thickness, perm, material)),
            "R": float(core_resistance(strip.thickness, material)), "model": perm.name, "beam": beam,
            "viscous_modulus": float(viscous_modulus), "notes": dynamic_notes(beam, viscous_modulus)}
    if beam == "dynamic":
        b = BeamDynamics(strip, material, viscous_modulus, 1).beam
        info["resonances"] = {s: natural_frequencies(s, b, 3).tolist() for s in ("clamped-free", "clamped-pinned")}
    return info


def drive_chunks(wave, duration, points, *, strip: Strip | None = None, model="constant",
                 material: Material | None = None, beam="dynamic", viscous_modulus=0.0, n_modes=TIME_MODES,
                 chunk=20_000):
    """Yield dicts of column arrays (:data:`DRIVE_COLUMNS`) over ``points`` equally spaced times in [0, duration].

    Parameters
    ----------
    wave : str or callable
        Waveform SPEC (:func:`ipmc_asym.dynamics.waveforms.parse_waveform`) or ``phi0(t)`` (V).
    duration : float   end time, s
    points : int       output times (2 .. :data:`MAX_DRIVE_POINTS`)
    strip, model, material : as in :func:`ipmc_asym.dynamics.circuit.step_response`
    beam : {"dynamic", "quasi-static"} ; viscous_modulus : float (Pa s) ; n_modes : int
    chunk : int        rows per chunk (memory ~ chunk, not points)

    Notes
    -----
    With ``beam="dynamic"`` the output spacing must resolve the first mode (>= 40 points per
    period, the first-order hold of ``M_A``), else ``ValueError`` says how many points are needed.
    """
    check_choice("beam", beam, BEAM_CHOICES)
    fun = _resolve(wave)
    s = Strip() if strip is None else strip
    m = NAFION_LI if material is None else material
    perm = get_model(model)
    if perm.is_custom:
        raise ValueError("dynamic models need an affine permittivity (constant, linear, affine)")
    d = check_positive("duration", duration, "s")
    n = int(points)
    if not 2 <= n <= MAX_DRIVE_POINTS:
        raise ValueError(f"points must be an integer in [2, {MAX_DRIVE_POINTS}]; got {points!r}")
    chunk = max(int(chunk), 16)
    dyn = BeamDynamics(s, m, viscous_modulus, n_modes) if beam == "dynamic" else None
    h = d / (n - 1)
    if dyn is not None and h > dyn.period / 40.0:
        need = int(math.ceil(40.0 * d / dyn.period)) + 1
        raise ValueError(f"points: the beam dynamics need >= 40 points per period of the first mode "
                         f"(T1 = {dyn.period:.4g} s): use --points >= {need} or beam quasi-static")
    stepper = CircuitStepper(fun, s, perm, m)
    R = float(core_resistance(s.thickness, m))
    Cg = stepper.Cg
    held = None  # last computed row, waiting for its successor (central difference of phi0 - u)
    prev = None  # (t, ub) of the row before it
    start = 0
    while start < n - 1 or held is None:
        stop = min(start + chunk, n - 1)
        idx = np.arange(start, stop + 1)
        t = idx * h
        t[-1] = d if stop == n - 1 else t[-1]
        u, ub, sigma = stepper.advance(t)
        # every time point through the forward model and its checks (the same as step's and estimate's)
        fr = quasi_static_forward(u, s, perm, m)
        M, th, w, Fb = (np.asarray(getattr(fr, k), dtype=float) for k in ("M_A", "theta", "w", "F_block"))
        phi = fun(t)
        checks = {c: np.asarray(getattr(fr, c), bool).reshape(-1) for c in CHECKS}
        warns = assumption_warnings(fr)
        over = np.abs(phi) > VALIDATED_VOLTAGE  # the applied voltage too: the layers' one lags behind it
        if np.any(over & checks["voltage"]):
            checks["voltage"] = checks["voltage"] & ~over
            warns = [x for x in warns if "VALIDATED_VOLTAGE" not in x] + [voltage_reason(np.max(np.abs(phi)))]
        valid = np.logical_and.reduce([checks[c] for c in CHECKS])
        if dyn is not None:
            th, w, Fb = dyn.advance(t, M, th, w, Fb)
        cols = {"t": t, "phi0": phi, "sigma": sigma, "layer_voltage": u, "M_A": M, "theta": th, "w": w,
                "F_block": Fb, "_ub": ub, **{f"check_{c}": checks[c].astype(float) for c in CHECKS},
                "valid": valid.astype(float)}
        if held is not None:  # the first row of this chunk repeats the held one
            cols = {k: v[1:] for k, v in cols.items()}
            cols = {k: np.concatenate(([held[k]], cols[k])) for k in cols}
        # derivative of ub at every row but the last (central; one-sided at t = 0)
        tt = cols["t"]
        uu = cols["_ub"]
        tb = np.concatenate(([prev[0]], tt)) if prev is not None else tt
        ubb = np.concatenate(([prev[1]], uu)) if prev is not None else uu
        last = stop == n - 1
        g = np.gradient(ubb, tb) if tb.size > 1 else np.zeros(tb.size)
        if prev is not None:
            g = g[1:]
        emit = slice(None) if last else slice(0, -1)
        J = uu / R + Cg * g
        out = {k: cols[k][emit] for k in DRIVE_COLUMNS + CHECK_COLUMNS if k != "current_density"}
        out["current_density"] = J[emit]
        if not last:
            held = {k: v[-1] for k, v in cols.items()}
            prev = (tt[-2], uu[-2])
        else:
            held = {}
        yield {**{k: out[k] for k in DRIVE_COLUMNS + CHECK_COLUMNS}, "warnings": warns}
        start = stop
        if last:
            break


def drive_response(wave, duration, points=1000, **kw):
    """All rows of :func:`drive_chunks` in memory (dict of arrays), for short runs and tests."""
    parts = list(drive_chunks(wave, duration, points, **kw))
    return {k: np.concatenate([p[k] for p in parts]) for k in DRIVE_COLUMNS + CHECK_COLUMNS}
