"""Dynamic calibration: time series and impedance spectra, alone or together with the static rows.

``fit_dynamic([read_file("static.csv"), read_file("step.csv"), read_file("imp.csv")],
"diffusion,c_moy")`` returns the :class:`~ipmc_asym.studies.calibrate.CalibrationResult` of
the static fit (same keys, same honesty: 95 % profile-likelihood intervals, ``status`` ``ok`` /
``at_bound`` / ``not_identifiable``, standard error only where the profile is locally
quadratic, ``chi2_red`` with sigma columns or ``noise_scale`` without; one decision for both,
:func:`ipmc_asym.studies.calibrate._report`).

Kinds of files (the header decides; each file is one kind):

* **static**: the columns of :func:`ipmc_asym.studies.calibrate.read_data` (deflection and/or
  blocking force at rest); the forward model at the cheapest rung of the static ladder.
* **time series** (a ``t`` column, s): the strip from the strip options (TOTAL thickness 2e),
  charged from rest at ``t = 0`` by the drive: a ``voltage`` column (the applied voltage at each
  ``t``, linear between rows and the first row's value from ``t = 0``: a constant column is a
  step of that height at ``t = 0``), or a waveform SPEC
  (:func:`ipmc_asym.dynamics.waveforms.parse_waveform`, ``--waveform``).  Measured, signed:
  ``current`` (A, total current into the face at ``phi0``), ``charge`` (C, charge of that
  face), ``deflection`` (m, tip deflection, positive in the direction a positive voltage bends
  the strip, i.e. ``-w``), ``blocking_force`` (N, positive for a positive voltage).  The model is
  :func:`ipmc_asym.dynamics.circuit.step_response` (reduced circuit or PNP, quasi-static or
  dynamic beam; the mechanics through the forward model).
* **impedance spectrum** (an ``f`` column, Hz): ``Z_re, Z_im`` (Ohm, the strip's impedance,
  ``Z_im < 0`` for a capacitive strip) or ``Z_abs`` (Ohm), ``Z_phase`` (degrees), about 0 V.
  The model is :func:`ipmc_asym.dynamics.line.line_response` on the linearised PNP (the exact
  closed form: the reference rung), with the electrodes' sheet resistance (0: ideal, exactly
  :func:`ipmc_asym.dynamics.circuit.frequency_response`).

* **sensing** (a ``t`` column, s; a ``w`` column, m, the imposed tip displacement; one or more of
  ``Q`` (C, charge of the electrode ``z = -e``), ``I`` (A, current through the load, ``-dQ/dt``),
  ``V`` (V, across the load)): the strip of the strip options at rest before ``t = 0``, its tip
  moved along ``w(t)`` (linear between rows, the first row's value from ``t = 0``), the electrodes
  on the load of the ``load`` setting (``--load``: ``short``, the default without a ``V`` column;
  ``open``, ``V`` only; a resistance).  The rows lie on a uniform grid ``t = k dt`` from 0 (the
  model's output grid: no interpolation of the prediction).  The model is
  :func:`ipmc_asym.dynamics.sensing_time.sensing_transient` (one rung; its stated error is the
  model error).  The columns ``sense --waveform --out`` writes besides these (``kappa``, ``emf``,
  ``power``, ``check_*``, ``valid``, ``model``) are the model's own and skipped.

Optional ``sigma_<column>`` (one standard deviation, same unit; ``sigma_Z_phase`` in degrees)
for every measured column of every file, or for none.  Without them one relative noise scale
``s`` is estimated for all values: static values relative to themselves, a time-series column
relative to its root mean square (a current or a charge passes through 0), ``Z_re``/``Z_im``
relative to ``|Z|`` of the row, ``Z_abs`` to itself and ``Z_phase`` in radians (``d ln Z =
d ln|Z| + i d phase``).

What sees what (:data:`ipmc_asym.studies.calibrate.VISIBLE_TO`): ``diffusion`` needs a time
series or a spectrum, ``viscous_modulus`` a time series of deflection or force with the
dynamic beam, ``sheet_resistance`` a spectrum (the electrode line exists in the frequency
domain only), ``modulus`` deflection or force data; a parameter the data given cannot see is
refused before any work, in one line naming the data that would identify it.  What the data
then determine is the profile's answer: a spectrum sees ``eps0`` and ``deps`` through
``eps_moy = eps0 + deps`` (about 0 V the layers linearise about the core; the split moves ``Z``
by ~1e-5 relative), so both free on a spectrum alone are ``not_identifiable``.

Fidelity: static rows climb the static ladder as in the static fit; time series start with the
reduced circuit, whose error at the optimum is its difference from the PNP solver run at a
hundredth of the data's relative noise plus that run's own estimate; they escalate to the PNP
rung where that error is not below a tenth of the data's noise at every value or shifts an
estimate by more than a tenth of its standard error.  The PNP rung's optimum is found by defect
correction of the circuit (:func:`_defect_solve`: a handful of PNP runs, not one per model
evaluation), its profile-interval ends checked with the PNP (:func:`_check_ends`).
Time series with the linear model are refused: its current stops abruptly when the anode
layer saturates, the circuit misplaces that stop by more than a tenth of a 5 % noise, and on
the PNP rung (:mod:`ipmc_asym.dynamics.transient` solves the linear model) a round trip took
minutes and was not validated.  Spectra are computed by the exact linearised PNP (rounding error only).

Outside every dynamic model (stated in the result's message): water transport and the
back-relaxation it causes; spectra are small signals about 0 V.

Layer rule: studies, after :mod:`ipmc_asym.studies.calibrate`; SciPy deferred.
"""

from __future__ import annotations

import itertools
import math
import os
from dataclasses import dataclass, replace

import numpy as np

from ipmc_asym.base.units import parse_force, parse_length, parse_quantity, parse_time, parse_voltage
from ipmc_asym.beam.dynamics import CLAMPED_OUTPUTS, Beam, natural_frequencies, viscous_modulus_from_damping_ratio
from ipmc_asym.dynamics.circuit import WATER_NOTE, step_response
from ipmc_asym.dynamics.line import line_response
from ipmc_asym.dynamics.sensing import WATER_ASSUMPTION
from ipmc_asym.dynamics.waveforms import Waveform, parse_waveform
from ipmc_asym.forward.sensing import DEFAULT_NU, SENSE_SUPPORTS
from ipmc_asym.model.params import NAFION_LI, Material, Strip
from ipmc_asym.model.permittivity import get_model
from ipmc_asym.parallel.executors import run_chunks
from ipmc_asym.studies.calibrate import (
    MAX_DATA_ROWS,
    CalibrationData,
    CalibrationResult,
    MeasuredColumns,
    _interval_scale,
    _log_covariance,
    _material,
    _multistart_task,
    _perm,
    _Problem,
    _report,
    _solve,
    _start_values,
    check_count,
    check_stiffness_free,
    check_visible,
    free_warnings,
    multistart_starts,
    parse_free,
    predict,
    read_data,
    read_rows,
    static_ladder,
)
from ipmc_asym.studies.calibrate import (
    fit as fit_static,
)

__all__ = ["TIME_MEASURED", "IMPEDANCE_MEASURED", "SENSING_MEASURED", "TimeData", "ImpedanceData", "SensingData",
           "read_file", "fit_dynamic", "fit",
           "predict_time", "predict_impedance", "predict_sensing", "TIME_FIDELITIES"]

#: measured columns of a time series -> unit (signed values)
TIME_MEASURED = {"current": "A", "charge": "C", "deflection": "m", "blocking_force": "N"}
#: measured columns of a sensing time series -> unit (signed; the sensing module's conventions)
SENSING_MEASURED = {"Q": "C", "I": "A", "V": "V"}
#: columns of ``sense --waveform --out`` that are the model's own: not data
SENSING_IGNORED = ("kappa", "emf", "power", "check_strain", "check_beam_regime", "check_one_way", "valid", "model")
#: measured columns of an impedance spectrum -> unit (pairs: Z_re with Z_im, Z_abs with Z_phase)
IMPEDANCE_MEASURED = {"Z_re": "Ohm", "Z_im": "Ohm", "Z_abs": "Ohm", "Z_phase": "deg"}
#: columns of a ``step --out`` / ``drive --out`` CSV -> (the fit's column, factor): read as they are
#: (``"area"``: per electrode area, multiplied by the strip's ``2l L``; ``w`` is the paper's signed
#: deflection, negative where a positive voltage bends the strip, the fit's ``deflection`` its opposite)
STEP_FILE_COLUMNS = {"phi0": ("voltage", 1.0), "sigma": ("charge", "area"), "current_density": ("current", "area"),
                     "w": ("deflection", -1.0), "F_block": ("blocking_force", 1.0)}
#: columns of those files that are the model's own (stated errors, internal state, checks): not data
STEP_FILE_IGNORED = ("M_A", "theta", "layer_voltage", "sigma_error", "current_error", "w_error", "valid",
                     *CLAMPED_OUTPUTS)
