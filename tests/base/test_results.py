"""Every public result type: a one-screen summary with units, ``.plot()`` (a bare Figure whose axes
carry units) and ``.to_xarray()`` (units and long names of the output vocabulary, the result's own
values)."""

from __future__ import annotations

import dataclasses
import functools
import os
import tempfile

import numpy as np
import pytest

import ipmc_asym as ia
from ipmc_asym.base.quantities import BY_NAME, QUANTITIES

xr = pytest.importorskip("xarray")
pytest.importorskip("matplotlib")

#: every label a figure of a result may carry: "long name [unit]", "|long name| [unit]" of the vocabulary
LABELS = {f"{q.long_name} [{q.unit}]" for q in QUANTITIES if q.unit} | {
    f"|{q.long_name}| [{q.unit}]" for q in QUANTITIES if q.unit}


def _fit():
    path = os.path.join(tempfile.mkdtemp(), "data.csv")
    with open(path, "w") as fh:
        fh.write("voltage,deflection\n0.5V,1.0mm\n1V,2.1mm\n1.5V,2.9mm\n")
    return ia.fit(ia.read_fit_data(path), "modulus", fidelity="corrected")


def _uq():
    scene = {"name": "demo", "model": "constant", "voltage": "1V", "outputs": ["I", "tip_deflection"],
             "uncertain": {"thickness": {"dist": "normal", "mean": "200um", "sd": "8um"}}}
    return ia.uq(scene, 64, fidelity="leading")


def _design():
    return ia.design({"strip": {"width": "5mm", "voltage": "1V"},
                      "vary": {"length": ["1cm", "4cm"], "thickness": ["100um", "400um"]},
                      "objective": {"maximize": "blocking_force"},
                      "constraints": {"tip_deflection": {"min": "2mm"}}})


def _forward():
    from ipmc_asym.forward.model import forward

    return forward(0.02, 5e-3, np.array([100e-6, 200e-6, 400e-6]), 1.0, fidelity="corrected")


BUILDERS = {
    "MomentResult": lambda: ia.moment(np.array([100e-6, 200e-6, 400e-6]), 1.0),
    "BVPResult": lambda: ia.solve_bvp_profile(ia.NOMINAL_STRIP, "constant"),
    "BeamResult": lambda: ia.solve_beam(np.array([1e-5, 1e-4, 1e-3]), 0.02, 1e-6, e=1e-4),
    "ForwardResult": _forward,
    "ChargeResult": lambda: ia.charge(np.array([100e-6, 200e-6]), np.array([0.5, 1.0])),
    "SenseResult": lambda: ia.sense(ia.NOMINAL_STRIP, tip_displacement=np.array([-1e-3, 0.0, 1e-3])),
    "StepResult": lambda: ia.step_response(1.0, points=40),
    "FrequencyResult": lambda: ia.frequency_response(np.geomspace(0.1, 1e3, 9)),
    "LineResult": lambda: ia.line_response(np.geomspace(0.1, 1e3, 9), sheet_resistance=2.5),
    "RationalModel": lambda: ia.transfer_function(0.01, 1000.0, model="constant"),
    "CalibrationResult": _fit,
    "UQResult": _uq,
    "DesignResult": _design,
}


@functools.cache
def _built(name):
    return BUILDERS[name]()


@pytest.fixture(scope="module", params=sorted(BUILDERS))
def result(request):
    r = _built(request.param)
    assert type(r).__name__ == request.param and isinstance(r, getattr(ia, request.param))
    return r


def test_every_public_result_type_is_covered():
    public = {n for n in ia.__all__ if n.endswith("Result") or n == "RationalModel"}
    assert public == set(BUILDERS)


def test_summary_fits_a_screen_and_names_units(result):
    text = repr(result)
    lines = text.splitlines()
    assert lines[0].startswith(type(result).__name__) and len(lines) <= 40
    assert all(len(line) <= 240 for line in lines)
    units = {BY_NAME[n].unit for n in result.to_xarray().data_vars} - {"", "1"}
    assert not units or any(f"[{u}]" in text for u in units)


def test_plot_is_a_bare_figure_with_units_on_its_axes(result):
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = result.plot()
    assert isinstance(fig, Figure) and isinstance(fig.canvas, FigureCanvasAgg)
    assert fig.axes
    for ax in fig.axes:
        assert ax.get_xlabel() in LABELS, ax.get_xlabel()
        # wrapped to the panel's height, an equation's spaces non-breaking
        assert ax.get_ylabel().replace("\n", " ").replace("\u00a0", " ") in LABELS, ax.get_ylabel()
        assert ax.lines or ax.patches
        leg = ax.get_legend()
        if leg is not None:
            assert all(h.get_visible() for h in leg.legend_handles)
    fig.canvas.draw()


