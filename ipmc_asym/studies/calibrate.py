"""Calibration: weighted least squares of a user's measurements, with honest error bars.

``fit(read_data("DATA.csv"), ["modulus", "c_moy"])`` returns a :class:`CalibrationResult`
whose :meth:`~CalibrationResult.as_dict` has exactly the keys ``parameters`` (name ->
``{value, stderr, ci95, identifiable}``), ``correlation``, ``chi2_red``, ``n_points``,
``fidelity``, ``model``.

Library choice: SciPy ``least_squares`` (``trf``, bounds) with a hand-rolled profile
likelihood, not lmfit.  Reasons: SciPy is already a core dependency (lmfit would add one,
plus asteval/uncertainties, to every install); the fit runs in log parameters with bounds
and a vectorised residual, which ``least_squares`` takes directly; and the part that matters
here -- deciding that a parameter is NOT identifiable (flat or one-sided profile, or a
profile that walks out of the model's domain) instead of printing a fake interval -- needs
control over the profile walk that lmfit's ``conf_interval`` (which raises or warns at a
bound) does not give.  The profile is the textbook one: fix the parameter, re-minimise over
the others, and find where ``Delta chi^2`` reaches the 95 % threshold.

Model (paper sections 3-4): ``M_A = A5 I`` with ``A5 = 6 l e^2 F |phi0| C_moy``; free-end
tip deflection ``|w| = 2 sin^2(kappa L/2)/|kappa|``, ``kappa = M_A/(E I_p)`` (large
displacement); blocking force ``|F| = psi(kappa L) |M_A|/L`` (large displacement).  Hence at
fixed geometry the deflection sees ``M_A/E`` only and the force ``M_A`` only (``psi``
depends on ``E`` through ``kappa L`` by a relative ``(kappa L)^2/3360``): ``modulus`` needs
deflection data AND something that fixes ``M_A`` (force data, or a known ``c_moy``), and
force-only data leave ``modulus`` not identifiable.  The profile finds this; nothing here
assumes it.

Weights: a ``sigma_<measured>`` column is one standard deviation (absolute, chi^2 with
known scale, threshold ``chi2.ppf(0.95, 1) = 3.84``).  Without it the weights are equal and
relative (``residual / |measured|``) and the scale is estimated from the residuals
(``s^2 = chi^2/(n - p)``; covariance scaled by ``s^2``; profile threshold ``t_{0.975,n-p}^2``).

Fidelity: the cheapest rung of ``leading -> corrected -> quadrature -> bvp`` whose error
estimate at every data point (from :func:`ipmc_asym.integral.api.moment`, propagated to each
output, at the fitted parameters) is below a tenth of the data's relative error (the
smallest ``sigma/|measured|``, or the fitted relative scale ``s`` without sigma columns),
and -- because the estimates average over the points while a model error does not -- whose
worst-case linearised shift of every estimate is below a tenth of its standard error
(:func:`_bias_check`).  The closed
forms exist for the paper's permittivity pairs only, so a free ``eps0``/``deps`` starts at
``quadrature``.

Time series and impedance spectra (with or without static rows; free ``diffusion``,
``viscous_modulus``, ``sheet_resistance``) are fitted by
:mod:`ipmc_asym.studies.calibrate_dynamic`, which shares this module's profile, statuses and
report (:func:`_report`) and its rule of which data see which parameter (:data:`VISIBLE_TO`).

Layer rule: stdlib + numpy at import; SciPy's optimiser and statistics deferred.
"""

from __future__ import annotations

import csv
import io
import math
import os
from dataclasses import dataclass, field

import numpy as np

from ipmc_asym.base.inputs import read_input_text
from ipmc_asym.base.quantities import BY_NAME
from ipmc_asym.base.registry import closed_form_fidelities, fidelity_names
from ipmc_asym.base.results import Panel, ResultMixin, ResultSpec
from ipmc_asym.base.units import (
    parse_force,
    parse_length,
    parse_voltage,
)
from ipmc_asym.beam.statics import blocking_force_ratio
from ipmc_asym.model.parameters import ALIASES, PARAMETERS, parse_value, with_values
from ipmc_asym.model.params import NAFION_LI, Material, Strip, check_c_moy, check_diffusion
from ipmc_asym.model.permittivity import Permittivity, get_model
from ipmc_asym.parallel.executors import run_chunks

__all__ = [
    "FREE_PARAMETERS",
    "free_warnings",
    "MEASURED",
    "CalibrationData",
    "CalibrationResult",
    "read_data",
    "parse_free",
    "predict",
    "fit",
]

#: free parameters: name -> (unit, default bounds, what it sets), from the one parameter table
#: (model.parameters.PARAMETERS); names as the CLI/sweeps use
FREE_PARAMETERS = {k: (p.unit, p.bounds, p.long_name) for k, p in PARAMETERS.items()}
#: other names a --free item may take (the key) for a name of FREE_PARAMETERS (the value)
FREE_ALIASES = {a: k for a, k in ALIASES.items() if k in FREE_PARAMETERS}
#: which kinds of data rows see each free parameter (static: deflection/blocking force at rest;
#: time: a transient t -> current/charge/deflection/force; impedance: a spectrum f -> Z), and
#: for a parameter no kind present sees, the data that would identify it
VISIBLE_TO = {k: (p.seen_by, p.identify) for k, p in PARAMETERS.items()}
#: free parameters that deflection and force data see only through the bending stiffness EI
#: (w = -M_A L^2/(2 EI), F from kappa L = M_A L/EI): at most one of them can be identified
STIFFNESS_PARAMETERS = ("modulus", "electrode_thickness", "electrode_modulus")


def check_stiffness_free(names, material: Material) -> None:
    """Refuse (one line) electrode parameters the data cannot identify.

    Deflection and force see ``E_p``, ``t_m`` and ``E_m`` only through the composite ``EI``
    (:data:`STIFFNESS_PARAMETERS`): at most one of them is free; a layer parameter needs a layer
    to start from (``--electrode-thickness > 0`` with ``--electrode-metal`` or
    ``--electrode-modulus``), its start value.
    """
    stiff = [k for k in names if k in STIFFNESS_PARAMETERS]
    if len(stiff) > 1:
        raise ValueError(f"--free {', '.join(stiff)}: deflection and force data see these only through the bending "
                         "stiffness EI (one number): free one of them, fix the others")
    for k in stiff:
        if k != "modulus" and not material.electrode.present:
            raise ValueError(f"--free {k}: the strip has no electrode layer to fit; give a starting layer "
                             "(--electrode-thickness > 0 and --electrode-metal or --electrode-modulus)")


