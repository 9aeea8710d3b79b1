"""From strip + material + model to the mechanical outputs (``ipmc-asym estimate``).

One strip through :func:`ipmc_asym.forward.model.forward` (``M_A = A5 I``, paper sections
3-4, then the beam of :mod:`ipmc_asym.beam.statics`), formatted as one result row.  Signs as
in the paper: a positive voltage gives ``M_A > 0``, ``theta < 0`` and ``w < 0``.

No number whose numerical check failed is returned as a result: :func:`moment_escalating`
climbs the fidelity ladder (``registry.FIDELITIES``, cheapest first) point by point to the
cheapest rung valid there.  A failed model assumption (beam regime, strain, voltage, slender
strip) keeps the numbers and flags the row (``checks``, ``warnings``).  The checks
(:data:`CHECKS`) and what each withholds or flags are defined once, in
:mod:`ipmc_asym.forward.model`.
"""

from __future__ import annotations

import time

import numpy as np

from ipmc_asym.base.quantities import BY_NAME as QUANTITY_NAMES
from ipmc_asym.base.registry import check_choice
from ipmc_asym.base.results import Panel, ResultMixin, ResultSpec
from ipmc_asym.forward.escalation import Escalated, check_tol, moment_escalating
from ipmc_asym.forward.model import CHECKS, FREE_STRIP_KEYS, MECHANICAL_KEYS, _forward, assumption_warnings, model_notes
from ipmc_asym.model.electrode import beam_label
from ipmc_asym.model.groups import pressure_beta
from ipmc_asym.model.params import (
    _PAPER_SETS,
    NAFION_LI,
    Material,
    Strip,
    as_material,
    as_strip,
    bending_stiffness,
    debye_length,
)
from ipmc_asym.model.permittivity import MODELS
from ipmc_asym.model.request import Request
from ipmc_asym.model.spread import spread_of

__all__ = ["evaluate", "EstimateRow", "StripLine", "arc", "estimate_rows",
           "estimate_report", "estimate_document", "model_spread", "spread_of",
           "spread_variants", "SPREAD_KEYS",
           "RESULT_KEYS", "CHECKS", "moment_escalating", "Escalated",
           "check_tol", "FREE_STRIP_KEYS", "MECHANICAL_KEYS"]

RESULT_KEYS = ("model", "fidelity", "fidelity_used", "escalated", "C_moy", "A0", "A1", "A2", "A3", "A5",
               "B1", "I", "M_A", "theta", "w", "w_small", "F_block", "F_block_small", "error_estimate",
               "seconds")


def _f(x):
    x = float(x)
    return x if np.isfinite(x) else None


def evaluate(strip: Strip, model="constant", fidelity="quadrature", material: Material = NAFION_LI,
             tol: float | None = None, *, escalate: bool = True, on_invalid: str = "raise",
             pressure_term: bool = False) -> EstimateRow:
    """One result row (SI units) for one strip and one permittivity model.

    Parameters
    ----------
    strip : Strip
    model : str or Permittivity
    fidelity : str
        The cheapest rung tried; with ``escalate`` (default) the first rung from there that
        is valid at this point is used (``fidelity_used``, ``escalated``).
    material : Material, str or dict
        A material, a set name (``"nafion-li"``) or a ``[material]`` table.
    tol : float, optional
        Relative accuracy the caller needs, in (0, 1): the rung's error bound must meet it
        (default ``settings.VALIDITY_LIMIT``), and it decides whether a displacement counts
        as "small" (``regime``).
    escalate : bool
    on_invalid : {"raise", "nan"}
        No valid rung (a numerical check failed at every rung tried): one-line ``ValueError``
        (default), or the row with the moment and mechanical outputs ``None`` and
        ``valid = False``.  A failed model assumption never raises: the row keeps its numbers,
        ``valid = False``, the failed ``checks`` and one warning line each.
    pressure_term : bool
        Keep the pressure term of the Nernst-Planck law (paper eq. (5)): ``I`` at ``exact`` or
        ``bvp`` (:func:`ipmc_asym.forward.model.forward`); the row then also has
        ``pressure_term`` and ``beta``.

    Returns
    -------
    EstimateRow
        A dict (the JSON row of ``ipmc-asym estimate --json``), with a summary, ``.plot()`` (the
        bent strip) and ``.to_xarray()``; the keys of :data:`RESULT_KEYS` plus ``regime``, ``warnings``, ``x_tip``, ``y_tip``,
        ``debye_length`` (m), ``max_strain``, ``checks`` (each of :data:`CHECKS` -> bool),
        ``valid`` (all checks), ``flagged`` (the model assumptions that failed), ``withheld``
        (outputs set to ``None``: no valid rung, or the tip position past a full turn);
        ``error_estimate`` bounds the relative error of ``I`` (hence of ``M_A``, ``theta``,
        ``w_small``, ``F_block_small``).
    """
    req = Request(model, fidelity, tol, escalate, pressure_term)
    check_choice("on_invalid", on_invalid, ("raise", "nan"))
    material = as_material(material)
    strip = as_strip(strip)
    row = _evaluate(strip, req, material, on_invalid)
    if pressure_term:
        _add_beta([row], material)
    return EstimateRow(row, strip)