#: the time-domain rungs, cheapest first (dynamics.circuit.STEP_FIDELITIES)
TIME_FIDELITIES = ("circuit", "pnp")

_CURRENT = {"A": 1.0, "mA": 1e-3, "uA": 1e-6, "µA": 1e-6, "nA": 1e-9}
_CHARGE = {"C": 1.0, "mC": 1e-3, "uC": 1e-6, "µC": 1e-6, "nC": 1e-9}
_OHM = {"Ohm": 1.0, "ohm": 1.0, "Ω": 1.0, "kOhm": 1e3, "kohm": 1e3, "kΩ": 1e3, "mOhm": 1e-3, "MOhm": 1e6}
_HZ = {"Hz": 1.0, "kHz": 1e3, "mHz": 1e-3, "MHz": 1e6}
#: the phase of an impedance spectrum: degrees, as every phase the commands read or write; a value may say rad
_DEG = {"deg": 1.0, "°": 1.0, "rad": 180.0 / math.pi}


# ---- data ------------------------------------------------------------------------------------
class _Interp:
    """``phi0(t)`` linear between the measured (t, V) rows, the first value from t = 0, the last held
    (a class, not a closure: a multistart sends the problem to worker processes)."""

    def __init__(self, t, v):
        self.t, self.v = np.asarray(t, float), np.asarray(v, float)

    def __call__(self, t):
        return np.interp(np.asarray(t, dtype=float), self.t, self.v)


@dataclass
class TimeData(MeasuredColumns):
    """A time series (SI).

    Attributes
    ----------
    t : ndarray (n,)           times, s (>= 0, increasing; the strip is at rest at t = 0)
    drive : callable           applied voltage phi0(t), V
    drive_spec : str           what the drive is (the voltage column or the waveform SPEC)
    measured : dict            column -> array (n,), NaN where not measured (signed)
    sigma : dict               column -> array (n,) or None
    source : str
    area : float or None       electrode area 2l L (m^2) that turned a ``step``/``drive --out`` file's
                               per-area columns into totals (None: the file gave totals)
    """

    t: np.ndarray
    drive: object
    drive_spec: str
    measured: dict
    sigma: dict
    source: str = "time series"
    area: float | None = None
    kind = "time"

    @property
    def kinds(self) -> set:
        mech = {"deflection", "blocking_force"} & set(self.measured)
        return ({"time_mech"} if mech else set()) | ({"time"} if set(self.measured) - mech else set())


@dataclass
class ImpedanceData(MeasuredColumns):
    """An impedance spectrum about 0 V (SI; ``Z_phase`` and its sigma in radians).

    Attributes
    ----------
    f : ndarray (n,)     frequencies, Hz
    measured : dict      ``Z_re``, ``Z_im`` or ``Z_abs``, ``Z_phase`` -> array (n,) (Ohm, rad)
    sigma : dict         column -> array (n,) or None
    source : str
    """

    f: np.ndarray
    measured: dict
    sigma: dict
    source: str = "spectrum"
    kind = "impedance"

    @property
    def kinds(self) -> set:
        return {"impedance"}


@dataclass
class SensingData(MeasuredColumns):
    """A sensing time series (SI): the tip displacement imposed, the charge/current/voltage measured.

    Attributes
    ----------
    t : ndarray (n,)        times, s (>= 0, increasing, on the grid ``k dt``; at rest before t = 0)
    w : ndarray (n,)        imposed tip displacement, m
    measured : dict         ``Q`` (C), ``I`` (A), ``V`` (V) -> array (n,), NaN where not measured
    sigma : dict            column -> array (n,) or None
    load : str or float     ``"short"``, ``"open"`` or the load resistance (Ohm)
    support : str           how the tip displacement bends the strip (:data:`SENSE_SUPPORTS`)
    dt : float              the grid step, s ; index : ndarray of int (the rows' grid points)
    nu : float              the drained Poisson ratio when it is not free (an assumption, default 0)
    source : str
    """

    t: np.ndarray
    w: np.ndarray
    measured: dict
    sigma: dict
    load: object = "short"
    support: str = "tip-force"
    dt: float = 1.0
    index: np.ndarray | None = None
    nu: float = DEFAULT_NU
    source: str = "sensing"
    kind = "sensing"

    @property
    def kinds(self) -> set:
        return {"sensing"}

    @property
    def waveform(self) -> Waveform:
        """``w(t)`` as a csv waveform (linear between rows, the first row's value from t = 0)."""
        t, w = self.t, self.w
        if t[0] > 0.0:  # the csv term holds its first value before its first time: make that t = 0 explicit
            t, w = np.concatenate(([0.0], t)), np.concatenate(([w[0]], w))
        return Waveform(f"the file's w column ({self.source})", [("csv", {"t": t, "v": w})])


def _kinds(data) -> set:
    return {"static"} if isinstance(data, CalibrationData) else data.kinds


def _columns(name, rows, allowed):
    header = [h.strip() for h in rows[0]]
    low = {a.lower(): a for a in allowed}
    out = []
    for j, h in enumerate(header, 1):
        k = low.get(h.lower())
        if k is None:
            raise ValueError(f"{name}: unknown column {j} {h!r} in the header; allowed: {', '.join(allowed)}")
        if k in out:
            raise ValueError(f"{name}: column {k!r} appears twice in the header")
        out.append(k)
    if len(rows) < 2:
        raise ValueError(f"{name}: no data rows after the header")
    return out


def _table(name, rows, header, parsers):
    """Parse every cell (empty -> NaN); one line naming the row and column on a bad cell."""
    n = len(rows) - 1
    cols = {h: np.full(n, np.nan) for h in header}
    for i, r in enumerate(rows[1:]):
        rowno = i + 2
        if len(r) != len(header):
            raise ValueError(f"{name} row {rowno}: {len(r)} fields, header has {len(header)}")
        for h, cell in zip(header, r):
            cell = cell.strip()
            if cell == "":
                continue
            try:
                v = parsers[h](h, cell)
            except ValueError as exc:
                raise ValueError(f"{name} row {rowno}, column {h!r}: {exc}") from None
            if not math.isfinite(v):
                raise ValueError(f"{name} row {rowno}, column {h!r}: must be finite; got {cell!r}")
            cols[h][i] = v
    return cols


def _sigmas(name, cols, meas):
    for m in meas:
        s = f"sigma_{m}"
        if s in cols:
            bad = np.isfinite(cols[s]) & ~(cols[s] > 0)
            if np.any(bad):
                raise ValueError(f"{name} row {int(np.argmax(bad)) + 2}, column {s!r}: must be > 0")
            miss = np.isfinite(cols[m]) & ~np.isfinite(cols[s])
            if np.any(miss):
                raise ValueError(f"{name} row {int(np.argmax(miss)) + 2}, column {s!r}: empty where {m} is given")
    sigma = {m: cols.get(f"sigma_{m}") for m in meas}
    if any(s is None for s in sigma.values()) and any(s is not None for s in sigma.values()):
        raise ValueError(f"{name}: give sigma_ columns for every measured column or for none")
    return sigma


def _need(name, cols, col, what):
    if not np.all(np.isfinite(cols[col])):
        i = int(np.argmax(~np.isfinite(cols[col])))
        raise ValueError(f"{name} row {i + 2}, column {col!r}: empty ({what} needs a value in every row)")


def _step_columns(name, rows, base):
    """A CSV of ``step --out`` / ``drive --out`` read as it is: its columns renamed to the fit's
    (:data:`STEP_FILE_COLUMNS`), the per-area ones multiplied by the electrode area ``2l L`` of
    ``base``, ``w`` negated (the fit's deflection is positive where a positive voltage bends the
    strip), the model's own columns (:data:`STEP_FILE_IGNORED`) dropped.  Returns the rows and
    the area used (None: not such a file)."""
    header = [h.strip() for h in rows[0]]
    low = [h.lower() for h in header]
    if not set(low) & {k.lower() for k in STEP_FILE_COLUMNS}:
        return rows, None
    if "model" in low:
        raise ValueError(f"{name}: column 'model': a file of several models (step --model all); write one model "
                         f"per file (--model NAME)")
    base = Strip() if base is None else base
    area = base.width * base.length
    renamed = {k.lower(): v for k, v in STEP_FILE_COLUMNS.items()}
    drop = {k.lower() for k in STEP_FILE_IGNORED}
    keep = [j for j, h in enumerate(low) if h not in drop and not h.startswith("check_")]
    new_header = [renamed.get(low[j], (header[j], 1.0))[0] for j in keep]
    factor = [renamed.get(low[j], (header[j], 1.0))[1] for j in keep]
    out = [new_header]
    for r in rows[1:]:
        row = []
        for j, f in zip(keep, factor):
            cell = r[j].strip() if j < len(r) else ""
            if f != 1.0 and cell != "":
                try:
                    cell = repr(float(cell) * (area if f == "area" else f))
                except ValueError:
                    raise ValueError(f"{name} row {len(out) + 1}, column {header[j]!r}: a number in SI units (as "
                                     f"step/drive --out write it); got {cell!r}") from None
            row.append(cell)
        if len(r) != len(header):
            raise ValueError(f"{name} row {len(out) + 1}: {len(r)} fields, header has {len(header)}")
        out.append(row)
    return out, area


