"""Parameter sweeps on a grid (``ipmc-asym sweep``), vectorised end to end.

``sweep({"length": np.linspace(0.01, 0.04, 16)}, model="constant")`` returns a numpy
structured array with one row per grid point (and per model), SI columns::

    length width thickness voltage modulus  (inputs; width/thickness are TOTAL 2l / 2e)
    model fidelity I M_A theta w w_small F_block F_block_small regime B1 error valid

``I`` comes from the vectorised :func:`ipmc_asym.integral.moment` (one call per model for the
whole grid) and the mechanics from the vectorised :func:`ipmc_asym.beam.solve_beam`; nothing
loops over points in Python except the ``bvp`` fidelity.

CLI spec: ``--vary NAME=START:STOP:N`` (N points, linear) or ``NAME=START:STOP:N:log``;
NAME in length, width, thickness, voltage, modulus; units as in ``estimate``
(``1cm``, ``200um``, ``500mV``, ``130MPa``).  Several ``--vary`` make a grid.

Layer rule: stdlib + numpy at import.
"""

from __future__ import annotations

import csv
import sys

import numpy as np

from .beam import solve_beam
from .fileio import atomic_write
from .integral import check_fidelity, moment
from .params import NAFION_LI, Material, Strip, moment_scale, second_moment
from .permittivity import get_model
from .progress import progress as progress_bar
from .registry import model_names
from .settings import OUTSIDE_REGIMES
from .units import parse_length, parse_pressure, parse_voltage

__all__ = ["VARIABLES", "DTYPE", "parse_vary", "sweep", "write_csv", "rows_as_dicts"]

VARIABLES = ("length", "width", "thickness", "voltage", "modulus")

_FLOAT_COLS = ("length", "width", "thickness", "voltage", "modulus", "I", "M_A", "theta", "w", "w_small",
               "F_block", "F_block_small", "B1", "error")
DTYPE = np.dtype([(c, "f8") for c in _FLOAT_COLS[:5]] + [("model", "U8"), ("fidelity", "U10")]
                 + [(c, "f8") for c in _FLOAT_COLS[5:]] + [("regime", "U17"), ("valid", "?")])
OUTSIDE = OUTSIDE_REGIMES


def _parse_value(name, text):
    if name in ("length", "width", "thickness"):
        return parse_length(name, text)
    if name == "voltage":
        return parse_voltage(name, text)
    return parse_pressure(name, text)


def parse_vary(spec: str):
    """``'length=1cm:4cm:16'`` -> ``("length", array)``; ``':log'`` suffix for log spacing."""
    if "=" not in spec:
        raise ValueError(f"--vary must be NAME=START:STOP:N[:log]; got {spec!r}")
    name, rng = spec.split("=", 1)
    name = name.strip()
    if name not in VARIABLES:
        raise ValueError(f"--vary name must be one of {', '.join(VARIABLES)}; got {name!r}")
    parts = rng.split(":")
    log = False
    if len(parts) == 4 and parts[3].strip().lower() in ("log", "lin"):
        log = parts[3].strip().lower() == "log"
        parts = parts[:3]
    if len(parts) != 3:
        raise ValueError(f"--vary {name}: expected START:STOP:N[:log]; got {rng!r}")
    a = _parse_value(name, parts[0])
    b = _parse_value(name, parts[1])
    try:
        n = int(parts[2])
    except ValueError:
        raise ValueError(f"--vary {name}: N must be an integer >= 1; got {parts[2]!r}") from None
    if n < 1:
        raise ValueError(f"--vary {name}: N must be an integer >= 1; got {n}")
    if log:
        if a <= 0 or b <= 0:
            raise ValueError(f"--vary {name}: log spacing needs START, STOP > 0")
        vals = np.geomspace(a, b, n)
    else:
        vals = np.linspace(a, b, n)
    if name != "voltage" and np.any(vals <= 0):
        raise ValueError(f"--vary {name}: values must be > 0")
    return name, vals


def _models(model):
    if model == "all":
        return list(model_names())
    if isinstance(model, (list, tuple)):
        return list(model)
    return [model]


