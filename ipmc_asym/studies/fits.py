"""Log-log power-law fits and the paper's scaling table (seed section 6.2-6.3).

``fit_power_law(x, y)`` fits ``|y| = a x^b`` by least squares on ``(ln x, ln |y|)`` and returns
the exponent ``b``, the prefactor ``a`` and the correlation coefficient ``r`` of the log-log
data (the paper's "coefficient de corrélation").  Points where the free strip passes a
quarter turn (beam regimes ``past-quarter-turn`` / ``multi-turn``) are outside the model and
left out of every fit on a sweep; each fit says how many it left out.

Default ranges (the paper does not state them; chosen around the nominal strip
``L = 2 cm, 2l = 5 mm, 2e = 200 um, phi0 = 1 V``): see :data:`RANGES`.

Layer rule: stdlib + numpy at import.
"""

from __future__ import annotations

import numpy as np

from ipmc_asym.base.registry import model_names
from ipmc_asym.base.settings import OUTSIDE_REGIMES
from ipmc_asym.model.params import NAFION_LI, Material, Strip
from ipmc_asym.studies.sweeps import sweep, withhold

__all__ = ["fit_power_law", "local_exponent", "sweep_fits", "axis_fits", "FIT_POINTS",
           "RANGES", "scaling_fits", "variation_table", "QUANTITIES",
           "linear_r"]

#: quantity keys fitted (sweep columns)
QUANTITIES = ("w", "w_small", "F_block", "F_block_small", "theta")

#: variable -> (start, stop, n) SI; thickness and width TOTAL
RANGES = {
    "length": (0.01, 0.04, 16),
    "width": (2e-3, 10e-3, 9),
    "thickness": (100e-6, 400e-6, 16),
    "voltage": (0.1, 3.0, 30),
}



def fit_power_law(x, y, mask=None) -> dict:
    """Least squares ``ln|y| = ln a + b ln x``.

    Returns
    -------
    dict
        ``exponent`` b, ``prefactor`` a, ``r`` (Pearson correlation of ln x, ln|y|; NaN if
        ``|y|`` is constant to 1e-12), ``n`` points used, ``n_left_out`` (mask False, or
        non-finite / zero values).
    """
    x = np.asarray(x, dtype=float).ravel()
    y = np.abs(np.asarray(y, dtype=float).ravel())
    keep = np.isfinite(x) & np.isfinite(y) & (x > 0) & (y > 0)
    if mask is not None:
        keep &= np.asarray(mask, dtype=bool).ravel()
    n = int(keep.sum())
    out = {"exponent": float("nan"), "prefactor": float("nan"), "r": float("nan"), "n": n,
           "n_left_out": int(x.size - n)}
    if n < 2:
        out["note"] = (f"only {n} usable point(s) (others past a quarter turn, zero or non-finite): "
                       "no fit")
        return out
    lx, ly = np.log(x[keep]), np.log(y[keep])
    A = np.vstack([lx, np.ones_like(lx)]).T
    (b, la), *_ = np.linalg.lstsq(A, ly, rcond=None)
    out["exponent"] = float(b)
    out["prefactor"] = float(np.exp(la))
    sx, sy = np.std(lx), np.std(ly)
    if sx > 0 and sy > 1e-12 * max(1.0, np.max(np.abs(ly))):
        out["r"] = float(np.mean((lx - lx.mean()) * (ly - ly.mean())) / (sx * sy))
        if n == 2:  # a line passes through any two points: |r| = 1 says nothing of a power law
            out["note"] = "2 points: the exponent is the slope between them, no test of a power law (r = +-1 always)"
    return out


def local_exponent(x, y):
    """Local power-law exponent ``d ln|y| / d ln x`` at each point (central differences)."""
    return np.gradient(np.log(np.abs(np.asarray(y, float))), np.log(np.asarray(x, float)))


def linear_r(x, y, mask=None) -> float:
    """Correlation coefficient of ``y`` vs ``x`` (linear, not log) on the kept points."""
    x = np.asarray(x, float).ravel()
    y = np.abs(np.asarray(y, float).ravel())
    keep = np.isfinite(x) & np.isfinite(y)
    if mask is not None:
        keep &= np.asarray(mask, bool).ravel()
    if keep.sum() < 2:
        return float("nan")
    return float(np.corrcoef(x[keep], y[keep])[0, 1])


