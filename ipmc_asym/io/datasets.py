"""Labelled results: xarray Datasets of sweeps and UQ runs, written atomically to NetCDF.

Coordinates are the varied parameters, data variables the outputs, each with ``units`` and
``long_name`` (thickness: "total thickness 2e"); the strip, material, model, fidelity and
package version are attributes (dicts as JSON strings: NetCDF attributes are flat).

NetCDF engine: the first importable of ``netCDF4``, ``h5netcdf``, ``scipy`` (NetCDF-3,
always present with SciPy, a core dependency); the ``netcdf`` extra installs ``netCDF4``
for NetCDF-4 files.  :func:`write_netcdf` writes a temporary file beside the target and
renames it on success (:func:`ipmc_asym.io.fileio.atomic_path`): Ctrl-C leaves no partial file.

Layer rule: stdlib + numpy at import; xarray deferred (heavy import, start-up).
"""

from __future__ import annotations

import dataclasses
import errno
import importlib.util
import json

import numpy as np

from ipmc_asym import __version__
from ipmc_asym.base.quantities import BY_NAME
from ipmc_asym.io.fileio import atomic_path, check_output_path

__all__ = ["VARIABLES", "sweep_dataset", "uq_dataset", "netcdf_engine", "available_engines", "write_netcdf"]

#: name -> (units, long_name) of every coordinate and output the builders know (the vocabulary)
VARIABLES = {name: (q.unit, q.long_name) for name, q in BY_NAME.items()}
_SWEEP_OUT = ("I", "M_A", "theta", "w", "w_small", "F_block", "F_block_small", "B1", "error", "max_strain",
              "fidelity_used", "escalated", "regime", "check_electrochemistry", "check_layer_separation",
              "check_beam_regime", "check_blocked_regime", "check_strain", "check_voltage", "check_slender",
              "valid")


def _label(da, name):
    u, ln = VARIABLES.get(name, ("", name))
    da.attrs.update(units=u, long_name=ln)
    return da


def _common_attrs(model, fidelity, strip=None, material=None, extra=None) -> dict:

    def js(o):
        if o is None:
            return "null"
        if dataclasses.is_dataclass(o):
            d = dataclasses.asdict(o)
            if hasattr(o, "C_moy"):
                d["C_moy_value"] = o.C_moy
            return json.dumps(d, default=str)
        return json.dumps(o, default=str)

    a = {"model": str(model), "fidelity": str(fidelity), "package": "ipmc_asym",
         "package_version": __version__, "strip": js(strip), "material": js(material),
         "thickness_convention": "thickness is the TOTAL thickness 2e; width the TOTAL width 2l"}
    for k, v in (extra or {}).items():
        a[k] = v if isinstance(v, (int, float, str)) else js(v)
    return a


def sweep_dataset(arr: np.ndarray, vary: dict, *, base=None, material=None):
    """Dataset of a sweep (:func:`ipmc_asym.studies.sweeps.sweep` rows) on its grid.

    Parameters
    ----------
    arr : structured ndarray
        Rows model-major, then the grid of ``vary`` in C order (first key slowest).
    vary : dict
        name -> 1-D values (SI), the axes of the grid, in the order of the sweep.
    base, material : Strip, Material (attributes)

    Returns
    -------
    xarray.Dataset
        Dims ``model`` and the varied names; coordinates labelled; outputs as data variables.
    """
    import xarray as xr  # deferred: heavy import (start-up)

    names = list(vary)
    axes = [np.atleast_1d(np.asarray(vary[k], float)) for k in names]
    shape = tuple(a.size for a in axes)
    models = list(dict.fromkeys(arr["model"].tolist()))
    npts = int(np.prod(shape)) if shape else 1
    if arr.size != npts * len(models):
        raise ValueError(f"sweep_dataset: {arr.size} rows do not fill {len(models)} model(s) x grid {shape}")
    fids = sorted(set(arr["fidelity"].tolist()))
    coords = {"model": ("model", np.array(models))}
    for k, a in zip(names, axes):
        coords[k] = _label(xr.DataArray(a, dims=(k,)), k)
    dv = {}
    for k in _SWEEP_OUT:
        if k not in arr.dtype.names:
            continue
        col = arr[k]
        if col.dtype == bool:
            col = col.astype(np.int8)
        dv[k] = _label(xr.DataArray(col.reshape((len(models),) + shape), dims=("model",) + tuple(names)), k)
    fixed = [k for k in ("length", "width", "thickness", "voltage", "modulus") if k not in names]
    for k in fixed:  # constant inputs: scalar variables with units
        dv[k] = _label(xr.DataArray(float(arr[k][0])), k)
    ds = xr.Dataset(dv, coords=coords)
    ds.attrs.update(_common_attrs(",".join(models), ",".join(fids), base, material,
                                  {"kind": "sweep", "varied": ",".join(names)}))
    return ds


