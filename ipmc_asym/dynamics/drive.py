"""Response to any voltage waveform, computed and handed out in chunks (memory independent of the length).

The reduced circuit (:class:`ipmc_asym.dynamics.circuit.CircuitStepper`), the quasi-static
mechanics of each time point from the one forward model and its checks
(:func:`ipmc_asym.dynamics.circuit.quasi_static_forward`; ``check_*`` and ``valid`` columns,
one ``warnings`` list per chunk) and, with ``beam="dynamic"``, the
strip's inertia and damping (:class:`ipmc_asym.dynamics.circuit.BeamDynamics`), each carrying
its state from one chunk to the next: the rows are those of one run over the whole grid.  The
current is the model's own at each row, not a difference over the rows (which would straddle a
jump of the drive): :meth:`~ipmc_asym.dynamics.circuit.CircuitStepper.current`, and the electrode
line's :meth:`~ipmc_asym.dynamics.line_time.LineStepper.current`.
"""

from __future__ import annotations

import math

import numpy as np

from ipmc_asym.base import interrupt
from ipmc_asym.base.registry import check_choice
from ipmc_asym.beam.dynamics import CLAMPED_OUTPUTS, natural_frequencies
from ipmc_asym.beam.statics import solve_beam
from ipmc_asym.dynamics.circuit import (
    BEAM_CHOICES,
    DEFAULT_BEAM,
    TIME_MODES,
    BeamDynamics,
    CircuitStepper,
    _linear_statics,
    check_electrode,
    check_support,
    dynamic_notes,
    quasi_static_forward,
    strip_beam,
    support_notes,
    waveform,
)
from ipmc_asym.dynamics.electrode import core_resistance, time_constant
from ipmc_asym.dynamics.line_time import (
    DEFAULT_SEGMENTS,
    ERROR_FACTOR,
    MAX_SEGMENTS,
    LineBeamDynamics,
    LineStepper,
    line_weights,
)
from ipmc_asym.dynamics.waveforms import Waveform, parse_waveform
from ipmc_asym.forward.model import CHECKS, assumption_warnings
from ipmc_asym.model.params import (
    NAFION_LI,
    SHEET_RESISTANCE_SOURCE,
    Material,
    Strip,
    bending_stiffness,
    check_positive,
    check_sheet_resistance,
)
from ipmc_asym.model.permittivity import get_model

__all__ = ["DRIVE_ERROR_NOTE", "MAX_STATED_POINTS",
           "DRIVE_COLUMNS", "CHECK_COLUMNS", "LINE_COLUMNS", "CLAMPED_COLUMNS", "MAX_DRIVE_POINTS", "drive_info", "drive_chunks",
           "drive_response", "LINE_NOTE"]

DRIVE_COLUMNS = ("t", "phi0", "sigma", "current_density", "layer_voltage", "M_A", "theta", "w", "F_block")
#: the forward model's checks at each time point (1 passed, 0 failed), as in step and estimate
CHECK_COLUMNS = tuple(f"check_{c}" for c in CHECKS) + ("valid",)

#: with support="clamped-clamped": the clamps' reaction moments (N m) and forces (N), the midspan deflection (m)
CLAMPED_COLUMNS = CLAMPED_OUTPUTS

#: with a sheet resistance: the stated discretisation error of sigma (C/m^2) and w (m) of the line
LINE_COLUMNS = ("sigma_error", "w_error")

#: cap on the output times of a drive run with a tolerance or the PNP (solved in memory; the PNP keeps
#: the profiles of every output time, ~10 kB each: about 100 MB)
MAX_STATED_POINTS = 10_001

