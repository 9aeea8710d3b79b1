"""Scene schema: a TOML file (or dict) -> a checked, typed :class:`Scene`.

Every section and key is checked here, once; anything unknown or out of range is a one-line
``ValueError`` naming the key.  The planner (:mod:`ipmc_asym.studies.scenes`) only ever sees a
:class:`Scene`.

File format::

    name = "nominal"                 # optional (default: file stem / "scene")
    model = "constant"               # a name of ipmc_asym.base.registry.MODELS
    voltage = "1V"                   # or voltages = [0.5, 1, "2V"], or a [sweep] of voltage
    outputs = ["I", "moment", "tip_deflection", "rotation", "blocking_force",
               "profiles", "scaling_fit"]
    tolerance = 1e-3                 # relative, in (0, 1) like --tol (default settings.DEFAULT_SCENE_TOL)
    profile_arrays = false           # "profiles": also return z, C, phi, E, D, p arrays
    pressure_term = false            # keep the pressure term of the Nernst-Planck law (eq. 5)

    [strip]                          # SI numbers or strings with units
    length = "2 cm"
    width = "5mm"                    # TOTAL width 2l
    thickness = "200um"              # TOTAL thickness 2e

    [material]                       # params.material_from_spec (the one material parser)
    preset = "nafion-li"
    E = 1.3e8                        # or modulus = "130MPa"
    c_moy = "paper"                  # "paper" | "formula" | number (mol/m^3)
    phi4 = 0.38                      # also Z3, rho3, rho2, T, strain_limit

    [sweep]                          # grid (outer product) over any of thickness, voltage,
    thickness = {start = "50um", stop = "1mm", n = 8, log = true}    # length, width;
    # or a list: thickness = ["100um", "200um"]

A dict may also give ``model`` as a callable ``eps(C)`` (SI), which the planner sends to the
BVP.  Layer rule: stdlib + numpy at import (TOML reader deferred, standard library).
"""

from __future__ import annotations

import sys

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    import tomli as tomllib

import os
from dataclasses import dataclass, field
from typing import Callable, Union

import numpy as np

from ipmc_asym.base.inputs import read_input_text
from ipmc_asym.base.registry import model_names
from ipmc_asym.base.settings import DEFAULT_SCENE_TOL, MAX_ROWS
from ipmc_asym.base.units import parse_length, parse_voltage
from ipmc_asym.forward.escalation import check_tol
from ipmc_asym.model.limits import material_warnings, range_warning, value_warning
from ipmc_asym.model.params import NOMINAL_STRIP, Material, Strip, check_dimension, check_voltage_cap, material_from_spec

__all__ = ["Scene", "OUTPUTS", "AXES", "load_scene", "parse_scene", "read_scene"]

#: outputs a scene may ask for
OUTPUTS = ("I", "moment", "tip_deflection", "rotation", "blocking_force", "profiles", "scaling_fit")
#: the strip parameters a point has (SI; width and thickness TOTAL)
AXES = ("length", "width", "thickness", "voltage")
_DEFAULT_OUTPUTS = ("I", "moment", "tip_deflection", "rotation", "blocking_force")
#: "uncertain" is read by ``ipmc-asym uq`` (ipmc_asym.studies.uq); a plain scene evaluates the nominal values
_TOP = {"name", "model", "voltage", "voltages", "sweep", "outputs", "tolerance", "strip", "material",
        "profile_arrays", "uncertain", "pressure_term"}
_STRIP = ("length", "width", "thickness")
_SWEEP = ("thickness", "voltage", "length", "width")
_RANGE = {"start", "stop", "n", "log"}


@dataclass(frozen=True)
class Scene:
    """A checked scene.

    Attributes
    ----------
    name : str
    model : str or callable
        A registry model name, or ``eps(C)`` (F/m, ``C`` in mol/m^3).
    material : Material
    points : dict of str -> ndarray, shape (n,)
        ``length``, ``width``, ``thickness`` (m; TOTAL width 2l and thickness 2e) and
        ``voltage`` (V) of each point of the (flattened, C-order) grid.
    swept : tuple of str
        Parameters taking more than one value, in grid order.
    outputs : tuple of str
        Subset of :data:`OUTPUTS`, in the order asked.
    tolerance : float
        Relative tolerance, in (0, 1).
    profile_arrays : bool
    warnings : tuple of str
        One line per implausible input (:mod:`ipmc_asym.model.limits`: a bare number implausible
        in SI, a length or material parameter outside its plausible range); the same rules as
        the command line.
    pressure_term : bool
        Keep the pressure term of the Nernst-Planck law (paper eq. (5)); default off.
    """

    name: str
    model: Union[str, Callable]
    material: Material
    points: dict
    swept: tuple
    outputs: tuple
    tolerance: float
    profile_arrays: bool
    warnings: tuple = field(default=())
    pressure_term: bool = False

    @property
    def n(self) -> int:
        """Number of points."""
        return int(self.points["thickness"].size)

    def strip(self, i: int) -> Strip:
        """The strip of point ``i``."""
        return Strip(**{k: float(self.points[k][i]) for k in AXES})