def check_visible(names, kinds) -> None:
    """Refuse (one-line ``ValueError``) a free parameter that none of the data ``kinds`` depends on.

    ``kinds``: the kinds of rows present (``static``, ``time`` for current/charge, ``time_mech``
    for a time series of deflection/force, ``impedance``); the message names the data that
    would identify the parameter (:data:`VISIBLE_TO`).
    """
    for k in names:
        seen, need = VISIBLE_TO[k]
        if not set(seen) & set(kinds):
            have = ", ".join(sorted(kinds)) or "none"
            raise ValueError(f"--free {k}: the data given ({have} rows) do not depend on it; it needs {need}")
#: measured columns -> unit (magnitudes)
MEASURED = {"deflection": "m", "blocking_force": "N"}
GEOMETRY = ("length", "width", "thickness", "voltage")
#: the fidelity ladder, cheapest first (the registry is the one list)
LADDER = fidelity_names()
#: data rows of a calibration file read at most (each is one forward evaluation per residual
#: call; --max-rows on the command line)
MAX_DATA_ROWS = 10**5
#: starting value of a permittivity parameter whose nominal value is 0 (log parameters)
_EPS_START = {"eps0": 5e-6, "deps": 1e-3}


# ---- data ------------------------------------------------------------------------------------
class MeasuredColumns:
    """What every data set of a fit has: ``measured`` and ``sigma`` dicts of columns (NaN where absent)."""

    @property
    def n_points(self) -> int:
        """Number of measured values (all columns)."""
        return int(sum(np.count_nonzero(np.isfinite(v)) for v in self.measured.values()))

    @property
    def has_sigma(self) -> bool:
        return all(s is not None for s in self.sigma.values())


@dataclass
class CalibrationData(MeasuredColumns):
    """Measurements, one entry per CSV row (SI).

    Attributes
    ----------
    geometry : dict
        ``length``, ``width`` (TOTAL 2l), ``thickness`` (TOTAL 2e), ``voltage``: arrays (n_rows,).
    measured : dict
        name -> array (n_rows,) of magnitudes, NaN where the row does not measure it.
    sigma : dict
        name -> array (n_rows,) of one standard deviation, or None (relative weights).
    source : str
    file_columns : tuple of str
        The geometry columns the file gave (the others took ``base``'s value).
    """

    geometry: dict
    measured: dict
    sigma: dict
    source: str = "data"
    file_columns: tuple = ()

    @property
    def n_rows(self) -> int:
        return int(next(iter(self.geometry.values())).size)


def _parse_cell(col, text):
    if col in ("length", "width", "thickness", "deflection") or col == "sigma_deflection":
        return parse_length(col, text)
    if col == "voltage":
        return parse_voltage(col, text)
    if col in ("blocking_force", "sigma_blocking_force"):
        return parse_force(col, text)
    raise ValueError(f"column {col!r} not readable")  # pragma: no cover - filtered earlier


def read_rows(path, max_rows: int | None = MAX_DATA_ROWS) -> list:
    """The non-empty, non-comment rows of a CSV (header first), at most ``max_rows`` data rows.

    A UTF-8 byte-order mark (Excel's "CSV UTF-8") is skipped; a line whose first cell starts
    with ``#`` is a comment.  One-line ``ValueError`` for an unreadable, empty or too long file.
    """
    p = os.fspath(path)
    name = os.path.basename(p)
    if max_rows is not None and (isinstance(max_rows, bool) or int(max_rows) < 1):
        raise ValueError(f"max_rows must be an integer >= 1 or None; got {max_rows!r}")
    rows = []
    reader = None
    try:
        # utf-8-sig: a byte-order mark (Excel's "CSV UTF-8") is not part of the first header name
        with io.StringIO(read_input_text(p, "data file", "utf-8-sig"), newline="") as fh:
            reader = csv.reader(fh)
            for r in reader:
                if not any(c.strip() for c in r) or r[0].lstrip().startswith("#"):
                    continue
                rows.append(r)
                # header + max_rows data rows; one more is refused before the rest is read
                if max_rows is not None and len(rows) > int(max_rows) + 1:
                    raise ValueError(f"{name}: more than {int(max_rows)} data rows (the cap; --max-rows "
                                     f"on the command line)")
    except csv.Error as exc:  # e.g. a field above the csv module's limit (131072 characters)
        raise ValueError(f"data file {p!r} line {reader.line_num if reader else 1}: cannot read ({exc})") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise ValueError(f"data file {p!r}: cannot read ({exc.__class__.__name__}: {exc})") from None
    if not rows:
        raise ValueError(f"{name}: empty file (need a header row and data rows)")
    return rows


