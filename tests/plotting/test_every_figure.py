"""Every figure of ``plotting/`` builds from small inputs on bare Agg figures, its axes carry units, and
every legend entry has a visible artist.

The figures are caught at :func:`ipmc_asym.plotting.savefig` (each module's name for it is swapped
for a recorder), so the test looks at the Figure objects themselves, not at PNG pixels."""

from __future__ import annotations

import os
import re
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("matplotlib")

import ipmc_asym.plotting.calibrate as p_calibrate  # noqa: E402
import ipmc_asym.plotting.charge as p_charge  # noqa: E402
import ipmc_asym.plotting.design as p_design  # noqa: E402
import ipmc_asym.plotting.figures as p_figures  # noqa: E402
import ipmc_asym.plotting.profiles as p_profiles  # noqa: E402
import ipmc_asym.plotting.speed as p_speed  # noqa: E402
import ipmc_asym.plotting.uq as p_uq  # noqa: E402
from ipmc_asym.model.params import NAFION_LI, Strip  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
MODULES = (p_calibrate, p_charge, p_design, p_figures, p_profiles, p_speed, p_uq)

#: a unit in a label: "[unit]" or "(unit)" with a unit the figures use (SI and the scaled ones)
UNIT = re.compile(r"[\[(](?:1/)?(?:mV|V|mm|µm|um|mN|N|rad|deg|ms|m|s|Hz|Ohm|Ω|C|F|Pa|1)(?![A-Za-z])[^\])]*[\])]")
#: labels of dimensionless quantities, which have no unit to show: ratios (t/tau, residual/sigma), the
#: paper's barred variables (eqs (22)-(23)), relative errors
DIMENSIONLESS = re.compile(r"^(t / τ|.*relative error.*|.*\)/(σ|weight)|.*\\bar.*|.*dimensionless.*)$", re.S)


def _carries_a_unit(text: str) -> bool:
    return bool(UNIT.search(text) or DIMENSIONLESS.match(text))


def _fit_static():
    from ipmc_asym.studies.calibrate import fit, read_data

    return fit(read_data(str(ROOT / "examples" / "fit_synthetic.csv")), "modulus", fidelity="corrected")


def _fit_dynamic(tmp):
    from ipmc_asym.dynamics.circuit import frequency_response
    from ipmc_asym.studies.calibrate_dynamic import fit_dynamic, read_file

    f = np.geomspace(1.0, 1e4, 8)
    z = frequency_response(f, material=NAFION_LI.with_(D=3e-10)).Z
    path = Path(tmp) / "spectrum.csv"
    path.write_text("f,Z_re,Z_im\n" + "".join(f"{float(a)!r},{float(b.real)!r},{float(b.imag)!r}\n"
                                              for a, b in zip(f, z)))
    return fit_dynamic([read_file(str(path))], "diffusion")


def _design():
    from ipmc_asym.studies.design import design

    return design(str(ROOT / "examples" / "design_blocking_force.toml"))


def _uq():
    from ipmc_asym.studies.uq import run_uq

    scene = {"name": "demo", "model": "constant", "voltage": "1V", "outputs": ["I", "tip_deflection"],
             "uncertain": {"thickness": {"dist": "normal", "mean": "200um", "sd": "8um"}}}
    return run_uq(scene, 64, fidelity="leading")


BENCH = {"points": 1e4, "bvp_points": 5, "targets": {"leading": {"seconds_per_point": 1e-6}},
         "results": [{"fidelity": f, "model": m, "seconds_per_point_serial": 1e-7 * (k + 1), "rel_error_max": 1e-3 / (k + 1)}
                     for k, (f, m) in enumerate([("leading", "constant"), ("exact", "linear"), ("bvp", "affine")])]}

