"""Scaling laws: leading-order ``I`` in each voltage regime and the mechanics that follow.

From ``I = lambda J1(A2, rho) + lambda^2 J2`` (``model.py``) and the layer functions
(``closed_forms.py``):

* small voltage (Debye-Hueckel, ``A2 << 1``): ``W0(Y) ~ Y``, ``Dhat(Y) ~ |Y|``,
  ``Yc ~ A2/2 ~ -Ya`` so ``J1 -> 1 + A3`` and ``I ~ (1 + A3) lambda``  (every model);
* large voltage (``A2 >> 1``):
    - constant: the anode depletion zone dominates, ``-W0(Ya) ~ (sqrt2/3) A2^{3/2}``:
      ``I ~ (sqrt2/3) A3 sqrt(A1)``  (the paper's ``I ~ phi0^{1/2}/e``);
    - linear: ``B1 -> 2``, ``W0(ln 2) = -Li2(-1) = pi^2/12``, ``W0(-inf) = -pi^2/6``:
      ``I ~ (lambda / A2) (2 + A3 pi^2/4)`` (so ``M_A = A5 I`` does not depend on ``phi0``);
    - affine: linear-like while ``rho A2 << 1``; once ``rho A2 >> 1`` the depletion zone
      (where ``eps -> eps0``) takes over and ``I ~ (sqrt2/3) A3 sqrt(A1)`` as in the
      constant model.

Mechanics (paper section 3, ``M_A = A5 I``, ``A5 = 6 l e^2 F phi0 C_moy``,
``I_p = 4 l e^3/3``)::

    theta = -M_A L/(E I_p) = -(9/2) (F C_moy / E) phi0 (L/e) I
    w_p   = -M_A L^2/(2 E I_p) = -(9/4) (F C_moy / E) phi0 (L^2/e) I
    F^p   = 3 M_A/(2 L) = 9 F C_moy phi0 l e^2 I / L

The paper's section 6.2 writes 3/2, 3/4 and 3 for these three prefactors: a factor 3 below
what its own sections 3-4 imply (:func:`factor_three`).  We use sections 3-4.
"""

from __future__ import annotations

import functools

import sympy as sp

F, Cm, E, phi0, L, l, e, eps0, deps, phi4, R, Tk, rho2, Z3 = sp.symbols(
    "F C_moy E phi0 L l e eps0 Delta_eps phi4 R T rho2 Z3", positive=True
)
I = sp.symbols("I")


def groups():
    A0 = phi0 * deps / (e**2 * phi4 * F * Cm)
    A1 = phi0 * eps0 / (e**2 * phi4 * F * Cm)
    A2 = F * phi0 / (R * Tk)
    A3 = -rho2 * Z3 / (Cm * F)
    A5 = 6 * l * e**2 * F * phi0 * Cm
    lam = sp.sqrt((A0 + A1) / A2)
    return A0, A1, A2, A3, A5, lam


def mechanics(Iexpr):
    """theta, w_p, F^p from I (paper section 3 with A5 and I_p)."""
    *_, A5, _ = groups()
    Ip = 4 * l * e**3 / 3
    MA = A5 * Iexpr
    return {
        "M_A": sp.simplify(MA),
        "theta": sp.simplify(-MA * L / (E * Ip)),
        "w_small": sp.simplify(-MA * L**2 / (2 * E * Ip)),
        "F_block": sp.simplify(3 * MA / (2 * L)),
    }


def factor_three():
    """Ratio of our (sections 3-4) prefactors to the paper's section 6.2 ones."""
    ours = mechanics(I)
    paper = {
        "theta": -sp.Rational(3, 2) * F * Cm / E * phi0 * L / e * I,
        "w_small": -sp.Rational(3, 4) * F * Cm / E * phi0 * L**2 / e * I,
        "F_block": 3 * F * Cm * phi0 * l * e**2 / L * I,
    }
    return {k: sp.simplify(ours[k] / paper[k]) for k in paper}


def leading_I():
    """Leading-order I per model and regime, as expressions in the physical data."""
    A0, A1, A2, A3, A5, lam = groups()
    lam_c = sp.sqrt(A1 / A2)  # constant model (A0 = 0)
    lam_l = sp.sqrt(A0 / A2)  # linear model (A1 = 0)
    return {
        ("constant", "small voltage"): (1 + A3) * lam_c,
        ("constant", "large voltage"): sp.sqrt(2) / 3 * A3 * sp.sqrt(A1),
        ("linear", "small voltage"): (1 + A3) * lam_l,
        ("linear", "large voltage"): lam_l / A2 * (2 + A3 * sp.pi**2 / 4),
        ("affine", "small voltage"): (1 + A3) * lam,
        ("affine", "large voltage, rho A2 << 1"): lam / A2 * (2 + A3 * sp.pi**2 / 4),
        ("affine", "very large voltage, rho A2 >> 1"): sp.sqrt(2) / 3 * A3 * sp.sqrt(A1),
    }


def exponents(expr):
    """Exponents of L, l, e, phi0 in a monomial expression."""
    out = {}
    for name, sym in (("L", L), ("l", l), ("e", e), ("phi0", phi0)):
        out[name] = sp.nsimplify(sp.simplify(sym * sp.diff(expr, sym) / expr))
    return out


def laws():
    """List of dicts: model, regime, quantity, expression, exponents (all leading order).

    Fresh dicts on every call (the caller may change them) around one cached derivation: it
    takes a second of SymPy, and ``ipmc-asym laws`` asks for it once per model.
    """
    return [{**r, "exponents": dict(r["exponents"])} for r in _laws()]


@functools.lru_cache(maxsize=None)
def _laws():
    rows = []
    for (model, regime), Iexpr in leading_I().items():
        Iexpr = sp.simplify(Iexpr)
        qs = {"I": Iexpr, **mechanics(Iexpr)}
        for q, ex in qs.items():
            rows.append({"model": model, "regime": regime, "quantity": q, "expr": ex, "exponents": exponents(ex)})
    return tuple(rows)


def main():
    print("factor between sections 3-4 and section 6.2 prefactors:", factor_three())
    for r in laws():
        ex = ", ".join(f"{k}^{v}" for k, v in r["exponents"].items())
        print(f"{r['model']:8s} {r['regime']:32s} {r['quantity']:8s} ~ {ex}")


if __name__ == "__main__":
    main()