def test_dataset_carries_the_vocabulary_and_the_result_values(result):
    ds = result.to_xarray()
    assert ds.data_vars
    for name, var in {**ds.data_vars, **ds.coords}.items():
        q = BY_NAME[name]
        assert (var.attrs["units"], var.attrs["long_name"]) == (q.unit, q.long_name), name
    spec = type(result)._result
    for f in spec.fields:
        head, _, key = f.partition(".")
        v = getattr(result, head)
        v = v[key] if key else v
        if v is None:
            continue
        got, want = ds[spec.names.get(f, f)].values, np.asarray(v)
        if want.dtype.kind in "fcb":
            np.testing.assert_array_equal(got, want)
        else:
            assert list(got.reshape(-1)) == [str(x) for x in want.reshape(-1)]
    if spec.coord is not None:
        np.testing.assert_array_equal(ds[spec.dim].values, getattr(result, spec.coord))


def test_dataset_values_of_the_study_results():
    fit = _built("CalibrationResult")
    ds = fit.to_xarray()
    np.testing.assert_allclose(ds["measured_deflection"].values, [1.0e-3, 2.1e-3, 2.9e-3], rtol=1e-15)
    np.testing.assert_array_equal(ds["measured_deflection"].values, fit.data.measured["deflection"])
    np.testing.assert_array_equal(ds["voltage"].values, [0.5, 1.0, 1.5])
    assert float(ds["modulus"]) == fit.parameters["modulus"]["value"]
    u = _built("UQResult")
    du = u.to_xarray()
    np.testing.assert_array_equal(du["tip_deflection"].values, u.outputs["tip_deflection"])
    np.testing.assert_array_equal(du["thickness"].values, u.samples["thickness"])
    df = u.to_dataframe()
    assert len(df) == u.n_stored and df.attrs["units"]["thickness"] == "m"
    tf = _built("RationalModel")
    dt = tf.to_xarray()
    np.testing.assert_array_equal(dt["H_w"].values, tf(dt["f"].values))
    assert dt["f"].values[0] == tf.band[0] and dt["f"].values[-1] == pytest.approx(tf.band[1], rel=1e-14)
    d = _built("DesignResult")
    dd = d.to_xarray()
    assert float(dd["blocking_force"].values[0]) == d.optimum["outputs"]["blocking_force"]
    assert float(dd["length"].values[0]) == d.optimum["inputs"]["length"]


def test_moment_points_are_labelled_by_their_inputs():
    """The inputs are coordinates: a point picked by thickness and voltage holds the moment that a
    call at that point alone gives (a different evaluation, one point)."""
    th = np.array([[100e-6], [300e-6]])
    v = np.array([-1.0, 0.5, 2.0])
    ds = ia.moment(th, v).to_xarray()
    assert set(ds.coords) >= {"thickness", "voltage"} and "thickness" not in ds.data_vars
    assert ds["thickness"].attrs["units"] == "m" and ds["voltage"].attrs["units"] == "V"
    assert ds["thickness"].shape == ds["I"].shape == (2, 3)
    i, j = 1, 0
    one = ia.moment(float(ds["thickness"].values[i, j]), float(ds["voltage"].values[i, j]))
    assert (float(ds["thickness"].values[i, j]), float(ds["voltage"].values[i, j])) == (300e-6, -1.0)
    assert float(ds["I"].values[i, j]) == pytest.approx(float(one.I), rel=1e-13)
    flat = ia.moment(np.array([100e-6, 200e-6]), 1.0).to_xarray().swap_dims(point="thickness")
    assert float(flat["I"].sel(thickness=200e-6)) == pytest.approx(float(ia.moment(200e-6, 1.0).I), rel=1e-13)


def test_numbered_points_are_plotted_against_the_input_that_varies():
    """moment and charge over an unsorted thickness array: the x axis is the thickness (total 2e),
    the line through the points in its order."""
    th = np.array([400e-6, 100e-6, 200e-6])
    for r in (ia.moment(th, 1.0), ia.charge(th, 1.0)):
        ax = r.plot().axes[0]
        assert ax.get_xlabel() == "total thickness 2e [m]"
        x, y = ax.lines[0].get_data()
        np.testing.assert_array_equal(x, np.sort(th))
        first = np.asarray(getattr(r, "I" if hasattr(r, "I") else "sigma"))
        np.testing.assert_array_equal(y, first[np.argsort(th)])
    assert "thickness (total 2e)" in repr(ia.moment(th, 1.0))


def test_tabular_results_as_dataframes():
    s = _built("StepResult")
    df = s.to_dataframe()
    assert len(df) == s.t.size and df.index.name == "t"
    np.testing.assert_array_equal(df["sigma"].to_numpy(), s.sigma)
    assert df.attrs["units"]["sigma"] == "C/m^2"


def test_results_keep_their_fields():
    """The mixin adds no dataclass field (as_dict, asdict and the JSON read the same fields)."""
    names = {f.name for f in dataclasses.fields(ia.StepResult)}
    assert "_result" not in names and "t" in names