#: said by a drive run of the circuit without a tolerance: its rows carry no error against the PNP.
#: The circuit's error is bounded in the frequency domain (``freq``: ``error``, at most lambda/2 about
#: 0 V, against the PNP linearised about the bias with a bias) and in time against a PNP run over the
#: same waveform (``drive --tol T``, as ``step --tol``: in memory, 100-1000 times the circuit's cost);
#: a streamed run over a long waveform is what the circuit is for, so the reference is not run by default
DRIVE_ERROR_NOTE = ("no error of the reduced circuit against the PNP is stated for these rows (the circuit stepped "
                    "through an arbitrary waveform carries no bound of its own): drive --tol T states it against a PNP "
                    "run over the same waveform (in memory, at most "
                    f"{MAX_STATED_POINTS} points); freq --method circuit states it in "
                    "the small signal ('error')")
LINE_NOTE = ("electrodes: sheet resistance R_s = {Rs:g} Ohm/sq each: the RC line along the strip discretised in {n2} "
             "segments (trapezoidal ladder, a reduced circuit at each node, driven at the clamp, open at the tip); "
             "sigma, current density and layer voltage are means over the electrode; sigma_error and w_error are twice "
             "the Richardson estimate against {n} segments (none is stated for the current density, which that "
             "estimate does not bound: ~2e-3 of it off the exact line at 2.5 Ohm/sq); the quasi-static beam takes the "
             "distributed moment as the uniform moments of equal tip rotation (theta, M_A = its mean) and of equal tip "
             "deflection (w, F_block): exact for small displacements and for a uniform moment; with beam dynamics the "
             "node moments (linear between nodes) drive the modes through int M phi_n'' dx; the bulk's geometric "
             "capacitance is instantaneous (its displacement charge is added to sigma)")

#: the electrode line's stated error may reach this fraction of the largest |sigma| and |w| so far;
#: beyond it the run is refused (more segments hold it): the numbers are not handed out
LINE_TOL = 1e-2

#: cap on the number of output times of one run (each row is ~9 numbers; streamed to a file)
MAX_DRIVE_POINTS = 100_000_000


def _resolve(wave):
    if isinstance(wave, str):
        return parse_waveform(wave)
    if isinstance(wave, Waveform) or callable(wave):
        return waveform(wave, 0.0)
    raise ValueError("waveform must be a SPEC string (e.g. 'sine:1V@10Hz') or a callable phi0(t) in volts")


def _sheet(sheet_resistance, beam):
    return check_sheet_resistance(sheet_resistance)


def _support(support, electrode, strip, Rs):
    """The checked support and electrode; a clamped-clamped strip or a partial electrode refuses the line."""
    support = check_support(support)
    el = check_electrode(electrode, strip.length)
    if Rs > 0.0 and (support == "clamped-clamped" or el is not None):
        what = "support clamped-clamped" if support == "clamped-clamped" else "a partial electrode"
        raise ValueError(f"sheet_resistance: {what} is not supported with the electrode line (its moment is "
                         "distributed over the full strip, clamped-free and clamped-pinned)")
    return support, el


def drive_info(strip: Strip, model, material: Material, beam=DEFAULT_BEAM, viscous_modulus=0.0, sheet_resistance=0.0,
               line_segments=DEFAULT_SEGMENTS, support=None, electrode=None):
    """Header of a run: time constant, R, resonances, notes (what is modelled and what is not)."""
    perm = get_model(model)
    Rs = _sheet(sheet_resistance, beam)
    support, el = _support(support, electrode, strip, Rs)
    info = {"tau": float(time_constant(strip.thickness, perm, material)),
            "R": float(core_resistance(strip.thickness, material)), "model": perm.name, "beam": beam,
            "viscous_modulus": float(viscous_modulus),
            "notes": dynamic_notes(beam, viscous_modulus, material) + [DRIVE_ERROR_NOTE]}
    if Rs > 0.0:
        info["sheet_resistance"] = Rs
        info["line_segments"] = 2 * int(line_segments)
        info["notes"] += [LINE_NOTE.format(Rs=Rs, n2=2 * int(line_segments), n=int(line_segments)),
                          SHEET_RESISTANCE_SOURCE]
    if support is not None or el is not None:
        info["support"] = support
        info["electrode"] = None if el is None else list(el)
        info["notes"] += support_notes(support, el)
    if beam == "dynamic":
        b = BeamDynamics(strip, material, viscous_modulus, 1).beam
        sups = ("clamped-free", "clamped-pinned") + (("clamped-clamped",) if support == "clamped-clamped" else ())
        info["resonances"] = {s: natural_frequencies(s, b, 3).tolist() for s in sups}
    return info


