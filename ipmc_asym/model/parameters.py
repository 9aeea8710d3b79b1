"""One name per model parameter: its aliases, unit, parser, plausible range and which data identify it.

Every place that names a material or model parameter -- the command line, ``fit --free``, the
uncertain tables of ``uq`` and ``design``, scene ``[material]`` tables and the material files --
reads it through :data:`PARAMETERS`: the canonical name (as the CLI and the output columns spell
it, e.g. ``modulus``), the other names kept working (the paper's symbol ``E``, the material files'
key), the :class:`~ipmc_asym.model.params.Material` field it sets, the unit, the fit's default
bounds and which kinds of data see it.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

from ipmc_asym.base.units import parse_diffusion, parse_length, parse_pressure, parse_quantity, parse_sheet_resistance
from ipmc_asym.model.limits import PLAUSIBLE
from ipmc_asym.model.params import Material

__all__ = ["Parameter", "PARAMETERS", "ALIASES", "canonical", "parse_value", "with_values", "material_value",
           "DATA_KINDS"]

#: kinds of data rows (``fit``): static deflection/blocking force at rest, a time series of the
#: electrical response, a time series of deflection/force, an impedance spectrum, a sensing time
#: series (imposed tip displacement, measured charge/current/voltage)
DATA_KINDS = ("static", "time", "time_mech", "impedance", "sensing")

_CONCENTRATION = {"mol/m^3": 1.0, "mol/m3": 1.0, "mM": 1.0, "M": 1e3, "mol/L": 1e3}
_PERMITTIVITY = {"F/m": 1.0}
_VISCOSITY = {"Pa s": 1.0, "Pa*s": 1.0, "Pa.s": 1.0, "kPa s": 1e3, "MPa s": 1e6}


@dataclass(frozen=True)
class Parameter:
    """One model parameter.

    Attributes
    ----------
    name : str                the canonical name (CLI, ``fit --free``, ``uq``/``design`` tables, columns)
    aliases : tuple of str    other names accepted for it (the paper's symbol, the material files' key)
    field : str or None       the :class:`~ipmc_asym.model.params.Material` field it sets (None: the
                              permittivity model's ``eps0``/``deps``, or the beam's ``viscous_modulus``)
    unit : str                SI unit
    long_name : str
    units : dict or None      unit -> factor to SI accepted on a value (None: the parser below)
    bounds : (float, float)   the fit's default bounds (SI)
    seen_by : tuple of str    the kinds of data (:data:`DATA_KINDS`) that identify it
    identify : str            the data that would identify it (the fit's refusal names them)
    """

    name: str
    aliases: tuple
    field: str | None
    unit: str
    long_name: str
    units: dict | None
    bounds: tuple
    seen_by: tuple
    identify: str

    @property
    def plausible(self):
        """(low, high) of :data:`ipmc_asym.model.limits.PLAUSIBLE` (SI), or None."""
        for k in (self.name, self.field, *self.aliases):
            if k in PLAUSIBLE:
                return PLAUSIBLE[k][:2]
        return None


_ANY = ("static", "time", "time_mech", "impedance", "sensing")

#: canonical name -> Parameter (the order is the order ``fit --free`` lists them in)
PARAMETERS = {p.name: p for p in (
    Parameter("modulus", ("E",), "E", "Pa", "Young's modulus E", None, (1e6, 1e11),
              ("static", "time_mech"), "deflection or blocking-force data (static rows or a time series)"),
    Parameter("c_moy", ("C_moy",), "c_moy", "mol/m^3", "mean cation concentration C_moy", _CONCENTRATION,
              (10.0, 1e5), _ANY, "any data"),
    Parameter("eps0", (), None, "F/m", "permittivity at C = 0, eps0", _PERMITTIVITY, (1e-10, 1.0), _ANY, "any data"),
    Parameter("deps", (), None, "F/m", "eps_moy - eps0", _PERMITTIVITY, (1e-10, 1.0), _ANY, "any data"),
    Parameter("diffusion", ("D",), "D", "m^2/s", "cation diffusion coefficient D", None, (1e-14, 1e-7),
              ("time", "time_mech", "impedance", "sensing"),
              "a time series (t, current/charge/deflection), an impedance spectrum (f, Z_re, Z_im) or sensing "
              "data (t, w, Q/I/V): the static state does not depend on D"),
    Parameter("viscous_modulus", ("eta_E",), None, "Pa s",
              "viscous modulus eta_E = E tau_v of the Kelvin-Voigt law (eq. (3))", _VISCOSITY, (1.0, 1e9),
              ("time_mech",), "a time series of deflection or blocking force (the beam's damping; beam dynamic)"),
    Parameter("sheet_resistance", ("R_s",), "sheet_resistance", "Ohm/sq", "sheet resistance R_s of each electrode",
              None, (1e-3, 1e4), ("impedance",),
              "an impedance spectrum (f, Z_re, Z_im): the fit's time-domain model has ideal electrodes"),
    # the metal layers of the composite beam (model.electrode): seen through the bending stiffness EI
    Parameter("electrode_thickness", ("t_m",), "electrode.thickness", "m", "thickness t_m of each metal electrode layer",
              None, (1e-8, 1e-4), ("static", "time_mech"),
              "deflection or blocking-force data (static rows or a time series): the layers change the beam, not "
              "the electrochemistry"),
    Parameter("electrode_modulus", ("E_m",), "electrode.modulus", "Pa", "Young's modulus E_m of the electrode metal",
              None, (1e9, 1e12), ("static", "time_mech"),
              "deflection or blocking-force data (static rows or a time series): the layers change the beam, not "
              "the electrochemistry"),
    # sensing only: the imposed bending changes the solution fraction through tr eps = -(1 - 2 nu) kappa z; the
    # actuation's beam does not see it (its moment is the paper's eq. (6)); no measured value was found, so
    # the default 0 (docs/sensing.md) is an assumption; log-parameter fit, so the bounds exclude 0 and 0.5
    Parameter("nu", ("poisson_ratio",), None, "1", "drained Poisson ratio nu of the membrane (sensing)",
              None, (1e-3, 0.499), ("sensing",),
              "sensing data (t, w and Q, I or V): the actuation models do not depend on it"),
)}

#: alias -> canonical name (every other name a parameter is known by)
ALIASES = {a: p.name for p in PARAMETERS.values() for a in p.aliases}

def _parse_nu(name, text):
    v = parse_quantity(name, text, {"1": 1.0}, "Poisson ratio (dimensionless)")
    if not 0.0 <= v < 0.5:
        raise ValueError(f"{name}: the drained Poisson ratio must be in [0, 0.5); got {text!r}")
    return v


_PARSERS = {"nu": _parse_nu, "modulus": parse_pressure, "diffusion": parse_diffusion, "sheet_resistance": parse_sheet_resistance,
            "electrode_thickness": parse_length, "electrode_modulus": parse_pressure}


def canonical(name: str) -> str:
    """The canonical name of ``name`` (itself or an alias); ``ValueError`` for an unknown one."""
    if name in PARAMETERS:
        return name
    if name in ALIASES:
        return ALIASES[name]
    raise ValueError(f"unknown parameter {name!r}; allowed: {', '.join(PARAMETERS)} (or {', '.join(ALIASES)})")


def parse_value(name: str, text, where: str | None = None) -> float:
    """A value of parameter ``name`` (a number in SI or a string with one of its units) -> SI float.

    ``where`` names the value in the one-line ``ValueError`` (default the parameter's name).
    """
    p = PARAMETERS[canonical(name)]
    label = where or p.name
    if p.name in _PARSERS:
        return _PARSERS[p.name](label, text)
    return parse_quantity(label, text, p.units, p.long_name)


def with_values(material: Material, values: dict) -> Material:
    """``material`` with the :class:`~ipmc_asym.model.params.Material` fields of ``values`` set.

    ``values`` maps parameter names (canonical or aliases) to SI numbers; the parameters that are not
    material fields (``eps0``, ``deps``: the permittivity model; ``viscous_modulus``: the beam) are
    left to their owners.
    """
    kw, layer = {}, {}
    for k, v in values.items():
        f = PARAMETERS[canonical(k)].field
        if f is not None and f.startswith("electrode."):  # a field of the electrode layers
            layer[f.split(".", 1)[1]] = float(v)
        elif f is not None:
            kw[f] = float(v)
    if layer:
        kw["electrode"] = replace(material.electrode, **layer)
    return material.with_(**kw) if kw else material


def material_value(material: Material, name: str) -> float:
    """The value (SI) ``material`` gives parameter ``name`` (``c_moy``: the concentration it resolves to)."""
    p = PARAMETERS[canonical(name)]
    if p.field is None:
        raise ValueError(f"{p.name} is not a material parameter")
    if p.field == "c_moy":
        return float(material.C_moy)
    if p.field.startswith("electrode."):
        return float(getattr(material.electrode, p.field.split(".", 1)[1]))
    return float(getattr(material, p.field))
