"""Voltage waveforms ``phi0(t)``: a small text grammar, sums of terms, and a measured CSV.

``SPEC`` is one or more terms joined by ``+`` (volts and seconds/hertz with units, as on the
command line)::

    dc:V                    constant V (from t = 0)
    step:V[@T0]             V from T0 (default 0)
    ramp:V/TR[@T0]          0 -> V linearly over TR from T0, then V
    sine:V@F[,PHASE]        V sin(2 pi F t + PHASE)            (PHASE in degrees, default 0)
    square:V@F              V sign(sin(2 pi F t))              (bipolar, +V first)
    triangle:V@F            bipolar triangle of amplitude V, in phase with the sine
    csv:PATH                measured (t, V) columns, linear between samples, held outside

e.g. ``dc:0.2V+sine:0.5V@10Hz`` or ``step:1V+square:0.1V@50Hz``.  :func:`parse_waveform`
returns a vectorised callable (volts); any Python callable ``f(t)`` is accepted by the dynamic
functions as well.  ``parse_waveform(spec, quantity="length")`` reads the same grammar with
lengths (``sine:1mm@0.01Hz``, ``step:0.5mm``; a bare number is metres): the imposed tip
displacement of sensing.  :meth:`Waveform.derivative` and :meth:`Waveform.jumps` give the regular
part of its time derivatives and its discontinuities (the streaming EMF of sensing needs them).
"""

from __future__ import annotations

import csv
import io
import math
import os
import re

import numpy as np

from ipmc_asym.base.inputs import read_input_text
from ipmc_asym.base.settings import FREQUENCY_RANGE, MIN_TIME
from ipmc_asym.base.units import parse_length, parse_quantity, parse_time, parse_voltage
from ipmc_asym.model.params import check_finite, check_voltage_cap

__all__ = ["Waveform", "parse_waveform", "WAVEFORM_KINDS", "MAX_CSV_ROWS", "voltage_rate", "check_time_span"]

WAVEFORM_KINDS = ("dc", "step", "ramp", "sine", "square", "triangle", "csv")

#: a measured waveform is held in memory: at most this many samples
MAX_CSV_ROWS = 10_000_000


def _freq(name, text):
    v = parse_quantity(name, text, {"Hz": 1.0, "kHz": 1e3, "mHz": 1e-3, "MHz": 1e6}, "frequency")
    if not v > 0:
        raise ValueError(f"{name} must be > 0 Hz; got {text!r}")
    lo, hi = FREQUENCY_RANGE  # its period a normal float, at least MIN_TIME
    if not lo <= v <= hi:
        raise ValueError(f"the frequency must be within {lo:g}..{hi:g} Hz (settings.FREQUENCY_RANGE, a numerical "
                         f"guard); got {text.strip()!r}")
    return v


def check_time_span(name, value) -> float:
    """``value`` (s) a finite time of at least :data:`~ipmc_asym.base.settings.MIN_TIME` (a ramp time, a
    duration), else a one-line ``ValueError`` naming ``name``."""
    v = check_finite(name, value, "a finite time in seconds")
    if not v >= MIN_TIME:
        raise ValueError(f"{name} must be at least {MIN_TIME:g} s (settings.MIN_TIME, a numerical guard: the period "
                         f"of the highest frequency settings.FREQUENCY_RANGE accepts); got {value!r}")
    return v


class Waveform:
    """A sum of terms, callable on an array of times (s) -> volts; ``spec`` is the text it was read from.

    Attributes
    ----------
    spec : str ; terms : list of (kind, params) ; max_frequency : float (Hz, 0 if none)
    """

    def __init__(self, spec, terms):
        self.spec = spec
        self.terms = terms
        self.max_frequency = max((p["f"] for k, p in terms if "f" in p), default=0.0)

    def __call__(self, t):
        t = np.asarray(t, dtype=float)
        v = np.zeros(t.shape)
        for kind, p in self.terms:
            v = v + _term(kind, p, t)
        return v

    def __repr__(self):
        return f"Waveform({self.spec!r})"

    def derivative(self, t, order=1):
        """Regular part of the ``order``-th time derivative (1 or 2) at ``t``: the jumps of step and
        square terms and the corners of ramp, triangle and csv terms are left out (their deltas live
        at isolated instants; :meth:`jumps` lists the jumps)."""
        t = np.asarray(t, dtype=float)
        d = np.zeros(t.shape)
        for kind, p in self.terms:
            d = d + _term_derivative(kind, p, t, order)
        return d

    def jumps(self, t0, t1):
        """``(times, sizes)`` of the discontinuities in ``(t0, t1]`` (sorted; steps after 0 and square flips)."""
        out = {}
        for kind, p in self.terms:
            if kind == "step" and t0 < p["t0"] <= t1:
                out[p["t0"]] = out.get(p["t0"], 0.0) + p["V"]
            elif kind == "square":
                f, ph = p["f"], p.get("phase", 0.0) / 360.0
                n0 = math.floor(2.0 * (f * t0 + ph)) + 1
                n1 = math.floor(2.0 * (f * t1 + ph))
                if n1 - n0 + 1 > MAX_CSV_ROWS:
                    raise ValueError(f"square term: more than {MAX_CSV_ROWS} flips in the duration")
                for n in range(n0, n1 + 1):
                    tj = (0.5 * n - ph) / f
                    if t0 < tj <= t1:
                        out[tj] = out.get(tj, 0.0) + (2.0 * p["V"] if n % 2 == 0 else -2.0 * p["V"])
        ts = np.array(sorted(out))
        return ts, np.array([out[x] for x in ts])


