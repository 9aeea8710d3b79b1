"""Labelled datasets: structure, units, and a NetCDF round trip through xarray.open_dataset."""

import json
import os
from pathlib import Path

import numpy as np
import pytest

xr = pytest.importorskip("xarray")

from ipmc_asym.io.datasets import available_engines, netcdf_engine, sweep_dataset, uq_dataset, write_netcdf  # noqa: E402
from ipmc_asym.model.params import NAFION_LI, Strip  # noqa: E402
from ipmc_asym.studies.sweeps import sweep  # noqa: E402


@pytest.mark.parametrize("engine", available_engines())
def test_sweep_round_trip(tmp_path, engine):
    vary = {"thickness": np.array([100e-6, 200e-6, 300e-6]), "voltage": np.array([0.5, 1.0])}
    arr = sweep(vary, model="all", fidelity="corrected", progress=False)
    ds = sweep_dataset(arr, vary, base=Strip(), material=NAFION_LI)
    assert ds["w"].dims == ("model", "thickness", "voltage")
    assert ds["thickness"].attrs["long_name"] == "total thickness 2e"
    assert ds["w"].attrs["units"] == "m"
    # the grid is labelled correctly: the row of (affine, 300um, 0.5V) is that point
    row = arr[(arr["model"] == "affine") & (arr["thickness"] == 300e-6) & (arr["voltage"] == 0.5)][0]
    assert float(ds["I"].sel(model="affine", thickness=300e-6, voltage=0.5)) == row["I"]
    p = tmp_path / "s.nc"
    write_netcdf(ds, p, engine=engine)
    back = xr.open_dataset(p, engine=engine)
    try:
        for k in ("I", "w", "F_block", "error"):
            np.testing.assert_array_equal(back[k].values, ds[k].values)
        assert back["thickness"].attrs["long_name"] == "total thickness 2e"
        assert back.attrs["model"] == "constant,linear,affine"
        assert back.attrs["fidelity"] == "corrected"
        assert json.loads(back.attrs["material"])["E"] == NAFION_LI.E
        assert back.attrs["package_version"]
    finally:
        back.close()
    assert [f for f in os.listdir(tmp_path) if f.endswith(".part")] == []


def test_uq_round_trip(tmp_path):
    from ipmc_asym.studies.uq import run_uq

    sc = {"name": "t", "voltage": "1V", "tolerance": 1e-2, "outputs": ["I", "rotation"],
          "uncertain": {"thickness": {"dist": "normal", "mean": "200um", "sd": "5um"},
                        "modulus": {"dist": "uniform", "low": "100MPa", "high": "150MPa"}}}
    r = run_uq(sc, 512)
    ds = uq_dataset(r)
    p = tmp_path / "u.nc"
    write_netcdf(ds, p)
    with xr.open_dataset(p) as back:
        np.testing.assert_array_equal(back["rotation"].values, r.outputs["rotation"])
        np.testing.assert_array_equal(back["thickness"].values, r.samples["thickness"])
        assert back["thickness"].attrs["long_name"] == "total thickness 2e"
        assert float(back["ST"].sel(output="I", parameter="modulus")) == 0.0  # I does not see E
        assert back.attrs["kind"] == "uq"


def test_write_refuses_bad_path_and_leaves_nothing(tmp_path, monkeypatch):
    vary = {"voltage": np.array([1.0])}
    ds = sweep_dataset(sweep(vary, fidelity="leading", progress=False), vary)
    with pytest.raises(ValueError, match="does not exist"):
        write_netcdf(ds, tmp_path / "nope" / "x.nc")

    class Boom(Exception):
        pass

    def bad(self, path, *a, **k):
        Path(path).write_bytes(b"partial")  # a writer that dies half-way
        raise Boom

    monkeypatch.setattr(xr.Dataset, "to_netcdf", bad)  # an error during the write: no file, no temp file
    with pytest.raises(Boom):
        write_netcdf(ds, tmp_path / "x.nc")
    assert os.listdir(tmp_path) == []
    assert netcdf_engine() in ("netcdf4", "h5netcdf", "scipy")
