"""The one registry of permittivity models and fidelities: pure data, no imports.

Everything that lists models or fidelities (CLI ``choices``, the scene schema, the bench,
sweeps, ``validate``, ``derivations/``) reads them from here.

Models (paper section 4, table of permittivities): ``eps(C) = eps0 + deps * C / C_moy``
(F/m).  The paper writes "alpha = 1e-3 F/m"; its quoted ``z0 ~ 4.8e-3`` only fits
``deps = eps_moy - eps0 = 1e-3 F/m`` (docs/design.md, section "Slips").
``rho = eps0 / (eps0 + deps) = A1 / (A0 + A1)`` is kept as an exact fraction
(numerator, denominator) so that ``derivations/`` can specialise the kernels exactly.

Fidelities are ordered by cost; each says what it computes and the error it states
(the error bound it attaches to its results) and its advertised ceiling (the worst
relative error it may state and still call a result valid).  The two-term rungs
(``corrected``, ``quadrature``) have a tight ceiling: they are exact up to the interaction of
the electrode layers across the core, so where that interaction is not negligible the
layers overlap and ``exact`` is the rung that holds.
"""

from __future__ import annotations

from typing import NamedTuple

__all__ = ["ModelSpec", "FidelitySpec", "MODELS", "FIDELITIES", "model_names", "fidelity_names",
           "closed_form_fidelities", "model_choices", "check_choice"]


class ModelSpec(NamedTuple):
    """A permittivity model of the paper.

    Attributes
    ----------
    name : str
    eps0 : float      permittivity at C = 0, F/m
    deps : float      eps_moy - eps0, F/m
    rho : tuple       exact ``eps0 / (eps0 + deps)`` as (numerator, denominator)
    id : int          index used by the compiled kernels
    note : str
    """

    name: str
    eps0: float
    deps: float
    rho: tuple
    id: int
    note: str


class FidelitySpec(NamedTuple):
    """A rung of the fidelity ladder (ordered by cost).

    Attributes
    ----------
    name : str
    order : int           argument of the compiled sweep driver (-1: not a compiled rung)
    computes : str        what the rung computes
    stated_error : str    how the rung bounds its error
    ceiling : float       advertised worst relative error of a result called valid
    closed_form : bool    closed form in lambda (the paper's three models only)
    interpreted_s : float  measured seconds per point of its interpreted twin (0: none), for
                           ``settings.INTERPRET_BUDGET_S``
    """

    name: str
    order: int
    computes: str
    stated_error: str
    ceiling: float
    closed_form: bool
    interpreted_s: float = 0.0


MODELS = {
    "constant": ModelSpec("constant", 5e-6, 0.0, (1, 1), 0,
                          "eps = 5e-6 F/m everywhere; the model the paper keeps"),
    "linear": ModelSpec("linear", 0.0, 1e-3, (0, 1), 1,
                        "eps proportional to C; eps -> 0 at the anode (unphysical there)"),
    "affine": ModelSpec("affine", 5e-6, 1e-3, (5, 1005), 2,
                        "eps = 5e-6 + 1e-3 C/C_moy F/m"),
}

FIDELITIES = {
    "leading": FidelitySpec(
        "leading", 1, "lambda J1: the O(lambda) term of the layer expansion, closed form",
        "the next term lambda^2 |J2| / |I| plus truncation and core interaction", 1e-2, True, 3e-5),
    "corrected": FidelitySpec(
        "corrected", 2, "lambda J1 + lambda^2 J2, closed form (the lambda-expansion stops there)",
        "truncation of the layer functions plus the core interaction ~4 exp(-core/lambda)", 1e-8, True, 3e-5),
    "quadrature": FidelitySpec(
        "quadrature", 0, "the same two terms, layer functions by compiled Gauss-Legendre panels",
        "settings.ROUNDING_ERROR plus the core interaction ~4 exp(-core/lambda)", 1e-8, False, 4e-4),
    "exact": FidelitySpec(
        "exact", 3, "nothing neglected, any thickness: first integral, exact B1, K from the thickness "
        "constraint (Newton on ln K), moments by compiled Gauss-Legendre panels",
        "settings.EXACT_STATED_ERROR (measured <= 3e-12 against the BVP, the exact linear solution "
        "and an ODE reference)", 1e-2, False, 1.5e-3),
    "bvp": FidelitySpec(
        "bvp", -1, "the full nonlinear BVP (scipy.integrate.solve_bvp, graded mesh)",
        "settings.BVP_STATED_ERROR (solve_bvp tolerance 1e-10; measured ~1e-12)", 1e-2, False),
}


def model_names() -> tuple:
    """The paper's model names, in the paper's order."""
    return tuple(MODELS)


def model_choices() -> list:
    """Model names plus ``all`` (CLI ``choices``)."""
    return list(MODELS) + ["all"]


def fidelity_names() -> tuple:
    """Fidelity names, cheapest first."""
    return tuple(FIDELITIES)


def closed_form_fidelities() -> tuple:
    return tuple(k for k, f in FIDELITIES.items() if f.closed_form)


def check_choice(what: str, value, allowed) -> str:
    """``value`` if it is one of ``allowed``, else a one-line ``ValueError`` listing them."""
    if value not in allowed:
        raise ValueError(f"{what} must be one of {', '.join(map(str, allowed))}; got {value!r}")
    return value