def _toml_loads(text: str) -> dict:
    # a UTF-8 byte-order mark (editors' "UTF-8 with BOM") is not part of the first key
    return tomllib.loads(text.removeprefix("\ufeff"))


def load_scene(path) -> dict:
    """Read a scene TOML file into a dict; ``ValueError`` naming the file if unreadable or not TOML."""
    p = os.fspath(path)
    try:
        text = read_input_text(p, "scene file")
    except (OSError, UnicodeDecodeError) as exc:
        raise ValueError(f"scene file {p!r}: cannot read ({exc.__class__.__name__}: {exc})") from None
    try:
        d = _toml_loads(text)
    except Exception as exc:  # tomllib.TOMLDecodeError
        raise ValueError(f"scene file {p!r}: not valid TOML ({exc})") from None
    d.setdefault("name", os.path.splitext(os.path.basename(p))[0])
    return d


def _check_keys(section: str, d, allowed):
    if not isinstance(d, dict):
        raise ValueError(f"{section} must be a table (section), got {type(d).__name__}")
    for k in d:
        if k not in allowed:
            where = f"[{section}]" if section != "scene" else "top level"
            raise ValueError(f"unknown key {k!r} in {where}; allowed: {', '.join(sorted(allowed))}")


def _num_or_str(key, v):
    if isinstance(v, bool) or not isinstance(v, (int, float, str)):
        raise ValueError(f"{key} must be a number or a string with units; got {type(v).__name__} {v!r}")
    return v


def _length(key, v):
    # the strip's own caps, at the scene's edge (the thickness keeps its stricter floor, checked with the grid)
    return check_dimension(key, parse_length(key, _num_or_str(key, v)), floor="thickness" not in key)


def _voltage(key, v):
    # capped here, at the scene's edge: the rungs would each overflow F|phi0|/(R T) before refusing it
    x = parse_voltage(key, _num_or_str(key, v))
    check_voltage_cap(x, key)
    return x


def _values(key, spec, axis):
    """A sweep entry: list of values or ``{start, stop, n, log}`` -> 1-D array (SI)."""
    conv = _voltage if axis == "voltage" else _length
    if isinstance(spec, list):
        if not spec:
            raise ValueError(f"{key} must not be empty")
        return np.array([conv(f"{key}[{i}]", v) for i, v in enumerate(spec)])
    if isinstance(spec, dict):
        _check_keys(key, spec, _RANGE)
        for k in ("start", "stop", "n"):
            if k not in spec:
                raise ValueError(f"{key}.{k} is required (range = {{start, stop, n, log}})")
        a, b = conv(f"{key}.start", spec["start"]), conv(f"{key}.stop", spec["stop"])
        n = spec["n"]
        if isinstance(n, bool) or not isinstance(n, int) or n < 1:
            raise ValueError(f"{key}.n must be an integer >= 1; got {n!r}")
        if n > MAX_ROWS:  # refuse before allocating (a scene is evaluated in memory)
            raise ValueError(f"{key}.n = {n} exceeds {MAX_ROWS} points (settings.MAX_ROWS); "
                             "use ipmc-asym sweep --out for streamed grids")
        log = spec.get("log", False)
        if not isinstance(log, bool):
            raise ValueError(f"{key}.log must be true or false; got {log!r}")
        if log:
            if a == 0 or b == 0 or (a > 0) != (b > 0):
                raise ValueError(f"{key}: log=true needs start and stop of the same sign, non-zero")
            return np.sign(a) * np.geomspace(abs(a), abs(b), n)
        return np.linspace(a, b, n)
    raise ValueError(f"{key} must be a list or a table {{start, stop, n, log}}; got {type(spec).__name__}")


def _model(model):
    if isinstance(model, str):
        if model not in model_names():
            raise ValueError(f"model must be one of {', '.join(model_names())}; got {model!r}")
    elif not callable(model):
        raise ValueError(f"model must be one of {', '.join(model_names())} (or a callable eps(C)); got {model!r}")
    return model


def _tolerance(tol):
    # the rule of --tol (forward.escalation.check_tol): a relative tolerance in (0, 1)
    return check_tol(tol, "tolerance")


