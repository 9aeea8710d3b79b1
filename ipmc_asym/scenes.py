"""Scenes: a TOML file naming a strip, a material, a model, voltage(s), outputs and a tolerance.

``ipmc-asym scene FILE.toml [--json]`` and :func:`run_scene` (dict or path).  The planner
computes ONLY the outputs asked for, each at the cheapest fidelity whose error estimate meets
the tolerance, escalating point by point ``leading -> corrected -> quadrature -> bvp``
(``bvp`` also where the layers overlap, i.e. ``valid`` is False, and for a custom ``eps(C)``
callable, accepted by :func:`run_scene` with a dict).  Beam formulas are picked the same way:
small-displacement deflection where :func:`ipmc_asym.beam.small_displacement_error` <= tol,
the arc otherwise; small blocking force where :func:`ipmc_asym.beam.blocking_force_error`
<= tol, the large-displacement root otherwise.

File format (every section and key is checked; anything unknown is a ``ValueError``
naming it)::

    name = "nominal"                 # optional (default: file stem / "scene")
    model = "constant"               # constant | linear | affine
    voltage = "1V"                   # or voltages = [0.5, 1, "2V"], or a [sweep] of voltage
    outputs = ["I", "moment", "tip_deflection", "rotation", "blocking_force",
               "profiles", "scaling_fit"]
    tolerance = 1e-3                 # relative, > 0 (default 1e-3)
    profile_arrays = false           # "profiles": also return z, C, phi, E, D, p arrays

    [strip]                          # SI numbers or strings with units
    length = "2 cm"
    width = "5mm"                    # TOTAL width 2l
    thickness = "200um"              # TOTAL thickness 2e

    [material]
    preset = "nafion-li"
    E = 1.3e8                        # or modulus = "130MPa"
    c_moy = "paper"                  # "paper" | "formula" | number (mol/m^3)
    phi4 = 0.38                      # also Z3, rho3, rho2, T

    [sweep]                          # grid (outer product) over any of thickness, voltage,
    thickness = {start = "50um", stop = "1mm", n = 8, log = true}    # length, width;
    # or a list: thickness = ["100um", "200um"]

Result (JSON-ready dict)::

    {"scene": name, "model": ..., "tolerance": ..., "material": {...},
     "swept": [names of varying parameters],
     "points": [{"length", "width", "thickness", "voltage"}, ...],      # SI
     "outputs": {
        "I" | "moment" | "tip_deflection" | "rotation" | "blocking_force": {
            "values": [per point], "unit": ..., "fidelity": [per point],
            "error_estimate": [per point, relative], "beam": [per point] (mechanical outputs:
            "small" | "large"; rotation: "exact")},
        "profiles": {"values": [{"B1", "I", "n_nodes", "anode_layer", "cathode_layer",
                     ("z", "C", ...)} per point], "fidelity": "bvp", "error_estimate": [...]},
        "scaling_fit": {"variable": name, "fits": {output: {"exponent", "prefactor",
                        "correlation", "fidelity"}}}}}

``error_estimate`` of the mechanical outputs is the relative error of ``I`` plus, for the
small-displacement formulas, their own relative deviation from the large-displacement ones.
Module-level imports are stdlib + numpy only.
"""

from __future__ import annotations

import math
import os

import numpy as np

__all__ = ["run_scene", "load_scene", "OUTPUTS", "LADDER"]

OUTPUTS = ("I", "moment", "tip_deflection", "rotation", "blocking_force", "profiles", "scaling_fit")
LADDER = ("leading", "corrected", "quadrature", "bvp")
_TOP = {"name", "model", "voltage", "voltages", "sweep", "outputs", "tolerance", "strip", "material",
        "profile_arrays"}
_STRIP = {"length", "width", "thickness"}
_MATERIAL = {"preset", "E", "modulus", "c_moy", "phi4", "Z3", "rho3", "rho2", "T"}
_SWEEP = {"thickness", "voltage", "length", "width"}
_RANGE = {"start", "stop", "n", "log"}
_DEFAULTS = {"length": 0.02, "width": 5e-3, "thickness": 200e-6}
_BVP_ERROR = 1e-9  # stated accuracy of the BVP path (ipmc_asym.integral)


def _toml_loads(text: str) -> dict:
    try:
        import tomllib  # Python >= 3.11
    except ModuleNotFoundError:  # pragma: no cover - Python 3.10
        import tomli as tomllib
    return tomllib.loads(text)


