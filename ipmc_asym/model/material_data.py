"""Material sets with their sources: the TOML files of ``ipmc_asym/materials/`` and user files.

One file per set (data, not code), read with :mod:`importlib.resources`.  Every parameter is
a table with its value, unit, the key of a source (a full citation in ``[sources]``) and,
where the source gives one, a range; a parameter a set has no source for either falls back
visibly to a stated library default (``fallback = true`` with the default's own source) or is
absent from the set (then the set is not offered for what needs it)::

    name = "nafion-li"
    title = "Nafion, Li+ form: the values of the paper"
    c_moy = "paper"                     # "paper": the stated C_moy; "formula": eq. (17)

    [sources.tixier-pouget]
    citation = "M. Tixier, J. Pouget, ..."

    [parameters.phi4]
    value = 0.38                        # or "38%"; a string may carry its unit ("130MPa")
    unit = "1"
    source = "tixier-pouget"
    quoted_from = "S. Nemat-Nasser, J. Li, J. Appl. Phys. 87 (2000) 3321-3331"
    where = "section 4"
    range = [0.30, 0.45]                # only where the source gives one

Layer rule: this module is part of ``model`` and imports the standard library and
``ipmc_asym.base.units`` only; :mod:`ipmc_asym.model.params` builds a ``Material`` from a
:class:`MaterialSet` and :mod:`ipmc_asym.model.materials` is the public API.
"""

from __future__ import annotations

import math
import os
import sys
from dataclasses import dataclass, field
from importlib import resources

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    import tomli as tomllib

from ipmc_asym.base.inputs import read_input_text
from ipmc_asym.base.units import parse_quantity
from ipmc_asym.model.electrode import METALS, NO_ELECTRODE, Electrode, electrode_from_spec

__all__ = ["Parameter", "MaterialSet", "PARAMETERS", "MATERIAL_FIELDS", "SCHEMA_VERSIONS", "set_names", "load_set", "read_set",
           "parse_set"]

_F = 96487.0  # the paper's Faraday constant (section 4), used for IEC -> Z3

#: parameter -> (unit name for messages, {unit: factor to SI}, what it is).  The units are
#: those a source states; the first is SI.
PARAMETERS = {
    "Z3": ("mass charge", {"C/kg": 1.0}, "mass charge of the polymer backbone (negative), C/kg"),
    "IEC": ("ion-exchange capacity", {"mol/kg": 1.0, "meq/g": 1.0, "mmol/g": 1.0},
            "ion-exchange capacity (Z3 = -F IEC)"),
    "rho3": ("density", {"kg/m^3": 1.0, "kg/m3": 1.0, "g/cm^3": 1e3, "g/cm3": 1e3}, "density of the solid phase"),
    "phi4": ("volume fraction", {"1": 1.0, "%": 0.01}, "volume fraction of the solution"),
    "rho2": ("density", {"kg/m^3": 1.0, "kg/m3": 1.0, "g/cm^3": 1e3, "g/cm3": 1e3}, "density of the solvent"),
    "E": ("pressure", {"Pa": 1.0, "kPa": 1e3, "MPa": 1e6, "GPa": 1e9}, "Young's modulus"),
    "T": ("temperature", {"K": 1.0}, "absolute temperature"),
    "F": ("Faraday constant", {"C/mol": 1.0}, "Faraday constant"),
    "R": ("gas constant", {"J/(mol K)": 1.0, "J/mol/K": 1.0}, "gas constant"),
    "D": ("diffusion coefficient", {"m^2/s": 1.0, "m2/s": 1.0, "cm^2/s": 1e-4, "cm2/s": 1e-4},
          "diffusion coefficient of the cations"),
    "C_moy": ("concentration", {"mol/m^3": 1.0, "mol/m3": 1.0, "mol/L": 1e3, "M": 1e3},
              "mean cation concentration (the value the source states)"),
    "thickness": ("length", {"m": 1.0, "mm": 1e-3, "um": 1e-6, "µm": 1e-6}, "typical TOTAL thickness of the membrane"),
}
#: parameters that become fields of ``params.Material`` (the others are derived or stated)
MATERIAL_FIELDS = ("Z3", "rho3", "phi4", "rho2", "E", "T", "F", "R", "D")
#: a set must give these (or IEC for Z3); the others fall back to the library default
_REQUIRED = ("rho3", "phi4", "E")
#: the versions of this file format the reader knows (``schema = 1``; a file without it is read as 1)
SCHEMA_VERSIONS = (1,)
_TOP = {"schema", "name", "title", "membrane", "cation", "c_moy", "description", "sources", "parameters",
        "permittivity", "electrode"}