def sweep_fits(arr, variables, quantities=QUANTITIES) -> list[dict]:
    """Power-law fits of each quantity vs each varied variable, per model (1-D sweeps)."""
    fits = []
    for m in dict.fromkeys(arr["model"].tolist()):
        sub = arr[arr["model"] == m]
        inside = ~np.isin(sub["regime"], OUTSIDE_REGIMES)
        for v in variables:
            for q in quantities:
                mask = inside if q in ("w", "F_block", "theta") else np.ones(sub.size, bool)
                f = fit_power_law(sub[v], sub[q], mask)
                f.update({"model": str(m), "quantity": q, "variable": v,
                          "x_min": float(np.min(sub[v])), "x_max": float(np.max(sub[v])),
                          "linear_r": linear_r(sub[v], sub[q], mask)})
                fits.append(f)
    return fits


#: points per axis used for the fits (a subsample of a longer axis fits the same law)
FIT_POINTS = 2000


def axis_fits(vary: dict, model, fidelity, base: Strip, material: Material = NAFION_LI, tol=None, *,
              escalate: bool = True) -> tuple[list, list]:
    """``(fits, notes)``: power-law fits along each axis of ``vary`` (name -> values, as
    :func:`ipmc_asym.studies.sweeps.sweep`), through the middle of the other axes.

    An axis of one value, or with a value <= 0, gives a note instead of a fit; an axis longer
    than :data:`FIT_POINTS` is subsampled (the same law).  ``ipmc-asym sweep`` reports these
    after its rows.
    """
    fits, notes = [], []
    for var, vals in vary.items():
        if vals.size < 2:
            notes.append(f"no fit along {var}: only {vals.size} value")
            continue
        if np.any(vals <= 0):
            notes.append(f"no fit along {var}: a power law needs values > 0 (got {vals.min():g})")
            continue
        sub = vals if vals.size <= FIT_POINTS else vals[np.linspace(0, vals.size - 1, FIT_POINTS).astype(int)]
        others = {k: v for k, v in vary.items() if k != var}
        mid = {k: float(v[v.size // 2]) for k, v in others.items()}
        strip = base.with_(**{k: x for k, x in mid.items() if k != "modulus"})
        m = material.with_(E=mid["modulus"]) if "modulus" in mid else material
        arr = sweep({var: sub}, model, fidelity, strip, m, tol, progress=False, escalate=escalate)
        for f in sweep_fits(withhold(arr), [var]):
            if others:
                f["through"] = mid
            if len(sub) < vals.size:
                f["subsample"] = len(sub)
            fits.append(f)
    return fits, notes


def scaling_fits(models=model_names(), ranges=None, fidelity="quadrature",
                 base: Strip | None = None, material: Material = NAFION_LI) -> list[dict]:
    """Fits of w, w_small, F^p (large/small), theta vs L, 2l, 2e, phi0 for each model."""
    ranges = dict(RANGES if ranges is None else ranges)
    out = []
    for var, (a, b, n) in ranges.items():
        arr = sweep({var: np.linspace(a, b, n)}, list(models), fidelity, base, material)
        out.extend(sweep_fits(arr, [var]))
    return out


def variation_table(fits: list[dict], model="constant") -> dict:
    """The paper's table regenerated: quantity -> variable -> fitted exponent (one model).

    For L and e the small-displacement w (``w_small``) and F (``F_block_small``) give the
    exact scaling; the large-displacement fits are in ``fits`` too.
    """
    tab = {}
    for q, src in (("theta", "theta"), ("F_block", "F_block_small"), ("w", "w_small"),
                   ("w (large)", "w"), ("F_block (large)", "F_block")):
        tab[q] = {}
        for f in fits:
            if f["model"] == model and f["quantity"] == src and f["variable"] in ("length", "width", "thickness"):
                tab[q][f["variable"]] = f["exponent"]
    return tab
