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
layers overlap and ``exact`` is the rung that holds.  Each rung carries the flags its users
test: ``compiled`` (run by the compiled drivers, with the integer ``kernel_code``) and
``any_thickness`` (valid with overlapping layers).

``MODELS`` and ``FIDELITIES`` here are dicts of specs; ``ipmc_asym.integral.api`` exports
``FIDELITIES`` as the tuple of names and ``MODELS`` from ``ipmc_asym.model.permittivity``
(``{name: Permittivity}``).  Both pairs keep their names (scripts use them).
"""

from __future__ import annotations

from typing import NamedTuple

__all__ = ["ModelSpec", "FidelitySpec", "MODELS", "FIDELITIES", "model_names", "fidelity_names",
           "closed_form_fidelities", "compiled_fidelities", "any_thickness_fidelities", "is_compiled",
           "model_choices", "check_choice"]


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
    kernel_code : int or None  integer passed to the compiled drivers (``integral.api``,
                               ``integral.samples``): 1 leading, 2 corrected, 0 quadrature,
                               3 exact; None for a rung without a compiled driver
    computes : str        what the rung computes
    stated_error : str    how the rung bounds its error
    ceiling : float       advertised worst relative error of a result called valid
    closed_form : bool    closed form in lambda (the paper's three models only)
    compiled : bool       the rung runs in the compiled drivers (``kernel_code`` is set)
    any_thickness : bool  the rung holds at every thickness (overlapping layers, non-neutral
                          core): its ``core`` output is informative, not a validity test
    interpreted_s : float  measured seconds per point of its interpreted twin (0: none), for
                           ``settings.INTERPRET_BUDGET_S``
    """

    name: str
    kernel_code: int | None
    computes: str
    stated_error: str
    ceiling: float
    closed_form: bool
    compiled: bool
    any_thickness: bool
    interpreted_s: float = 0.0

    @property
    def order(self) -> int:
        """Deprecated alias of ``kernel_code`` with -1 for a rung that is not compiled."""
        return -1 if self.kernel_code is None else self.kernel_code


#: The paper's permittivity models as data: ``{name: ModelSpec}`` (dict, paper's order).
#: Not the same object as ``ipmc_asym.model.permittivity.MODELS`` (``{name: Permittivity}``,
#: built from this one) nor ``ipmc_asym.integral.api.MODELS``.
MODELS = {
    "constant": ModelSpec("constant", 5e-6, 0.0, (1, 1), 0,
                          "eps = 5e-6 F/m everywhere; the model the paper keeps"),
    "linear": ModelSpec("linear", 0.0, 1e-3, (0, 1), 1,
                        "eps proportional to C; eps -> 0 at the anode (unphysical there)"),
    "affine": ModelSpec("affine", 5e-6, 1e-3, (5, 1005), 2,
                        "eps = 5e-6 + 1e-3 C/C_moy F/m"),
}

#: The fidelity ladder as data: ``{name: FidelitySpec}`` (dict, cheapest first).  Not the
#: same object as ``ipmc_asym.integral.api.FIDELITIES``, the tuple of the names
#: (``fidelity_names()``).
FIDELITIES = {
    "leading": FidelitySpec(
        "leading", 1, "lambda J1: the O(lambda) term of the layer expansion, closed form",
        "the next term lambda^2 |J2| / |I| plus truncation and core interaction", 1e-2, True,
        compiled=True, any_thickness=False, interpreted_s=3e-5),
    "corrected": FidelitySpec(
        "corrected", 2, "lambda J1 + lambda^2 J2, closed form (the lambda-expansion stops there)",
        "truncation of the layer functions plus the core interaction ~4 exp(-core/lambda)", 1e-8, True,
        compiled=True, any_thickness=False, interpreted_s=3e-5),
    "quadrature": FidelitySpec(
        "quadrature", 0, "the same two terms, layer functions by compiled Gauss-Legendre panels",
        "settings.ROUNDING_ERROR plus the core interaction ~4 exp(-core/lambda)", 1e-8, False,
        compiled=True, any_thickness=False, interpreted_s=4e-4),
    "exact": FidelitySpec(
        "exact", 3, "nothing neglected, any thickness: first integral, exact B1, K from the thickness "
        "constraint (Newton on ln K), moments by compiled Gauss-Legendre panels",
        "settings.EXACT_STATED_ERROR (measured <= 3e-12 against the BVP, the exact linear solution "
        "and an ODE reference)", 1e-2, False,
        compiled=True, any_thickness=True, interpreted_s=1.5e-3),
    "bvp": FidelitySpec(
        "bvp", None, "the full nonlinear BVP (scipy.integrate.solve_bvp, graded mesh)",
        "settings.BVP_STATED_ERROR (solve_bvp tolerance 1e-10; measured ~1e-12)", 1e-2, False,
        compiled=False, any_thickness=True),
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
    """Names of the closed-form rungs (``closed_form``), cheapest first."""
    return tuple(k for k, f in FIDELITIES.items() if f.closed_form)


def compiled_fidelities() -> tuple:
    """Names of the rungs run by the compiled drivers (``compiled``), cheapest first."""
    return tuple(k for k, f in FIDELITIES.items() if f.compiled)


def any_thickness_fidelities() -> tuple:
    """Names of the rungs valid at every thickness (``any_thickness``), cheapest first."""
    return tuple(k for k, f in FIDELITIES.items() if f.any_thickness)


def is_compiled(fidelity) -> bool:
    """True where ``fidelity`` names a rung of the compiled drivers (False for any other value)."""
    spec = FIDELITIES.get(fidelity) if isinstance(fidelity, str) else None
    return spec is not None and spec.compiled


def check_choice(what: str, value, allowed) -> str:
    """``value`` if it is one of ``allowed``, else a one-line ``ValueError`` listing them."""
    if value not in allowed:
        raise ValueError(f"{what} must be one of {', '.join(map(str, allowed))}; got {value!r}")
    return value