def uq_dataset(result):
    """Dataset of a :class:`ipmc_asym.studies.uq.UQResult`.

    Dim ``sample``: the uncertain inputs are coordinates along it, the outputs data
    variables (the runs kept per sample: ``n_samples_stored`` of ``n_samples``, the first
    whole Saltelli groups); ``S1``, ``S1_conf``, ``ST``, ``ST_conf`` on (``output``,
    ``parameter``); ``quantile_value`` on (``output``, ``quantile``) with its guaranteed
    interval ``quantile_low``, ``quantile_high`` and ``quantile_rank_error`` on ``output``
    when the result has them; ``mean``, ``sd`` on ``output``.
    """
    import xarray as xr  # deferred: heavy import (start-up)

    outs = list(result.outputs)
    pars = list(result.samples)
    coords = {k: _label(xr.DataArray(v, dims=("sample",)), k) for k, v in result.samples.items()}
    coords["output"] = ("output", np.array(outs))
    coords["parameter"] = ("parameter", np.array(pars))
    coords["quantile"] = _label(xr.DataArray(np.array([0.025, 0.5, 0.975]), dims=("quantile",)), "quantile")
    coords["quantile"].attrs.update(units="1", long_name="probability level")
    dv = {}
    for o, y in result.outputs.items():
        dv[o] = _label(xr.DataArray(y, dims=("sample",)), o)
    # the forward model's checks per sample (1 passed, 0 failed) and their conjunction
    for c, ok in getattr(result, "checks", {}).items():
        dv["check_" + c] = _label(xr.DataArray(np.asarray(ok, np.int8), dims=("sample",)), "check_" + c)
    if getattr(result, "valid", None) is not None:
        dv["valid"] = _label(xr.DataArray(np.asarray(result.valid, np.int8), dims=("sample",)), "valid")
    for key in ("S1", "S1_conf", "ST", "ST_conf"):
        a = np.full((len(outs), len(pars)), np.nan)
        for i, o in enumerate(outs):
            if result.sobol.get(o):
                a[i] = [result.sobol[o][p][key] for p in pars]
        what = "first-order" if key.startswith("S1") else "total"
        ln = f"Sobol' {what} index" + (" (95 % interval half-width)" if key.endswith("conf") else "")
        dv[key] = xr.DataArray(a, dims=("output", "parameter"), attrs={"units": "1", "long_name": ln})
    q = np.array([[result.summary[o][k] for k in ("q2.5", "q50", "q97.5")] for o in outs])
    dv["quantile_value"] = xr.DataArray(q, dims=("output", "quantile"),
                                        attrs={"units": "see output_units", "long_name": "quantile of each output"})
    if all("q50_interval" in result.summary[o] for o in outs):
        for i, k in enumerate(("quantile_low", "quantile_high")):
            a = np.array([[result.summary[o][q + "_interval"][i] for q in ("q2.5", "q50", "q97.5")] for o in outs])
            dv[k] = xr.DataArray(a, dims=("output", "quantile"),
                                 attrs={"units": "see output_units",
                                        "long_name": f"{k.split('_')[1]} end of the interval holding the exact "
                                                     "sample quantile"})
        dv["quantile_rank_error"] = xr.DataArray([result.summary[o]["quantile_rank_error"] for o in outs],
                                                 dims=("output",),
                                                 attrs={"units": "1", "long_name": "bound on the rank error of the "
                                                                                   "quantiles (fraction of n)"})
    for k in ("mean", "sd"):
        dv[k] = xr.DataArray([result.summary[o][k] for o in outs], dims=("output",),
                             attrs={"units": "see output_units", "long_name": f"{k} of each output"})
    dv["output_units"] = xr.DataArray(np.array([VARIABLES.get(o, ("", ""))[0] or "1" for o in outs]),
                                      dims=("output",), attrs={"long_name": "units of each output"})
    ds = xr.Dataset(dv, coords=coords)
    ds.attrs.update(_common_attrs(result.model, json.dumps(result.fidelity), None, result.material,
                                  {"kind": "uq", "scene": result.scene, "tolerance": result.tolerance,
                                   "n_samples": result.n_samples, "base_n": result.base_n,
                                   "n_samples_stored": getattr(result, "n_stored", result.n_samples),
                                   "n_outside_model": getattr(result, "n_outside", 0),
                                   "keep_invalid": int(getattr(result, "keep_invalid", False)),
                                   "n_used": getattr(result, "n_used", result.n_samples),
                                   "n_sobol_base_points": getattr(result, "n_sobol", result.base_n),
                                   "seed": getattr(result, "seed", 0),
                                   "nominal": result.base,
                                   "distributions": {k: [d, list(p)] for k, (d, p) in result.inputs.items()}}))
    return ds


#: engine -> modules it needs at write time (h5netcdf is useless without h5py)
_ENGINES = {"netcdf4": ("netCDF4",), "h5netcdf": ("h5netcdf", "h5py"), "scipy": ("scipy.io",)}


def available_engines() -> list:
    """Engines whose modules all import, in order of preference."""
    out = []
    for eng, mods in _ENGINES.items():
        try:
            if all(importlib.util.find_spec(m.split(".")[0]) is not None for m in mods):
                for m in mods:
                    importlib.import_module(m)
                out.append(eng)
        except ImportError:
            continue
    return out


def netcdf_engine() -> str:
    """The first working of netCDF4, h5netcdf (+h5py), scipy (NetCDF-3)."""
    for eng in available_engines():
        return eng
    raise ValueError("no NetCDF engine: install netCDF4 (pip install \".[netcdf]\") or h5netcdf")


def write_netcdf(ds, path, engine: str | None = None) -> str:
    """Write ``ds`` to ``path`` atomically (temp file + rename); returns the engine used."""
    p = check_output_path(path, what="--out", formats=(".nc",))
    eng = engine or netcdf_engine()
    with atomic_path(p) as tmp:
        try:
            ds.to_netcdf(tmp, engine=eng)
        except RuntimeError as exc:
            # the NetCDF/HDF5 libraries report a full disk or a failed write as "NetCDF: HDF
            # error", naming no file: say which file could not be written
            raise OSError(errno.EIO, f"cannot write the NetCDF file ({exc}; disk full?)", p) from None
    return eng