def _outputs(outputs):
    if not isinstance(outputs, list) or not outputs:
        raise ValueError(f"outputs must be a non-empty list of {', '.join(OUTPUTS)}; got {outputs!r}")
    for o in outputs:
        if o not in OUTPUTS:
            raise ValueError(f"outputs: unknown output {o!r}; allowed: {', '.join(OUTPUTS)}")
    return tuple(outputs)


def parse_scene(scene: dict) -> Scene:
    """Check a scene dict (same keys as the TOML) and return a :class:`Scene`.

    Raises
    ------
    ValueError
        Unknown section/key, wrong type or impossible value (the message names the key).
    """
    if not isinstance(scene, dict):
        raise ValueError(f"a scene must be a dict or a path; got {type(scene).__name__}")
    _check_keys("scene", scene, _TOP)
    name = scene.get("name", "scene")
    if not isinstance(name, str):
        raise ValueError(f"name must be a string; got {name!r}")
    model = _model(scene.get("model", "constant"))
    tol = _tolerance(scene.get("tolerance", DEFAULT_SCENE_TOL))
    arrays = scene.get("profile_arrays", False)
    if not isinstance(arrays, bool):
        raise ValueError(f"profile_arrays must be true or false; got {arrays!r}")
    outputs = _outputs(scene.get("outputs", list(_DEFAULT_OUTPUTS)))
    pressure_term = scene.get("pressure_term", False)
    if not isinstance(pressure_term, bool):
        raise ValueError(f"pressure_term must be true or false; got {pressure_term!r}")
    if pressure_term and "profiles" in outputs:
        raise ValueError("pressure_term: the profiles output is the paper's model only; drop 'profiles' or pressure_term")
    material = material_from_spec(scene.get("material"))
    strip = scene.get("strip", {})
    _check_keys("strip", strip, _STRIP)
    base = {k: _length(f"strip.{k}", strip[k]) if k in strip else getattr(NOMINAL_STRIP, k) for k in _STRIP}
    sweep = scene.get("sweep", {})
    _check_keys("sweep", sweep, _SWEEP)
    if sum(k in scene for k in ("voltage", "voltages")) + ("voltage" in sweep) > 1:
        raise ValueError("voltage: give only one of voltage, voltages, [sweep].voltage")
    axes = {}
    for k in _SWEEP:
        if k in sweep:
            if k in strip:
                raise ValueError(f"{k}: given both in [strip] and [sweep]")
            axes[k] = _values(f"sweep.{k}", sweep[k], k)
    if "voltages" in scene:
        if not isinstance(scene["voltages"], list):
            raise ValueError(f"voltages must be a list; got {scene['voltages']!r}")
        axes["voltage"] = _values("voltages", scene["voltages"], "voltage")
    elif "voltage" in scene:
        base["voltage"] = _voltage("voltage", scene["voltage"])
    elif "voltage" not in axes:
        raise ValueError("voltage: missing (give voltage, voltages or [sweep].voltage)")
    names = list(axes)
    if int(np.prod([axes[k].size for k in names], dtype=float)) > MAX_ROWS:
        raise ValueError(f"the scene grid has {int(np.prod([axes[k].size for k in names], dtype=float))} "
                         f"points, more than {MAX_ROWS} (settings.MAX_ROWS); use ipmc-asym sweep --out")
    grids = np.meshgrid(*[axes[k] for k in names], indexing="ij") if names else []
    shape = grids[0].shape if names else ()
    pts = {k: (grids[names.index(k)] if k in names else np.full(shape, base[k])).reshape(-1) for k in AXES}
    swept = tuple(k for k in names if axes[k].size > 1)
    warns = []
    for k, v in strip.items():  # the rules of the command line's length options (model.limits)
        text = v if isinstance(v, str) else str(v) if isinstance(v, int) else repr(float(v))
        line = value_warning(k, text, base[k], f"strip.{k}")
        if line:
            warns.append(line)
    for k, a in axes.items():  # swept lengths: the first implausible value
        line = next((m for m in (range_warning(k, x, f"sweep.{k}") for x in a) if m), None) if k in _STRIP else None
        if line:
            warns.append(line)
    warns += material_warnings(material)
    return Scene(name, model, material, pts, swept, outputs, tol, arrays, tuple(warns), pressure_term)


def read_scene(scene) -> Scene:
    """A :class:`Scene` from a dict, a path of a TOML file, or a :class:`Scene` (returned as is)."""
    if isinstance(scene, Scene):
        return scene
    if not isinstance(scene, dict):
        scene = load_scene(scene)
    return parse_scene(scene)