def drive_chunks(wave, duration, points, *, strip: Strip | None = None, model="constant",
                 material: Material | None = None, beam=DEFAULT_BEAM, viscous_modulus=0.0, n_modes=TIME_MODES,
                 chunk=20_000, sheet_resistance=0.0, line_segments=DEFAULT_SEGMENTS, support=None, electrode=None,
                 times=None):
    """Yield dicts of column arrays (:data:`DRIVE_COLUMNS`) over ``points`` equally spaced times in [0, duration].

    Parameters
    ----------
    wave : str or callable
        Waveform SPEC (:func:`ipmc_asym.dynamics.waveforms.parse_waveform`) or ``phi0(t)`` (V).
    duration : float   end time, s
    points : int       output times (2 .. :data:`MAX_DRIVE_POINTS`)
    strip, model, material : as in :func:`ipmc_asym.dynamics.circuit.step_response`
    beam : {"quasi-static", "dynamic"}
        Default :data:`~ipmc_asym.dynamics.circuit.DEFAULT_BEAM` (quasi-static).
    viscous_modulus : float (Pa s) ; n_modes : int
    chunk : int        rows per chunk (memory ~ chunk, not points)
    times : callable or None
        ``times(idx)`` -> the output times (s) of row indices ``idx`` (increasing, ``times(0) = 0``,
        ``times(points - 1) = duration``) instead of equal spacing (a step's default window,
        :func:`ipmc_asym.dynamics.circuit.default_times`).
    sheet_resistance : float
        ``R_s`` of each electrode (Ohm/sq, default 0: the uniform strip, exactly).  > 0: the
        discretised RC line (:class:`ipmc_asym.dynamics.line_time.LineStepper`, ``2 line_segments``
        segments reported, ``line_segments`` for the error), the forward model at every node,
        with ``beam="dynamic"`` the node moments drive the modes
        (:class:`ipmc_asym.dynamics.line_time.LineBeamDynamics`); the chunks also hold :data:`LINE_COLUMNS`.  A stated error above
        :data:`LINE_TOL` of the largest response so far is refused (``ValueError``: more segments).
    line_segments : int   ``N`` of the coarser line
    support : {None, "clamped-free", "clamped-pinned", "clamped-clamped"}
        ``None`` (default) and the first two: the columns :data:`DRIVE_COLUMNS` (free tip ``theta``,
        ``w``; blocked tip ``F_block``); ``clamped-clamped`` adds :data:`CLAMPED_COLUMNS` (the clamps'
        reaction moments and forces, the midspan deflection; small displacements).
    electrode : (x1, x2), optional
        Covered part of the length (m); the moment acts there only and the beam outputs are the
        small-displacement statics of that load (the forward model's beam is for a full electrode).
        Neither with ``sheet_resistance > 0`` (``ValueError``).

    Notes
    -----
    With ``beam="dynamic"`` the output spacing must resolve the first mode (>= 40 points per
    period, the first-order hold of ``M_A``), else ``ValueError`` says how many points are needed.
    """
    check_choice("beam", beam, BEAM_CHOICES)
    Rs = _sheet(sheet_resistance, beam)
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
    support, el = _support(support, electrode, s, Rs)
    clamped = support == "clamped-clamped"
    ccols = CLAMPED_COLUMNS if clamped else ()
    dyn = BeamDynamics(s, m, viscous_modulus, n_modes, el, clamped) if beam == "dynamic" else None
    lb = strip_beam(s, m, viscous_modulus, el)
    h = d / (n - 1)
    if times is not None:  # the largest output interval is the one the modes must resolve
        h = float(np.max(np.diff(times(np.arange(n)))))
    if dyn is not None and h > dyn.period / 40.0:
        need = int(math.ceil(40.0 * d / dyn.period)) + 1
        raise ValueError(f"points: the beam dynamics need >= 40 points per period of the first mode "
                         f"(T1 = {dyn.period:.4g} s): use --points >= {need} or beam quasi-static")
    line = LineStepper(fun, s, perm, m, Rs, line_segments) if Rs > 0.0 else None
    ldyn = None
    if line is not None and dyn is not None:
        # the line's node moments drive the modes (both ladders: the coarse one for the error of w)
        ldyn = (LineBeamDynamics(s, m, viscous_modulus, n_modes, line.x),
                LineBeamDynamics(s, m, viscous_modulus, n_modes, line.x_coarse))
    stepper = CircuitStepper(fun, s, perm, m) if line is None else None
    lcols = LINE_COLUMNS if line is not None else ()
    if line is not None:
        # the forward model runs on every node of both ladders: keep its arrays at ~2e5 points a chunk
        chunk = max(16, min(chunk, 200_000 // (3 * line.segments + 2)))
    peak = {"sigma": 0.0, "w": 0.0}
    start = 0
    while True:
        stop = min(start + chunk, n - 1)
        idx = np.arange(start, stop + 1)
        t = idx * h if times is None else np.asarray(times(idx), dtype=float)
        t[-1] = d if stop == n - 1 else t[-1]
        lc = {}
        phi = fun(t)
        if line is None:
            u, _, sigma = stepper.advance(t)
            # every time point through the forward model and its checks (the same as step's and estimate's)
            fr = quasi_static_forward(u, s, perm, m, applied=phi)
            M, th, w, Fb = (np.asarray(getattr(fr, k), dtype=float) for k in ("M_A", "theta", "w", "F_block"))
            checks = {c: np.asarray(getattr(fr, c), bool).reshape(-1) for c in CHECKS}
            if el is not None:  # the moment on [x1, x2] only: its small-displacement statics
                w = _linear_statics(lb, M, "clamped-free", ("w",))["w"]
                th = _linear_statics(lb, M, "clamped-free", ("theta",))["theta"]
                Fb = _linear_statics(lb, M, "clamped-pinned", ("F",))["F"]
            cc = _linear_statics(lb, M, "clamped-clamped") if clamped else {}
            lc = {"_J": stepper.current(t, u)}
        else:
            o = line.advance(t)
            # every node at every time through the forward model; a time point passes a check where every node does
            fr = quasi_static_forward(o["u"].ravel(), s, perm, m, applied=np.repeat(phi, o["u"].shape[1]))
            checks = {c: np.asarray(getattr(fr, c), bool).reshape(o["u"].shape).all(axis=1) for c in CHECKS}
            Mn = np.asarray(fr.M_A, dtype=float).reshape(o["u"].shape)
            M, th, w, Fb = _line_mechanics(Mn, line.x, s, m)
            frc = quasi_static_forward(o["u_coarse"].ravel(), s, perm, m)
            Mc = np.asarray(frc.M_A, dtype=float).reshape(o["u_coarse"].shape)
            _, thc, wc, Fc = _line_mechanics(Mc, line.x_coarse, s, m)
            w_qs = w
            if ldyn is not None:
                th, w, Fb = ldyn[0].advance(t, Mn, (th, w), Fb)
                wc = ldyn[1].advance(t, Mc, (thc, wc), Fc)[1]
            u = o["u"] @ line_weights(2 * line.segments, s.length)[1] / s.length
            sigma = o["sigma_mean"]
            lc = {"sigma_error": o["sigma_error"], "w_error": ERROR_FACTOR * np.abs(w - wc),
                  "_J": line.current(t, o["u"], o["v"])}
            for k, v in (("sigma", sigma), ("w", np.maximum(np.abs(w), np.abs(w_qs)))):
                # the error bound against the largest response so far (a numerical check: refuse, not flag);
                # for w the quasi-static deflection too (the strip's inertia delays the dynamic one)
                scale = np.maximum.accumulate(np.maximum(np.abs(v), peak[k]))
                over = lc[f"{k}_error"] > LINE_TOL * scale
                if np.any(over):
                    i = int(np.argmax(over))
                    n = line.segments
                    raise ValueError(f"line_segments: the electrode line's discretisation error on {k} exceeds "
                                     f"{LINE_TOL:g} of the response at t = {t[i]:.4g} s with line_segments = {n} "
                                     f"(the reported line of {2 * n} segments against the {n} of its error estimate); "
                                     f"raise line_segments (--line-segments on the command line) above {n}, at most "
                                     f"{MAX_SEGMENTS}")
                peak[k] = float(scale[-1])
        warns = assumption_warnings(fr)
        valid = np.logical_and.reduce([checks[c] for c in CHECKS])
        if dyn is not None and line is None:
            th, w, Fb = dyn.advance(t, M, th, w, Fb)
            if clamped:
                cc = dyn.advance_clamped(t, M, cc)
        cols = {"t": t, "phi0": phi, "sigma": sigma, "layer_voltage": u, "M_A": M, "theta": th, "w": w,
                "F_block": Fb, "current_density": lc.pop("_J"),
                **{f"check_{c}": checks[c].astype(float) for c in CHECKS},
                "valid": valid.astype(float), **lc, **(cc if line is None else {})}
        # every row is the model's own (its current too): a chunk after the first drops its first
        # row, the previous chunk's last
        emit = slice(1, None) if start > 0 else slice(None)
        out = {k: cols[k][emit] for k in DRIVE_COLUMNS + CHECK_COLUMNS + lcols + ccols}
        last = stop == n - 1
        interrupt.check()  # a Ctrl-C/SIGTERM swallowed inside the chunk's compiled code stops here
        yield {**{k: out[k] for k in DRIVE_COLUMNS + CHECK_COLUMNS + lcols + ccols}, "warnings": warns}
        start = stop
        if last:
            break


def drive_response(wave, duration, points=1000, **kw):
    """All rows of :func:`drive_chunks` in memory (dict of arrays), for short runs and tests."""
    parts = list(drive_chunks(wave, duration, points, **kw))
    return {k: np.concatenate([p[k] for p in parts])
            for k in DRIVE_COLUMNS + CHECK_COLUMNS + LINE_COLUMNS + CLAMPED_COLUMNS if k in parts[0]}


def _line_mechanics(M, x, strip: Strip, material: Material):
    """``(M_A, theta, w, F_block)`` of the strip under the node moments ``M`` (n, nodes) of a ladder at ``x``.

    The beam (:func:`ipmc_asym.beam.statics.solve_beam`) at the uniform moment of equal
    small-displacement tip rotation, ``int M dx/L`` (theta; reported as M_A), and of equal tip
    deflection, ``2 int (L - x) M dx/L^2`` (w and F_block: ``F = 3 int (L - x) M dx/L^3``,
    ``derivations/line.py`` item 3 and ``beam.dynamics.moment_kernels``), trapezoidal sums on the
    ladder's nodes.
    """
    L = strip.length
    _, wt = line_weights(x.size - 1, L)
    Mt = M @ wt / L
    Mw = M @ (2.0 * (L - x) * wt / L**2)
    EI = float(bending_stiffness(material, strip.width, strip.thickness))  # composite with electrode layers
    with np.errstate(all="ignore"):
        bt = solve_beam(Mt, L, EI, e=strip.e, strain_limit=material.strain_limit)
        bw = solve_beam(Mw, L, EI, e=strip.e, strain_limit=material.strain_limit)
    return Mt, np.asarray(bt.theta, dtype=float), np.asarray(bw.w, dtype=float), np.asarray(bw.F_block, dtype=float)