def read_data(path, base: Strip | None = None, max_rows: int | None = MAX_DATA_ROWS) -> CalibrationData:
    """Read a calibration CSV (header row; SI numbers or values with units).

    Columns: any of ``length, width, thickness, voltage`` (width/thickness TOTAL; a missing
    column takes ``base``), measured ``deflection`` (``|w|``, m) and/or ``blocking_force``
    (``|F|``, N), optional ``sigma_deflection``, ``sigma_blocking_force``.  An empty measured
    cell means "not measured in this row".  Every error is one line naming the row/column.

    The header is case-insensitive and a UTF-8 byte-order mark (Excel's "CSV UTF-8") is
    skipped.  Physically impossible rows are refused, naming the row: a magnitude <= 0, or a
    deflection ``|w| >= L`` (an arc of length ``L`` never reaches ``L`` off its clamp line:
    ``max (1 - cos u)/u = 0.72`` of ``L``).  More than ``max_rows`` data rows (default
    :data:`MAX_DATA_ROWS`; None: no cap) are refused before they are parsed.

    Examples
    --------
    >>> import os, tempfile
    >>> path = os.path.join(tempfile.mkdtemp(), "data.csv")
    >>> with open(path, "w") as fh:
    ...     _ = fh.write("voltage,deflection\\n0.5V,1.0mm\\n1V,2.1mm\\n1.5V,2.9mm\\n")
    >>> data = read_data(path)
    >>> data.n_points
    3
    """
    base = Strip() if base is None else base
    p = os.fspath(path)
    name = os.path.basename(p)
    if max_rows is not None and (isinstance(max_rows, bool) or int(max_rows) < 1):
        raise ValueError(f"max_rows must be an integer >= 1 or None; got {max_rows!r}")
    rows = read_rows(p, max_rows)
    header = [h.strip().lower() for h in rows[0]]
    allowed = list(GEOMETRY) + list(MEASURED) + [f"sigma_{m}" for m in MEASURED]
    for j, h in enumerate(header, 1):
        if h == "charge_density" or h == "sigma_charge_density":
            raise ValueError(f"{name}: column {j} {h!r} is not supported yet (charge output not in this "
                             f"version); allowed: {', '.join(allowed)}")
        if h not in allowed:
            raise ValueError(f"{name}: unknown column {j} {h!r} in the header; allowed: {', '.join(allowed)}")
        if header.count(h) > 1:
            raise ValueError(f"{name}: column {h!r} appears twice in the header")
    meas = [m for m in MEASURED if m in header]
    if not meas:
        raise ValueError(f"{name}: no measured column; need deflection and/or blocking_force")
    for m in MEASURED:
        if f"sigma_{m}" in header and m not in header:
            raise ValueError(f"{name}: column sigma_{m} without a {m} column")
    data = rows[1:]
    if not data:
        raise ValueError(f"{name}: no data rows after the header")
    n = len(data)
    cols = {h: np.full(n, np.nan) for h in header}
    for i, r in enumerate(data):
        rowno = i + 2  # 1-based, header is row 1
        if len(r) != len(header):
            raise ValueError(f"{name} row {rowno}: {len(r)} fields, header has {len(header)}")
        for h, cell in zip(header, r):
            cell = cell.strip()
            if cell == "":
                if h in GEOMETRY:
                    raise ValueError(f"{name} row {rowno}, column {h!r}: empty (geometry/drive needs a value)")
                continue
            try:
                v = _parse_cell(h, cell)
            except ValueError as exc:
                raise ValueError(f"{name} row {rowno}, column {h!r}: {exc}") from None
            if h != "voltage" and not v > 0:
                what = "a magnitude > 0" if h in MEASURED else "> 0"
                raise ValueError(f"{name} row {rowno}, column {h!r}: must be {what}; got {cell!r}")
            if not math.isfinite(v):
                raise ValueError(f"{name} row {rowno}, column {h!r}: must be finite; got {cell!r}")
            cols[h][i] = v
    for m in meas:
        s = f"sigma_{m}"
        if s in cols:
            miss = np.isfinite(cols[m]) & ~np.isfinite(cols[s])
            if np.any(miss):
                raise ValueError(f"{name} row {int(np.argmax(miss)) + 2}, column {s!r}: empty where {m} is given")
    geometry = {g: (cols[g] if g in cols else np.full(n, float(getattr(base, g)))) for g in GEOMETRY}
    if "deflection" in cols:
        # the tip of an arc of length L lies within 0.72 L of the clamp line: |w| >= L is no bending
        far = np.isfinite(cols["deflection"]) & (cols["deflection"] >= geometry["length"])
        if np.any(far):
            i = int(np.argmax(far))
            raise ValueError(f"{name} row {i + 2}, column 'deflection': |w| = {cols['deflection'][i]:.4g} m is not "
                             f"below the strip length L = {geometry['length'][i]:.4g} m (physically impossible; "
                             f"units?)")
    for m in meas:
        zero_v = np.isfinite(cols[m]) & (geometry["voltage"] == 0.0)
        if np.any(zero_v):
            raise ValueError(f"{name} row {int(np.argmax(zero_v)) + 2}, column 'voltage': 0 V gives no bending; "
                             f"a measured {m} needs a non-zero voltage")
    measured = {m: cols[m] for m in meas}
    sigma = {m: cols.get(f"sigma_{m}") for m in meas}
    if any(s is None for s in sigma.values()) and any(s is not None for s in sigma.values()):
        raise ValueError(f"{name}: give sigma_ columns for every measured column or for none")
    return CalibrationData(geometry, measured, sigma, source=name,
                           file_columns=tuple(k for k in GEOMETRY if k in header))


def parse_free(spec) -> dict:
    """``"modulus=50MPa:500MPa,c_moy"`` or a list/dict -> ``{name: (lo, hi)}`` (SI)."""
    if isinstance(spec, dict):
        items = list(spec.items())
    else:
        if isinstance(spec, str):
            spec = [s for s in spec.split(",") if s.strip()]
        items = []
        for s in spec:
            s = s.strip()
            if "=" in s:
                k, rng = s.split("=", 1)
                parts = rng.split(":")
                if len(parts) != 2:
                    raise ValueError(f"--free {k.strip()}: bounds must be LO:HI; got {rng!r}")
                items.append((k.strip(), tuple(parts)))
            else:
                items.append((s, None))
    out = {}
    for k, b in items:
        k = FREE_ALIASES.get(k, k)
        if k not in FREE_PARAMETERS:
            raise ValueError(f"--free: unknown parameter {k!r}; allowed: {', '.join(FREE_PARAMETERS)}")
        if k in out:
            raise ValueError(f"--free: {k!r} given twice")
        unit, dflt, _ = FREE_PARAMETERS[k]
        if b is None:
            out[k] = dflt
            continue
        lo, hi = (_bound(k, x) for x in b)
        if not 0 < lo < hi:
            raise ValueError(f"--free {k}: bounds must satisfy 0 < LO < HI ({unit}); got {lo:g}:{hi:g}")
        out[k] = (lo, hi)
    if not out:
        raise ValueError("--free needs at least one of " + ", ".join(FREE_PARAMETERS))
    return out


def free_warnings(bounds: dict) -> list:
    """One line per free parameter whose bounds (``{name: (lo, hi)}``, SI, of :func:`parse_free`) lie
    wholly outside its plausible range (:data:`ipmc_asym.model.limits.PLAUSIBLE`): a bare number is
    SI (``modulus=1:2`` is 1-2 Pa), and such a fit searches where no strip is (it runs, as asked)."""
    out = []
    for k, (lo, hi) in bounds.items():
        par = PARAMETERS[k]
        pl = par.plausible
        if pl is None or (hi >= pl[0] and lo <= pl[1]):
            continue
        out.append(f"--free {k} {lo:g}:{hi:g} {par.unit} lies wholly outside the plausible {pl[0]:g}-{pl[1]:g} "
                   f"{par.unit} (a bare number is SI, {par.unit}); fitted as given")
    return out


