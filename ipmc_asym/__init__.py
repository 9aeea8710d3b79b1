"""ipmc_asym: static bending of ionic polymer-metal composite strips.

Matched-asymptotic closed forms (generated from SymPy derivations into Numba kernels), a
layer quadrature, and a full-BVP cross-check of the Tixier & Pouget model.

One subpackage per concern; each imports only the ones before it in this list (the layer
rule, ``docs/design.md``, checked by ``tests/test_layers.py``)::

    base -> model -> kernels -> bvp -> integral -> beam -> io -> forward -> dynamics
         -> parallel -> studies -> validation -> plotting -> cli

Public API (lazy: importing the package loads no Numba, SciPy or SymPy).  The module paths
of the flat layout (``ipmc_asym.params``, ``ipmc_asym.sweeps``, ...) still import: they are
names of the modules in their subpackages (:data:`MOVED`).
"""

from __future__ import annotations

import importlib
import importlib.abc
import importlib.util
import sys
import types

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
    "drive_response",
    "parse_waveform",
    "line_response",
    "fit",
    "read_fit_data",
    "uq",
    "profiles",
    "validate",
    "laws",
    "scene",
    "figures",
    "transfer_function",
    "materials",
    "design",
]

_LAZY = {
    "Strip": ("ipmc_asym.model.params", "Strip"),
    "Material": ("ipmc_asym.model.params", "Material"),
    "NAFION_LI": ("ipmc_asym.model.params", "NAFION_LI"),
    "NOMINAL_STRIP": ("ipmc_asym.model.params", "NOMINAL_STRIP"),
    "Permittivity": ("ipmc_asym.model.permittivity", "Permittivity"),
    "MODELS": ("ipmc_asym.model.permittivity", "MODELS"),
    "FIDELITIES": ("ipmc_asym.integral.api", "FIDELITIES"),
    "moment_integral": ("ipmc_asym.integral.api", "moment_integral"),
    "moment": ("ipmc_asym.integral.api", "moment"),
    "evaluate": ("ipmc_asym.forward.estimate", "evaluate"),
    "solve_bvp_profile": ("ipmc_asym.bvp.solver", "solve"),
    "solve_beam": ("ipmc_asym.beam.statics", "solve_beam"),
    "run_scene": ("ipmc_asym.studies.scenes", "run_scene"),
    "sweep": ("ipmc_asym.studies.sweeps", "sweep"),
    "charge": ("ipmc_asym.dynamics.electrode", "charge"),
    "step_response": ("ipmc_asym.dynamics.circuit", "step_response"),
    "frequency_response": ("ipmc_asym.dynamics.circuit", "frequency_response"),
    "drive_response": ("ipmc_asym.dynamics.drive", "drive_response"),
    "parse_waveform": ("ipmc_asym.dynamics.waveforms", "parse_waveform"),
    "line_response": ("ipmc_asym.dynamics.line", "line_response"),
    "fit": ("ipmc_asym.studies.calibrate", "fit"),
    "read_fit_data": ("ipmc_asym.studies.calibrate", "read_data"),
    "uq": ("ipmc_asym.studies.uq", "run_uq"),
    "profiles": ("ipmc_asym.studies.profiles", "profile_summary"),
    "validate": ("ipmc_asym.validation.validate", "claims"),
    "laws": ("ipmc_asym.studies.laws", "law_table"),
    "scene": ("ipmc_asym.studies.scenes", "run_scene"),
    "figures": ("ipmc_asym.plotting.figures", "make_all"),
    "transfer_function": ("ipmc_asym.dynamics.reduction", "transfer_function"),
    "materials": ("ipmc_asym.model.materials", "MATERIAL_SETS"),
    "design": ("ipmc_asym.studies.design", "design"),
}


#: module paths of the flat layout -> where the module lives now (same module object)
MOVED = {
    "registry": "base.registry", "settings": "base.settings", "units": "base.units",
    "progress": "base.progress", "params": "model.params", "permittivity": "model.permittivity",
    "_jit": "kernels.jit", "bvp_mesh": "bvp.mesh", "bvp_problems": "bvp.problems",
    "integral_samples": "integral.samples", "fileio": "io.fileio", "jsonio": "io.jsonio",
    "textfmt": "io.textfmt", "datasets": "io.datasets", "estimate": "forward.estimate",
    "electrode": "dynamics.electrode", "transient": "dynamics.transient",
    "circuit": "dynamics.circuit", "executors": "parallel.executors", "sweeps": "studies.sweeps",
    "fits": "studies.fits", "profiles": "studies.profiles", "scene_schema": "studies.scene_schema",
    "scenes": "studies.scenes", "laws": "studies.laws", "charge_studies": "studies.charge_studies",
    "calibrate": "studies.calibrate", "uq": "studies.uq", "validate": "validation.validate",
}


class _MovedLoader(importlib.abc.Loader):
    """Loads ``ipmc_asym.<old>`` as the module ``ipmc_asym.<new>`` (one module, two names)."""

    def __init__(self, target):
        self.target = target

    def create_module(self, spec):
        return importlib.import_module(self.target)

    def exec_module(self, module):
        pass


class _MovedFinder(importlib.abc.MetaPathFinder):
    """Answers only for the names in :data:`MOVED`; every other import is left to Python."""

    def find_spec(self, fullname, path=None, target=None):
        old = fullname[len(__name__) + 1:] if fullname.startswith(__name__ + ".") else None
        if old not in MOVED:
            return None
        return importlib.util.spec_from_loader(fullname, _MovedLoader(f"{__name__}.{MOVED[old]}"))


class _Package(types.ModuleType):
    """The package module: a flat module path imported (``import ipmc_asym.uq``) does not shadow
    the public function of the same name (``ipmc_asym.uq`` stays :func:`run_uq`)."""

    def __setattr__(self, name, value):
        if name in _LAZY and isinstance(value, types.ModuleType):
            return
        super().__setattr__(name, value)


sys.modules[__name__].__class__ = _Package

if not any(isinstance(f, _MovedFinder) for f in sys.meta_path):
    sys.meta_path.append(_MovedFinder())


def __getattr__(name):
    try:
        mod, attr = _LAZY[name]
    except KeyError:
        raise AttributeError(f"module 'ipmc_asym' has no attribute {name!r}") from None
    return getattr(importlib.import_module(mod), attr)


def __dir__():
    # the public names and the package's own attributes; not the modules this file imports
    # for its machinery (importlib, sys, types, annotations of ``from __future__``)
    hidden = {"annotations", "importlib", "sys", "types"}
    own = {k for k in globals() if k not in hidden and not (k.startswith("_") and not k.startswith("__"))}
    own -= {k for k, v in globals().items() if isinstance(v, type) and k.startswith("_")}
    return sorted(own | set(__all__) | set(_LAZY))