def _read_time(name, rows, header, waveform, base=None):
    rows, area = _step_columns(name, rows, base)
    allowed = ["t", "voltage"] + list(TIME_MEASURED) + [f"sigma_{m}" for m in TIME_MEASURED]
    header = _columns(name, rows, allowed)
    unit = {"current": lambda c, x: parse_quantity(c, x, _CURRENT, "current"),
            "charge": lambda c, x: parse_quantity(c, x, _CHARGE, "charge"),
            "deflection": parse_length, "blocking_force": parse_force}
    parsers = {"t": parse_time, "voltage": parse_voltage,
               **unit, **{f"sigma_{m}": unit[m] for m in TIME_MEASURED}}
    cols = _table(name, rows, header, parsers)
    _need(name, cols, "t", "the time")
    t = cols["t"]
    if t[0] < 0 or np.any(np.diff(t) <= 0):
        i = int(np.argmax(np.diff(t) <= 0)) + 3 if t[0] >= 0 else 2
        raise ValueError(f"{name} row {i}, column 't': times must be >= 0 s and strictly increasing (the strip is "
                         f"at rest at t = 0)")
    meas = [m for m in TIME_MEASURED if m in header]
    if not meas:
        raise ValueError(f"{name}: no measured column; a time series needs current, charge, deflection and/or "
                         f"blocking_force")
    if all(not np.any(np.isfinite(cols[m])) for m in meas):
        raise ValueError(f"{name}: no measured value in any row")
    if "voltage" in header and waveform is not None:
        raise ValueError(f"{name}: the drive is given twice (a voltage column and --waveform); keep one")
    if "voltage" in header:
        _need(name, cols, "voltage", "the drive")
        drive, spec = _Interp(t, cols["voltage"]), "the file's voltage column (linear between rows, from t = 0)"
        if np.all(cols["voltage"] == cols["voltage"][0]):
            spec = f"a step of {cols['voltage'][0]:g} V at t = 0"
        peak = float(np.max(np.abs(cols["voltage"])))
    elif waveform is not None:
        drive = parse_waveform(waveform)
        spec = f"waveform {drive.spec}"
        peak = float(np.max(np.abs(drive(np.linspace(0.0, float(t[-1]), 4097)))))
    else:
        raise ValueError(f"{name}: a time series needs its drive: a voltage column (V at each t) or --waveform SPEC")
    if peak == 0.0:
        raise ValueError(f"{name}: the drive is 0 V at every time: nothing charges or bends")
    sigma = _sigmas(name, cols, meas)
    measured = {m: cols[m] for m in meas}
    if "current" in measured and t[0] == 0.0 and np.isfinite(measured["current"][0]):
        # the current at the step's jump instant is not compared: the model's is the layers'
        # initial spike, which the PNP withholds where it diverges with the mesh (no error can be
        # stated), and a measurement's is the instrument's rise time
        measured["current"] = measured["current"].copy()
        measured["current"][0] = np.nan
        if not np.any(np.isfinite(measured["current"])) and len(meas) == 1:
            raise ValueError(f"{name}: the current is measured at t = 0 only (the step's jump, not compared)")
    return TimeData(t=t, drive=drive, drive_spec=spec, measured=measured, sigma=sigma, source=name, area=area)


def _load_setting(name, load):
    if load is None or (isinstance(load, str) and load.strip().lower() in ("short", "open")):
        return None if load is None else load.strip().lower()
    if isinstance(load, bool) or not isinstance(load, (int, float, np.floating, np.integer)) or not (
            math.isfinite(float(load)) and float(load) > 0):
        raise ValueError(f"{name}: load must be short, open or a resistance > 0 Ohm; got {load!r}")
    return float(load)


def _read_sensing(name, rows, load, support, base):
    from ipmc_asym.dynamics.sensing_time import MAX_SENSE_POINTS  # deferred: SciPy (start-up)

    header = [h.strip() for h in rows[0]]
    low = [h.lower() for h in header]
    if "model" in low:  # sense --out's model column: one model is data of that model, several are not one strip
        j = low.index("model")
        if len({r[j].strip() for r in rows[1:] if j < len(r)}) > 1:
            raise ValueError(f"{name}: column 'model': a file of several models (sense --model all); write one model "
                             f"per file (--model NAME)")
    drop = {k.lower() for k in SENSING_IGNORED}
    keep = [j for j, h in enumerate(header) if h.lower() not in drop and not h.lower().startswith("check_")]
    if len(keep) < len(header):
        rows = [[r[j] if j < len(r) else "" for j in keep] if len(r) == len(header) else r for r in rows]
    allowed = ["t", "w"] + list(SENSING_MEASURED) + [f"sigma_{m}" for m in SENSING_MEASURED]
    header = _columns(name, rows, allowed)
    unit = {"Q": lambda c, x: parse_quantity(c, x, _CHARGE, "charge"),
            "I": lambda c, x: parse_quantity(c, x, _CURRENT, "current"), "V": parse_voltage}
    parsers = {"t": parse_time, "w": parse_length, **unit, **{f"sigma_{m}": unit[m] for m in SENSING_MEASURED}}
    cols = _table(name, rows, header, parsers)
    _need(name, cols, "t", "the time")
    _need(name, cols, "w", "the imposed tip displacement")
    t, w = cols["t"], cols["w"]
    if t[0] < 0 or np.any(np.diff(t) <= 0):
        i = int(np.argmax(np.diff(t) <= 0)) + 3 if t[0] >= 0 else 2
        raise ValueError(f"{name} row {i}, column 't': times must be >= 0 s and strictly increasing (the strip is "
                         f"at rest before t = 0)")
    meas = [m for m in SENSING_MEASURED if m in header]
    if not meas:
        raise ValueError(f"{name}: no measured column; sensing data need Q (C), I (A) and/or V (V) besides t and w")
    if all(not np.any(np.isfinite(cols[m])) for m in meas):
        raise ValueError(f"{name}: no measured value in any row")
    meas = [m for m in meas if np.any(np.isfinite(cols[m]))]  # an empty column measured nothing
    L = (Strip() if base is None else base).length
    big = np.abs(w) >= L
    if np.any(big):
        raise ValueError(f"{name} row {int(np.argmax(big)) + 2}, column 'w': |w| = {abs(w[np.argmax(big)]):.4g} m is not "
                         f"below the strip length {L:.4g} m; w is in metres (or give a unit: 1mm)")
    if not np.any(w != 0.0):
        raise ValueError(f"{name}: w is 0 in every row: nothing bends the strip")
    # the model's output grid is uniform from t = 0; the rows must lie on it (no interpolation of the model)
    steps = np.diff(np.concatenate(([0.0], t)))
    dt = float(np.min(steps[steps > 0]))
    k = t / dt
    off = np.abs(k - np.round(k)) > 1e-6 * np.maximum(1.0, k)
    if np.any(off):
        raise ValueError(f"{name} row {int(np.argmax(off)) + 2}, column 't': sensing rows must lie on a uniform grid "
                         f"t = k dt from 0 (dt = {dt:.6g} s here, the smallest step); resample the file")
    points = int(round(t[-1] / dt)) + 1
    if points > MAX_SENSE_POINTS:
        raise ValueError(f"{name}: the grid t = k dt up to {t[-1]:.6g} s has {points} points (at most "
                         f"{MAX_SENSE_POINTS}); resample the file")
    load = _load_setting(name, load)
    if load is None:
        if "V" in meas:
            raise ValueError(f"{name}: a V column needs its load: --load open (open-circuit voltage) or --load OHMS")
        load = "short"
    if load == "open" and set(meas) & {"Q", "I"}:
        raise ValueError(f"{name}: Q or I in open circuit (--load open) are 0; open-circuit data are a V column")
    if load == "short" and "V" in meas:
        raise ValueError(f"{name}: V across a short circuit is 0; give --load open or --load OHMS for a V column")
    support = "tip-force" if support is None else support
    if support not in SENSE_SUPPORTS:
        raise ValueError(f"{name}: support must be one of {', '.join(SENSE_SUPPORTS)}; got {support!r}")
    sigma = _sigmas(name, cols, meas)
    return SensingData(t=t, w=w, measured={m: cols[m] for m in meas}, sigma=sigma, load=load, support=support,
                       dt=dt, index=np.round(k).astype(np.int64), source=name)