def _bound(k, x):
    """A bound of ``--free k`` in SI (a bare number or a value with one of the parameter's units)."""
    where = k if k == "modulus" else f"--free {k}"
    v = parse_value(k, x, where)
    # a bound past the material's own range would be refused in the middle of the fit
    if k == "diffusion":
        check_diffusion(v, where)
    elif k == "c_moy":
        check_c_moy(v, where)
    return v


# ---- forward model ---------------------------------------------------------------------------
def _perm(model, values):

    p = get_model(model)
    if "eps0" in values or "deps" in values:
        p = Permittivity(p.name, eps0=values.get("eps0", p.eps0), deps=values.get("deps", p.deps))
    return p


def _material(material: Material, values) -> Material:
    """``material`` with the fitted material fields of ``values`` (model.parameters.with_values)."""
    return with_values(material, values)


def predict(values: dict, geometry: dict, model="constant", fidelity="leading",
            material: Material = NAFION_LI, *, with_checks: bool = False):
    """Model predictions at the data's geometry for parameter ``values`` (SI).

    Returns
    -------
    outputs : dict
        ``deflection`` (``|w|``, large displacement, m) and ``blocking_force`` (``|F|``, large
        displacement, N): arrays (n_rows,), NaN where the beam has no answer.
    errors : dict
        Relative error estimate of each output, arrays (n_rows,): the error estimate of ``I``
        (hence of ``M_A``) times ``|d ln y / d ln M_A|`` -- for the arc deflection
        ``2u cot(u) - 1`` with ``u = kappa L/2`` (1 for small bending, unbounded where the
        strip curls back and ``w`` stops growing with ``M``); for the force
        ``1 + d ln psi / d ln(kappa L)`` (by a central difference).
    valid : ndarray of bool (n_rows,)
    checks : dict, only with ``with_checks``
        The forward model's model assumptions at each row (``forward.model.ASSUMPTION_CHECKS``
        -> bool array, False where the row's state fails it).
    """
    from ipmc_asym.forward.model import ASSUMPTION_CHECKS, forward  # deferred: heavy import (Numba kernels)

    mat = _material(material, values)
    perm = _perm(model, values)
    g = geometry
    # the forward model at the one rung asked for (the fit chooses the rung; no escalation)
    r = forward(g["length"], g["width"], g["thickness"], g["voltage"], material=mat, model=perm,
                fidelity=fidelity, escalate=False)
    err = np.asarray(r.error, float)
    with np.errstate(all="ignore"):
        w = np.abs(np.asarray(r.w, dtype=float))
        F = np.abs(np.asarray(r.F_block, dtype=float))
        m = np.abs(np.asarray(r.theta, dtype=float))  # |kappa L|
        u = 0.5 * m
        sw = np.where(u < 1e-4, 1.0, 2.0 * u / np.tan(np.where(u < 1e-4, 1.0, u)) - 1.0)
        h = 1e-4
        dpsi = (np.asarray(blocking_force_ratio(m * (1 + h)), float)
                - np.asarray(blocking_force_ratio(m * (1 - h)), float)) / (2 * h)
        sF = 1.0 + dpsi / np.asarray(blocking_force_ratio(m), float)
        errors = {"deflection": np.abs(sw) * err, "blocking_force": np.abs(sF) * err}
    errors = {k: np.where(np.isfinite(v), v, np.inf) for k, v in errors.items()}
    if with_checks:
        checks = {c: np.asarray(getattr(r, c), bool) for c in ASSUMPTION_CHECKS}
        return {"deflection": w, "blocking_force": F}, errors, np.asarray(r.moment_valid, bool), checks
    return {"deflection": w, "blocking_force": F}, errors, np.asarray(r.moment_valid, bool)


# ---- the fit ---------------------------------------------------------------------------------
@dataclass(repr=False)
class CalibrationResult(ResultMixin):
    """Outcome of :func:`fit`.

    Attributes
    ----------
    parameters : dict
        name -> ``{"value", "stderr", "ci95", "identifiable", "status", "note"}`` (SI).
        ``ci95`` is the profile-likelihood interval, the answer; None on an open side.
        ``stderr`` (linearised, from the Jacobian) only where the profile is locally quadratic
        (both profile ends within :data:`QUADRATIC_TOL` of the linearised ones), else None
        with the reason in ``note``.  ``status``: ``"ok"``, ``"at_bound"`` (the best fit lies
        on a bound of ``--free``: the data want a value beyond it) or ``"not_identifiable"``
        (flat or one-sided profile with the optimum inside the bounds).
    correlation : list of list
        Correlation matrix of the free parameters (order of ``names``); None entries for
        non-identifiable parameters.
    chi2_red : float or None
        ``chi^2/(n - p)`` with the given ``sigma_`` columns (a goodness of fit: ~1 if the model
        and the sigma are right).  None without sigma columns: the noise scale is then
        estimated from the residuals (``noise_scale``) and ``chi2_red`` would be 1 by
        construction, no test of anything.
    noise_scale : float or None
        Without sigma columns: the estimated relative noise ``s = sqrt(chi^2/(n - p))`` of the
        relative residuals (e.g. 0.03 for 3 % noise); None with sigma columns.
    warnings : list of str
        Outliers (a large ``chi2_red`` with known sigma), rows where the forward model's
        assumptions fail at the fitted parameters (past a quarter turn, above the strain limit).
    n_points, fidelity, model
    success : bool
    message : str
        What was decided (fidelity, identifiability) in one or a few sentences.
    names : list of str
    predictions : dict   model at the optimum (for plots)
    data : CalibrationData
    flagged_rows : dict   model assumption -> indices of the data rows whose fitted state fails
        it (the forward model's checks, as ``evaluate`` flags them); empty if none
    """

    _result = ResultSpec("row", None, ())

    def _arrays(self):
        """Fitted parameters (0-d), and per data row the geometry, the measured and fitted values."""
        out = {k: np.asarray(v["value"], float) for k, v in self.parameters.items() if k in BY_NAME}
        if isinstance(self.data, CalibrationData):
            out.update({k: np.asarray(v) for k, v in self.data.geometry.items()})
            for m in MEASURED:
                if m in self.data.measured and m in self.predictions:
                    out[f"measured_{m}"] = np.asarray(self.data.measured[m], float)
                    out[f"fitted_{m}"] = np.asarray(self.predictions[m], float)
        return "row", None, out

    def _panels(self, arrays):
        return tuple(Panel("row", (f"measured_{m}", f"fitted_{m}")) for m in MEASURED if f"fitted_{m}" in arrays)

    parameters: dict
    correlation: list
    chi2_red: float | None
    n_points: int
    fidelity: str
    model: str
    success: bool = True
    message: str = ""
    names: list = field(default_factory=list)
    predictions: dict = field(default_factory=dict, repr=False)
    data: CalibrationData | None = field(default=None, repr=False)
    flagged_rows: dict = field(default_factory=dict)
    noise_scale: float | None = None
    warnings: list = field(default_factory=list)

    @property
    def chi2_note(self) -> str:
        """What ``chi2_red`` means here (one sentence)."""
        if self.chi2_red is None and self.noise_scale is None:
            return ("as many free parameters as measured values (n = p): no degree of freedom is left, "
                    "so there is no goodness of fit")
        if self.chi2_red is None:
            return ("no sigma_ columns: the noise scale is estimated from the residuals (noise_scale, relative), "
                    "so chi2_red would be 1 by construction and is not a goodness of fit")
        return "chi2/(n - p) with the given sigma_ columns: ~1 when the model and the sigma are right"

    def as_dict(self) -> dict:
        """The keys of ``--json``."""
        return {"parameters": self.parameters, "correlation": self.correlation, "chi2_red": self.chi2_red,
                "n_points": self.n_points, "fidelity": self.fidelity, "model": self.model,
                "noise_scale": self.noise_scale, "chi2_note": self.chi2_note, "warnings": self.warnings}


