"""ipmc_asym: static bending of ionic polymer-metal composite strips.

Matched-asymptotic closed forms (generated from SymPy derivations into Numba kernels), a
layer quadrature, and a full-BVP cross-check of the Tixier & Pouget model.

Layer rule (each layer imports only layers to its left; the core never imports matplotlib)::

    params -> permittivity -> kernels -> moment / bvp -> beam -> estimate, sweeps, scenes
           -> plots, CLI

Public API (lazy: importing the package loads no Numba, SciPy or SymPy).
"""

from __future__ import annotations

import importlib

__version__ = "0.1.0"

__all__ = [
    "Strip",
    "Material",
    "NAFION_LI",
    "NOMINAL_STRIP",
    "Permittivity",
    "MODELS",
    "FIDELITIES",
    "moment_integral",
    "moment",
    "evaluate",
    "solve_bvp_profile",
    "solve_beam",
    "run_scene",
    "sweep",
    "charge",
    "step_response",
    "frequency_response",
]

_LAZY = {
    "Strip": ("ipmc_asym.params", "Strip"),
    "Material": ("ipmc_asym.params", "Material"),
    "NAFION_LI": ("ipmc_asym.params", "NAFION_LI"),
    "NOMINAL_STRIP": ("ipmc_asym.params", "NOMINAL_STRIP"),
    "Permittivity": ("ipmc_asym.permittivity", "Permittivity"),
    "MODELS": ("ipmc_asym.permittivity", "MODELS"),
    "FIDELITIES": ("ipmc_asym.integral", "FIDELITIES"),
    "moment_integral": ("ipmc_asym.integral", "moment_integral"),
    "moment": ("ipmc_asym.integral", "moment"),
    "evaluate": ("ipmc_asym.estimate", "evaluate"),
    "solve_bvp_profile": ("ipmc_asym.bvp", "solve"),
    "solve_beam": ("ipmc_asym.beam", "solve_beam"),
    "run_scene": ("ipmc_asym.scenes", "run_scene"),
    "sweep": ("ipmc_asym.sweeps", "sweep"),
    "charge": ("ipmc_asym.electrode", "charge"),
    "step_response": ("ipmc_asym.circuit", "step_response"),
    "frequency_response": ("ipmc_asym.circuit", "frequency_response"),
}


def __getattr__(name):
    try:
        mod, attr = _LAZY[name]
    except KeyError:
        raise AttributeError(f"module 'ipmc_asym' has no attribute {name!r}") from None
    return getattr(importlib.import_module(mod), attr)


def __dir__():
    return sorted(list(globals()) + __all__)