#: keys of the optional ``[electrode]`` table: the metal layers of the set's strips (the metal's
#: handbook values unless modulus/density are given; a source for the thickness)
_ELECTRODE_KEYS = {"metal", "thickness", "modulus", "density", "source", "where", "note"}
_PARAM_KEYS = {"value", "unit", "source", "quoted_from", "where", "range", "note", "fallback"}
_PERM_KEYS = {"eps0", "deps", "source", "where", "note"}


@dataclass(frozen=True)
class Parameter:
    """One parameter of a set: value in SI, as given, and where it comes from.

    Attributes
    ----------
    name : str         key of :data:`PARAMETERS`
    value : float      SI value used by the code
    given : str        the value as written in the file, with its unit
    source : str       full citation of the source read ("" for a fallback without one)
    quoted_from : str  the work the source quotes for the number ("" if its own)
    where : str        section / equation / table of the source
    range : tuple or None   (low, high) in SI where the source gives one
    note : str
    fallback : bool    True: the set has no source for it; the value is the stated library default
    """

    name: str
    value: float
    given: str
    source: str = ""
    quoted_from: str = ""
    where: str = ""
    range: tuple | None = None
    note: str = ""
    fallback: bool = False

    def as_dict(self) -> dict:
        return {"value": self.value, "unit": _si_unit(self.name), "given": self.given, "source": self.source,
                "quoted_from": self.quoted_from, "where": self.where,
                "range": list(self.range) if self.range else None, "note": self.note, "fallback": self.fallback}


@dataclass(frozen=True)
class MaterialSet:
    """A checked material set.

    Attributes
    ----------
    name, title, membrane, cation, description : str
    c_moy : str or float   ``"paper"`` (the stated ``C_moy``), ``"formula"`` (eq. (17)) or a number
    origin : str           ``"built-in"`` or the file's path
    parameters : dict      name -> :class:`Parameter`
    sources : dict         key -> full citation
    permittivity : dict    model -> {"eps0", "deps", "source", "where", "note"} (F/m), as the source states
    electrode : Electrode  the metal layers the set's source gives (``[electrode]``); none by default
    """

    name: str
    title: str
    c_moy: object
    origin: str
    parameters: dict
    sources: dict
    membrane: str = ""
    cation: str = ""
    description: str = ""
    permittivity: dict = field(default_factory=dict)
    electrode: Electrode = NO_ELECTRODE

    def material_kwargs(self) -> dict:
        """Keyword arguments of ``params.Material`` (SI): every field, the name and the sources."""
        kw = {k: self.parameters[k].value for k in MATERIAL_FIELDS if k in self.parameters}
        c = self.c_moy
        if c == "paper":
            if "C_moy" not in self.parameters:
                raise ValueError(f"material {self.name}: c_moy = 'paper' needs a stated parameters.C_moy")
            c = self.parameters["C_moy"].value
        kw["c_moy"] = c
        kw["name"] = self.name
        kw["sources"] = self.citations()
        if self.electrode.present:
            kw["electrode"] = self.electrode
        return kw

    def citations(self) -> tuple:
        """Full citations of every source a value of the set comes from (first use order)."""
        out = []
        for p in self.parameters.values():
            for c in (p.source,):
                if c and c not in out:
                    out.append(c)
        for p in self.permittivity.values():
            c = p.get("source", "")
            if c and c not in out:
                out.append(c)
        if self.electrode.present and self.electrode.source and self.electrode.source not in out:
            out.append(self.electrode.source)
        return tuple(out)

    def fallbacks(self) -> list:
        """Names of the parameters taken from the library default (no source in the set)."""
        return [k for k, p in self.parameters.items() if p.fallback]

    def as_dict(self) -> dict:
        return {"name": self.name, "title": self.title, "membrane": self.membrane, "cation": self.cation,
                "description": self.description, "origin": self.origin,
                "c_moy": self.c_moy if isinstance(self.c_moy, str) else float(self.c_moy),
                "parameters": {k: p.as_dict() for k, p in self.parameters.items()},
                "permittivity": self.permittivity, "sources": list(self.citations()),
                "fallbacks": self.fallbacks()}