class _Problem:
    """Weighted residuals in log parameters (picklable: workers of a multistart get one)."""

    def __init__(self, data, names, model, material, fidelity, fixed=None):
        self.data, self.names, self.model, self.material, self.fidelity = data, names, model, material, fidelity
        self.fixed = dict(fixed or {})
        self.keys = list(data.measured)
        self.masks = {k: np.isfinite(data.measured[k]) for k in self.keys}
        if data.has_sigma:
            self.scale = {k: data.sigma[k][self.masks[k]] for k in self.keys}
        else:
            self.scale = {k: data.measured[k][self.masks[k]] for k in self.keys}
        self.bar = None  # a progress bar counting model evaluations (this process only)

    def __getstate__(self):
        d = dict(self.__dict__)
        d["bar"] = None  # workers of a multistart get no bar
        return d

    def sub(self, names, fixed):
        """The same data with ``names`` free and ``fixed`` held (a profile's inner problem)."""
        out = _Problem(self.data, names, self.model, self.material, self.fidelity, fixed)
        out.bar = self.bar
        return out

    def labels(self):
        """What each residual is, for warnings: ``"row N"`` (data rows count from 2, header 1)."""
        return [f"row {int(i) + 2}" for i in _row_of_residual(self)]

    def values(self, x):
        v = dict(self.fixed)
        v.update({n: math.exp(float(xi)) for n, xi in zip(self.names, x)})
        return v

    def residuals(self, x):
        if self.bar is not None:
            self.bar.update(1)
        out, _, _ = predict(self.values(x), self.data.geometry, self.model, self.fidelity, self.material)
        parts = []
        for k in self.keys:
            m = self.masks[k]
            parts.append((out[k][m] - self.data.measured[k][m]) / self.scale[k])
        r = np.concatenate(parts)
        # outside the model's domain (beam branch not tracked): a large finite residual so the
        # trust region backs off instead of the optimiser seeing NaN
        return np.where(np.isfinite(r), r, 1e3)


def _solve(problem, x0, lo, hi):
    from scipy.optimize import least_squares  # deferred: heavy import (start-up)

    x0 = np.clip(np.asarray(x0, float), lo + 1e-12, hi - 1e-12)
    with np.errstate(all="ignore"):
        return least_squares(problem.residuals, x0, bounds=(lo, hi), method="trf", x_scale=1.0,
                             xtol=1e-12, ftol=1e-12, gtol=1e-12, max_nfev=400)


def _multistart_task(args):
    """One start of a multistart (module level: runs on workers)."""
    problem, x0, lo, hi = args
    r = _solve(problem, x0, lo, hi)
    return float(r.cost), np.asarray(r.x, float)


def _start_values(names, model, material):

    p = get_model(model)
    out = []
    for n in names:
        if n == "modulus":
            v = material.E
        elif n == "c_moy":
            v = material.C_moy
        elif n == "electrode_thickness":
            v = material.electrode.thickness
        elif n == "electrode_modulus":
            v = material.electrode.modulus
        else:
            v = getattr(p, n)
            if v <= 0:
                v = _EPS_START[n]
        out.append(v)
    return out


def check_count(names, n, has_sigma) -> None:
    """Refuse (one line) more free parameters than ``n`` measured values can determine."""
    p = len(names)
    need = p + (0 if has_sigma else 1)
    if n < need:
        extra = "" if has_sigma else " (without sigma_ columns one more, to estimate the noise scale)"
        raise ValueError(f"too many free parameters: {p} ({', '.join(names)}) for {n} measured value(s); "
                         f"need at least {need}{extra}")


def static_ladder(names, fidelity) -> list:
    """The static rungs a fit climbs: ``fidelity`` alone if forced, else :data:`LADDER`, without the
    closed-form rungs when ``eps0`` or ``deps`` is free."""
    if fidelity is not None:
        if fidelity not in LADDER:
            raise ValueError(f"fidelity must be one of {', '.join(LADDER)}; got {fidelity!r}")
        return [fidelity]
    perm_free = any(k in ("eps0", "deps") for k in names)
    return [f for f in LADDER if not (perm_free and f in closed_form_fidelities())]


def multistart_starts(x0, lo, hi, multistart, seed) -> list:
    """``x0`` and ``multistart`` more starts, log-uniform in the bounds (seeded)."""
    starts = [x0]
    if multistart and multistart > 0:
        rng = np.random.default_rng(seed)
        starts += [rng.uniform(lo, hi) for _ in range(int(multistart))]
    return starts