def load_scene(path) -> dict:
    """Read a scene TOML file; ``ValueError`` naming the file if unreadable or not TOML."""
    p = os.fspath(path)
    try:
        with open(p, "rb") as fh:
            text = fh.read().decode("utf-8")
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
    from .units import parse_length

    x = parse_length(key, _num_or_str(key, v))
    if x <= 0:
        raise ValueError(f"{key} must be > 0 m; got {v!r}")
    return x


def _voltage(key, v):
    from .units import parse_voltage

    return parse_voltage(key, _num_or_str(key, v))


def _conv(name):
    return _voltage if name == "voltage" else _length


def _values(key, spec, name):
    """A sweep entry: list of values or {start, stop, n, log}."""
    conv = _conv(name)
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
        log = spec.get("log", False)
        if not isinstance(log, bool):
            raise ValueError(f"{key}.log must be true or false; got {log!r}")
        if log:
            if a == 0 or b == 0 or (a > 0) != (b > 0):
                raise ValueError(f"{key}: log=true needs start and stop of the same sign, non-zero")
            return np.sign(a) * np.geomspace(abs(a), abs(b), n)
        return np.linspace(a, b, n)
    raise ValueError(f"{key} must be a list or a table {{start, stop, n, log}}; got {type(spec).__name__}")


def _material(d):
    from .params import MATERIALS

    if d is None:
        d = {}
    _check_keys("material", d, _MATERIAL)
    preset = d.get("preset", "nafion-li")
    if preset not in MATERIALS:
        raise ValueError(f"material.preset must be one of {', '.join(MATERIALS)}; got {preset!r}")
    m = MATERIALS[preset]
    kw = {}
    if "E" in d and "modulus" in d:
        raise ValueError("material: give E or modulus, not both")
    for k in ("E", "modulus"):
        if k in d:
            from .units import parse_pressure

            kw["E"] = parse_pressure(f"material.{k}", _num_or_str(f"material.{k}", d[k]))
    for k in ("phi4", "Z3", "rho3", "rho2", "T"):
        if k in d:
            v = d[k]
            if isinstance(v, bool) or not isinstance(v, (int, float)):
                raise ValueError(f"material.{k} must be a number; got {v!r}")
            kw[k] = float(v)
    if "c_moy" in d:
        v = d["c_moy"]
        if isinstance(v, bool) or not isinstance(v, (int, float, str)):
            raise ValueError(f"material.c_moy must be 'paper', 'formula' or a number; got {v!r}")
        kw["c_moy"] = float(v) if not isinstance(v, str) else v
    try:
        return m.with_(**kw)
    except ValueError as exc:
        raise ValueError(f"material: {exc}") from None


def _parse(scene: dict):
    """Validate a scene dict; return (name, model, material, points dict of arrays, swept, outputs, tol, arrays)."""
    if not isinstance(scene, dict):
        raise ValueError(f"a scene must be a dict or a path; got {type(scene).__name__}")
    _check_keys("scene", scene, _TOP)
    name = scene.get("name", "scene")
    if not isinstance(name, str):
        raise ValueError(f"name must be a string; got {name!r}")
    model = scene.get("model", "constant")
    if isinstance(model, str):
        from .permittivity import MODELS

        if model not in MODELS:
            raise ValueError(f"model must be one of {', '.join(MODELS)}; got {model!r}")
    elif not callable(model):
        raise ValueError(f"model must be one of constant, linear, affine (or a callable eps(C)); got {model!r}")
    tol = scene.get("tolerance", 1e-3)
    if isinstance(tol, bool) or not isinstance(tol, (int, float)) or not math.isfinite(tol) or tol <= 0:
        raise ValueError(f"tolerance must be a number > 0 (relative); got {tol!r}")
    arrays = scene.get("profile_arrays", False)
    if not isinstance(arrays, bool):
        raise ValueError(f"profile_arrays must be true or false; got {arrays!r}")
    outputs = scene.get("outputs", ["I", "moment", "tip_deflection", "rotation", "blocking_force"])
    if not isinstance(outputs, list) or not outputs:
        raise ValueError(f"outputs must be a non-empty list of {', '.join(OUTPUTS)}; got {outputs!r}")
    for o in outputs:
        if o not in OUTPUTS:
            raise ValueError(f"outputs: unknown output {o!r}; allowed: {', '.join(OUTPUTS)}")
    material = _material(scene.get("material"))
    strip = scene.get("strip", {})
    _check_keys("strip", strip, _STRIP)
    base = {k: _length(f"strip.{k}", strip[k]) if k in strip else v for k, v in _DEFAULTS.items()}
    sweep = scene.get("sweep", {})
    _check_keys("sweep", sweep, _SWEEP)
    nv = sum(k in scene for k in ("voltage", "voltages")) + ("voltage" in sweep)
    if nv > 1:
        raise ValueError("voltage: give only one of voltage, voltages, [sweep].voltage")
    axes = {}
    for k in ("thickness", "voltage", "length", "width"):
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
    grids = np.meshgrid(*[axes[k] for k in names], indexing="ij") if names else []
    shape = grids[0].shape if names else ()
    pts = {}
    for k in ("length", "width", "thickness", "voltage"):
        pts[k] = (grids[names.index(k)] if k in names else np.full(shape, base[k])).reshape(-1)
    swept = [k for k in names if axes[k].size > 1]
    return name, model, material, pts, swept, outputs, float(tol), arrays


