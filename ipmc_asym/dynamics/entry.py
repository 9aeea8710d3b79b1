"""One entry for time and frequency responses: the choice of solver a command or a Python user makes.

:func:`time_response` chooses between the in-memory transient (:func:`~ipmc_asym.dynamics.circuit.step_response`:
the reduced circuit or the PNP solver, with a tolerance and a refined grid for the dynamic beam), the
uniform strip stepped on the output grid chunk by chunk (:func:`~ipmc_asym.dynamics.drive.drive_chunks`)
and the electrode line (the same stepper with a sheet resistance, :mod:`ipmc_asym.dynamics.line_time`).
:func:`spectrum` chooses between the uniform strip (:func:`~ipmc_asym.dynamics.circuit.frequency_response`)
and the electrode line (:func:`~ipmc_asym.dynamics.line.line_response`).  ``ipmc-asym step``, ``drive``
and ``freq`` parse their options, call these and print.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field

import numpy as np

from ipmc_asym.base.registry import check_choice
from ipmc_asym.base.results import Panel, ResultMixin, ResultSpec
from ipmc_asym.dynamics.circuit import (
    BEAM_CHOICES,
    CIRCUIT_NO_TOL_NOTE,
    DEFAULT_BEAM,
    DEFAULT_SPAN,
    FREQ_METHODS,
    STEP_FIDELITIES,
    TIME_MODES,
    ReferenceFailed,
    StepResult,
    default_times,
    drive_frequency,
    frequency_response,
    step_response,
    waveform,
)
from ipmc_asym.dynamics.drive import DRIVE_COLUMNS, MAX_STATED_POINTS, drive_chunks, drive_info, drive_response
from ipmc_asym.dynamics.line import line_response
from ipmc_asym.dynamics.line_time import DEFAULT_SEGMENTS
from ipmc_asym.dynamics.waveforms import Waveform, check_drive_voltage, parse_waveform
from ipmc_asym.forward.model import CHECKS
from ipmc_asym.model.params import NAFION_LI, Material, Strip, check_sheet_resistance

__all__ = ["DEFAULT_BEAM", "TIME_PATHS", "ERROR_COLUMNS", "AUTO_TOL", "AUTO_WORK", "WORK_PER_SECOND", "Drive",
           "TimeResponse", "stated_tol", "time_path", "time_response", "spectrum", "sampling_note"]

#: solvers of a time response: ``memory`` (step_response: circuit or PNP, optional tolerance, the dynamic
#: beam on a refined grid), ``stream`` (the circuit stepped on the output grid, chunk by chunk, memory
#: independent of the number of points; supports and partial electrodes), ``line`` (the electrode line:
#: the same stepper with resistive electrodes, its discretisation error stated)
TIME_PATHS = ("memory", "stream", "line")

#: the stated errors of the in-memory solve (with a tolerance, or the PNP): sigma (C/m^2), its current
#: density (A/m^2) and the tip deflection (m), each a bound at every output time
ERROR_COLUMNS = ("sigma_error", "current_error", "w_error")

#: the tolerance on sigma of ``tol="auto"`` (``ipmc-asym step``'s default): the circuit's sigma, current and w
#: errors stated against a reference PNP run (the PNP where the circuit misses it).  1 % of sigma's peak: the
#: circuit meets it on the nominal strip at 1 V (constant model), the reference runs at a tenth of it, and the
#: run costs ~1-10 s CPU instead of the bare circuit's ~0.02 s (measured: constant 1.5 s, linear 1.9 s,
#: affine 2.4 s at 1 V, where the affine and linear circuits miss 1 % and the PNP is used)
AUTO_TOL = 1e-2

#: the cap on the reference PNP run's work under ``tol="auto"`` (cell-evaluations,
#: :func:`~ipmc_asym.dynamics.transient.solve_transient`'s ``max_work``: a count, the same on every
#: machine).  Where the reference would cost more, ``auto`` states no error and says so; a number
#: for ``tol`` runs it whatever it costs.  5e7 is ~15 s CPU here at most (measured on this 2-core
#: x86-64: 2 s of a 1 Hz sine 5.9e6 = 2.4 s, constant model, and 3.3e7 = 9.4 s, affine; 10 Hz
#: 4.7e7 = 10.8 s); the reference's cost grows with the periods and jumps in the duration, and a
#: case beyond the cap is given up after a sixth of it or less (the ladder's first level predicts it)
AUTO_WORK = 5e7

#: cell-evaluations of the transient solver per second of CPU, to say a cap in seconds (measured on
#: this 2-core x86-64, 2.4e6-4.4e6 over the cases of :data:`AUTO_WORK`; a figure, not a check)
WORK_PER_SECOND = 3.3e6

#: how the dynamic beam meets the output grid: ``refined`` (the transient is solved on a grid of >= 40
#: points per period of the first mode and sampled at the output times) or ``output`` (the modes are
#: stepped on the output grid itself, which must resolve the first mode; it streams)
BEAM_GRIDS = ("refined", "output")


class Drive:
    """The applied voltage ``phi0(t)`` (V) between the electrodes, checked when built.

    Build it from a number (a step of that many volts at ``t = 0``), a waveform SPEC
    (:func:`ipmc_asym.dynamics.waveforms.parse_waveform`: ``'sine:1V@10Hz'``, ``'step:1V+square:0.1V@5Hz'``,
    ``'csv:V.csv'``), a parsed :class:`~ipmc_asym.dynamics.waveforms.Waveform` or a callable
    ``phi0(t)`` (volts, vectorised or not), or with :meth:`step` / :meth:`parse`.

    Attributes
    ----------
    kind : {"step", "waveform", "function"}
    voltage : float
        The step's height (V); ``nan`` for a waveform or a function.
    spec : str
        ``"step"`` for a step (as the outputs' ``waveform`` key), the SPEC of a waveform, ``"function"``.
    function : callable
        ``phi0(t)``: array of times (s) -> array of volts.
    """

    __slots__ = ("kind", "voltage", "spec", "function", "source")

    def __init__(self, drive):
        if isinstance(drive, Drive):
            self.kind, self.voltage, self.spec = drive.kind, drive.voltage, drive.spec
            self.function, self.source = drive.function, drive.source
            return
        if isinstance(drive, bool) or drive is None:
            raise ValueError(f"drive must be a voltage (V), a waveform SPEC such as 'sine:1V@10Hz' or a callable "
                             f"phi0(t) in volts; got {drive!r}")
        if isinstance(drive, str):
            drive = parse_waveform(drive)
        if isinstance(drive, Waveform):
            self.kind, self.voltage, self.spec, self.function, self.source = "waveform", float("nan"), drive.spec, drive, drive
        elif isinstance(drive, (int, float, np.floating, np.integer)):
            self.kind, self.spec = "step", "step"
            self.voltage = check_drive_voltage("drive", drive)
            self.function = self.source = waveform("step", self.voltage)
        elif callable(drive):
            self.kind, self.voltage, self.spec = "function", float("nan"), "function"
            self.function, self.source = waveform(drive, 0.0), drive
        else:
            raise ValueError(f"drive must be a voltage (V), a waveform SPEC such as 'sine:1V@10Hz' or a callable "
                             f"phi0(t) in volts; got {type(drive).__name__}")

    @classmethod
    def step(cls, voltage) -> Drive:
        """A step of ``voltage`` (V) at ``t = 0``."""
        if isinstance(voltage, str):
            raise ValueError(f"voltage must be a finite number of volts; got {voltage!r}")
        return cls(voltage)

    @classmethod
    def parse(cls, spec) -> Drive:
        """A waveform SPEC (:func:`ipmc_asym.dynamics.waveforms.parse_waveform`)."""
        return cls(parse_waveform(spec))

    def __call__(self, t):
        return self.function(t)

    def __repr__(self):
        return f"Drive.step({self.voltage!r})" if self.kind == "step" else f"Drive({self.spec!r})"


@dataclass(repr=False)
class TimeResponse(ResultMixin):
    """What :func:`time_response` ran and its rows.

    Attributes
    ----------
    path : {"memory", "stream", "line"}   the solver (:data:`TIME_PATHS`)
    drive : Drive
    duration : float or None    end time, s (None: the in-memory solve's default, 5 tau)
    info : dict                 header of the run (:func:`ipmc_asym.dynamics.drive.drive_info`: tau, R,
                                notes, resonances, line segments; the in-memory solve adds its
                                ``fidelity``, the ``tol`` it met and ``valid_from``)
    result : StepResult or None the in-memory solve (path ``memory``)
    chunks : iterator of dict or None   the stepped paths with ``stream=True``: dicts of column arrays
                                (:data:`ipmc_asym.dynamics.drive.DRIVE_COLUMNS`, checks, line columns)
                                and ``warnings``, computed as iterated
    columns : dict or None      the stepped paths with ``stream=False``: every row in memory

    Its summary, ``.plot()`` and ``.to_xarray()`` are those of the rows in memory (``result`` or
    ``columns``); a streamed response has none until it is read.
    """

    _result = ResultSpec("t", "t", ("phi0", "sigma", "current_density", "layer_voltage", "M_A", "theta", "w",
                                    "F_block", "sigma_error"),
                         (Panel("t", ("voltage", "layer_voltage")), Panel("t", ("sigma",)), Panel("t", ("w",))),
                         (), {"phi0": "voltage"})
    _HEADLINE = ("path",)

    path: str
    drive: Drive
    duration: float | None
    info: dict | None = None
    result: StepResult | None = None
    chunks: Iterator | None = None
    columns: dict | None = field(default=None, repr=False)

    def iter_chunks(self):
        """The rows as dicts of column arrays, whatever the path: the stepped paths' chunks, or one chunk
        of the in-memory solve (the same columns, :data:`ipmc_asym.dynamics.drive.DRIVE_COLUMNS` and the
        checks, with its stated errors :data:`ERROR_COLUMNS` and ``warnings``)."""
        if self.chunks is not None:
            yield from self.chunks
            return
        if self.columns is not None:
            yield self.columns
            return
        r = self.result
        ch = {c: np.asarray(getattr(r, c), dtype=float) for c in DRIVE_COLUMNS}
        for c in CHECKS:
            ch[f"check_{c}"] = np.asarray(r.checks[c], dtype=float)
        ch["valid"] = np.asarray(r.valid, dtype=float)
        nan = np.full(r.t.shape, np.nan)
        for c in ERROR_COLUMNS:
            v = getattr(r, c)
            ch[c] = nan if v is None else np.asarray(v, dtype=float)
        ch["warnings"] = list(r.warnings)
        yield ch

    def _arrays(self):
        if self.result is not None:
            return self.result._arrays()
        if self.columns is None:
            raise ValueError("a streamed time response has no rows in memory: read its chunks, or call "
                             "time_response(..., stream=False)")
        spec = self._result
        cols = {spec.names.get(k, k): np.asarray(self.columns[k]) for k in spec.fields if k in self.columns}
        return spec.dim, np.asarray(self.columns["t"]), cols


def stated_tol(tol, *, fidelity="circuit", points: int = 1000, sheet_resistance=0.0, support=None,
               electrode=None):
    """The tolerance a time response runs at: ``tol`` itself, or what ``"auto"`` means for these choices.

    ``"auto"`` is :data:`AUTO_TOL` for the in-memory circuit (its errors stated against a reference PNP
    run) and ``None`` where no tolerance applies: the PNP (it states its own errors, at its default
    1e-6), the electrode line (its discretisation error is stated), a clamped-clamped support or a
    partial electrode (only the stepped circuit has them), and more than
    :data:`~ipmc_asym.dynamics.drive.MAX_STATED_POINTS` output times (the reference PNP run keeps every
    time's profiles in memory).

    Returns
    -------
    tol : float or None
    note : str or None
        Why ``"auto"`` states no circuit error here (``None`` where it does, or where another error is
        stated).
    """
    if not (isinstance(tol, str) and tol == "auto"):
        return tol, None
    if fidelity == "pnp" or float(sheet_resistance) > 0.0:
        return None, None
    if support == "clamped-clamped" or electrode is not None:
        return None, ("circuit: no error stated against the PNP: a clamped-clamped support or a partial electrode "
                      "is stepped by the reduced circuit only")
    if points > MAX_STATED_POINTS:
        return None, (f"circuit: no error stated against the PNP: {points} output times are more than the "
                      f"{MAX_STATED_POINTS} a reference PNP run keeps in memory (--points {MAX_STATED_POINTS} or "
                      f"fewer states it)")
    return AUTO_TOL, None


def time_path(*, fidelity="circuit", tol=None, beam=DEFAULT_BEAM, sheet_resistance=0.0, support=None,
              electrode=None, stream=False, beam_grid="refined") -> str:
    """The solver :func:`time_response` runs for these choices (one of :data:`TIME_PATHS`).

    The electrode line when ``sheet_resistance > 0``; the stepped uniform strip for a support other
    than the free/blocked tip pair or a partial electrode (only that stepper has them), or when the
    rows are streamed at circuit fidelity without a tolerance (with the dynamic beam only on the
    output grid, ``beam_grid="output"``); the in-memory solve otherwise (PNP, a tolerance, the dynamic
    beam on its refined grid).  The stepped paths are the reduced circuit: ``fidelity="pnp"`` or a
    ``tol`` with them is refused (``ValueError``).
    """
    check_choice("fidelity", fidelity, STEP_FIDELITIES)
    check_choice("beam", beam, BEAM_CHOICES)
    check_choice("beam_grid", beam_grid, BEAM_GRIDS)
    Rs = check_sheet_resistance(sheet_resistance)
    stepped = ("line" if Rs > 0.0 else
               "stream" if support == "clamped-clamped" or electrode is not None else None)
    if stepped is not None:
        what = "sheet_resistance" if stepped == "line" else "support clamped-clamped or a partial electrode"
        for bad, why in ((fidelity != "circuit", f"fidelity {fidelity}"), (tol is not None, "tol")):
            if bad:
                raise ValueError(f"{what} with {why}: only the reduced circuit steps it (the electrode line's "
                                 f"discretisation error is stated); drop {why}")
        return stepped
    if stream and fidelity == "circuit" and tol is None and (beam == "quasi-static" or beam_grid == "output"):
        return "stream"
    return "memory"


def sampling_note(drive: Drive, duration, points: int):
    """A note where the output rows are spaced wider than half a period of the drive's fastest
    component (its ``max_frequency``): each row is the state at its time (the substeps resolve the
    drive, :func:`~ipmc_asym.dynamics.circuit.drive_substep`), but the rows do not trace the
    oscillation between them; None otherwise."""
    f = drive_frequency(drive.function)
    if duration is None or f <= 0.0 or points < 2:
        return None
    dt = float(duration) / (points - 1)
    if dt <= 0.5 / f:
        return None
    need = int(min(2.0 * f * float(duration), 1e18)) + 2
    return (f"output rows every {dt:.3g} s sample the drive's {f:.4g} Hz component below twice a period "
            f"({1.0 / (dt * f):.3g} rows a period): each row is the state at its time, but the rows do not "
            f"trace the oscillation between them (at least {need:.3g} points would)")


def time_response(strip: Strip | None = None, drive=None, *, duration=None, points: int = 1000, model="constant",
                  material: Material | None = None, fidelity="circuit", tol: float | None = None,
                  beam=DEFAULT_BEAM, viscous_modulus=0.0, sheet_resistance=0.0, line_segments=DEFAULT_SEGMENTS,
                  support=None, electrode=None, stream=False, beam_grid="refined", n_modes=TIME_MODES,
                  pnp_options=None, notice=None) -> TimeResponse:
    """Response of the strip to an applied voltage ``phi0(t)``, starting uncharged at t = 0.

    Parameters
    ----------
    strip : Strip, optional
        Geometry (``thickness`` TOTAL 2e, ``width`` TOTAL 2l, ``length``, m); its ``voltage`` (V) is
        the step when ``drive`` is not given.
    drive : Drive, float, str or callable, optional
        The voltage: a number (a step, V), a waveform SPEC, a callable ``phi0(t)`` (V) or a
        :class:`Drive`; default a step of ``strip.voltage``.
    duration : float, optional
        End time, s; default ``5 tau`` (``tau = R C_d(0)``).
    points : int
        Output times, equally spaced in ``[0, duration]``; without ``duration``, on the in-memory
        path, 0 then log-spaced from ``1e-4 tau`` to ``5 tau``
        (:func:`ipmc_asym.dynamics.circuit.default_times`: the nonlinear charging ends well before
        ``tau``).
    model, material :
        As in :func:`ipmc_asym.dynamics.circuit.step_response`.
    fidelity : {"circuit", "pnp"} ; tol : float, "auto" or None
        The in-memory solve's rung and tolerance on sigma (:func:`~ipmc_asym.dynamics.circuit.step_response`);
        ``"auto"``: :data:`AUTO_TOL` where the circuit's error can be stated, none elsewhere (:func:`stated_tol`,
        its reason in the notes); None: the circuit states no error (the PNP its own at 1e-6).
    beam : {"quasi-static", "dynamic"}
        Default :data:`DEFAULT_BEAM`; ``viscous_modulus`` (Pa s) and ``n_modes`` with ``dynamic``.
    sheet_resistance : float
        Of each electrode, Ohm/sq; > 0: the electrode line of ``2 line_segments`` segments (its error
        from ``line_segments``).
    support, electrode :
        As in :func:`ipmc_asym.dynamics.drive.drive_chunks` (the stepped path).
    stream : bool
        The caller takes the rows chunk by chunk (``.chunks``, memory independent of ``points``)
        where a stepped path serves; the in-memory solve is used otherwise (see :func:`time_path`).
    beam_grid : {"refined", "output"}
        How the dynamic beam meets the output grid (:data:`BEAM_GRIDS`).
    pnp_options : dict, optional
        The PNP solver's options (in-memory path).
    notice : callable, optional
        In-memory path: called with no argument just before the PNP solver starts (the long
        part; :func:`~ipmc_asym.dynamics.circuit.step_response`), never ahead of a refusal.

    Returns
    -------
    TimeResponse
        ``path`` says which solver ran; ``result`` (a :class:`~ipmc_asym.dynamics.circuit.StepResult`),
        ``chunks`` or ``columns`` hold the rows.
    """
    s = Strip() if strip is None else strip
    m = NAFION_LI if material is None else material
    d = Drive.step(s.voltage) if drive is None else Drive(drive)
    auto = isinstance(tol, str) and tol == "auto"
    tol, why = stated_tol(tol, fidelity=fidelity, points=points, sheet_resistance=sheet_resistance, support=support,
                          electrode=electrode)
    path = time_path(fidelity=fidelity, tol=tol, beam=beam, sheet_resistance=sheet_resistance, support=support,
                     electrode=electrode, stream=stream, beam_grid=beam_grid)
    if path == "memory":
        # step_response reads the step's height from its first argument, a waveform from waveform_kind
        kind = "step" if d.kind == "step" else d.source
        args = (d.voltage if d.kind == "step" else s.voltage, duration)
        kw = dict(strip=s, model=model, fidelity=fidelity, material=m, points=points, waveform_kind=kind, beam=beam,
                  viscous_modulus=viscous_modulus, n_modes=n_modes, pnp_options=pnp_options, notice=notice)
        if auto and tol is not None:  # the reference's cost capped (pnp_options may set its own cap)
            kw["pnp_options"] = {"max_work": AUTO_WORK, **(pnp_options or {})}
        try:
            r = step_response(*args, tol=tol, **kw)
        except (ValueError, ReferenceFailed) as ex:
            if not auto or tol is None:
                raise
            # "auto" asked for an error where one can be stated: where the reference PNP run itself
            # refuses the strip (e.g. layers that fill a 1 um strip at 20 V), fails, or would cost more
            # than its cap, the circuit as it is, said
            cap = kw["pnp_options"].get("max_work")
            r = step_response(*args, tol=None, **dict(kw, pnp_options=pnp_options))
            # the general "no tolerance" note gives way to the reason below (the run asked for one)
            r.notes = [n for n in r.notes if n != CIRCUIT_NO_TOL_NOTE]
            tol, why = None, ("circuit: no error stated against the PNP: " + (
                f"the reference PNP run over this drive would cost more than tol='auto' allows ({cap:.3g} "
                f"cell-evaluations, ~{cap / WORK_PER_SECOND:.0f} s CPU; it grows with the periods and jumps in "
                f"the duration); a tolerance (e.g. --tol 1e-2) runs it whatever it costs" if getattr(ex, "over_budget", False)
                else f"the reference PNP run {'refuses' if isinstance(ex, ValueError) else 'fails in'} this "
                     f"case ({ex})"))
        # the header of the stepped paths, with the run's own notes (what it states and what it leaves out)
        info = dict(drive_info(s, model, m, beam, viscous_modulus), notes=list(r.notes), fidelity=r.fidelity,
                    tol=tol if tol is not None else r.extra.get("tol"), valid_from=r.extra.get("valid_from"))
        for n in (why, sampling_note(d, duration, points)):
            if n is not None:
                r.notes.append(n)
                info["notes"].append(n)
        return TimeResponse(path, d, duration, info=info, result=r)
    # the stepped paths: the uniform strip streams with the quasi-static beam unless the output grid
    # carries the modes (time_path); the line and the supports with either beam
    vm = viscous_modulus
    line = dict(sheet_resistance=sheet_resistance, line_segments=line_segments)
    where = {} if support is None and electrode is None else {"support": support, "electrode": electrode}
    info = drive_info(s, model, m, beam, vm, **line, **where)
    if why is not None:
        info["notes"].append(why)
    dur = float(duration) if duration is not None else DEFAULT_SPAN * info["tau"]
    if (n := sampling_note(d, dur, points)) is not None:
        info["notes"].append(n)
    kw = dict(strip=s, model=model, material=m, beam=beam, viscous_modulus=vm, n_modes=n_modes, **line, **where)
    if duration is None and d.kind == "step":  # the in-memory step's default window (circuit.default_times)
        grid = default_times(info["tau"], points)
        kw["times"] = grid.__getitem__
    if stream:
        return TimeResponse(path, d, dur, info=info, chunks=drive_chunks(d.function, dur, points, **kw))
    return TimeResponse(path, d, dur, info=info, columns=drive_response(d.function, dur, points, **kw))


def spectrum(f, strip: Strip | None = None, *, model="constant", material: Material | None = None,
             method=None, beam=DEFAULT_BEAM, viscous_modulus=0.0, voltage=0.0, sheet_resistance=None,
             support=None, electrode=None):
    """Small-signal impedance and transfer functions of the strip at frequencies ``f`` (Hz).

    The electrode line (:func:`ipmc_asym.dynamics.line.line_response`) when ``sheet_resistance`` is
    given (Ohm/sq, >= 0; 0 is the uniform strip exactly), else the uniform strip
    (:func:`ipmc_asym.dynamics.circuit.frequency_response`, with ``support``/``electrode``).

    Parameters
    ----------
    f : array_like (n,)
        Frequencies, Hz, > 0.
    strip, model, material, method, beam, viscous_modulus, voltage :
        As in :func:`~ipmc_asym.dynamics.circuit.frequency_response` (``voltage``: DC bias, V, with
        ``method="circuit"``); ``method`` None: ``pnp-linear`` (the reference) at 0 V, ``circuit`` (the
        method that supports a bias) with a ``voltage``; ``beam`` default :data:`DEFAULT_BEAM`.
    sheet_resistance : float, optional
    support, electrode :
        Supports of the uniform strip only (``ValueError`` with a sheet resistance).

    Returns
    -------
    FrequencyResult or LineResult
    """
    if method is None:  # the reference where it applies, else the method that supports the bias
        method = "pnp-linear" if float(voltage) == 0.0 else "circuit"
    check_choice("method", method, FREQ_METHODS)
    check_choice("beam", beam, BEAM_CHOICES)
    if sheet_resistance is not None:
        if support == "clamped-clamped" or electrode is not None:
            what = "support clamped-clamped" if support == "clamped-clamped" else "a partial electrode"
            raise ValueError(f"sheet_resistance: {what} is not supported with the electrode line (its moment is "
                             "distributed over the full strip, clamped-free and clamped-pinned)")
        return line_response(f, strip=strip, model=model, material=material, method=method,
                             sheet_resistance=sheet_resistance, beam=beam, viscous_modulus=viscous_modulus,
                             voltage=voltage)
    where = {} if support is None and electrode is None else {"support": support, "electrode": electrode}
    return frequency_response(f, strip=strip, model=model, material=material, method=method, beam=beam,
                              viscous_modulus=viscous_modulus, voltage=voltage, **where)
