"""Scenes: a TOML file naming a strip, a material, a model, voltage(s), outputs and a tolerance.

``ipmc-asym scene FILE.toml [--json]`` and :func:`run_scene` (dict or path).  The planner
computes ONLY the outputs asked for, each at the cheapest fidelity whose error estimate meets
the tolerance, escalating point by point along the registry's ladder (``leading ->
corrected -> quadrature -> exact -> bvp``; ``exact`` holds where the layers overlap, ``bvp``
is the last resort and the only rung for a custom ``eps(C)`` callable, accepted by
:func:`run_scene` with a dict).  Beam formulas are picked the same way:
small-displacement deflection where :func:`ipmc_asym.beam.statics.small_displacement_error` <= tol,
the arc otherwise; small blocking force where :func:`ipmc_asym.beam.statics.blocking_force_error`
<= tol, the large-displacement root otherwise.

The file format and every check live in :mod:`ipmc_asym.studies.scene_schema` (TOML -> a typed
:class:`~ipmc_asym.studies.scene_schema.Scene`); this module is the planner.  It calls the same
functions as everything else: the forward model :func:`ipmc_asym.forward.model.forward` for ``I``,
the moment, the beam outputs and their checks, :func:`ipmc_asym.studies.fits.fit_power_law`, and
the layer widths of :func:`ipmc_asym.studies.profiles.layer_widths`.

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
Layer rule: studies layer (stdlib + numpy at import; the BVP loads SciPy when called).
"""

from __future__ import annotations

import numpy as np

from ipmc_asym.base.registry import fidelity_names
from ipmc_asym.base.settings import BVP_STATED_ERROR
from ipmc_asym.forward.model import assumption_warnings, forward
from ipmc_asym.studies.fits import fit_power_law
from ipmc_asym.studies.profiles import LAYER_WIDTHS, profile, profile_summary
from ipmc_asym.studies.scene_schema import OUTPUTS, Scene, load_scene, read_scene

__all__ = ["run_scene", "load_scene", "OUTPUTS", "LADDER", "Scene"]

#: the fidelity ladder, cheapest first (the registry's order)
LADDER = fidelity_names()
_MECHANICAL = {"moment", "tip_deflection", "rotation", "blocking_force"}
#: the layer widths reported for each face (definitions in ipmc_asym.studies.profiles.LAYER_WIDTHS)
_ANODE_WIDTH, _CATHODE_WIDTH = "devoid_um", "accumulation_um"


def _plan(sc: Scene):
    """The forward model at the scene's points (:func:`ipmc_asym.forward.model.forward`): ``I``
    at the cheapest rung meeting the tolerance, escalating along the registry's ladder, then the
    beam and its checks.  Where no rung is valid: a one-line ``ValueError`` (never a number that
    failed its check)."""
    pts = sc.points
    r = forward(pts["length"], pts["width"], pts["thickness"], pts["voltage"], material=sc.material,
                model=sc.model, fidelity=LADDER[0], tol=min(sc.tolerance, 0.5), pressure_term=sc.pressure_term)
    if not np.all(r.moment_valid):
        raise ValueError(r.moment_message)
    return r


def _scaling_fit(x, y, what):
    """Power-law fit of one output over the swept variable (fits.fit_power_law)."""
    x, y = np.asarray(x, float), np.asarray(y, float)
    keep = np.isfinite(y)  # points withheld, or outside a model assumption, are left out of the fit
    x, y = x[keep], y[keep]
    if x.size < 2 or np.unique(x).size < 2:
        raise ValueError("scaling_fit needs a [sweep] (or voltages) over at least 2 distinct values")
    if np.any(x <= 0) or np.any(y == 0) or not np.all(np.isfinite(y)):
        raise ValueError(f"scaling_fit: {what} and the swept variable must be non-zero, finite and of "
                         f"one sign (log-log fit)")
    if not (np.all(y > 0) or np.all(y < 0)):
        raise ValueError(f"scaling_fit: {what} changes sign over the sweep (no power law)")
    f = fit_power_law(x, y)
    return {"exponent": f["exponent"], "prefactor": float(np.sign(y[0]) * f["prefactor"]),
            "correlation": f["r"]}


