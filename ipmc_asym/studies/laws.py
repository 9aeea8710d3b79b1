"""``ipmc-asym laws``: the analytic scaling laws and where they hold.

The laws come from ``derivations/scaling.py`` (SymPy, imported lazily); the local exponents
``d ln I / d ln phi0`` and ``d ln I / d ln e`` are computed from the ``quadrature`` fidelity
(exact to ~1e-13 against the BVP), so that each law is confirmed or refuted with numbers and
the range where it holds is stated.
"""

from __future__ import annotations

import numpy as np

from ipmc_asym.base.settings import LAW_HOLD_TOL
from ipmc_asym.integral.api import moment
from ipmc_asym.studies.fits import local_exponent

__all__ = ["local_exponents", "law_table", "law_ranges", "factor_three"]

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


def law_ranges(model):
    """Where ``I ~ phi0^a`` (each regime's a) and ``I ~ e^-1`` hold, from local exponents."""
    v, exv = local_exponents(model, "voltage")
    t, ext = local_exponents(model, "thickness")
    targets = {"constant": {"small voltage": 0.0, "large voltage": 0.5},
               "linear": {"small voltage": 0.0, "large voltage": -1.0},
               "affine": {"small voltage": 0.0, "large voltage, rho A2 << 1": -1.0,
                          "very large voltage, rho A2 >> 1": 0.5}}[model]
    out = {"voltage": {}, "thickness": {}}
    for regime, a in targets.items():
        spans = _ranges(v, exv, a)
        # a limit law holds at its own end of the range; a crossing elsewhere is not the law
        if regime == "small voltage":
            spans = [s for s in spans if s[0] == float(v[0])]
        elif regime.startswith("very large") or regime == "large voltage":
            spans = [s for s in spans if s[1] == float(v[-1])] if model != "affine" else spans
        out["voltage"][f"I ~ phi0^{a:g} ({regime})"] = spans
    out["thickness"]["I ~ e^-1"] = _ranges(t, ext, -1.0)
    out["exponent_phi0"] = {"min": float(exv.min()), "max": float(exv.max()),
                            "at_1V": float(np.interp(0.0, np.log(v), exv))}
    out["exponent_e"] = {"min": float(ext.min()), "max": float(ext.max()),
                         "at_200um": float(np.interp(np.log(200e-6), np.log(t), ext))}
    return out


def factor_three() -> dict:
    """Ratio of the section 3-4 prefactors of theta, w_p, F^p to the section 6.2 ones (SymPy)."""
    from ipmc_asym_derivations import scaling  # deferred: SymPy (start-up)

    return {k: str(v) for k, v in scaling.factor_three().items()}