def _read_impedance(name, rows, header):
    allowed = ["f"] + list(IMPEDANCE_MEASURED) + [f"sigma_{m}" for m in IMPEDANCE_MEASURED]
    header = _columns(name, rows, allowed)
    ohm = lambda c, x: parse_quantity(c, x, _OHM, "resistance")  # noqa: E731
    deg = lambda c, x: parse_quantity(c, x, _DEG, "phase (degrees)")  # noqa: E731
    parsers = {"f": lambda c, x: parse_quantity(c, x, _HZ, "frequency"), "Z_re": ohm, "Z_im": ohm, "Z_abs": ohm,
               "Z_phase": deg, "sigma_Z_re": ohm, "sigma_Z_im": ohm, "sigma_Z_abs": ohm, "sigma_Z_phase": deg}
    cols = _table(name, rows, header, parsers)
    _need(name, cols, "f", "the frequency")
    if np.any(cols["f"] <= 0):
        raise ValueError(f"{name} row {int(np.argmax(cols['f'] <= 0)) + 2}, column 'f': must be > 0 Hz")
    pairs = [p for p in (("Z_re", "Z_im"), ("Z_abs", "Z_phase")) if p[0] in header or p[1] in header]
    if len(pairs) != 1 or not all(c in header for c in pairs[0]):
        raise ValueError(f"{name}: an impedance spectrum needs the pair Z_re, Z_im or the pair Z_abs, Z_phase (deg), "
                         f"one of them")
    a, b = pairs[0]
    half = np.isfinite(cols[a]) != np.isfinite(cols[b])
    if np.any(half):
        raise ValueError(f"{name} row {int(np.argmax(half)) + 2}: {a} and {b} go together (one is empty)")
    if not np.any(np.isfinite(cols[a])):
        raise ValueError(f"{name}: no measured value in any row")
    if a == "Z_abs":
        bad = np.isfinite(cols[a]) & ~(cols[a] > 0)
        if np.any(bad):
            raise ValueError(f"{name} row {int(np.argmax(bad)) + 2}, column 'Z_abs': must be > 0 Ohm")
        for c in ("Z_phase", "sigma_Z_phase"):
            if c in cols:
                cols[c] = np.deg2rad(cols[c])
    # a strip with blocking electrodes is capacitive at every frequency (Im Z < 0): all positive
    # is the -Z'' convention of some instruments
    im = cols["Z_im"] if a == "Z_re" else cols["Z_phase"]
    if np.all(im[np.isfinite(im)] > 0):
        raise ValueError(f"{name}: {b} > 0 in every row, but the strip is capacitive ({b} < 0); if the file holds "
                         f"-Z'' (or minus the phase), negate that column")
    sigma = _sigmas(name, cols, [a, b])
    return ImpedanceData(f=cols["f"], measured={a: cols[a], b: cols[b]}, sigma=sigma, source=name)


def _sensing_header(header):
    # t and w with Q, I or V, or with nothing of a step/drive file besides (its w is a measured deflection)
    other = {k.lower() for k in (*STEP_FILE_COLUMNS, *TIME_MEASURED, "voltage")} - {"w"}
    return "t" in header and "w" in header and bool({"q", "i", "v"} & set(header) or not other & set(header))


def is_sensing_file(path) -> bool:
    """Whether the header of ``path`` makes it sensing data (False for a file that cannot be read: the
    reader says why)."""
    try:
        rows = read_rows(os.fspath(path), None)
    except (ValueError, OSError):
        return False
    return bool(rows) and _sensing_header([h.strip().lower() for h in rows[0]])


def read_file(path, base: Strip | None = None, *, waveform=None, load=None, support=None,
              max_rows: int | None = MAX_DATA_ROWS):
    """Read one calibration file; its header decides the kind (module docstring).

    Parameters
    ----------
    path : str or path
    base : Strip, optional
        Static rows: the geometry of a missing column (as :func:`~ipmc_asym.studies.calibrate.read_data`).
    waveform : str, optional
        The drive of a time series without a ``voltage`` column (a SPEC of
        :func:`ipmc_asym.dynamics.waveforms.parse_waveform`).
    load : "short", "open" or float, optional
        Sensing data: the load on the electrodes (default short; a ``V`` column needs it given).
    support : {"tip-force", "free"}, optional
        Sensing data: how the tip displacement bends the strip (default tip-force, the one default
        of every sensing entry).
    max_rows : int or None

    Returns
    -------
    CalibrationData, TimeData, ImpedanceData or SensingData

    Raises
    ------
    ValueError
        One line naming the file, the row and the column.
    """
    p = os.fspath(path)
    name = os.path.basename(p)
    rows = read_rows(p, max_rows)
    header = [h.strip().lower() for h in rows[0]]
    if "t" in header and "f" in header:
        raise ValueError(f"{name}: both t and f columns; a file holds a time series (t) or a spectrum (f), not both")
    sensing = _sensing_header(header)
    for opt, val in (("--load", load), ("--support", support)):
        if val is not None and not sensing:
            raise ValueError(f"{name}: {opt} is for sensing data (columns t, w and Q, I or V)")
    if sensing:
        if waveform is not None:
            raise ValueError(f"{name}: sensing data carry their drive (the w column); --waveform is for time series")
        return _read_sensing(name, rows, load, support, base)
    if "t" in header:
        return _read_time(name, rows, header, waveform, base)
    if "f" in header:
        return _read_impedance(name, rows, header)
    return read_data(p, base, max_rows)


# ---- forward models --------------------------------------------------------------------------
def predict_time(values, data: TimeData, strip: Strip, model, material: Material, fidelity="circuit",
                 beam="quasi-static", viscous_modulus=0.0, pnp_tol=None):
    """The time series' columns at the parameter ``values`` (name -> SI value).

    Through :func:`ipmc_asym.dynamics.circuit.step_response` from rest at ``t = 0`` (a time 0
    is added to the grid when the data start later).  Returns ``(out, rel_error, result)``:
    columns of :data:`TIME_MEASURED` (signed, module docstring), the rung's stated error on the
    charge relative to the largest charge (the PNP's Richardson estimate; NaN for the circuit,
    which states none by itself) and the :class:`~ipmc_asym.dynamics.circuit.StepResult`
    (checks, warnings).
    """
    mat = _material(material, values)
    perm = _perm(model, values)
    eta = float(values.get("viscous_modulus", viscous_modulus))
    t = data.t
    grid = t if t[0] == 0.0 else np.concatenate(([0.0], t))
    k = grid.size - t.size
    opts = None if pnp_tol is None else {"tol": float(pnp_tol)}
    with np.errstate(all="ignore"):
        r = step_response(strip=strip, model=perm, material=mat, t=grid, waveform_kind=data.drive, fidelity=fidelity,
                          beam=beam, viscous_modulus=eta, pnp_options=opts)
    area = strip.width * strip.length
    out = {"current": r.current_density[k:] * area, "charge": r.sigma[k:] * area, "deflection": -r.w[k:],
           "blocking_force": r.F_block[k:]}
    big = float(np.max(np.abs(r.sigma)))
    rel = float(np.nanmax(r.sigma_error)) / big if fidelity == "pnp" and big > 0 else math.nan
    return out, rel, r


def predict_sensing(values, data: SensingData, strip: Strip, model, material: Material):
    """The sensing columns at ``values`` (name -> SI) and the model's stated relative error.

    Through :func:`ipmc_asym.dynamics.sensing_time.sensing_transient` driven by the file's ``w(t)``
    on the grid ``k dt`` (the rows picked out exactly).  Returns ``(out, rel_error, result)``.
    """
    from ipmc_asym.dynamics.sensing_time import sensing_transient  # deferred: SciPy (start-up)

    mat = _material(material, values)
    perm = _perm(model, values)
    nu = float(values.get("nu", data.nu))
    n = int(data.index[-1]) + 1
    with np.errstate(all="ignore"):
        r = sensing_transient(data.waveform, max(n - 1, 1) * data.dt, max(n, 2), strip, model=perm, material=mat,
                              load=data.load, nu=nu, support=data.support)
    out = {"Q": r.Q[data.index], "I": r.I[data.index], "V": r.V[data.index]}
    return out, float(r.error), r


def predict_impedance(values, data: ImpedanceData, strip: Strip, model, material: Material):
    """``Z`` (Ohm, complex, per frequency) of the strip at ``values``: the linearised PNP through the
    electrode line (:func:`ipmc_asym.dynamics.line.line_response`; ideal electrodes when ``R_s = 0``)."""
    mat = _material(material, values)
    perm = _perm(model, values)
    return line_response(data.f, strip=strip, model=perm, material=mat, method="pnp-linear").Z


def _wrap(a):
    return (a + math.pi) % (2.0 * math.pi) - math.pi


def _impedance_columns(Z, data):
    if "Z_re" in data.measured:
        return {"Z_re": Z.real, "Z_im": Z.imag}
    return {"Z_abs": np.abs(Z), "Z_phase": np.angle(Z)}


