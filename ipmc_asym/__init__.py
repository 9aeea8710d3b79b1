"""ipmc_asym: static bending of ionic polymer-metal composite strips.

Matched-asymptotic closed forms (generated from SymPy derivations into Numba kernels), a
layer quadrature, and a full-BVP cross-check of the Tixier & Pouget model.

The public API is the names of :data:`__all__`, importable from here (``import ipmc_asym as
ia``; lazy: importing the package loads no Numba, SciPy or SymPy): the strip and material,
the functions behind the commands and their result types.  The subpackages are internal:
their modules, names and signatures may change without notice.  One subpackage per concern;
each imports only the ones before it in this list (the layer rule, ``docs/design.md``,
checked by ``tests/integration/test_layers.py``)::

    base -> model -> kernels -> bvp -> integral -> beam -> io -> forward -> dynamics
         -> parallel -> studies -> validation -> plotting -> cli
"""

from __future__ import annotations

import importlib

__version__ = "0.1.0"

#: public name -> (module, attribute), loaded on first use
_LAZY = {
    # strips, materials, models
    "Strip": ("ipmc_asym.model.params", "Strip"),
    "Material": ("ipmc_asym.model.params", "Material"),
    "NAFION_LI": ("ipmc_asym.model.params", "NAFION_LI"),
    "NOMINAL_STRIP": ("ipmc_asym.model.params", "NOMINAL_STRIP"),
    "Permittivity": ("ipmc_asym.model.permittivity", "Permittivity"),
    "MODELS": ("ipmc_asym.model.permittivity", "MODELS"),
    "FIDELITIES": ("ipmc_asym.integral.api", "FIDELITIES"),
    "materials": ("ipmc_asym.model.materials", "MATERIAL_SETS"),
    # static forward model (estimate, sweep, scene, profiles)
    "moment_integral": ("ipmc_asym.integral.api", "moment_integral"),
    "moment": ("ipmc_asym.integral.api", "moment"),
    "evaluate": ("ipmc_asym.forward.estimate", "evaluate"),
    "solve_bvp_profile": ("ipmc_asym.bvp.solver", "solve"),
    "solve_beam": ("ipmc_asym.beam.statics", "solve_beam"),
    "run_scene": ("ipmc_asym.studies.scenes", "run_scene"),
    "scene": ("ipmc_asym.studies.scenes", "run_scene"),
    "sweep": ("ipmc_asym.studies.sweeps", "sweep"),
    # charge and dynamics (charge, step, drive, freq): the dynamic entry (Drive, time_response,
    # spectrum) makes the choice the commands make; the functions behind it stay public
    "charge": ("ipmc_asym.integral.charge", "charge"),
    "sense": ("ipmc_asym.forward.sensing", "sense"),
    "sensing_response": ("ipmc_asym.dynamics.sensing", "sensing_response"),
    "sensing_transient": ("ipmc_asym.dynamics.sensing_time", "sensing_transient"),
    "Drive": ("ipmc_asym.dynamics.entry", "Drive"),
    "time_response": ("ipmc_asym.dynamics.entry", "time_response"),
    "spectrum": ("ipmc_asym.dynamics.entry", "spectrum"),
    "step_response": ("ipmc_asym.dynamics.circuit", "step_response"),
    "frequency_response": ("ipmc_asym.dynamics.circuit", "frequency_response"),
    "drive_response": ("ipmc_asym.dynamics.drive", "drive_response"),
    "parse_waveform": ("ipmc_asym.dynamics.waveforms", "parse_waveform"),
    "line_response": ("ipmc_asym.dynamics.line", "line_response"),
    "transfer_function": ("ipmc_asym.dynamics.reduction", "transfer_function"),
    "load_export": ("ipmc_asym.dynamics.reduction", "load_export"),
    # studies (fit, uq, design, profiles, validate, laws, figures)
    "fit": ("ipmc_asym.studies.calibrate_dynamic", "fit"),
    "read_fit_data": ("ipmc_asym.studies.calibrate", "read_data"),
    "uq": ("ipmc_asym.studies.uq", "run_uq"),
    "design": ("ipmc_asym.studies.design", "design"),
    "profiles": ("ipmc_asym.studies.profiles", "profile_summary"),
    "validate": ("ipmc_asym.validation.validate", "claims"),
    "laws": ("ipmc_asym.studies.laws", "law_table"),
    "figures": ("ipmc_asym.plotting.figures", "make_all"),
    "plot_speed_accuracy": ("ipmc_asym.plotting.speed", "plot_speed_accuracy"),
    # result types (each with a summary repr, .plot() and .to_xarray())
    "MomentResult": ("ipmc_asym.integral.api", "MomentResult"),
    "BVPResult": ("ipmc_asym.bvp.solver", "BVPResult"),
    "BeamResult": ("ipmc_asym.beam.statics", "BeamResult"),
    "ForwardResult": ("ipmc_asym.forward.model", "ForwardResult"),
    "ChargeResult": ("ipmc_asym.integral.charge", "ChargeResult"),
    "SenseResult": ("ipmc_asym.forward.sensing", "SenseResult"),
    "TimeResponse": ("ipmc_asym.dynamics.entry", "TimeResponse"),
    "StepResult": ("ipmc_asym.dynamics.circuit", "StepResult"),
    "FrequencyResult": ("ipmc_asym.dynamics.circuit", "FrequencyResult"),
    "LineResult": ("ipmc_asym.dynamics.line", "LineResult"),
    "RationalModel": ("ipmc_asym.dynamics.reduction", "RationalModel"),
    "CalibrationResult": ("ipmc_asym.studies.calibrate", "CalibrationResult"),
    "UQResult": ("ipmc_asym.studies.uq", "UQResult"),
    "DesignResult": ("ipmc_asym.studies.design", "DesignResult"),
    # the output vocabulary (names, units, long names of every output)
    "QUANTITIES": ("ipmc_asym.base.quantities", "QUANTITIES"),
}

#: the public API (at most 60 names, ``tests/integration/test_public_face.py``)
__all__ = list(_LAZY)


def __getattr__(name):
    try:
        mod, attr = _LAZY[name]
    except KeyError:
        raise AttributeError(f"module 'ipmc_asym' has no attribute {name!r}") from None
    value = getattr(importlib.import_module(mod), attr)
    # bound here once loaded: a later ``ia.name`` is a plain attribute, not this function
    # (~1 us a call: half the cost of a scalar ``ia.moment_integral``)
    globals()[name] = value
    return value


def __dir__():
    # the public names and the package's dunder attributes; not the machinery of this file
    # (importlib, the annotations of ``from __future__``, the table _LAZY)
    own = {k for k in globals() if k.startswith("__")}
    return sorted(own | set(__all__))