class EstimateRow(ResultMixin, dict):
    """One row of :func:`evaluate`: the dict of the JSON row (its keys read as attributes too,
    ``row.theta``), with a summary with units, ``.plot()`` and ``.to_xarray()`` (the numbers as
    0-d variables).  ``strip`` is the one evaluated: its length, total width and thickness and
    voltage lead the summary and the dataset (not keys of the row, whose JSON is as before)."""

    _result = ResultSpec("point", None, ())
    _HEADLINE = ("model", "fidelity_used", "regime", "valid")
    #: the strip's inputs shown with the row (vocabulary names)
    _INPUTS = ("length", "width", "thickness", "voltage")

    def __init__(self, row: dict, strip: Strip):
        super().__init__(row)
        self.strip = strip

    def __getattr__(self, key):
        try:
            return self[key]
        except KeyError:
            raise AttributeError(key) from None

    def _arrays(self):
        out = {k: np.asarray(float(getattr(self.strip, k))) for k in self._INPUTS}
        out.update({k: np.asarray(v) for k, v in self.items()
                    if k in QUANTITY_NAMES and isinstance(v, (bool, int, float)) and v is not None})
        return "point", None, out

    def _headline(self) -> str:
        s = self.strip
        return (super()._headline() + f" of L = {s.length * 1e3:.4g} mm, 2l = {s.width * 1e3:.4g} mm, "
                f"2e = {s.thickness * 1e6:.4g} um, phi0 = {s.voltage:g} V")

    def plot(self, *, figsize=(6.4, 3.6)):
        """The free strip's centre line (:class:`StripLine`: the arc of the tip rotation ``theta``
        over the length, the quasi-static beam of uniform moment); a ``Figure``."""
        th = self.get("theta")
        if th is None or self.get("x_tip") is None:  # withheld: a line with nothing to plot
            return StripLine(np.empty(0), np.empty(0), self._headline()).plot(figsize=figsize)
        x, y = arc(th, self.strip.length)
        fig = StripLine(x, y, self._headline()).plot(figsize=figsize)
        fig.axes[0].set_aspect("equal", adjustable="datalim")  # an arc drawn as an arc
        return fig


class StripLine(ResultMixin):
    """The centre line ``(x_line, y_line)`` (m) of a bent free strip, for :meth:`EstimateRow.plot`."""

    _result = ResultSpec("x_line", "x_line", ("y_line",), (Panel("x_line", ("y_line",)),))

    def __init__(self, x_line, y_line, headline: str):
        self.x_line, self.y_line, self._title = x_line, y_line, headline

    def _headline(self) -> str:
        return self._title