# ---- the joint problem -----------------------------------------------------------------------
class _Joint:
    """Weighted residuals of every file in log parameters (the interface of ``calibrate._Problem``)."""

    def __init__(self, parts, names, model, material, strip, beam, viscous_modulus, fidelity, fixed=None):
        self.parts, self.names, self.model, self.material = parts, list(names), model, material
        self.strip, self.beam, self.viscous_modulus = strip, beam, viscous_modulus
        self.fidelity = dict(fidelity)  # {"static": rung, "time": rung, "pnp_tol": float}
        self.fixed = dict(fixed or {})
        self.data = parts
        self.bar = None
        #: the PNP rung as the circuit plus a defect correction (:func:`_defect_solve`): None, or a
        #: dict with ``names``, ``xi0`` (log values of those names), ``d0`` and ``slope`` (residual
        #: space: PNP minus circuit at ``xi0`` and its secant per log value), ``rel`` (the PNP's
        #: stated relative error there) and ``serial``
        self.defect = None
        self.pnp_rel = math.nan  # the PNP's stated relative error at its last run (max over the time series)
        self._last = None  # (key, predictions) of the last point
        self.static = [_Problem(d, self.names, model, material, self.fidelity.get("static"), self.fixed)
                       if isinstance(d, CalibrationData) else None for d in parts]
        self.scales = []
        for d in parts:
            if isinstance(d, CalibrationData):
                self.scales.append(None)
                continue
            sc = {}
            for k, v in d.measured.items():
                m = np.isfinite(v)
                if d.has_sigma:
                    sc[k] = d.sigma[k][m]
                elif isinstance(d, (TimeData, SensingData)):
                    rms = math.sqrt(float(np.mean(v[m] ** 2)))
                    if not rms > 0:
                        raise ValueError(f"{d.source}: column {k!r} is 0 in every row; without sigma_ columns it "
                                         f"sets no scale (give sigma_{k})")
                    sc[k] = np.full(int(m.sum()), rms)
                elif k in ("Z_re", "Z_im"):
                    sc[k] = np.hypot(d.measured["Z_re"], d.measured["Z_im"])[m]
                elif k == "Z_abs":
                    sc[k] = v[m]
                else:
                    sc[k] = np.ones(int(m.sum()))
            self.scales.append(sc)

    def __getstate__(self):
        d = dict(self.__dict__)
        d["bar"] = None
        d["_last"] = None
        return d

    def sub(self, names, fixed):
        out = _Joint(self.parts, names, self.model, self.material, self.strip, self.beam, self.viscous_modulus,
                     self.fidelity, fixed)
        out.bar = self.bar
        out.defect = self.defect
        return out

    def values(self, x):
        v = dict(self.fixed)
        v.update({n: math.exp(float(xi)) for n, xi in zip(self.names, x)})
        return v

    def predictions(self, x):
        """Per file: ``(columns, model error per measured value)`` (dicts, measured rows only)."""
        vals = self.values(x)
        # the PNP rung's checks ask for the same point twice (the model error and the interval
        # ends' reference at the optimum): one PNP run is ~0.5 s, so the last point is kept
        key = (tuple(sorted(vals.items())), None if self.defect is None else self.defect["serial"])
        if self._last is not None and self._last[0] == key:
            return self._last[1]
        self.pnp_rel = math.nan
        out = []
        dc = self._correction(vals)
        off = 0
        for d, sp in zip(self.parts, self.static):
            if sp is not None:
                pr, errs, valid = predict(vals, d.geometry, self.model, sp.fidelity, self.material)
                e = {k: np.where(valid, errs[k], np.inf) * np.abs(pr[k]) for k in pr}
                off += sum(int(np.count_nonzero(sp.masks[k])) for k in sp.keys)
            elif isinstance(d, TimeData):
                fid = "circuit" if dc is not None else self.fidelity["time"]
                pr, rel, _ = predict_time(vals, d, self.strip, self.model, self.material, fid,
                                          self.beam, self.viscous_modulus, self.fidelity.get("pnp_tol"))
                if fid == "pnp":
                    self.pnp_rel = rel if math.isnan(self.pnp_rel) else max(self.pnp_rel, rel)
                if dc is not None:
                    rel = self.defect["rel"]
                    for k, v in d.measured.items():
                        m = np.isfinite(v)
                        pr[k] = np.array(pr[k], float)
                        pr[k][m] += dc[off:off + int(m.sum())] * self.scales[len(out)][k]
                        off += int(m.sum())
                e = {k: rel * np.abs(v) for k, v in pr.items()}  # NaN at the circuit (no estimate alone)
            elif isinstance(d, SensingData):
                pr, rel, _ = predict_sensing(vals, d, self.strip, self.model, self.material)
                # the stated relative error applied to each value, as for the time series
                e = {k: rel * np.abs(v) for k, v in pr.items()}
                off += sum(int(np.count_nonzero(np.isfinite(v))) for v in d.measured.values())
            else:
                pr = _impedance_columns(predict_impedance(vals, d, self.strip, self.model, self.material), d)
                e = {k: np.zeros(d.f.size) for k in pr}
                off += sum(int(np.count_nonzero(np.isfinite(v))) for v in d.measured.values())
            keep = {k: np.isfinite(d.measured[k]) for k in d.measured}
            out.append(({k: pr[k][keep[k]] for k in d.measured}, {k: e[k][keep[k]] for k in d.measured}))
        self._last = (key, out)
        return out

    def _correction(self, vals):
        """The defect correction (residual space) at the parameter values ``vals``, or None."""
        if self.defect is None:
            return None
        df = self.defect
        xi = np.log([vals[k] for k in df["names"]])
        return df["d0"] + df["slope"] @ (xi - df["xi0"])

    def residuals(self, x):
        if self.bar is not None:
            self.bar.update(1)
        parts = []
        for d, sp, sc, (pr, _) in zip(self.parts, self.static, self.scales, self.predictions(x)):
            if sp is not None:
                parts.append((np.concatenate([pr[k] for k in sp.keys])
                              - np.concatenate([d.measured[k][sp.masks[k]] for k in sp.keys]))
                             / np.concatenate([sp.scale[k] for k in sp.keys]))
                continue
            for k, v in d.measured.items():
                diff = pr[k] - v[np.isfinite(v)]
                if k == "Z_phase":
                    diff = _wrap(diff)
                parts.append(diff / sc[k])
        r = np.concatenate(parts)
        # outside the model's domain: a large finite residual so the trust region backs off
        return np.where(np.isfinite(r), r, 1e3)

    def labels(self):
        out = []
        for d, sp in zip(self.parts, self.static):
            if sp is not None:
                out += [f"{d.source} row {int(i) + 2} ({k})" for k in sp.keys for i in np.flatnonzero(sp.masks[k])]
                continue
            for k, v in d.measured.items():
                out += [f"{d.source} row {int(i) + 2} ({k})" for i in np.flatnonzero(np.isfinite(v))]
        return out

    def scale_vector(self):
        """Weight scale of each residual (the denominator), in the order of :meth:`residuals`."""
        parts = []
        for sp, sc, d in zip(self.static, self.scales, self.parts):
            if sp is not None:
                parts.append(np.concatenate([sp.scale[k] for k in sp.keys]))
            else:
                parts += [sc[k] for k in d.measured]
        return np.concatenate(parts)


def _model_error(prob, x, reference=None):
    """Weighted model error of each residual at ``x`` (same order), and per kind the worst one.

    Static rows: the forward model's error estimate propagated to each output.  Time series at
    the circuit: ``|circuit - reference| + reference's own estimate``, ``reference`` the same
    problem at the PNP rung (its tolerance a hundredth of the noise); at the PNP: its own
    Richardson estimate on the charge, relative to the largest charge, applied to every column
    (the solver states none for the current or the mechanics).  Spectra: 0 (exact closed form).
    """
    preds = prob.predictions(x)
    refs = reference.predictions(x) if reference is not None else None
    parts, worst = [], {}
    for i, (d, sp, (pr, e)) in enumerate(zip(prob.parts, prob.static, preds)):
        if sp is not None:
            v = np.concatenate([e[k] for k in sp.keys]) / np.concatenate([sp.scale[k] for k in sp.keys])
            kind = "static"
        else:
            kind = ("time" if isinstance(d, TimeData) else "sensing" if isinstance(d, SensingData)
                    else "impedance")
            if kind == "time" and refs is not None:
                rp, re = refs[i]
                v = np.concatenate([np.abs(pr[k] - rp[k]) + re[k] for k in d.measured])
            else:
                v = np.concatenate([e[k] for k in d.measured])
            v = v / np.concatenate([prob.scales[i][k] for k in d.measured])
        v = np.where(np.isfinite(v), v, np.inf)
        parts.append(v)
        worst[kind] = max(worst.get(kind, 0.0), float(np.max(v)) if v.size else 0.0)
    return np.concatenate(parts), worst


def _bias(J, rm, s2):
    """Worst-case linearised shift of each log estimate by the model error ``rm`` (weighted), over its
    standard error: ``|G| |rm| / sd``, ``G = (J^T J)^+ J^T`` (as ``calibrate._bias_check``)."""
    JtJ = np.linalg.pinv(J.T @ J)
    sd = np.sqrt(np.clip(np.diag(s2 * JtJ), 0.0, None))
    b = np.abs(JtJ @ J.T) @ np.abs(rm)
    return np.where(sd > 0, b / np.where(sd > 0, sd, 1.0), 0.0)