def _plan_moment(pts, model, material, tol):
    """I, error estimate and fidelity per point, escalating until the estimate meets tol."""
    from .integral import moment

    th, v = pts["thickness"], pts["voltage"]
    n = th.size
    I = np.full(n, np.nan)
    err = np.full(n, np.inf)
    fid = np.array(["bvp"] * n, dtype=object)
    todo = np.ones(n, bool)
    if isinstance(model, str):
        for f in LADDER[:-1]:
            idx = np.flatnonzero(todo)
            if idx.size == 0:
                break
            r = moment(th[idx], v[idx], model, f, material=material)
            ok = r.valid & (r.error <= tol) & np.isfinite(r.I)
            sel = idx[ok]
            I[sel], err[sel], fid[sel] = r.I[ok], r.error[ok], f
            todo[sel] = False
    idx = np.flatnonzero(todo)
    if idx.size:
        r = moment(th[idx], v[idx], model, "bvp", material=material, progress=False)
        I[idx], err[idx] = r.I, r.error
    return I, err, fid


def _groups_A5(pts, material, model):
    from .params import moment_scale

    return moment_scale(pts["width"], pts["thickness"], pts["voltage"], material.F, material.C_moy)


def _layer_width(z, C, side, thr=0.01):
    """Distance (units of e) from the face where ``|C - 1|`` first drops below ``thr``."""
    dev = np.abs(C - 1.0) > thr
    if side == "anode":
        k = np.argmax(~dev) if not dev.all() else dev.size - 1
        return float(z[k] + 1.0)
    rz, rd = z[::-1], dev[::-1]
    k = np.argmax(~rd) if not rd.all() else rd.size - 1
    return float(1.0 - rz[k])


def _fit(x, y, what):
    x, y = np.asarray(x, float), np.asarray(y, float)
    if x.size < 2 or np.unique(x).size < 2:
        raise ValueError("scaling_fit needs a [sweep] (or voltages) over at least 2 distinct values")
    if np.any(x <= 0) or np.any(y == 0) or not np.all(np.isfinite(y)):
        raise ValueError(f"scaling_fit: {what} and the swept variable must be non-zero, finite and of "
                         f"one sign (log-log fit)")
    if not (np.all(y > 0) or np.all(y < 0)):
        raise ValueError(f"scaling_fit: {what} changes sign over the sweep (no power law)")
    lx, ly = np.log(x), np.log(np.abs(y))
    k, c = np.polyfit(lx, ly, 1)
    r = float(np.corrcoef(lx, ly)[0, 1]) if np.std(ly) > 0 else 1.0
    return {"exponent": float(k), "prefactor": float(np.sign(y[0]) * math.exp(c)), "correlation": r}