def _profiles(sc: Scene):
    prof = []
    for i in range(sc.n):
        s = sc.strip(i)
        # the profiles command's own (the BVP; below its floor, the Debye-Hueckel solution), and
        # its summary's B1: the cathode's concentration, whatever the voltage's sign
        try:
            r = profile(sc.model, s, sc.material)
        except RuntimeError as exc:
            raise RuntimeError(f"profiles: at point {i}: {exc}") from None
        summary = profile_summary(sc.model, s, sc.material, res=r)  # its layer widths and B1, once
        wa, wc = summary[_ANODE_WIDTH] * 1e-6, summary[_CATHODE_WIDTH] * 1e-6
        item = {"B1": summary["B1"], "I": float(r.I), "n_nodes": int(r.n_nodes),
                "anode_layer": {"width_e": wa / s.e, "width_m": wa},
                "cathode_layer": {"width_e": wc / s.e, "width_m": wc},
                "C_min": float(r.C.min()), "C_max": float(r.C.max())}
        if sc.profile_arrays:
            for k in ("z", "C", "phi", "E", "D", "p"):
                item[k] = getattr(r, k).tolist()
        prof.append(item)
    return {"values": prof, "fidelity": LADDER[-1], "error_estimate": [BVP_STATED_ERROR] * sc.n,
            "layer_threshold": f"anode: {LAYER_WIDTHS[_ANODE_WIDTH][1]}; "
                               f"cathode: {LAYER_WIDTHS[_CATHODE_WIDTH][1]}"}