def _start(names, model, material, strip, viscous_modulus, nu=DEFAULT_NU):
    out = []
    stat = [n for n in names if n in ("modulus", "c_moy", "eps0", "deps", "electrode_thickness", "electrode_modulus")]
    sv = dict(zip(stat, _start_values(stat, model, material)))
    for n in names:
        if n in sv:
            out.append(sv[n])
        elif n == "diffusion":
            out.append(material.D)
        elif n == "nu":  # a log-parameter: the assumed 0 is no start; the middle of [0, 0.5) is
            out.append(nu if nu > 0 else 0.25)
        elif n == "sheet_resistance":
            out.append(material.sheet_resistance if material.sheet_resistance > 0 else 1.0)
        else:  # viscous modulus: the given one, or a damping ratio of 5 % on the first mode
            b = Beam.from_strip(strip.length, strip.width, strip.thickness, material)
            f1 = float(natural_frequencies("clamped-free", b, 1)[0])
            out.append(viscous_modulus if viscous_modulus > 0 else
                       viscous_modulus_from_damping_ratio(0.05, f1, material.E))
    return out


def fit_dynamic(datasets, free, model="constant", material: Material = NAFION_LI, strip: Strip | None = None,
                beam: str | None = None, viscous_modulus: float = 0.0, fidelity: str | None = None,
                time_fidelity: str | None = None, multistart: int = 0, seed: int = 0, scheduler=None,
                progress: bool | None = False, nu: float = DEFAULT_NU) -> CalibrationResult:
    """Weighted least squares of static rows, time series and impedance spectra together.

    Parameters
    ----------
    datasets : list
        Of :class:`~ipmc_asym.studies.calibrate.CalibrationData`, :class:`TimeData`,
        :class:`ImpedanceData` (:func:`read_file`); a single one is accepted.
    free : str, list or dict
        Names of :data:`ipmc_asym.studies.calibrate.FREE_PARAMETERS` (``modulus``, ``c_moy``,
        ``eps0``, ``deps``, ``diffusion`` (alias ``D``), ``viscous_modulus``,
        ``sheet_resistance``), with optional bounds (``"diffusion=1e-11m2/s:1e-9m2/s"``).
    model : {"constant", "linear", "affine"}
    material : Material
        Fixed values and starting values (``D``, ``sheet_resistance``, ``E``, ``C_moy``).
    strip : Strip, optional
        Geometry of the time series and spectra (``thickness`` TOTAL 2e, ``width`` TOTAL 2l).
    beam : {"quasi-static", "dynamic"}, optional
        Mechanics of the time series; default ``dynamic`` when ``viscous_modulus`` is free, else
        ``quasi-static``.
    viscous_modulus : float
        ``eta_E`` (Pa s) when not free (default 0).
    fidelity : str, optional
        Force the static rows' rung.
    time_fidelity : {"circuit", "pnp"}, optional
        Force the time series' rung (its error is still checked).
    multistart, seed, scheduler, progress
        As :func:`ipmc_asym.studies.calibrate.fit`.
    nu : float
        Sensing data: the drained Poisson ratio when ``nu`` is not free, the start when it is
        (default 0, an assumption: docs/sensing.md).

    Returns
    -------
    CalibrationResult
        ``data`` and ``predictions`` are lists (one entry per file); ``flagged_rows`` maps a
        model assumption to the labels (``FILE row N``) of the time points it flags.

    Raises
    ------
    ValueError
        One line: a parameter the data cannot see, too many parameters, sigma columns in some
        files only, a time series with the linear model, no rung accurate enough.
    """
    from scipy import stats  # deferred: heavy import (start-up)

    from ipmc_asym.base.progress import progress as _bar  # deferred: tqdm

    parts = list(datasets) if isinstance(datasets, (list, tuple)) else [datasets]
    if not parts:
        raise ValueError("fit: no data file")
    for d in parts:
        if not isinstance(d, (CalibrationData, TimeData, ImpedanceData, SensingData)):
            raise ValueError(f"datasets must be read by read_file (CalibrationData, TimeData, ImpedanceData, "
                             f"SensingData); got {type(d).__name__}")
    if isinstance(nu, bool) or not isinstance(nu, (int, float, np.floating)) or not 0.0 <= float(nu) < 0.5:
        raise ValueError(f"nu (drained Poisson ratio) must be a number in [0, 0.5); got {nu!r}")
    # the fixed nu travels with the sensing data (copies: the caller's data sets are left as they were)
    parts = [replace(d, nu=float(nu)) if isinstance(d, SensingData) else d for d in parts]
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise ValueError(f"seed must be an integer >= 0; got {seed!r}")
    sig = {d.has_sigma for d in parts}
    if len(sig) > 1:
        raise ValueError("sigma_ columns in some files only: give them for every measured column of every file, or "
                         "for none (one noise scale is then estimated)")
    has_sigma = sig.pop()
    strip = Strip() if strip is None else strip
    bounds = parse_free(free)
    names = list(bounds)
    kinds = set().union(*(_kinds(d) for d in parts))
    check_visible(names, kinds)
    check_stiffness_free(names, material)
    if beam is None:
        beam = "dynamic" if "viscous_modulus" in names else "quasi-static"
    if "viscous_modulus" in names and beam != "dynamic":
        raise ValueError("--free viscous_modulus: the quasi-static beam has no damping; use --beam dynamic")
    has_time = any(isinstance(d, TimeData) for d in parts)
    for d in parts:
        # a step/drive file's per-area columns were made totals with the area of the strip it was read with
        if isinstance(d, TimeData) and d.area is not None and not math.isclose(
                d.area, strip.width * strip.length, rel_tol=1e-9):
            raise ValueError(f"{d.source}: its per-area columns were read with an electrode area {d.area:.6g} m^2, "
                             f"the fit's strip has {strip.width * strip.length:.6g} m^2; read it with the same strip")
    has_static = any(isinstance(d, CalibrationData) for d in parts)
    for d in parts:
        if isinstance(d, SensingData) and abs(float(np.max(np.abs(d.w)))) >= strip.length:
            raise ValueError(f"{d.source}: |w| reaches the strip length {strip.length:.4g} m; w is in metres")
    if any(isinstance(d, SensingData) for d in parts) and ("sheet_resistance" in names
                                                           or material.sheet_resistance > 0):
        raise ValueError("sensing data with an electrode sheet resistance: the sensing transient has ideal electrodes; "
                         "fit sheet_resistance on spectra without the sensing data")
    if has_time and ("sheet_resistance" in names or material.sheet_resistance > 0):
        raise ValueError("time series with an electrode sheet resistance: the time-domain model has ideal electrodes "
                         "(the time-domain electrode line of step/drive --sheet-resistance is not a rung of the fit); fit "
                         "sheet_resistance on spectra without the time series")
    if has_time and get_model(model).eps0 == 0.0 and "eps0" not in names:
        raise ValueError("time series with the linear model: not validated in the fit (the circuit misplaces the "
                         "abrupt stop of the current when the anode layer saturates, and a fit on the PNP rung takes "
                         "minutes); use the constant or affine model")
    if time_fidelity is not None and time_fidelity not in TIME_FIDELITIES:
        raise ValueError(f"time_fidelity must be one of {', '.join(TIME_FIDELITIES)}; got {time_fidelity!r}")
    n = sum(d.n_points for d in parts)
    check_count(names, n, has_sigma)
    s_ladder = static_ladder(names, fidelity)
    t_ladder = list(TIME_FIDELITIES) if time_fidelity is None else [time_fidelity]
    lo = np.log([bounds[k][0] for k in names])
    hi = np.log([bounds[k][1] for k in names])
    x0 = np.clip(np.log(_start(names, model, material, strip, viscous_modulus, nu)), lo, hi)
    starts = multistart_starts(x0, lo, hi, multistart, seed)
    bar = _bar(None, "fit", enabled=progress, unit="eval")
    try:
        res = _fit_joint(parts, names, bounds, lo, hi, starts, s_ladder, t_ladder, has_static, has_time, has_sigma,
                         n, model, material, strip, beam, viscous_modulus, scheduler, bar, stats, fidelity,
                         time_fidelity)
    finally:
        bar.close()
    res.warnings[:0] = free_warnings(bounds)
    return res