def sweep(vary: dict, model="constant", fidelity="quadrature", base: Strip | None = None,
          material: Material = NAFION_LI, tol=None, progress: bool | None = None) -> np.ndarray:
    """Evaluate the strip on the grid spanned by ``vary`` (name -> 1-D values, SI).

    Parameters
    ----------
    vary : dict
        Keys among :data:`VARIABLES`; each value a 1-D array.  The grid is their outer
        product (first key slowest).  Variables not in ``vary`` take ``base`` / ``material``.
    model : str, list of str or "all"
    fidelity : {"leading", "corrected", "quadrature", "bvp"}
    base : Strip, default nominal
    material : Material (``modulus`` overrides ``material.E``)
    tol : float, optional   tolerance of the "small" beam regime (default 1 %)

    Returns
    -------
    numpy structured array (dtype :data:`DTYPE`), one row per grid point and model.
    """
    check_fidelity(fidelity)
    base = Strip() if base is None else base
    for k in vary:
        if k not in VARIABLES:
            raise ValueError(f"vary: unknown variable {k!r}; use {', '.join(VARIABLES)}")
    axes = [np.atleast_1d(np.asarray(v, dtype=float)).ravel() for v in vary.values()]
    grids = np.meshgrid(*axes, indexing="ij") if axes else []
    cols = {
        "length": base.length, "width": base.width, "thickness": base.thickness,
        "voltage": base.voltage, "modulus": material.E,
    }
    for k, g in zip(vary, grids):
        cols[k] = g.ravel()
    n = int(np.prod([a.size for a in axes])) if axes else 1
    for k in cols:
        cols[k] = np.broadcast_to(np.asarray(cols[k], dtype=float), (n,)).copy()
    for k in ("length", "width", "thickness", "modulus"):
        if np.any(~np.isfinite(cols[k])) or np.any(cols[k] <= 0):
            raise ValueError(f"{k} must be finite and > 0")
    mats = material
    C_moy = mats.C_moy
    A5 = moment_scale(cols["width"], cols["thickness"], cols["voltage"], mats.F, C_moy)
    EI = cols["modulus"] * second_moment(cols["width"], cols["thickness"])
    out_parts = []
    models = _models(model)
    show = (n * len(models) > 20000 or fidelity == "bvp") if progress is None else progress
    bar = progress_bar(len(models), "sweep", enabled=show and fidelity != "bvp", unit="model")
    for m in models:
        perm = get_model(m)
        # I depends on (thickness, voltage) only: evaluate each distinct pair once
        tv = np.stack([cols["thickness"], cols["voltage"]], axis=1)
        uniq, inv = np.unique(tv, axis=0, return_inverse=True)
        inv = np.asarray(inv).reshape(-1)
        r = moment(uniq[:, 0], uniq[:, 1], perm, fidelity, material=mats,
                   progress=(show if fidelity == "bvp" else False))
        I = np.asarray(r.I, dtype=float)[inv]
        M = A5 * I
        with np.errstate(all="ignore"):
            b = solve_beam(M, cols["length"], EI, tol=tol)
        arr = np.empty(n, dtype=DTYPE)
        for k in ("length", "width", "thickness", "voltage", "modulus"):
            arr[k] = cols[k]
        arr["model"] = perm.name
        arr["fidelity"] = fidelity
        arr["I"] = I
        arr["M_A"] = M
        for k in ("theta", "w", "w_small", "F_block", "F_block_small"):
            arr[k] = np.broadcast_to(np.asarray(getattr(b, k), dtype=float), (n,))
        arr["regime"] = np.broadcast_to(np.asarray(b.regime), (n,))
        arr["B1"] = np.asarray(r.B1)[inv]
        arr["error"] = np.asarray(r.error)[inv]
        arr["valid"] = np.asarray(r.valid)[inv]
        out_parts.append(arr)
        bar.update(1)
    bar.close()
    return np.concatenate(out_parts)


def rows_as_dicts(arr: np.ndarray) -> list[dict]:
    """JSON-ready rows (NaN -> None)."""
    out = []
    names = arr.dtype.names
    for rec in arr:
        d = {}
        for k in names:
            v = rec[k]
            if isinstance(v, (np.floating, float)):
                v = float(v)
                d[k] = v if np.isfinite(v) else None
            elif isinstance(v, (np.bool_, bool)):
                d[k] = bool(v)
            else:
                d[k] = str(v)
        out.append(d)
    return out


def write_csv(arr: np.ndarray, path):
    """CSV with SI columns (header = field names)."""
    def rows(fh):
        wr = csv.writer(fh)
        wr.writerow(arr.dtype.names)
        for rec in arr:
            wr.writerow([f"{v:.10g}" if isinstance(v, (np.floating, float)) else
                         (str(bool(v)) if isinstance(v, np.bool_) else str(v)) for v in rec.tolist()])

    if path in (None, "-"):
        rows(sys.stdout)
    else:
        with atomic_write(path) as fh:
            rows(fh)