def _si_unit(name):
    return next(iter(PARAMETERS[name][1]))


def _value(where: str, name: str, v, unit) -> tuple[float, str]:
    """``(SI value, as given)`` of ``value``/``unit`` of parameter ``name``."""
    unit_name, units, _ = PARAMETERS[name]
    if isinstance(v, bool) or not isinstance(v, (int, float, str)):
        raise ValueError(f"{where}.value must be a number or a string with a unit; got {v!r}")
    if unit is not None and (not isinstance(unit, str) or unit not in units):
        raise ValueError(f"{where}.unit must be one of {', '.join(units)}; got {unit!r}")
    if isinstance(v, str):
        if unit is not None:
            raise ValueError(f"{where}: give the unit in the value string or in unit, not both")
        s = v.strip()
        if name == "phi4" and s.endswith("%"):
            x = parse_quantity(where, s[:-1], {}, unit_name) * 0.01
        else:
            x = parse_quantity(where, s, units, unit_name)
        return x, s
    x = float(v) * units[unit or _si_unit(name)]
    if not math.isfinite(x):
        raise ValueError(f"{where}.value must be finite; got {v!r}")
    return x, f"{v:g} {unit or _si_unit(name)}"


def _text(where, d, key):
    v = d.get(key, "")
    if not isinstance(v, str):
        raise ValueError(f"{where}.{key} must be a string; got {v!r}")
    return v


