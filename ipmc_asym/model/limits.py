"""Plausible ranges of the inputs and the slender-beam limits, each with its reason.

The one place the command line, scene files and the forward model read them: a strip outside
the slender-beam model, a material parameter outside its plausible range, a bare number that
is implausible in SI (``--thickness 200`` is 200 m) each give one line of warning; the numbers
are still computed (the forward model flags its rows with ``check_slender``).  Hard limits
(a positive length, ``phi4`` in (0, 1), ...) stay in :mod:`ipmc_asym.model.params`.
"""

from __future__ import annotations

import re

import numpy as np

from ipmc_asym.base.settings import MIN_THICKNESS

__all__ = ["SLENDER_LIMITS", "PLAUSIBLE", "slender_ok", "slender_warnings", "range_warning", "material_warnings",
           "bare_number_warning", "value_warning", "strip_warnings"]

#: geometry ratio -> (smallest, largest, reason) for the slender-beam model of the paper (sections
#: 3-4); None where a side is unbounded
SLENDER_LIMITS = {
    "L/2e": (10.0, None,
             "Bernoulli beam (paper section 3): under the blocking force the shear deflection is "
             "~0.9 (2e/L)^2 of the bending one (rectangle, nu = 0.5), <= 1 % from L/2e = 10"),
    "2l/2e": (10.0, None,
              "1-D electrochemistry across the thickness (paper section 4): the side faces perturb a "
              "band ~e wide at each edge, a fraction 2e/2l of the width, <= 10 % from 2l/2e = 10"),
    "2l/L": (None, 1.0,
             "a strip, not a plate: the beam bends along L only; wider than long, bending across the "
             "width and the clamp's edge effects are not small"),
}

#: parameter -> (low, high, unit, reason): outside, a one-line warning (the value is used)
PLAUSIBLE = {
    "length": (1e-4, 1.0, "m", "IPMC strips are mm to tens of cm long"),
    "width": (1e-5, 0.1, "m", "IPMC strips are tens of um to cm wide (TOTAL 2l)"),
    "thickness": (MIN_THICKNESS, 1e-2, "m",
                  "TOTAL 2e: from the continuum floor settings.MIN_THICKNESS to a cm-thick slab"),
    "E": (1e6, 1e10, "Pa", "from a soft gel to a glassy polymer; the preset's hydrated Nafion is 1.3e8 Pa"),
    "c_moy": (100.0, 2e4, "mol/m^3",
              "the preset's ion-exchange data give ~3e3; above 2e4 there are under 3 water molecules "
              "per cation (water is 5.5e4 mol/m^3)"),
    "phi4": (0.05, 0.8, "1", "volume fraction of the solution in a swollen ionomer"),
    "Z3": (-3e5, -1e4, "C/kg", "-F/EW for equivalent weights EW of ~0.3-10 kg/mol (Nafion ~1.1 kg/mol: -8.8e4)"),
    "rho3": (500.0, 5000.0, "kg/m^3", "density of a solid polymer"),
    "rho2": (500.0, 2000.0, "kg/m^3", "density of a liquid solvent (water 1000)"),
    "T": (273.0, 373.0, "K", "liquid water (the model's solvent) at ~1 bar"),
    "D": (1e-13, 1e-8, "m^2/s",
          "orders of magnitude: ions in free water diffuse at ~1e-9 m^2/s, cations in hydrated Nafion "
          "at ~1e-10 (model.params.D_CATION_SOURCE); every dynamic time scales as 1/D"),
    "strain_limit": (1e-4, 0.2, "1", "onset of nonlinearity of a polymer in tension"),
}


def _ratios(length, width, thickness):
    L, w, t = (np.asarray(a, dtype=float) for a in (length, width, thickness))
    with np.errstate(all="ignore"):
        return {"L/2e": L / t, "2l/2e": w / t, "2l/L": w / L}


def slender_ok(length, width, thickness):
    """Bool array: the strip is within every limit of :data:`SLENDER_LIMITS` (SI inputs, TOTAL 2l, 2e)."""
    ok = True
    for k, r in _ratios(length, width, thickness).items():
        lo, hi, _ = SLENDER_LIMITS[k]
        if lo is not None:
            ok = ok & (r >= lo)
        if hi is not None:
            ok = ok & (r <= hi)
    return np.asarray(ok)