def _term(kind, p, t):
    V = p.get("V", 0.0)
    if kind == "dc":
        return np.full(t.shape, V)
    if kind == "step":
        return np.where(t >= p["t0"], V, 0.0)
    if kind == "ramp":
        return V * np.clip((t - p["t0"]) / p["tr"], 0.0, 1.0)
    if kind == "csv":
        return np.interp(t, p["t"], p["v"])
    x = p["f"] * t + p.get("phase", 0.0) / 360.0  # cycles
    if kind == "sine":
        return V * np.sin(2.0 * math.pi * x)
    frac = x - np.floor(x)
    if kind == "square":
        return np.where(frac < 0.5, V, -V)
    # triangle: 0 -> V at a quarter period, -V at three quarters, in phase with the sine
    return V * np.where(frac < 0.25, 4.0 * frac, np.where(frac < 0.75, 2.0 - 4.0 * frac, 4.0 * frac - 4.0))


def _term_derivative(kind, p, t, order):
    V = p.get("V", 0.0)
    if kind in ("dc", "step", "square"):
        return np.zeros(t.shape)
    if kind == "ramp":
        inside = (t >= p["t0"]) & (t < p["t0"] + p["tr"])
        return np.where(inside, V / p["tr"], 0.0) if order == 1 else np.zeros(t.shape)
    if kind == "csv":
        if order != 1:
            return np.zeros(t.shape)
        tp, vp = p["t"], p["v"]
        i = np.clip(np.searchsorted(tp, t, side="right") - 1, 0, tp.size - 2)
        slope = (vp[i + 1] - vp[i]) / (tp[i + 1] - tp[i])
        return np.where((t >= tp[0]) & (t < tp[-1]), slope, 0.0)
    w = 2.0 * math.pi * p["f"]
    x = p["f"] * t + p.get("phase", 0.0) / 360.0
    if kind == "sine":
        return V * w**order * np.sin(2.0 * math.pi * x + 0.5 * math.pi * order)
    # triangle: slope +-4 V f, no curvature between corners
    if order != 1:
        return np.zeros(t.shape)
    frac = x - np.floor(x)
    return np.where((frac < 0.25) | (frac >= 0.75), 4.0 * V * p["f"], -4.0 * V * p["f"])


def _read_csv(path, parse_value=parse_voltage):
    if not os.path.exists(path):
        raise ValueError(f"waveform csv: no such file {path!r}")
    ts, vs = [], []
    try:
        text = read_input_text(path, "waveform csv")
    except (OSError, UnicodeDecodeError) as exc:
        raise ValueError(f"waveform csv {path!r}: cannot read ({exc.__class__.__name__}: {exc})") from None
    with io.StringIO(text, newline="") as fh:
        reader = csv.reader(fh)
        try:
            rows = list(reader)
        except csv.Error as exc:  # e.g. a field above the csv module's limit (131072 characters)
            raise ValueError(f"waveform csv {path!r} line {reader.line_num}: cannot read ({exc})") from None
        for i, row in enumerate(rows):
            if not row or row[0].lstrip().startswith("#"):
                continue
            if len(row) < 2:
                raise ValueError(f"waveform csv {path!r} line {i + 1}: needs two columns t, V")
            try:
                t = parse_time("waveform csv t", row[0].strip())
                v = parse_value("waveform csv V", row[1].strip())
            except ValueError:
                if not ts and i == 0:
                    continue  # header row
                raise ValueError(f"waveform csv {path!r} line {i + 1}: cannot read t, V from {row[:2]!r}") from None
            ts.append(t)
            vs.append(v)
            if len(ts) > MAX_CSV_ROWS:
                raise ValueError(f"waveform csv {path!r}: more than {MAX_CSV_ROWS} samples")
    t = np.asarray(ts)
    if t.size < 2 or np.any(np.diff(t) <= 0):
        raise ValueError(f"waveform csv {path!r}: needs >= 2 rows with strictly increasing times")
    return t, np.asarray(vs)


_TERM = re.compile(r"^\s*([a-z]+)\s*:\s*(.+?)\s*$", re.IGNORECASE)