def run_scene(scene) -> dict:
    """Plan and evaluate a scene.

    Parameters
    ----------
    scene : dict or str or os.PathLike
        A parsed scene (same keys as the TOML; ``model`` may also be a callable ``eps(C)``,
        which forces the BVP) or the path of a TOML file.

    Returns
    -------
    dict
        See the module docstring.

    Raises
    ------
    ValueError
        Unknown section/key, wrong type, impossible value or unreadable file (the message
        names the key).
    """
    from .beam import (
        blocking_force_error,
        blocking_force_large,
        small_displacement_error,
        tip_position,
    )

    if not isinstance(scene, dict):
        scene = load_scene(scene)
    name, model, material, pts, swept, outputs, tol, arrays = _parse(scene)
    n = pts["thickness"].size
    res = {"scene": name, "model": model if isinstance(model, str) else "custom", "tolerance": tol,
           "material": {"name": material.name, "E": material.E, "C_moy": material.C_moy,
                        "c_moy": str(material.c_moy), "phi4": material.phi4},
           "swept": swept,
           "points": [{k: float(pts[k][i]) for k in ("length", "width", "thickness", "voltage")}
                      for i in range(n)],
           "outputs": {}}
    out = res["outputs"]
    mech = {"moment", "tip_deflection", "rotation", "blocking_force"}
    need_I = bool(set(outputs) & (mech | {"I", "scaling_fit"}))
    vals = {}
    if need_I:
        I, err, fid = _plan_moment(pts, model, material, tol)
        fl = [str(f) for f in fid]
        el = [float(x) for x in err]
        vals["I"] = I
        if "I" in outputs:
            out["I"] = {"values": I.tolist(), "unit": "dimensionless", "fidelity": fl, "error_estimate": el}
        M = _groups_A5(pts, material, model) * I
        vals["moment"] = M
        if "moment" in outputs:
            out["moment"] = {"values": M.tolist(), "unit": "N m", "fidelity": fl, "error_estimate": el}
        L = pts["length"]
        from .params import second_moment

        EI = material.E * second_moment(pts["width"], pts["thickness"])
        if "rotation" in outputs:
            th = -M * L / EI
            vals["rotation"] = th
            out["rotation"] = {"values": th.tolist(), "unit": "rad", "fidelity": fl, "error_estimate": el,
                               "beam": ["exact"] * n}
        if "tip_deflection" in outputs:
            serr = np.atleast_1d(small_displacement_error(M, L, EI))
            small = serr <= tol
            w_s = -0.5 * M * L * L / EI
            w_l = np.atleast_1d(tip_position(M, L, EI)[1])
            w = np.where(small, w_s, w_l)
            vals["tip_deflection"] = w
            out["tip_deflection"] = {"values": w.tolist(), "unit": "m", "fidelity": fl,
                                     "error_estimate": (err + np.where(small, serr, 0.0)).tolist(),
                                     "beam": ["small" if s else "large" for s in small]}
        if "blocking_force" in outputs:
            berr = np.atleast_1d(blocking_force_error(M, L, EI))
            small = berr <= tol
            F_s = 1.5 * M / L
            F_l = np.atleast_1d(blocking_force_large(M, L, EI))
            F = np.where(small, F_s, F_l)
            if not np.all(np.isfinite(F)):
                k = int(np.flatnonzero(~np.isfinite(F))[0])
                raise ValueError(f"blocking_force: no large-displacement blocking force at point {k} "
                                 f"({res['points'][k]}); the strip bends too far (|kappa L| too large)")
            vals["blocking_force"] = F
            out["blocking_force"] = {"values": F.tolist(), "unit": "N", "fidelity": fl,
                                     "error_estimate": (err + np.where(small, berr, 0.0)).tolist(),
                                     "beam": ["small" if s else "large" for s in small]}
    if "profiles" in outputs:
        from .bvp import solve
        from .params import Strip

        prof = []
        for i in range(n):
            s = Strip(length=float(pts["length"][i]), width=float(pts["width"][i]),
                      thickness=float(pts["thickness"][i]), voltage=float(pts["voltage"][i]))
            r = solve(s, model, material)
            if not r.success:
                raise RuntimeError(f"profiles: BVP did not converge at point {i} ({r.message})")
            e = s.e
            pa, pc = ("anode", "cathode") if s.voltage >= 0 else ("cathode", "anode")
            wa, wc = _layer_width(r.z, r.C, pa), _layer_width(r.z, r.C, pc)
            item = {"B1": float(r.B1), "I": float(r.I), "n_nodes": int(r.n_nodes),
                    "anode_layer": {"width_e": wa, "width_m": wa * e},
                    "cathode_layer": {"width_e": wc, "width_m": wc * e},
                    "C_min": float(r.C.min()), "C_max": float(r.C.max())}
            if arrays:
                for k in ("z", "C", "phi", "E", "D", "p"):
                    item[k] = getattr(r, k).tolist()
            prof.append(item)
        out["profiles"] = {"values": prof, "fidelity": "bvp", "error_estimate": [_BVP_ERROR] * n,
                           "layer_threshold": "|C/C_moy - 1| > 0.01"}
    if "scaling_fit" in outputs:
        if len(swept) != 1:
            raise ValueError(f"scaling_fit needs exactly one swept variable (sweep or voltages); got "
                             f"{swept or 'none'}")
        var = swept[0]
        x = pts[var]
        wanted = [o for o in outputs if o in vals] or ["I"]
        fits = {}
        for o in wanted:
            f = _fit(np.abs(x) if var == "voltage" else x, vals[o], o)
            f["fidelity"] = sorted(set(fl), key=LADDER.index)
            fits[o] = f
        out["scaling_fit"] = {"variable": var, "fits": fits}
    return res