def slender_warnings(length, width, thickness) -> list:
    """One line per ratio of :data:`SLENDER_LIMITS` that fails (at the first failing point of arrays)."""
    out = []
    for k, r in _ratios(length, width, thickness).items():
        lo, hi, why = SLENDER_LIMITS[k]
        r = np.atleast_1d(r).reshape(-1)
        bad = np.zeros(r.shape, bool)
        if lo is not None:
            bad |= r < lo
        if hi is not None:
            bad |= r > hi
        if bad.any():
            v = float(r[np.flatnonzero(bad)[0]])
            lim = f">= {lo:g}" if lo is not None and v < lo else f"<= {hi:g}"
            n = int(bad.sum())
            where = "" if r.size == 1 else f" ({n} of {r.size} points)"
            shown = f"{v:.3g}" if np.isfinite(v) else "> 1e300"  # a ratio that overflows (e.g. L = 5e-324 m)
            out.append(f"strip outside the slender-beam model: {k} = {shown}{where}, needs {lim}: {why}; "
                       "numbers kept, flagged check_slender = false")
    return out


def range_warning(name, value, label=None):
    """One line if ``value`` is outside :data:`PLAUSIBLE` ``[name]`` (None inside or for an unknown name)."""
    if name not in PLAUSIBLE:
        return None
    lo, hi, unit, why = PLAUSIBLE[name]
    v = float(value)
    if lo * (1 - 1e-9) <= v <= hi * (1 + 1e-9):  # a value written as the bound itself (100um) is inside
        return None
    u = "" if unit == "1" else f" {unit}"
    return f"{label or name} = {v:g}{u} is outside the plausible range {lo:g}-{hi:g}{u} ({why}); used as given"


def material_warnings(material) -> list:
    """One line per parameter of ``material`` outside :data:`PLAUSIBLE`."""
    out = []
    for k in ("E", "phi4", "Z3", "rho3", "rho2", "T", "D", "strain_limit"):
        m = range_warning(k, getattr(material, k), f"material {k}")
        if m:
            out.append(m)
    m = range_warning("c_moy", material.C_moy, "material C_moy")
    if m:
        out.append(m)
    return out


_BARE = re.compile(r"^\s*[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?\s*$")
_SUGGEST = (("um", 1e-6), ("mm", 1e-3), ("cm", 1e-2))


def bare_number_warning(name, text, value, label=None):
    """One line if ``text`` is a bare number (read as SI metres) whose value is implausible for
    ``name`` (a key of :data:`PLAUSIBLE`), suggesting the units that would make it plausible."""
    if not isinstance(text, str) or not _BARE.match(text) or name not in PLAUSIBLE:
        return None
    lo, hi, _unit, _why = PLAUSIBLE[name]
    v = float(value)
    if lo <= v <= hi:
        return None
    t = text.strip()
    sugg = [f"{t}{u}" for u, f in _SUGGEST if lo <= v * f <= hi]
    hint = f"; did you mean {' or '.join(sugg)}?" if sugg else ""
    return (f"{label or name} {t} is read as {v:g} m (a bare number is SI), implausible for an IPMC strip "
            f"(plausible {lo:g}-{hi:g} m){hint}")


def value_warning(name, text, value, label=None):
    """The one line on a length as written (``text``) and read (``value``): the bare-number hint
    (:func:`bare_number_warning`) where it applies, else the plausible range (:func:`range_warning`);
    None where neither has anything to say."""
    return bare_number_warning(name, text, value, label) or range_warning(name, value, label)


def strip_warnings(length, width, thickness) -> list:
    """Plausible-range and slender-beam lines of one strip (SI, TOTAL 2l and 2e)."""
    out = [m for m in (range_warning(k, v) for k, v in (("length", length), ("width", width),
                                                       ("thickness", thickness))) if m]
    return out + slender_warnings(length, width, thickness)