def parse_set(data: dict, origin: str = "built-in", defaults: dict | None = None) -> MaterialSet:
    """Check a set (the dict of a TOML file) and convert it to SI.

    Parameters
    ----------
    data : dict
        The file's content (schema in the module docstring).
    origin : str
        ``"built-in"`` or the file's path (for messages).
    defaults : dict, optional
        ``{parameter: (value SI, source)}``: what a missing parameter falls back to (visibly,
        ``fallback = True``).  Without a default a missing required parameter is an error.

    Returns
    -------
    MaterialSet

    Raises
    ------
    ValueError
        One line naming the key: unknown key, missing value or source, value out of range.
    """
    if not isinstance(data, dict):
        raise ValueError(f"material file {origin}: not a table")
    for k in data:
        if k not in _TOP:
            raise ValueError(f"material file {origin}: unknown key {k!r}; allowed: {', '.join(sorted(_TOP))}")
    schema = data.get("schema", SCHEMA_VERSIONS[0])
    # a later format may mean other things by the same keys: read only the versions known here
    if isinstance(schema, bool) or not isinstance(schema, int) or schema not in SCHEMA_VERSIONS:
        raise ValueError(f"material file {origin}: schema = {schema!r} is not supported; supported: "
                         f"{', '.join(map(str, SCHEMA_VERSIONS))}")
    name = data.get("name")
    if not isinstance(name, str) or not name.strip():
        raise ValueError(f"material file {origin}: name must be a non-empty string")
    sources = data.get("sources", {})
    if not isinstance(sources, dict) or not sources:
        raise ValueError(f"material {name}: [sources] must hold at least one source (key = {{citation = ...}})")
    cites = {}
    for key, s in sources.items():
        if not isinstance(s, dict) or not isinstance(s.get("citation"), str) or not s["citation"].strip():
            raise ValueError(f"material {name}: sources.{key}.citation must be a full citation (string)")
        cites[key] = s["citation"].strip()
    params = data.get("parameters", {})
    if not isinstance(params, dict):
        raise ValueError(f"material {name}: [parameters] must be a table")
    out = {}
    for pname, p in params.items():
        where = f"material {name}: parameters.{pname}"
        if pname not in PARAMETERS:
            raise ValueError(f"{where}: unknown parameter; allowed: {', '.join(PARAMETERS)}")
        if not isinstance(p, dict):
            raise ValueError(f"{where} must be a table with value, unit, source")
        for k in p:
            if k not in _PARAM_KEYS:
                raise ValueError(f"{where}: unknown key {k!r}; allowed: {', '.join(sorted(_PARAM_KEYS))}")
        if "value" not in p:
            raise ValueError(f"{where}.value is missing")
        x, given = _value(where, pname, p["value"], p.get("unit"))
        fallback = p.get("fallback", False)
        if not isinstance(fallback, bool):
            raise ValueError(f"{where}.fallback must be true or false")
        src = p.get("source", "")
        if not isinstance(src, str) or src not in cites:
            raise ValueError(f"{where}.source must name a key of [sources] ({', '.join(cites)}); got {src!r}")
        rng = p.get("range")
        if rng is not None:
            if not isinstance(rng, list) or len(rng) != 2:
                raise ValueError(f"{where}.range must be [low, high]")
            lo, hi = (_value(f"{where}.range", pname, r, p.get("unit"))[0] for r in rng)
            if not lo <= x <= hi:
                raise ValueError(f"{where}: value {x:g} outside its range [{lo:g}, {hi:g}]")
            rng = (lo, hi)
        out[pname] = Parameter(pname, x, given, cites[src], _text(where, p, "quoted_from"), _text(where, p, "where"),
                               rng, _text(where, p, "note"), fallback)
    if "IEC" in out:
        iec = out["IEC"]
        z3 = -_F * iec.value
        if "Z3" in out and not math.isclose(out["Z3"].value, z3, rel_tol=0.02):
            raise ValueError(f"material {name}: Z3 = {out['Z3'].value:g} C/kg disagrees with -F IEC = {z3:g} C/kg")
        if "Z3" not in out:
            out["Z3"] = Parameter("Z3", z3, f"-F IEC, IEC = {iec.given}", iec.source, iec.quoted_from, iec.where,
                                  None, "derived: Z3 = -F IEC (F = 96487 C/mol)", iec.fallback)
    defaults = defaults or {}
    for req in ("Z3",) + _REQUIRED:
        if req not in out and req not in defaults:
            raise ValueError(f"material {name}: parameters.{req} is missing (a set gives it with its source)")
    for k in MATERIAL_FIELDS:
        if k not in out and k in defaults:
            v, src = defaults[k]
            out[k] = Parameter(k, v, f"{v:g} {_si_unit(k)}", src, "", "", None,
                               "not given by the set: the value of the paper's set nafion-li", True)
    c_moy = data.get("c_moy", "formula")
    if isinstance(c_moy, bool) or not (c_moy in ("paper", "formula") or isinstance(c_moy, (int, float))):
        raise ValueError(f"material {name}: c_moy must be 'paper', 'formula' or a number > 0 mol/m^3; got {c_moy!r}")
    perm = {}
    for model, d in (data.get("permittivity") or {}).items():
        where = f"material {name}: permittivity.{model}"
        if not isinstance(d, dict):
            raise ValueError(f"{where} must be a table (eps0, deps, source)")
        for k in d:
            if k not in _PERM_KEYS:
                raise ValueError(f"{where}: unknown key {k!r}; allowed: {', '.join(sorted(_PERM_KEYS))}")
        src = d.get("source", "")
        if src not in cites:
            raise ValueError(f"{where}.source must name a key of [sources]; got {src!r}")
        vals = {}
        for k in ("eps0", "deps"):
            v = d.get(k)
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) or v < 0:
                raise ValueError(f"{where}.{k} must be a number >= 0 (F/m); got {v!r}")
            vals[k] = float(v)
        perm[model] = {**vals, "source": cites[src], "where": _text(where, d, "where"), "note": _text(where, d, "note")}
    return MaterialSet(name=name.strip(), title=_text(name, data, "title"), c_moy=c_moy, origin=origin,
                       parameters=out, sources=cites, membrane=_text(name, data, "membrane"),
                       cation=_text(name, data, "cation"), description=_text(name, data, "description"),
                       permittivity=perm, electrode=_electrode(name, data.get("electrode"), cites))