def fit(data, free, model="constant", material: Material = NAFION_LI, fidelity: str | None = None,
        multistart: int = 0, seed: int = 0, scheduler=None, progress: bool | None = False, *,
        strip: Strip | None = None, waveform=None, beam: str | None = None, viscous_modulus: float = 0.0,
        time_fidelity: str | None = None, load=None, support: str | None = None,
        nu: float = DEFAULT_NU) -> CalibrationResult:
    """Weighted least squares of any data over the ``free`` parameters, with profile intervals.

    One entry for every kind of data, as ``ipmc-asym fit``: static rows alone are fitted by
    :func:`ipmc_asym.studies.calibrate.fit`, time series and impedance spectra (alone or with
    static rows) by :func:`fit_dynamic`; the same :class:`~ipmc_asym.studies.calibrate.CalibrationResult`.

    Parameters
    ----------
    data : CalibrationData, TimeData, ImpedanceData, path, or a list of them
        Data sets (:func:`ipmc_asym.studies.calibrate.read_data`, :func:`read_file`) or CSV paths
        (read by :func:`read_file` with ``strip`` as the geometry and ``waveform`` as the drive of a
        time series without a voltage column); several are fitted together.
    free : str, list or dict
        Names of :data:`ipmc_asym.studies.calibrate.FREE_PARAMETERS` (``modulus``, ``c_moy``,
        ``eps0``, ``deps``; with time series or spectra also ``diffusion`` (alias ``D``),
        ``viscous_modulus``, ``sheet_resistance``), with optional bounds
        (``"diffusion=1e-11m2/s:1e-9m2/s"``) or ``{name: (lo, hi)}`` in SI.  A parameter the data
        cannot see is refused naming the data that would identify it.
    model : {"constant", "linear", "affine"}
    material : Material
        Fixed values and start values.
    fidelity : str, optional
        Force the static rows' rung.
    multistart, seed, scheduler, progress
        As :func:`ipmc_asym.studies.calibrate.fit`.
    strip : Strip, optional
        Geometry of time series and spectra (TOTAL thickness 2e, TOTAL width 2l; the electrode
        area 2l L of a ``step``/``drive --out`` file's per-area columns).
    waveform : str, optional
        Drive of time series read from paths without a voltage column (``"step:0.5V"``).
    beam, viscous_modulus, time_fidelity
        Time series only: as :func:`fit_dynamic`.
    load, support
        Sensing data read from paths: as :func:`read_file`.
    nu : float
        Sensing data: the drained Poisson ratio when not free (as :func:`fit_dynamic`).

    Returns
    -------
    CalibrationResult

    Raises
    ------
    ValueError
        One line: as the two fits, and a time-series option given with static rows only.

    Examples
    --------
    >>> import os, tempfile
    >>> path = os.path.join(tempfile.mkdtemp(), "data.csv")
    >>> with open(path, "w") as fh:
    ...     _ = fh.write("voltage,deflection\\n0.5V,1.0mm\\n1V,2.1mm\\n1.5V,2.9mm\\n")
    >>> res = fit(path, "modulus", fidelity="corrected")
    >>> res.success, res.parameters["modulus"]["identifiable"]
    (True, True)
    """
    parts = list(data) if isinstance(data, (list, tuple)) else [data]
    parts = [read_file(d, strip, waveform=waveform, load=load, support=support)
             if isinstance(d, (str, os.PathLike)) else d for d in parts]
    if not (len(parts) == 1 and isinstance(parts[0], CalibrationData)):
        return fit_dynamic(parts, free, model=model, material=material, strip=strip, beam=beam,
                           viscous_modulus=viscous_modulus, fidelity=fidelity, time_fidelity=time_fidelity,
                           multistart=multistart, seed=seed, scheduler=scheduler, progress=progress, nu=nu)
    for opt, val in (("beam", beam), ("time_fidelity", time_fidelity), ("waveform", waveform)):
        if val is not None:
            raise ValueError(f"{opt}: only for time series (a file with a t column); {parts[0].source} holds static "
                             f"rows")
    return fit_static(parts[0], free, model=model, material=material, fidelity=fidelity, multistart=multistart,
                      seed=seed, scheduler=scheduler, progress=progress)


def _fit_joint(parts, names, bounds, lo, hi, starts, s_ladder, t_ladder, has_static, has_time, has_sigma, n, model,
               material, strip, beam, viscous_modulus, scheduler, bar, stats, fidelity, time_fidelity):
    p = len(names)
    si, ti = 0, 0
    notes, warns = [], []
    x = starts[0]
    pnp_tol = None
    first = True
    while True:
        fid = {"static": s_ladder[si] if has_static else None, "time": t_ladder[ti] if has_time else None,
               "pnp_tol": pnp_tol,
               "sensing": "transient" if any(isinstance(d, SensingData) for d in parts) else None}
        prob = _Joint(parts, names, model, material, strip, beam, viscous_modulus, fid)
        prob.bar = bar
        if first and len(starts) > 1:
            outs = run_chunks(_multistart_task, [(prob, s, lo, hi) for s in starts], scheduler=scheduler)
            best = min(range(len(outs)), key=lambda i: outs[i][0])
            x = outs[best][1]
            notes.append(f"multistart: best of {len(starts)} starts is #{best}")
        first = False
        ref = None
        if has_time and fid["time"] == "pnp":
            res, ref = _defect_solve(prob, x, lo, hi, has_sigma, n, notes)
        else:
            res = _solve(prob, x, lo, hi)
        x = res.x
        chi2 = 2.0 * float(res.cost)
        rel = 1.0 if has_sigma else math.sqrt(chi2 / max(n - p, 1))
        # the noise as the PNP reference must resolve it: a hundredth of the relative noise,
        # relative to the largest charge (its tolerance is on sigma)
        if has_time and fid["time"] == "circuit":
            tol = _pnp_tol(prob, x, rel)
            ref = _Joint(parts, names, model, material, strip, beam, viscous_modulus,
                         dict(fid, time="pnp", pnp_tol=tol))
            ref.bar = bar
            rm, worst = _model_error(prob, x, ref)
        elif ref is not None:
            # the corrected circuit against the PNP run at the optimum (their difference: the
            # correction's remainder) plus the PNP's own estimate
            rm, worst = _model_error(prob, x, ref)
        else:
            rm, worst = _model_error(prob, x)
        bias = _bias(np.asarray(res.jac, float), rm, 1.0 if has_sigma else rel * rel)
        fails = [k for k, w in worst.items() if not w < 0.1 * rel]
        bias_bad = bool(np.any(bias >= 0.1))
        if not fails and not bias_bad:
            break
        why = ", ".join(f"{k} rows: model error up to {worst[k]:.2g} x the weight scale" for k in fails)
        if bias_bad:
            j = int(np.argmax(bias))
            why += (", " if why else "") + f"model error could shift {names[j]} by {bias[j]:.2g} standard errors"
        need = "0.1 sigma" if has_sigma else f"0.1 x the estimated relative noise s = {rel:.2g}"
        notes.append(f"at {', '.join(f'{k} {v}' for k, v in fid.items() if v and k != 'pnp_tol')}: {why} "
                     f"(need < {need})")
        # escalate the kinds that fail (the bias alone: every kind that carries model error)
        up = set(fails) or {k for k, w in worst.items() if w > 0}
        moved = False
        if "static" in up and si + 1 < len(s_ladder):
            si += 1
            moved = True
        if "time" in up and ti + 1 < len(t_ladder):
            ti += 1
            pnp_tol = _pnp_tol(prob, x, rel)
            moved = True
        if not moved:
            forced = fidelity is not None or time_fidelity is not None
            raise ValueError(f"no rung is accurate enough for data this precise ({'; '.join(notes)})"
                             + ("; leave the fidelity unset to escalate" if forced else ""))
    ends = [] if prob.defect is not None else None
    params, corr, chi2_red, noise_scale = _report(prob, res, lo, hi, n, has_sigma, stats, notes, warns, ends)
    if ends:
        _check_ends(prob, ref, res, ends, params, n, has_sigma, stats, notes)
    preds = [pr for pr, _ in prob.predictions(res.x)]
    flagged = _time_flags(prob, res.x, warns)
    used = []
    if has_static:
        used.append(f"static rows {fid['static']}")
    if has_time:
        used.append(f"time series {fid['time']}" + (f" (tol {fid['pnp_tol']:.2g})" if fid["time"] == "pnp"
                                                     and fid["pnp_tol"] is not None else ""))
    if any(isinstance(d, ImpedanceData) for d in parts):
        used.append("spectra pnp-linear (exact)")
    if any(isinstance(d, SensingData) for d in parts):
        used.append("sensing transient (reduced circuit + leading-order EMF, one rung)")
    fidelity_used = "; ".join(used)
    # the two sides' water assumptions differ (actuation: solvent at rest; sensing: drained at every instant)
    sensing_only = all(isinstance(d, SensingData) for d in parts)
    water = []
    if not sensing_only:
        water.append(f"beam {beam}; {WATER_NOTE}")
    if any(isinstance(d, SensingData) for d in parts):
        water.append("sensing data: " + ", ".join(f"{d.source} support {d.support}, load {d.load}" for d in parts
                                                  if isinstance(d, SensingData))
                     + f"; {WATER_ASSUMPTION}; drained Poisson ratio "
                     + ("fitted" if "nu" in names else f"nu = {next(d.nu for d in parts if isinstance(d, SensingData)):g} "
                        "(an assumption)"))
    msg = (f"fidelity: {fidelity_used} (cheapest with model error < 1/10 of the data's noise at every value and a "
           f"shift < 0.1 standard error on every estimate); {'; '.join(water)}")
    if notes:
        msg += "; " + "; ".join(notes)
    return CalibrationResult(parameters=params, correlation=corr, chi2_red=chi2_red, n_points=n,
                             fidelity=fidelity_used, model=get_model(model).name, success=bool(res.success),
                             message=msg, names=names, predictions=preds, data=parts, flagged_rows=flagged,
                             noise_scale=noise_scale, warnings=warns)