def fit(data: CalibrationData, free, model="constant", material: Material = NAFION_LI,
        fidelity: str | None = None, multistart: int = 0, seed: int = 0, scheduler=None,
        progress: bool | None = False) -> CalibrationResult:
    """Weighted least squares of ``data`` over the ``free`` parameters, with profile intervals.

    Parameters
    ----------
    data : CalibrationData
    free : str, list or dict
        Names from :data:`FREE_PARAMETERS` (``modulus``, ``c_moy``, ``eps0``, ``deps``), or
        ``{name: (lo, hi)}`` bounds in SI (default bounds otherwise).  ``diffusion``,
        ``viscous_modulus`` and ``sheet_resistance`` are refused here (static rows do not
        depend on them): time series and spectra go to
        :func:`ipmc_asym.studies.calibrate_dynamic.fit_dynamic`.
    model : {"constant", "linear", "affine"}
        Permittivity model (its eps0/deps are the start/fixed values).
    material : Material
        Fixed material data and start values of ``modulus``/``c_moy``.
    fidelity : str, optional
        Force a fidelity; default: the cheapest whose error estimate is < 1/10 of the data's
        relative error at the fitted parameters.
    multistart : int
        Extra starts, log-uniform inside the bounds (seeded by ``seed``), run through
        :func:`ipmc_asym.parallel.executors.run_chunks` on ``scheduler``; the best one is kept.
    scheduler : None, "local" or "tcp://HOST:PORT"
    progress : bool or None
        A bar on stderr counting model evaluations (None: when stderr is a terminal).

    Returns
    -------
    CalibrationResult

    Raises
    ------
    ValueError
        One line: unknown parameter, too many free parameters for the data (the request is
        refused before any work), a fidelity outside its validity at every rung.

    Examples
    --------
    >>> import os, tempfile
    >>> path = os.path.join(tempfile.mkdtemp(), "data.csv")
    >>> with open(path, "w") as fh:
    ...     _ = fh.write("voltage,deflection\\n0.5V,1.0mm\\n1V,2.1mm\\n1.5V,2.9mm\\n")
    >>> res = fit(read_data(path), "modulus", fidelity="corrected")
    >>> res.success, res.parameters["modulus"]["identifiable"]
    (True, True)
    """
    from scipy import stats  # deferred: heavy import (start-up)

    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise ValueError(f"seed must be an integer >= 0; got {seed!r}")
    bounds = parse_free(free)
    names = list(bounds)
    check_visible(names, ("static",))
    check_stiffness_free(names, material)
    p = len(names)
    n = data.n_points
    check_count(names, n, data.has_sigma)
    lo = np.log([bounds[k][0] for k in names])
    hi = np.log([bounds[k][1] for k in names])
    x0 = np.clip(np.log(_start_values(names, model, material)), lo, hi)
    ladder = static_ladder(names, fidelity)
    # multistart (fidelity of the first rung; the ladder then refines the best start)
    starts = multistart_starts(x0, lo, hi, multistart, seed)
    from ipmc_asym.base.progress import progress as _bar  # deferred: tqdm

    bar = _bar(None, "fit", enabled=progress, unit="eval")
    try:
        res = _fit(data, bounds, names, p, n, lo, hi, x0, ladder, starts, model, material, fidelity, scheduler,
                   bar, stats)
    finally:
        bar.close()
    res.warnings[:0] = free_warnings(bounds)
    return res


def _fit(data, bounds, names, p, n, lo, hi, x0, ladder, starts, model, material, fidelity, scheduler, bar,
         stats) -> CalibrationResult:
    """The body of :func:`fit` (``bar`` counts model evaluations)."""
    notes = []
    warns = []
    res = None
    chosen = None
    x = x0
    for k, fid in enumerate(ladder):
        prob = _Problem(data, names, model, material, fid)
        prob.bar = bar
        if k == 0 and len(starts) > 1:

            outs = run_chunks(_multistart_task, [(prob, s, lo, hi) for s in starts], scheduler=scheduler)
            best = min(range(len(outs)), key=lambda i: outs[i][0])
            x = outs[best][1]
            notes.append(f"multistart: best of {len(starts)} starts is #{best}")
        res = _solve(prob, x, lo, hi)
        x = res.x
        out, errs, valid = predict(prob.values(x), data.geometry, model, fid, material)
        rows = np.zeros(data.n_rows, bool)
        for m in prob.masks.values():
            rows |= m
        worst = max(float(np.max(errs[k][prob.masks[k]])) for k in prob.keys)
        chi2 = 2.0 * float(res.cost)
        if data.has_sigma:
            rel = min(float(np.min(data.sigma[m][prob.masks[m]] / data.measured[m][prob.masks[m]]))
                      for m in prob.keys)
        else:
            rel = math.sqrt(chi2 / max(n - p, 1))
        bias_ok, bias_note = _bias_check(prob, res, out, errs, chi2, n, p, data.has_sigma)
        if bool(np.all(valid[rows])) and worst < 0.1 * rel and bias_ok:
            chosen = fid
            break
        if bool(np.all(valid[rows])) and worst < 0.1 * rel:
            notes.append(f"{fid}: {bias_note}")
            continue
        notes.append(f"{fid}: error estimate {worst:.2g} not below a tenth of the data's relative error "
                     f"{rel:.2g}" + ("" if np.all(valid[rows]) else " (outside validity)"))
    if chosen is None:
        if fidelity is not None:
            why = notes[-1].split(": ", 1)[-1] if notes else "not accurate enough"
            raise ValueError(f"fidelity {fidelity!r}: {why}; leave --fidelity unset to escalate")
        raise ValueError(f"no fidelity is accurate enough for data this precise ({'; '.join(notes)})")
    prob = _Problem(data, names, model, material, chosen)
    prob.bar = bar
    params, corr, chi2_red, noise_scale = _report(prob, res, lo, hi, n, data.has_sigma, stats, notes, warns)
    out, _, _, chk = predict(prob.values(res.x), data.geometry, model, chosen, material, with_checks=True)
    flagged = {c: [int(i) for i in np.flatnonzero(~ok)] for c, ok in chk.items() if not np.all(ok)}
    warns.extend(_assumption_warnings(flagged, data))
    msg = (f"fidelity {chosen} (cheapest with error estimate < 1/10 of the data's relative error and a model-error "
           f"shift < 0.1 standard error on every estimate)")
    if notes:
        msg += "; " + "; ".join(notes)
    if flagged:  # the rows' fitted states outside a model assumption (kept in the fit, said here)
        msg += "; at the fit, data rows outside a model assumption: " + "; ".join(
            f"{c}: rows {', '.join(map(str, rows[:10]))}{' ...' if len(rows) > 10 else ''}" for c, rows in flagged.items())

    return CalibrationResult(parameters=params, correlation=corr, chi2_red=chi2_red, n_points=n,
                             fidelity=chosen, model=get_model(model).name, success=bool(res.success),
                             message=msg, names=names, predictions=out, data=data, flagged_rows=flagged,
                             noise_scale=noise_scale, warnings=warns)