def run_scene(scene) -> dict:
    """Plan and evaluate a scene.

    Parameters
    ----------
    scene : dict or str or os.PathLike or Scene
        A parsed scene (same keys as the TOML; ``model`` may also be a callable ``eps(C)``,
        which forces the BVP), the path of a TOML file, or a checked :class:`Scene`.

    Returns
    -------
    dict
        See the module docstring.

    Raises
    ------
    ValueError
        Unknown section/key, wrong type, impossible value or unreadable file (the message
        names the key).

    Examples
    --------
    >>> r = run_scene({"name": "demo", "model": "constant", "voltage": "1V", "outputs": ["I"]})
    >>> r["valid"], r["points"][0]["thickness"]
    (True, 0.0002)
    """
    raw = scene
    if not isinstance(scene, (dict, Scene)):
        raw = load_scene(scene)
    sc = read_scene(raw)
    pts, n, tol, outputs = sc.points, sc.n, sc.tolerance, sc.outputs
    defaults = []
    if isinstance(raw, dict):
        given = set(raw.get("strip", {}) or {}) | set(raw.get("sweep", {}) or {})
        defaults = [k for k in ("length", "width", "thickness") if k not in given]
    material = sc.material
    res = {"scene": sc.name, "model": sc.model if isinstance(sc.model, str) else "custom", "tolerance": tol,
           "material": {"name": material.name, "E": material.E, "C_moy": material.C_moy,
                        "c_moy": str(material.c_moy), "phi4": material.phi4,
                        "sources": list(material.sources)},
           "swept": list(sc.swept),
           "defaults_used": {k: float(pts[k][0]) for k in defaults},
           "notes": (["the [uncertain] table is for `ipmc-asym uq`; this scene is evaluated at the "
                      "nominal values"] if isinstance(raw, dict) and "uncertain" in raw else []),
           "warnings": list(sc.warnings),
           "point_units": {"length": "m", "width": "m, TOTAL width 2l", "thickness": "m, TOTAL thickness 2e",
                           "voltage": "V"},
           "points": [{k: float(pts[k][i]) for k in ("length", "width", "thickness", "voltage")}
                      for i in range(n)],
           "outputs": {}}
    out = res["outputs"]
    vals = {}
    fl = []
    if set(outputs) & (_MECHANICAL | {"I", "scaling_fit"}):
        r = _plan(sc)
        I, err = np.atleast_1d(r.I), np.atleast_1d(r.error)
        fl = [str(f) for f in np.atleast_1d(r.fidelity_used)]
        el = [float(x) for x in err]
        vals["I"] = I
        if "I" in outputs:
            out["I"] = {"values": I.tolist(), "unit": "dimensionless", "fidelity": fl, "error_estimate": el}
        M = np.atleast_1d(r.M_A)
        vals["moment"] = M
        if "moment" in outputs:
            out["moment"] = {"values": M.tolist(), "unit": "N m", "fidelity": fl, "error_estimate": el}
        # the forward model's checks (forward.model.CHECKS): a failed model assumption keeps the
        # value and flags the point (left out of scaling fits); the free strip's tip position past
        # a full turn is withheld (None)
        strain = np.atleast_1d(r.max_strain)
        res["checks"] = [dict(r.checks(i if np.ndim(r.valid) else ()), max_strain=float(strain[i]))
                         for i in range(n)]
        res["valid"] = bool(np.all(r.valid))
        res["warnings"] += assumption_warnings(r)
        tip_ok = ~np.atleast_1d(r.withheld_mask("w"))

        def _fit_vals(a, key):  # NaN where the point is outside a model assumption concerning key
            return np.where(np.atleast_1d(r.flag_mask(key)), np.nan, np.atleast_1d(a))

        def _kept(a, ok):
            return [float(x) if o else None for x, o in zip(np.atleast_1d(a), ok)]
        if "rotation" in outputs:
            th = np.atleast_1d(r.theta)  # -M L/EI, paper eq. 12
            vals["rotation"] = _fit_vals(th, "theta")
            out["rotation"] = {"values": th.tolist(), "unit": "rad", "fidelity": fl, "error_estimate": el,
                               "beam": ["exact"] * n}
        if "tip_deflection" in outputs:
            # the small-displacement formula (eq. 13) where its deviation from the arc is within tol
            serr = np.atleast_1d(r.small_error)
            small = serr <= tol
            w = np.where(small, np.atleast_1d(r.w_small), np.atleast_1d(r.w))
            vals["tip_deflection"] = np.where(tip_ok, _fit_vals(w, "w"), np.nan)
            out["tip_deflection"] = {"values": _kept(w, tip_ok), "unit": "m", "fidelity": fl,
                                     "error_estimate": (err + np.where(small, serr, 0.0)).tolist(),
                                     "beam": ["small" if s else "large" for s in small]}
        if "blocking_force" in outputs:
            # 3M/(2L) (eq. 14) where its deviation from the large-displacement root is within tol
            berr = np.atleast_1d(r.block_error)
            small = berr <= tol
            F = np.where(small, np.atleast_1d(r.F_block_small), np.atleast_1d(r.F_block))
            # no large-displacement root (|kappa L| past the tracked branch): that point's value is
            # withheld (None), as evaluate and sweep do; the other points and outputs stand
            F_ok = np.isfinite(F)
            if not np.all(F_ok):
                k = int(np.flatnonzero(~F_ok)[0])
                res["warnings"].append(f"blocking_force withheld (None) at {int((~F_ok).sum())} point(s), first "
                                       f"{k} ({res['points'][k]}): no large-displacement blocking force, the strip "
                                       f"bends too far (|kappa L| too large)")
            vals["blocking_force"] = np.where(F_ok, _fit_vals(F, "F_block"), np.nan)
            out["blocking_force"] = {"values": _kept(F, F_ok), "unit": "N", "fidelity": fl,
                                     "error_estimate": (err + np.where(small, berr, 0.0)).tolist(),
                                     "beam": ["small" if s else "large" for s in small]}
    if "profiles" in outputs:
        out["profiles"] = _profiles(sc)
    if "scaling_fit" in outputs:
        if len(sc.swept) != 1:
            raise ValueError(f"scaling_fit needs exactly one swept variable (sweep or voltages); got "
                             f"{list(sc.swept) or 'none'}")
        var = sc.swept[0]
        x = pts[var]
        wanted = [o for o in outputs if o in vals] or ["I"]
        fits = {}
        for o in wanted:
            f = _scaling_fit(np.abs(x) if var == "voltage" else x, vals[o], o)
            f["fidelity"] = sorted(set(fl), key=LADDER.index)
            fits[o] = f
        out["scaling_fit"] = {"variable": var, "fits": fits}
    return res