SMALL = Strip(thickness=200e-6)
#: figure -> function of a temporary directory drawing it (small inputs)
FIGURES = {
    "charge_capacitance": lambda d: p_charge.plot_charge_capacitance(os.path.join(d, "a.png")),
    "step": lambda d: p_charge.plot_step(os.path.join(d, "b.png")),
    "bode": lambda d: p_charge.plot_bode(os.path.join(d, "c.png")),
    "influence_voltage": lambda d: p_figures.influence_figure("voltage", os.path.join(d, "v.png"),
                                                              values=np.geomspace(0.1, 5.0, 5)),
    "influence_thickness": lambda d: p_figures.influence_figure("thickness", os.path.join(d, "t.png"),
                                                                values=np.geomspace(50e-6, 800e-6, 5)),
    "profiles": lambda d: p_profiles.write_all(d, models=("constant",), strip=SMALL, quantities=("C", "phi", "D", "p")),
    "speed_accuracy": lambda d: p_speed.plot_speed_accuracy(BENCH, os.path.join(d, "s.png")),
    "fit": lambda d: p_calibrate.plot_fit(_fit_static(), os.path.join(d, "f.png")),
    "fit_dynamic": lambda d: p_calibrate.plot_fit_dynamic(_fit_dynamic(d), os.path.join(d, "g.png")),
    "design": lambda d: p_design.plot_design(_design(), os.path.join(d, "d.png")),
    "uq": lambda d: p_uq.plot_uq(_uq(), os.path.join(d, "u.png")),
}


def test_every_public_figure_function_is_listed():
    """A new figure function of plotting/ must join FIGURES (make_all draws the influence figures,
    the profiles and the speed plot listed here; write_all draws plot_profiles)."""
    drawn = {"plot_charge_capacitance", "plot_step", "plot_bode", "influence_figure", "write_all", "plot_profiles",
             "plot_speed_accuracy", "plot_fit", "plot_fit_dynamic", "plot_design", "plot_uq", "make_all"}
    public = {n for m in MODULES for n in getattr(m, "__all__", ()) if n.startswith(("plot_", "influence", "write_all",
                                                                                        "make_all"))}
    assert public <= drawn, public - drawn


@pytest.fixture
def recorded(monkeypatch):
    figs = []

    def record(fig, path, **kw):
        figs.append(fig)
        return os.fspath(path)

    for m in MODULES:
        monkeypatch.setattr(m, "savefig", record)
    return figs


def _visible(handle) -> bool:
    if not handle.get_visible():
        return False
    if hasattr(handle, "get_marker"):  # a line: a drawn line or a marker
        line = handle.get_linestyle() not in ("None", "", " ", "none") and handle.get_linewidth() > 0
        marker = handle.get_marker() not in (None, "", "None", " ", "none")
        return line or marker
    return True  # patches and collections are drawn with their face or edge


#: figures whose BVP or PNP markers take ~5-10 s: drawn in CI, not in the dev loop
_SLOW_FIGURES = ("charge_capacitance", "step")


@pytest.mark.parametrize("name", [pytest.param(n, marks=pytest.mark.slow) if n in _SLOW_FIGURES else n
                                  for n in sorted(FIGURES)])
def test_figure_builds_with_units_and_legends(name, recorded, tmp_path):
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    FIGURES[name](str(tmp_path))
    assert recorded, "no figure drawn"
    for fig in recorded:
        assert isinstance(fig, Figure)
        FigureCanvasAgg(fig).draw()  # builds on Agg, without pyplot
        for ax in fig.axes:
            if not ax.get_visible() or not ax.axison or (not ax.lines and not ax.collections and not ax.patches):
                continue
            cbar = getattr(ax, "_colorbar", None)
            if cbar is not None:  # a colorbar: its long axis names the colour
                text = ax.get_ylabel() if cbar.orientation == "vertical" else ax.get_xlabel()
                assert _carries_a_unit(text), (name, "colorbar", text)
                continue
            for axis, text in (("x", ax.get_xlabel()), ("y", ax.get_ylabel())):
                if not text:  # a shared axis is labelled on one of its siblings
                    shared = getattr(ax, f"get_shared_{axis}_axes")().get_siblings(ax)
                    text = next((t for a in shared if (t := getattr(a, f"get_{axis}label")())), "")
                assert _carries_a_unit(text), (name, axis, text)
            if ax.get_legend() is not None:
                _check_legend(name, ax.get_legend())
        for leg in fig.legends:
            _check_legend(name, leg)


def _check_legend(name, leg):
    """Each entry's handle box (one DrawingArea per entry) holds at least one visible artist (an
    errorbar's entry is a line without a marker plus a marker artist: any of them counts)."""
    from matplotlib.offsetbox import DrawingArea

    boxes = leg.findobj(DrawingArea)
    texts = [t.get_text() for t in leg.get_texts()]
    assert len(boxes) == len(texts), (name, texts)
    for box, text in zip(boxes, texts):
        assert any(_visible(a) for a in box.get_children()), (name, text)