def _log_covariance(J, s2):
    """``(cov, sd_log)``: the linearised covariance ``s2 (J^T J)^+`` of the log parameters and their
    standard errors."""
    J = np.asarray(J, float)
    cov = s2 * np.linalg.pinv(J.T @ J)
    return cov, np.sqrt(np.clip(np.diag(cov), 0.0, None))


def _interval_scale(J, chi2, n, p, has_sigma, stats):
    """``(s2, thr, cov, sd_log)`` at an optimum with Jacobian ``J`` and ``chi2``: the residuals'
    scale (1 with known sigma, else ``chi2/(n - p)``, NaN without a degree of freedom), the
    threshold of ``Delta chi^2 / s2`` for a 95 % profile interval, and :func:`_log_covariance`."""
    dof = n - p
    s2 = 1.0 if has_sigma else (chi2 / dof if dof > 0 else float("nan"))
    thr = float(stats.chi2.ppf(0.95, 1)) if has_sigma else float(stats.t.ppf(0.975, dof) ** 2)
    return (s2, thr, *_log_covariance(J, s2))


def _report(prob, res, lo, hi, n, has_sigma, stats, notes, warns, ends=None):
    """Estimates, profile intervals, statuses and correlations at the optimum ``res`` of ``prob``.

    The one place that decides what is reported (``ok`` / ``at_bound`` / ``not_identifiable``,
    standard error only where the profile is locally quadratic) for the static fit and the
    joint fit of :mod:`ipmc_asym.studies.calibrate_dynamic`.  ``prob`` is a residual problem
    (``names``, ``residuals``, ``sub``, ``labels``); appends to ``notes`` and ``warns``; a list
    ``ends`` receives ``(j, side, x)`` per profile end found (``x`` the full log parameters there,
    the others re-minimised).  Returns ``(parameters, correlation, chi2_red, noise_scale)``.
    """
    names = prob.names
    p = len(names)
    chi2 = 2.0 * float(res.cost)
    dof = n - p
    s2_hat = chi2 / dof if dof > 0 else float("nan")
    # chi2_red is a goodness of fit only with known sigma; without it the scale is estimated
    # (s^2 = chi^2/(n - p)) and chi2/(s^2 (n - p)) = 1 identically; with n = p (allowed with
    # sigma) no degree of freedom is left for either: None, not 0/0
    chi2_red = s2_hat if has_sigma and dof > 0 else None
    noise_scale = None if has_sigma else math.sqrt(s2_hat)
    s2, thr, cov, sd_log = _interval_scale(res.jac, chi2, n, p, has_sigma, stats)
    if has_sigma and dof > 0:
        pval = float(stats.chi2.sf(chi2, dof))
        if pval < 1e-3:
            warns.append(_outlier_warning(prob, res.x, chi2_red, pval, dof))

    J = np.asarray(res.jac, float)
    params, quad = {}, []
    for j, nm in enumerate(names):
        lo_ci, hi_ci, why = _profile(prob, res.x, j, lo, hi, chi2, s2, thr, sd_log[j], ends)
        ok = lo_ci is not None and hi_ci is not None
        val = math.exp(float(res.x[j]))
        at = _at_bound(res.x[j], lo[j], hi[j])
        if at and not ok:
            # "at the bound" only where the data pull beyond it: the profile's slope there
            # (others re-minimised: d(chi^2/s^2)/dx_j = 2 J_j.r / s^2) would lower chi^2 by more
            # than the 95 % threshold within an e-fold beyond; a flat approach is not identifiable
            g = 2.0 * float(J[:, j] @ np.asarray(res.fun, float)) / s2
            if not (-at * g > thr):
                at = 0
        status = "ok" if ok else ("at_bound" if at else "not_identifiable")
        # the linearised standard error describes the profile only where it is locally
        # quadratic: both profile ends at the Wald ends x^ -+ sqrt(thr) sd (log parameter)
        h = math.sqrt(thr) * float(sd_log[j])
        is_quad = ok and h > 0 and math.isfinite(h) and all(
            abs(d - h) <= QUADRATIC_TOL * h for d in (float(res.x[j]) - lo_ci, hi_ci - float(res.x[j])))
        quad.append(is_quad)
        if status == "at_bound":
            side, bnd = ("lower", lo[j]) if at < 0 else ("upper", hi[j])
            note = (f"the best fit lies on the {side} bound {math.exp(bnd):.4g} {FREE_PARAMETERS[nm][0]}: the data "
                    f"want a value beyond it; widen --free {nm}=LO:HI (no interval, no standard error)")
        elif status == "not_identifiable":
            note = f"not identifiable from these data: {why}"
        elif not is_quad:
            wald = (math.exp(float(res.x[j]) - h), math.exp(float(res.x[j]) + h)) if math.isfinite(h) else None
            note = ("profile not locally quadratic (the linearised interval "
                    + (f"[{wald[0]:.4g}, {wald[1]:.4g}]" if wald else "is undefined")
                    + " differs from the profile's by more than "
                    + f"{QUADRATIC_TOL:.0%} of its half-width): no standard error; the profile interval is the answer")
        else:
            note = ""
        params[nm] = {
            "value": val,
            "stderr": val * float(sd_log[j]) if is_quad else None,
            "ci95": [None if lo_ci is None else math.exp(lo_ci), None if hi_ci is None else math.exp(hi_ci)],
            "identifiable": ok,
            "status": status,
            "note": note,
        }
        if note:
            notes.append(f"{nm} {note}" if status == "not_identifiable" else f"{nm}: {note}")
    ident = quad
    corr = []
    for a in range(p):
        row = []
        for b in range(p):
            if ident[a] and ident[b] and sd_log[a] > 0 and sd_log[b] > 0:
                row.append(float(cov[a, b] / (sd_log[a] * sd_log[b])))
            else:
                row.append(None)
        corr.append(row)
    return params, corr, chi2_red, noise_scale


#: the profile is "locally quadratic" when each of its 95 % ends lies within this fraction of
#: the linearised half-width from the linearised end (then the standard error describes it)
QUADRATIC_TOL = 0.2


def _at_bound(x, lo, hi, tol=1e-6) -> int:
    """-1 / +1 if log parameter ``x`` sits on its lower / upper bound, else 0."""
    if x - lo <= tol * max(1.0, abs(lo)):
        return -1
    if hi - x <= tol * max(1.0, abs(hi)):
        return 1
    return 0