def parse_waveform(spec, quantity="voltage") -> Waveform:
    """Read a waveform ``SPEC`` (module docstring); ``ValueError`` naming the bad term.

    ``quantity``: ``"voltage"`` (volts, capped at the drive's voltage) or ``"length"`` (metres, the
    imposed tip displacement of sensing; its caps are the caller's: the static sense's limits).

    >>> parse_waveform("dc:0.2V+sine:0.5V@10Hz")(np.array([0.025]))
    array([0.7])
    """
    if isinstance(spec, Waveform):
        return spec
    if quantity not in ("voltage", "length"):
        raise ValueError(f"quantity must be voltage or length; got {quantity!r}")
    unit = "V" if quantity == "voltage" else "mm"
    if not isinstance(spec, str) or not spec.strip():
        raise ValueError(f"waveform must be a SPEC such as 'sine:1{unit}@10Hz' or 'step:1{unit}+square:0.1{unit}@50Hz'")
    parse_value = parse_voltage if quantity == "voltage" else parse_length
    parts = [p for p in re.split(r"\+(?=\s*[a-zA-Z]+\s*:)", spec) if p.strip()]
    terms = []
    for part in parts:
        m = _TERM.match(part)
        if not m:
            raise ValueError(f"waveform term {part!r}: expected KIND:ARGS with KIND one of {', '.join(WAVEFORM_KINDS)}")
        kind, arg = m.group(1).lower(), m.group(2)
        name = f"waveform term {part.strip()!r}"
        try:
            if kind == "csv":
                t, v = _read_csv(arg, parse_value)
                terms.append((kind, {"t": t, "v": v}))
                continue
            if kind not in WAVEFORM_KINDS:
                raise ValueError(f"kind must be one of {', '.join(WAVEFORM_KINDS)}")
            if kind in ("dc",):
                terms.append((kind, {"V": parse_value(name, arg)}))
            elif kind == "step":
                a, _, t0 = arg.partition("@")
                terms.append((kind, {"V": parse_value(name, a), "t0": parse_time(name, t0) if t0 else 0.0}))
            elif kind == "ramp":
                a, _, rest = arg.partition("/")
                tr, _, t0 = rest.partition("@")
                if not tr:
                    raise ValueError("ramp needs V/TR, e.g. ramp:1V/0.1s")
                trv = check_time_span("the ramp time TR", parse_time(name, tr))
                terms.append((kind, {"V": parse_value(name, a), "tr": trv, "t0": parse_time(name, t0) if t0 else 0.0}))
            else:
                a, _, rest = arg.partition("@")
                if not rest:
                    raise ValueError(f"{kind} needs V@F, e.g. {kind}:1{unit}@10Hz")
                fq, _, ph = rest.partition(",")
                p = {"V": parse_value(name, a), "f": _freq(name, fq)}
                if ph:
                    if kind != "sine":
                        raise ValueError("a phase is only read for a sine")
                    try:
                        phase = float(ph)
                    except ValueError:
                        phase = math.nan
                    if not math.isfinite(phase):
                        raise ValueError(f"the phase must be a finite number of degrees (e.g. sine:1V@10Hz,90); "
                                         f"got {ph.strip()!r}")
                    p["phase"] = phase
                terms.append((kind, p))
        except ValueError as exc:
            msg = str(exc)
            raise ValueError(msg if msg.startswith("waveform") else f"{name}: {msg}") from None
    peak = sum(abs(p["V"]) if "V" in p else float(np.max(np.abs(p["v"]), initial=0.0)) for _, p in terms)
    if quantity == "voltage":
        check_drive_voltage("waveform", peak)
    return Waveform(spec, terms)


def voltage_rate(fun, t, dt_min: float):
    """``dphi0/dt`` (V/s) at the times ``t`` (s) for the displacement current ``C_g dphi0/dt``.

    A :class:`Waveform` gives the regular part of its derivative (:meth:`Waveform.derivative`);
    any other callable a difference over ``dt = 1e-7 max(t, dt_min)``: central, or one-sided where
    the other side jumps (its value moves by more than 1e-4 of the function's size within ``dt``,
    which a slope the outputs resolve does not; a smooth side taken for one changes the rate by
    ``O(dt)`` only); 0 at ``t = 0``.  A jump's displacement impulse (an ideal step, at 0 or later,
    a square wave's flip) is not a current density: at a jump the rate is the one just after it.
    """
    t = np.asarray(t, dtype=float)
    regular = getattr(fun, "derivative", None)
    if regular is not None:
        return np.asarray(regular(t), dtype=float)
    dt = 1e-7 * np.maximum(t, dt_min)
    f0, fp, fm = (np.asarray(fun(x), dtype=float) for x in (t, t + dt, np.maximum(t - dt, 0.0)))
    size = 1e-4 * np.maximum(np.maximum(np.abs(f0), np.abs(fp)), np.abs(fm))
    jr, jl = np.abs(fp - f0) > size, np.abs(f0 - fm) > size
    right, left = (fp - f0) / dt, (f0 - fm) / dt
    rate = np.where(jl & ~jr, right, np.where(jr & ~jl, left, 0.5 * (right + left)))
    return np.where(t > 0.0, rate, 0.0)


def check_drive_voltage(name, volts) -> float:
    """``volts`` (the largest ``|phi0|`` a drive reaches) as a float, finite and within
    :data:`~ipmc_asym.base.settings.MAX_VOLTAGE`, else a one-line ``ValueError`` naming ``name``."""
    v = check_finite(name, volts, "a finite number of volts")
    check_voltage_cap(v, name)
    return float(volts)
