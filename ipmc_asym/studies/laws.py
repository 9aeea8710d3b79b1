"""``ipmc-asym laws``: the analytic scaling laws and where they hold.

The laws come from ``derivations/scaling.py`` (SymPy, imported lazily); the local exponents
``d ln I / d ln phi0`` and ``d ln I / d ln e`` are computed from the ``quadrature`` fidelity
(exact to ~1e-13 against the BVP), so that each law is confirmed or refuted with numbers and
the range where it holds is stated.
"""

from __future__ import annotations

import numpy as np

from ipmc_asym.base.registry import check_choice, model_names
from ipmc_asym.base.settings import LAW_HOLD_TOL
from ipmc_asym.integral.api import moment
from ipmc_asym.studies.fits import local_exponent

__all__ = ["local_exponents", "law_table", "law_ranges", "factor_three", "VOLTAGE_LAWS"]

HOLD_TOL = LAW_HOLD_TOL


def local_exponents(model, var, n=241, thickness=200e-6, voltage=1.0):
    """Local exponent of ``I`` vs ``var`` ("voltage": 1 mV-10 V; "thickness": 10 um-4 mm).

    Returns (x, exponent) arrays; ``x`` is the voltage (V) or the TOTAL thickness (m).
    """
    if var == "voltage":
        x = np.logspace(-3, 1, n)
        I = moment(thickness, x, model, "quadrature").I
    elif var == "thickness":
        x = np.logspace(np.log10(10e-6), np.log10(4e-3), n)
        I = moment(x, voltage, model, "quadrature").I
    else:
        raise ValueError(f"var must be 'voltage' or 'thickness'; got {var!r}")
    return x, local_exponent(x, I)


#: LaTeX of the quantity names and of the symbols SymPy would spell as plain text
LATEX_NAMES = {"I": "I", "M_A": "M_A", "theta": r"\theta", "w_small": "w_{small}", "w": "w",
               "F_block": "F_{block}", "F_block_small": "F_{block,small}"}
LATEX_SYMBOLS = {"eps0": r"\varepsilon_0", "Delta_eps": r"\Delta\varepsilon", "deps": r"\Delta\varepsilon", "eps_moy": r"\varepsilon_{moy}",
                 "phi0": r"\phi_0", "phi4": r"\phi_4"}


def law_table(model=None):
    """Leading-order laws from the derivation: list of dict rows (SymPy objects stringified).

    Examples
    --------
    >>> rows = law_table("constant")
    >>> {r["model"] for r in rows}, "I" in {r["quantity"] for r in rows}
    ({'constant'}, True)
    """
    if model is not None:
        check_choice("model", model, model_names())  # one line naming the choices, not an empty table
    import sympy as sp  # deferred: SymPy (start-up)
    from ipmc_asym_derivations import scaling  # deferred: SymPy (start-up)

    rows = []
    for r in scaling.laws():
        if model and r["model"] != model:
            continue
        names = {s: LATEX_SYMBOLS[s.name] for s in r["expr"].free_symbols if s.name in LATEX_SYMBOLS}
        rows.append({
            "model": r["model"], "regime": r["regime"], "quantity": r["quantity"],
            "latex_name": LATEX_NAMES.get(r["quantity"], r["quantity"]),
            "formula": str(r["expr"]), "latex": sp.latex(r["expr"], symbol_names=names),
            "exponents": {k: str(v) for k, v in r["exponents"].items()},
        })
    return rows


def _ranges(x, ex, target, tol=HOLD_TOL):
    ok = np.abs(ex - target) < tol
    spans, start = [], None
    for i, flag in enumerate(ok):
        if flag and start is None:
            start = i
        if (not flag or i == len(ok) - 1) and start is not None:
            end = i if flag else i - 1
            if end > start:
                spans.append((float(x[start]), float(x[end])))
            start = None
    return spans


#: each regime's law: (exponent of I in phi0, where in the voltage range the regime lives).
#: "low"/"high": a limit law, which holds at its own end of the range; "middle": an intermediate
#: regime (A2 >> 1 but rho A2 << 1), which holds only on a plateau of the local exponent.
VOLTAGE_LAWS = {
    "constant": {"small voltage": (0.0, "low"), "large voltage": (0.5, "high")},
    "linear": {"small voltage": (0.0, "low"), "large voltage": (-1.0, "high")},
    "affine": {"small voltage": (0.0, "low"), "large voltage, rho A2 << 1": (-1.0, "middle"),
               "very large voltage, rho A2 >> 1": (0.5, "high")},
}


def _is_the_law(span, x, ex, where) -> bool:
    """A crossing is not the law: the span must reach its regime's end, or hold a plateau.

    A local exponent that passes through a law's exponent on its way elsewhere (e.g. the affine
    model's 0.5 between 4.6 and 8.3 V, overshooting to 0.56 at 10 V) is within the tolerance
    over an interval without the law holding there.  A limit law ("low"/"high") must hold up to
    its own end of the range; an intermediate law ("middle") must hold where the exponent turns
    (an interior extremum of the local exponent inside the span).
    """
    if where == "low":
        return span[0] == float(x[0])
    if where == "high":
        return span[1] == float(x[-1])
    inside = np.nonzero((x >= span[0]) & (x <= span[1]))[0]
    d = np.diff(ex[inside])
    return bool(inside.size > 2 and np.any(np.sign(d[:-1]) != np.sign(d[1:])))


def law_ranges(model):
    """Where ``I ~ phi0^a`` (each regime's a) and ``I ~ e^-1`` hold, from local exponents.

    A law holds where the local exponent is within ``HOLD_TOL`` of its exponent AND the span is
    the law's own (:func:`_is_the_law`, the same rule for every model and law): ``I ~ e^-1`` is
    the thick-strip limit, so its span must reach the thickest strip.
    """
    v, exv = local_exponents(model, "voltage")
    t, ext = local_exponents(model, "thickness")
    out = {"voltage": {}, "thickness": {}}
    for regime, (a, where) in VOLTAGE_LAWS[model].items():
        spans = [s for s in _ranges(v, exv, a) if _is_the_law(s, v, exv, where)]
        out["voltage"][f"I ~ phi0^{a:g} ({regime})"] = spans
    out["thickness"]["I ~ e^-1"] = [s for s in _ranges(t, ext, -1.0) if _is_the_law(s, t, ext, "high")]
    out["exponent_phi0"] = {"min": float(exv.min()), "max": float(exv.max()),
                            "at_1V": float(np.interp(0.0, np.log(v), exv))}
    out["exponent_e"] = {"min": float(ext.min()), "max": float(ext.max()),
                         "at_200um": float(np.interp(np.log(200e-6), np.log(t), ext))}
    return out


def factor_three() -> dict:
    """Ratio of the section 3-4 prefactors of theta, w_p, F^p to the section 6.2 ones (SymPy)."""
    from ipmc_asym_derivations import scaling  # deferred: SymPy (start-up)

    return {k: str(v) for k, v in scaling.factor_three().items()}