#: the defect correction has converged when a refit moves every estimate by less than this many
#: standard errors (the PNP optimum is then the corrected circuit's to that fraction)
DEFECT_STEP = 0.01
#: refits before the direct PNP optimisation takes over
DEFECT_ITERATIONS = 8
#: tells one correction from the next (a cached prediction belongs to one)
_DEFECT_SERIAL = itertools.count()


def _defect_solve(prob, x, lo, hi, has_sigma, n, notes):
    """The optimum of ``prob`` (its time series on the PNP rung) by defect correction of the circuit.

    Each PNP run costs ~0.5 s, the circuit ~3 ms (measured on the 199-row step of
    docs/calibration.md); a direct PNP optimisation took ~700 PNP runs, mostly for the
    profile intervals.  Here the PNP's weighted residuals are modelled as the circuit's plus
    ``d0 + S (xi - xi0)``: ``d0`` the PNP-minus-circuit discrepancy at ``xi0`` (one PNP run), ``S``
    its forward secant over one standard error of each log parameter (one PNP run each, redone
    only after a step of more than a standard error).  Value and slope then match the PNP's at
    ``xi0``, so a fixed point (a refit moving every estimate by less than :data:`DEFECT_STEP`
    standard errors) is the PNP's stationary point to that fraction; the discrepancy's
    curvature over a standard error is the remainder, which the ladder's model-error check at
    the optimum and :func:`_check_ends` at the interval ends measure with the PNP itself.
    Without convergence in :data:`DEFECT_ITERATIONS` refits the PNP is optimised directly.
    Returns ``(res, pnp)``: the optimum (of ``prob``, which keeps the correction for the
    profile intervals) and the uncorrected PNP problem.
    """
    p = len(prob.names)
    circ = _Joint(prob.parts, prob.names, prob.model, prob.material, prob.strip, prob.beam, prob.viscous_modulus,
                  dict(prob.fidelity, time="circuit"), prob.fixed)
    pnp = _Joint(prob.parts, prob.names, prob.model, prob.material, prob.strip, prob.beam, prob.viscous_modulus,
                 prob.fidelity, prob.fixed)
    circ.bar = pnp.bar = prob.bar
    prob.defect = None
    x = np.clip(np.asarray(x, float), lo + 1e-12, hi - 1e-12)

    def s2_of(r):
        return 1.0 if has_sigma else float(r @ r) / max(n - p, 1)

    # first standard errors: the circuit's Jacobian (cheap; sizes the secant steps)
    rc = circ.residuals(x)
    Jc = np.empty((rc.size, p))
    for j in range(p):
        h = 1e-6 if x[j] + 1e-6 < hi[j] else -1e-6
        xs = x.copy()
        xs[j] += h
        Jc[:, j] = (circ.residuals(xs) - rc) / h
    sd = _log_covariance(Jc, s2_of(rc))[1]
    slope, runs, step = None, 0, math.inf
    for it in range(DEFECT_ITERATIONS):
        rp = pnp.residuals(x)
        rc = circ.residuals(x)
        rel = pnp.pnp_rel
        runs += 1
        d0 = rp - rc
        if slope is None or step > 1.0:
            slope = np.empty((rp.size, p))
            for j in range(p):
                h = float(np.clip(sd[j], 1e-4, 0.05)) if np.isfinite(sd[j]) and sd[j] > 0 else 1e-3
                if x[j] + h > hi[j]:
                    h = -h
                xs = x.copy()
                xs[j] += h
                slope[:, j] = ((pnp.residuals(xs) - circ.residuals(xs)) - d0) / h
                runs += 1
        prob.defect = {"names": list(prob.names), "xi0": x.copy(), "d0": d0, "slope": slope, "rel": rel,
                       "serial": next(_DEFECT_SERIAL)}
        res = _solve(prob, x, lo, hi)
        sd = _log_covariance(res.jac, s2_of(np.asarray(res.fun, float)))[1]
        step = float(np.max(np.abs(res.x - x) / np.where(sd > 0, sd, np.inf)))
        x = res.x
        if step < DEFECT_STEP:
            notes.append(f"PNP optimum by defect correction of the circuit: {it + 1} refits, {runs} PNP runs, last "
                         f"step {step:.2g} standard errors")
            return res, pnp
    prob.defect = None
    notes.append(f"defect correction of the circuit did not settle in {DEFECT_ITERATIONS} refits (last step "
                 f"{step:.2g} standard errors): the PNP optimised directly")
    return _solve(prob, x, lo, hi), pnp


def _check_ends(prob, pnp, res, ends, params, n, has_sigma, stats, notes):
    """The corrected circuit's profile-interval ends checked with the PNP run there.

    At an end ``x_e`` (the others re-minimised) the PNP changes ``Delta chi^2 / s^2`` by
    ``dd = [(chi2_pnp - chi2_corr)(x_e) - (chi2_pnp - chi2_corr)(x^)] / s^2`` (to first order
    the profile is the same minimisation: the envelope theorem); the profile's slope there is
    ``2 sqrt(thr) / sd`` (quadratic profile), so the end moves by ``dd / (2 sqrt(thr))`` standard
    errors, inwards when positive.  An end that would move outwards is widened by that much
    (a margin, not a re-solve); the largest move is stated in the notes.
    """
    # the scale, threshold and standard errors the intervals were profiled with (one home: calibrate)
    s2, thr, _, sd = _interval_scale(res.jac, 2.0 * float(res.cost), n, len(prob.names), has_sigma, stats)

    def gap(x):
        a, b = pnp.residuals(x), prob.residuals(x)
        return float(a @ a - b @ b)

    g0 = gap(res.x)
    worst = 0.0
    for j, side, xe in ends:
        move = (gap(xe) - g0) / s2 / (2.0 * math.sqrt(thr))
        worst = max(worst, abs(move))
        ci = params[prob.names[j]]["ci95"]
        k = 0 if side < 0 else 1
        if move < 0 and ci[k] is not None and sd[j] > 0:
            ci[k] = ci[k] * math.exp(side * abs(move) * float(sd[j]))
    notes.append(f"profile ends checked with the PNP: they move by at most {worst:.2g} standard errors "
                 f"(outward moves added as a margin)")


def _pnp_tol(prob, x, rel):
    """The PNP reference's tolerance (relative on the charge): a hundredth of the noise on the
    smallest weight scale of a time series, relative to its largest charge; in [1e-7, 1e-3]."""
    return float(min(max(0.01 * rel * _time_scale_ratio(prob), 1e-7), 1e-3))


def _time_scale_ratio(prob):
    """Smallest ratio of a time series' weight scale to its largest measured magnitude (<= 1)."""
    r = 1.0
    for d, sc in zip(prob.parts, prob.scales):
        if isinstance(d, TimeData):
            for k, v in d.measured.items():
                big = float(np.nanmax(np.abs(v)))
                if big > 0:
                    r = min(r, float(np.min(sc[k])) / big)
    return r


def _time_flags(prob, x, warns):
    """The forward model's assumption checks at the time points (labels) and their warnings."""
    from ipmc_asym.forward.model import ASSUMPTION_CHECKS  # deferred: heavy import (Numba kernels)

    flagged = {}
    vals = prob.values(x)
    for d, sp in zip(prob.parts, prob.static):
        if sp is not None:
            _, _, _, chk = predict(vals, d.geometry, prob.model, sp.fidelity, prob.material, with_checks=True)
            for c, ok in chk.items():
                if not np.all(ok):
                    flagged.setdefault(c, []).extend(f"{d.source} row {int(i) + 2}" for i in np.flatnonzero(~ok))
        elif isinstance(d, TimeData):
            _, _, r = predict_time(vals, d, prob.strip, prob.model, prob.material, prob.fidelity["time"], prob.beam,
                                   prob.viscous_modulus, prob.fidelity.get("pnp_tol"))
            k = r.t.size - d.t.size
            for c in ASSUMPTION_CHECKS:
                ok = np.asarray(r.checks[c], bool)[k:]
                if not np.all(ok):
                    flagged.setdefault(c, []).extend(f"{d.source} row {int(i) + 2}" for i in np.flatnonzero(~ok))
        elif isinstance(d, SensingData):
            _, _, r = predict_sensing(vals, d, prob.strip, prob.model, prob.material)
            for c in ("check_strain", "check_beam_regime", "check_one_way"):
                ok = np.asarray(getattr(r, c), bool)[d.index]
                if not np.all(ok):
                    flagged.setdefault(c, []).extend(f"{d.source} row {int(i) + 2}" for i in np.flatnonzero(~ok))
    for c, rows in flagged.items():
        warns.append(f"{len(rows)} data rows outside the {c} assumption at the fitted parameters ({', '.join(rows[:6])}"
                     f"{', ...' if len(rows) > 6 else ''}): the forward model flags them; they still enter the fit")
    return flagged