def arc(theta: float, length: float, points: int = 200):
    """Centre line ``(x, y)`` (m, arrays of ``points``) of a strip clamped at the origin along x
    and bent to the tip rotation ``theta`` (rad) at uniform curvature ``theta/length``; ``y`` has
    the sign of ``theta`` (``theta < 0``: ``w < 0``, paper eq. 12)."""
    s = np.linspace(0.0, length, points)
    k = theta / length
    if abs(k) * length < 1e-8:  # straight to within rounding: the series' first term
        return s, 0.5 * k * s * s
    return np.sin(k * s) / k, 2.0 * np.sin(0.5 * k * s) ** 2 / k  # 1 - cos without its cancellation


def _evaluate(strip: Strip, req: Request, material: Material, on_invalid: str) -> dict:
    """:func:`evaluate` of checked inputs (a built ``Strip``, ``Request`` and ``Material``)."""
    perm, fidelity = req.model, req.fidelity
    t0 = time.perf_counter()
    # the Strip holds its checks (the thickness floor: no 1e-300 m strip reaches the groups)
    g = perm.groups(strip, material)
    r = _forward(strip.length, strip.width, strip.thickness, strip.voltage, req, material=material)
    settled = bool(r.moment_valid)
    if not settled and on_invalid == "raise":
        raise ValueError(r.moment_message)
    used = str(r.fidelity_used)
    checks = r.checks()
    withheld = list(r.withheld())
    # one line per failed model assumption (limit and source); the beam's own line where the
    # large-displacement blocking force is not tracked
    warnings = [] if not settled else assumption_warnings(r, ())
    warnings += [w for w in r.beam_warnings if w.startswith("F_block")]
    if not settled:
        warnings.append(r.message)
    if settled and used != fidelity:
        warnings.append(f"escalated from {fidelity!r} to {used!r} (first rung valid here)")
    valid = all(checks.values())
    row = {
        "model": perm.name,
        "fidelity": fidelity,
        "fidelity_used": used or None,
        "escalated": bool(r.escalated),
        "C_moy": g.C_moy,
        "A0": g.A0,
        "A1": g.A1,
        "A2": g.A2,
        "A3": g.A3,
        "A5": g.A5,
        "B1": _f(r.B1),
        "I": _f(r.I),
        "M_A": _f(r.M_A),
        "theta": _f(r.theta),
        "w": _f(r.w),
        "w_small": _f(r.w_small),
        "F_block": _f(r.F_block),
        "F_block_small": _f(r.F_block_small),
        "error_estimate": _f(r.error),
        "seconds": time.perf_counter() - t0,
        "x_tip": _f(r.x_tip),
        "y_tip": _f(r.y_tip),
        "regime": str(r.regime) if settled else None,
        "debye_length": None if perm.is_custom else
        _f(debye_length(strip.thickness, perm.eps0 + perm.deps, material) * strip.e),
        "max_strain": _f(r.max_strain) if settled else None,
        "checks": checks,
        "valid": valid,
        "flagged": r.flagged(),
        "withheld": withheld,
        "warnings": warnings,
    }
    for k in withheld:
        row[k] = None
    return row


def estimate_rows(strip: Strip, models=("constant", "linear", "affine"), fidelity="quadrature",
                  material: Material = NAFION_LI, tol=None, *, escalate=True, on_invalid="raise",
                  pressure_term: bool = False) -> list[dict]:
    return [evaluate(strip, m, fidelity, material, tol, escalate=escalate, on_invalid=on_invalid,
                     pressure_term=pressure_term) for m in models]


def estimate_report(strip: Strip, models, fidelity="quadrature", material: Material = NAFION_LI, tol=None, *,
                    escalate: bool = True, on_invalid: str = "raise", pressure_term: bool = False,
                    spread: bool = True) -> tuple:
    """``(rows, model_spread)`` of ``estimate``: the rows of ``models`` and the model-form spread,
    from ONE checked request (the model, fidelity and tolerance checked once; the spread's other
    models are the paper's, already resolved).  ``strip`` and ``material`` are built objects;
    ``models`` as :func:`model_list` gives them (one name, or the paper's three).

    Returns
    -------
    rows : list of dict   as :func:`estimate_rows`
    spread : dict or None   as :func:`model_spread` (None with ``spread=False``)
    """
    base = Request(models[0], fidelity, tol, escalate, pressure_term)
    # a second model is one of the paper's (model_list): resolved already, checked once in base
    reqs = [base] + [base.with_model(MODELS[m]) for m in models[1:]]
    rows, spread_rows = _rows(strip, material, reqs, on_invalid, spread)
    if pressure_term:
        _add_beta(rows, material)
    return rows, (_spread(spread_rows, material) if spread else None)