def _row_of_residual(prob) -> np.ndarray:
    """Row index (0-based data row) of each entry of the residual vector."""
    return np.concatenate([np.flatnonzero(prob.masks[k]) for k in prob.keys])


def _outlier_warning(prob, x, chi2_red, pval, dof) -> str:
    r = prob.residuals(x)
    labels = prob.labels()
    worst = np.argsort(-np.abs(r))[:3]
    which = ", ".join(f"{labels[i]} ({r[i]:+.1f} sigma)" for i in worst)
    pv = f"= {pval:.1g}" if pval > 0 else "< 1e-300"
    return (f"chi2_red = {chi2_red:.3g} with the given sigma (p {pv}, {dof} degrees of freedom): outliers "
            f"or underestimated sigma; largest standardised residuals: {which}; the intervals assume the model "
            f"and the sigma are right")


def _assumption_warnings(flagged: dict, data) -> list:
    """One line per model assumption that rows fail at the fitted parameters (``flagged``: check ->
    0-based rows, from the forward model through :func:`predict`); data rows count from 2 (header 1)."""
    out = []
    for check, idx in flagged.items():
        rows = ", ".join(str(i + 2) for i in idx[:8]) + (", ..." if len(idx) > 8 else "")
        out.append(f"{len(idx)} of {data.n_rows} rows {_ASSUMPTION_WORDS.get(check, 'outside an assumption')} "
                   f"(the {check} check) at the fitted parameters (rows {rows}): the forward model flags them; "
                   f"they still enter the fit")
    return out


#: what each model assumption's failure means, in the fit's warnings
_ASSUMPTION_WORDS = {"beam_regime": "past a quarter turn (|theta| > pi/2)",
                     "blocked_regime": "with the blocked strip past a quarter turn",
                     "strain": "above the face-strain limit", "voltage": "beyond the validated voltage",
                     "slender": "outside the slender-strip limits"}


def _bias_check(prob, res, out, errs, chi2, n, p, has_sigma):
    """Does the model error move the estimates by less than a tenth of their standard error?

    The per-point rule (error < 1/10 of the data's relative error) does not see that the
    estimates average over ``n`` points while a systematic model error does not average out.
    Linearised: the shift of the log parameters is ``G r_model`` with ``G = (J^T J)^+ J^T``
    and ``r_model`` the worst-case weighted model error (error estimate x ``|prediction|`` /
    weight scale, every sign the worst one: ``|G| |r_model|``).
    """
    J = np.asarray(res.jac, float)
    rm = np.concatenate([errs[k][prob.masks[k]] * np.abs(out[k][prob.masks[k]]) / prob.scale[k] for k in prob.keys])
    if not np.all(np.isfinite(rm)):
        return False, "model error estimate not finite at some point"
    JtJ = np.linalg.pinv(J.T @ J)
    G = JtJ @ J.T
    s2 = 1.0 if has_sigma else chi2 / max(n - p, 1)
    sd = np.sqrt(np.clip(np.diag(s2 * JtJ), 0.0, None))
    bias = np.abs(G) @ np.abs(rm)
    ok = (sd <= 0) | (bias < 0.1 * sd)
    if np.all(ok):
        return True, ""
    j = int(np.argmax(np.where(sd > 0, bias / np.where(sd > 0, sd, 1.0), 0.0)))
    return False, (f"model error could shift {prob.names[j]} by {bias[j] / sd[j]:.2g} standard errors "
                   f"(> 0.1)")


def _profile(prob, xhat, j, lo, hi, chi2min, s2, thr, sd, points=None):
    """95 % profile-likelihood interval of parameter ``j`` in log space.

    Walks away from the optimum on each side (steps growing x1.6 from ~2 standard errors)
    until ``Delta chi^2 / s^2`` crosses ``thr`` (then brentq), the bound is reached, or the
    model has no answer (beam branch not tracked).  Returns ``(lo, hi, why)`` with None on a
    side that never crossed; appends ``(j, side, x)`` to the list ``points`` for each end found
    (``x``: the full log parameters there, the others as last re-minimised, within brentq's
    ``xtol`` of the end).
    """
    from scipy.optimize import brentq  # deferred: heavy import (start-up)

    others = [i for i in range(len(xhat)) if i != j]
    sub_lo, sub_hi = lo[others], hi[others]
    warm = {+1: xhat[others].copy(), -1: xhat[others].copy()}

    def delta(xj, side):
        if others:
            fixed = dict(prob.fixed)
            fixed[prob.names[j]] = math.exp(xj)
            sub = prob.sub([prob.names[i] for i in others], fixed)
            r = _solve(sub, warm[side], sub_lo, sub_hi)
            warm[side] = r.x
            c = 2.0 * float(r.cost)
        else:
            x = xhat.copy()
            x[j] = xj
            r = prob.residuals(x)
            c = float(r @ r)
        return (c - chi2min) / s2

    ends, why = {}, []
    for side in (-1, +1):
        bound = lo[j] if side < 0 else hi[j]
        step = min(max(2.0 * sd if np.isfinite(sd) and sd > 0 else 0.05, 1e-3), 0.5)
        x_prev = float(xhat[j])
        ends[side] = None
        for _ in range(60):
            x_new = x_prev + side * step
            at_bound = (x_new - bound) * side >= 0
            if at_bound:
                x_new = float(bound)
            d = delta(x_new, side)
            if not np.isfinite(d):
                why.append(f"the model has no answer {'below' if side < 0 else 'above'} "
                           f"{math.exp(x_prev):.3g}")
                break
            if d >= thr:
                if d > thr:
                    a, b = sorted((x_prev, x_new))
                    ends[side] = brentq(lambda t: delta(t, side) - thr, a, b, xtol=1e-6)
                else:
                    ends[side] = x_new
                break
            if at_bound:
                why.append(f"profile stays within the 95 % threshold down to the bound "
                           f"{math.exp(bound):.3g}" if side < 0 else
                           f"profile stays within the 95 % threshold up to the bound {math.exp(bound):.3g}")
                break
            x_prev = x_new
            step *= 1.6
    if points is not None:
        for side in (-1, +1):
            if ends[side] is not None:
                x = np.array(xhat, float)
                x[j] = ends[side]
                x[others] = warm[side]
                points.append((j, side, x))
    if ends[-1] is None and ends[+1] is None:
        kind = "flat profile"
    elif ends[-1] is None or ends[+1] is None:
        kind = "one-sided profile"
    else:
        kind = ""
    return ends[-1], ends[+1], (kind + (": " + "; ".join(why) if why else "")) if kind else ""