def _electrode(name, d, cites) -> Electrode:
    """The ``[electrode]`` table: ``thickness`` (each layer; a number in m or a string with a unit),
    ``metal`` (:data:`ipmc_asym.model.electrode.METALS`) and/or ``modulus`` (Pa or with a unit),
    ``density`` (kg/m^3), ``source`` (a key of ``[sources]``: where the thickness was read)."""
    if d is None:
        return NO_ELECTRODE
    where = f"material {name}: electrode"
    if not isinstance(d, dict):
        raise ValueError(f"{where} must be a table (thickness, metal, source)")
    for k in d:
        if k not in _ELECTRODE_KEYS:
            raise ValueError(f"{where}: unknown key {k!r}; allowed: {', '.join(sorted(_ELECTRODE_KEYS))}")
    src = d.get("source", "")
    if not isinstance(src, str) or src not in cites:
        raise ValueError(f"{where}.source must name a key of [sources] ({', '.join(cites)}); got {src!r}")
    spec = {}
    if "metal" in d:
        if d["metal"] not in METALS:
            raise ValueError(f"{where}.metal must be one of {', '.join(METALS)}; got {d['metal']!r}")
        spec["metal"] = d["metal"]
    if "thickness" not in d:
        raise ValueError(f"{where}.thickness is missing (each layer, e.g. \"5um\")")
    spec["thickness"] = parse_quantity(f"{where}.thickness", d["thickness"], PARAMETERS["thickness"][1], "length")
    if "modulus" in d:
        spec["modulus"] = parse_quantity(f"{where}.modulus", d["modulus"], PARAMETERS["E"][1], "pressure")
    if "density" in d:
        spec["density"] = parse_quantity(f"{where}.density", d["density"], PARAMETERS["rho3"][1], "density")
    el = electrode_from_spec(spec, {k: f"{where}.{k}" for k in spec})
    if not el.present:
        return NO_ELECTRODE
    cite = f"electrode layers ({_text(where, d, 'where') or 'thickness'}): {cites[src]}"
    note = _text(where, d, "note")
    return Electrode(el.thickness, el.modulus, el.density, el.metal,
                     "; ".join(x for x in (cite, note, el.source.replace("given by the user", "given by the set")) if x))


def _files():
    return resources.files("ipmc_asym").joinpath("materials")


def set_names() -> tuple:
    """Names of the built-in sets (file stems of ``ipmc_asym/materials/*.toml``), sorted."""
    return tuple(sorted(p.name[:-5] for p in _files().iterdir() if p.name.endswith(".toml")))


def load_set(name: str, defaults: dict | None = None) -> MaterialSet:
    """The built-in set ``name`` (``ValueError`` naming the sets offered if unknown)."""
    names = set_names()
    if name not in names:
        raise ValueError(f"material must be one of {', '.join(names)} or a file NAME.toml; got {name!r}")
    data = tomllib.loads(_files().joinpath(f"{name}.toml").read_text(encoding="utf-8"))
    s = parse_set(data, "built-in", defaults)
    if s.name != name:
        raise ValueError(f"built-in material file {name}.toml names itself {s.name!r}")
    return s


def read_set(path, defaults: dict | None = None) -> MaterialSet:
    """A user's material file (TOML, the schema of the built-in sets; units accepted)."""
    path = os.fspath(path)
    if not path.endswith(".toml"):
        raise ValueError(f"material file must be a .toml file; got {path!r}")
    # regular files only, and the size cap of every input file (--max-input-size): the one reader
    try:
        data = tomllib.loads(read_input_text(path, "material file"))
    except FileNotFoundError:
        raise ValueError(f"material file {path!r} does not exist") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise ValueError(f"material file {path!r}: cannot read ({exc.__class__.__name__}: {exc})") from None
    except tomllib.TOMLDecodeError as exc:
        raise ValueError(f"material file {path}: not valid TOML ({exc})") from None
    return parse_set(data, path, defaults)