def estimate_document(strip: Strip, material: Material = NAFION_LI, model: str = "all", fidelity="quadrature",
                      tol=None, *, escalate: bool = True, on_invalid: str = "nan", pressure_term: bool = False,
                      thickness_note: str = "") -> dict:
    """All of ``ipmc-asym estimate --json``: ``{"inputs", "results", "model_spread", "notes"}``.

    ``inputs`` echoes the strip, the material and the beam (with ``thickness_source`` =
    ``thickness_note`` where one is given: the material set's typical thickness stood in for
    the option), ``results`` the rows of ``model`` (a name or ``"all"``, :func:`model_list`)
    and ``model_spread`` the spread over the paper's models and C_moy forms, as
    :func:`estimate_report`.  With ``on_invalid="nan"`` a row where no rung is valid keeps
    ``I = None``; the command refuses it, a Python caller may keep the others.
    """
    models = model_list(model)
    notes = model_notes(strip.voltage, material, models)  # from the inputs alone
    base = Request(models[0], fidelity, tol, escalate, pressure_term)
    reqs = [base] + [base.with_model(MODELS[m]) for m in models[1:]]
    rows, spread_rows = _rows(strip, material, reqs, on_invalid, True)
    spread = _spread(spread_rows, material)
    # what depends on the material and the section only, once for the whole report
    if pressure_term:
        beta = float(pressure_beta(material))
        for r in rows:
            r["pressure_term"], r["beta"] = True, beta
    inputs = {
        "length": strip.length, "width_total": strip.width, "thickness_total": strip.thickness,
        "half_thickness_e": strip.e, "half_width_l": strip.l, "voltage": strip.voltage,
        "modulus": material.E, "c_moy": material.C_moy, "c_moy_source": str(material.c_moy),
        "I_p": strip.I_p, "material": material.name, "material_sources": list(material.sources),
        "pressure_term": bool(pressure_term),
        "beam": beam_label(material.electrode),
        "electrode_thickness": material.electrode.thickness,
        "electrode_modulus": material.electrode.modulus if material.electrode.present else None,
        "bending_stiffness": float(bending_stiffness(material, strip.width, strip.thickness)),
    }
    if thickness_note:
        inputs["thickness_source"] = thickness_note
    return {"inputs": inputs, "results": rows, "model_spread": spread, "notes": notes}


def _rows(strip: Strip, material: Material, reqs: list, on_invalid: str, spread: bool) -> tuple:
    """``(rows of reqs, {label: row})``: the requested rows and, with ``spread``, the row of each
    paper model for each C_moy form of :func:`spread_variants` (a requested row is reused where
    its model and C_moy are the same), every row from one :func:`_evaluate` each."""
    variants = spread_variants(material) if spread else []
    labelled = [(None, r, material, on_invalid) for r in reqs]
    for cm, mat in variants:
        for m, perm in MODELS.items():
            reused = mat.c_moy == material.c_moy and any(r.model.name == m for r in reqs)
            labelled.append((m if cm is None else f"{m}/{cm}", None if reused else reqs[0].with_model(perm), mat,
                             "nan"))
    done = [None if req is None else _evaluate(strip, req, mat, how) for _, req, mat, how in labelled]
    rows = done[:len(reqs)]
    by_model = {r["model"]: r for r in rows}
    out = {}
    for (label, req, _, _), row in zip(labelled[len(reqs):], done[len(reqs):]):
        out[label] = row if req is not None else by_model[label.split("/")[0]]
    return rows, out


def _add_beta(rows: list, material: Material) -> None:
    """The pressure term's ``beta`` (material only) on each row, after its numbers."""
    beta = float(pressure_beta(material))
    for r in rows:
        r["pressure_term"], r["beta"] = True, beta


def model_list(name: str) -> list:
    """The models ``name`` stands for: the paper's three for ``"all"``, else ``[name]`` (checked
    when its request is built)."""
    if name == "all":
        return list(MODELS)
    return [name]


#: the outputs of a row that depend on the permittivity model (and on C_moy): the spread is
#: reported for each
SPREAD_KEYS = ("M_A", "theta", "w", "w_small", "F_block", "F_block_small")

SPREAD_NOTE = (
    "error_estimate is the numerical error of one model: how exactly the code solves the paper's equations for "
    "that permittivity law. model_spread is the range of what the equally plausible model forms predict (the "
    "three permittivity laws of section 6, and C_moy stated vs eq. (17) for the paper's Nafion Li+): a lower "
    "bound on the model-form uncertainty of a prediction for a real strip, which is usually far larger than "
    "the numerical error (docs/measurements.md compares the predictions with published measurements)")


def spread_variants(material: Material):
    """``[(label, material)]``: the C_moy forms to span (paper and formula for the paper's sets,
    and a given value; ``label`` None for another set: its own C_moy only)."""
    if material.name in _PAPER_SETS:
        out = [("paper", material.with_(c_moy="paper")), ("formula", material.with_(c_moy="formula"))]
        if material.c_moy not in ("paper", "formula"):  # a given value: spanned too
            out.append((f"{material.C_moy:g}", material))
        return out
    return [(None, material)]


def model_spread(strip: Strip, material: Material = NAFION_LI, fidelity="quadrature", tol=None, rows=None, *,
                 escalate: bool = True, pressure_term: bool = False) -> dict:
    """The range of each model-dependent output over the model forms (the model-form spread).

    Parameters
    ----------
    strip, material, fidelity, tol, escalate, pressure_term
        As :func:`evaluate`.
    rows : list of dict, optional
        Rows already computed for ``material`` (:func:`estimate_rows`): reused, not recomputed.

    Returns
    -------
    dict
        ``over`` (list of str: what is spanned: the three permittivity models, and ``C_moy``
        paper/formula for the paper's sets), ``variants`` (labels ``model`` or
        ``model/c_moy``), ``quantities``: for each of :data:`SPREAD_KEYS` ``{"min", "max",
        "ratio" (max|y|/min|y|, None if a sign changes or a value is 0), "values" {label: SI
        value or None}, "numerical_error" (the largest error_estimate of the rows)}``, and
        ``note`` (numerical error vs model-form spread).  Values withheld by a row (no valid
        rung) are None and left out of min/max.
    """
    req = Request(MODELS[next(iter(MODELS))], fidelity, tol, escalate, pressure_term)
    return _model_spread(as_strip(strip), as_material(material), req, rows)


def _model_spread(strip: Strip, material: Material, req: Request, rows=None) -> dict:
    """:func:`model_spread` of checked inputs: ``req`` evaluated for each paper model (its
    ``with_model``) and each ``C_moy`` variant; ``rows`` already computed are reused."""
    done = {r["model"]: r for r in rows or ()}
    out_rows = {}
    for cm, mat in spread_variants(material):
        for m, perm in MODELS.items():
            r = done.get(m) if mat.c_moy == material.c_moy else None
            if r is None:
                r = _evaluate(strip, req.with_model(perm), mat, "nan")
            out_rows[m if cm is None else f"{m}/{cm}"] = r
    return _spread(out_rows, material)


def _spread(out_rows: dict, material: Material) -> dict:
    """The model-form spread of the rows ``{label: row}`` (:func:`model_spread`'s dict)."""
    err = [r["error_estimate"] for r in out_rows.values() if r["error_estimate"] is not None]
    q = {k: spread_of({lab: r.get(k) for lab, r in out_rows.items()}, max(err) if err else None)
         for k in SPREAD_KEYS}
    over = ["permittivity model: " + ", ".join(MODELS)]
    if material.name in _PAPER_SETS:
        over.append("C_moy: paper (the stated 3082 mol/m^3) and formula (eq. (17) from the set's data)")
    return {"over": over, "variants": list(out_rows), "quantities": q, "note": SPREAD_NOTE}
