"""The paper's figures (seed Figs 4-10) regenerated: ``ipmc-asym figures --out figures/``.

* ``profile_{C,phi,D,p}.png`` (Figs 4-7) and ``profile_{E,rhoZ}.png``: full BVP at nominal,
  full thickness + log zooms at each electrode (:mod:`ipmc_asym.studies.profiles`);
* ``influence_length.png`` (Fig 8), ``influence_thickness.png`` (Fig 9),
  ``influence_voltage.png`` (Fig 10), ``influence_width.png``: deflection, blocking force and
  rotation, three models overlaid; each curve dotted where a model assumption that concerns it
  fails (the rule of ``forward.model.FLAGS``, as in ``estimate``: the free strip past a quarter
  turn for w and theta, the strain limit for every mechanical output), empty only where withheld;
* ``speed_accuracy.png`` from a bench result (:func:`ipmc_asym.plotting.speed.plot_speed_accuracy`)
  when one is given or can be measured.

All matplotlib code lives in :mod:`ipmc_asym.plotting`.
"""

from __future__ import annotations

import os

import numpy as np

from ipmc_asym.base.registry import model_names
from ipmc_asym.forward.model import flag_mask
from ipmc_asym.model.params import NAFION_LI, Material, Strip
from ipmc_asym.plotting import COLUMN_WIDTH_IN, MODEL_COLOURS, MODEL_MARKERS, check_figure_format, model_style, print_fonts, pyplot, savefig
from ipmc_asym.plotting.profiles import write_all
from ipmc_asym.plotting.speed import plot_speed_accuracy
from ipmc_asym.studies.profiles import compute_all
from ipmc_asym.studies.sweeps import sweep, withhold

__all__ = ["influence_figure", "make_all", "INFLUENCE"]

MODELS3 = model_names()

#: variable -> (values SI, axis scale to display, axis label, file stem, paper fig)
INFLUENCE = {
    "length": (np.linspace(0.005, 0.04, 36), 1e2, "length $L$ (cm)", "influence_length", 8),
    "thickness": (np.linspace(50e-6, 400e-6, 36), 1e6, "TOTAL thickness $2e$ (µm)", "influence_thickness", 9),
    # dense at small voltage as well: I(phi0) changes regime around 0.1 V (Debye-Hueckel ->
    # layers); drawn on a linear axis as the paper (whose "approximately linear" is read
    # there) and on a log axis below it
    "voltage": (np.unique(np.concatenate([np.geomspace(0.01, 3.0, 60), np.linspace(0.05, 3.0, 60)])), 1.0,
                r"voltage $\varphi_0$ (V)", "influence_voltage", 10),
    "width": (np.linspace(1e-3, 10e-3, 19), 1e3, "TOTAL width $2l$ (mm)", "influence_width", None),
}

#: the three panels: (row key, small-displacement key, display factor, axis label, title)
_PANELS = (("w", "w_small", 1e3, "$|w|$ (mm)", "(a) tip deflection"),
           ("F_block", None, 1e3, r"$|F^p|$ (mN)", "(b) blocking force"),
           ("theta", None, 1.0, r"$|\theta|$ (rad)", "(c) tip rotation"))


def _si(value: float, unit: str) -> str:
    """``130 MPa`` rather than ``1.3e+08 Pa`` in a title."""
    for f, p in ((1e9, "G"), (1e6, "M"), (1e3, "k"), (1.0, "")):
        if abs(value) >= f:
            return f"{value / f:.4g} {p}{unit}"
    return f"{value:.4g} {unit}"


def influence_figure(var, path, base: Strip | None = None, material: Material = NAFION_LI, dpi=110,
                     values=None):
    """``|w|``, ``|F^p|``, ``|theta|`` against ``var`` for the three models (quadrature fidelity, escalated).

    Each model has its colour and marker.  Solid: every check of the forward model holds;
    dotted: the number is kept but a model assumption fails (the free strip past a quarter
    turn for ``w`` and ``theta``, the face strain above the material's limit for all three);
    dashed (panel a): the small-displacement deflection, eq. (13).  A thin vertical dotted
    line marks where a model's free strip reaches a quarter turn.  The voltage figure has a
    second row with a log voltage axis.
    """
    plt = pyplot()
    from matplotlib.lines import Line2D  # deferred: matplotlib is heavy and only figures need it

    vals, sc, xlabel, _stem, fig_no = INFLUENCE[var]
    vals = vals if values is None else np.asarray(values, float)
    base = Strip() if base is None else base
    arr = withhold(sweep({var: vals}, list(MODELS3), "quadrature", base, material))
    rows = 2 if var == "voltage" else 1
    # print layout: the three panels stacked, one column wide (8.5 cm); the voltage figure has a
    # second column (log voltage axis) and is a page-width figure (17 cm)
    fig, axs = plt.subplots(3, rows, figsize=(COLUMN_WIDTH_IN * rows, 5.9), dpi=dpi, squeeze=False)
    axs = axs.T  # axs[r, k]: axis row r (linear / log voltage), panel k
    ymax = [0.0, 0.0, 0.0]
    drawn = {"dotted": False, "quarter": False}
    every = max(1, len(vals) // 8)
    for m in MODELS3:
        a = arr[arr["model"] == m]
        order = np.argsort(a[var])
        a = a[order]
        x = a[var] * sc
        free_ok = a["check_beam_regime"].astype(bool)
        for k, (q, qs, fac, _lab, _t) in enumerate(_PANELS):
            y = np.abs(a[q]) * fac
            # the estimate's rule (forward.model.flag_mask): dotted where an assumption concerning q fails
            ok = ~flag_mask(lambda c: a["check_" + c], q)
            # the dotted part joins the solid one: it starts at the last point inside
            edge = ok & (np.roll(~ok, 1) | np.roll(~ok, -1))
            ys = None if qs is None else np.where(ok, np.abs(a[qs]) * fac, np.nan)
            for ax in axs[:, k]:
                ax.plot(x, np.where(ok, y, np.nan), **model_style(m, line=False, marker=True, markevery=every))
                if (~ok & np.isfinite(y)).any():
                    ax.plot(x, np.where(~ok | edge, y, np.nan), ":", color=MODEL_COLOURS[m], lw=1.3)
                    drawn["dotted"] = True
                if ys is not None:
                    # dashed, with the model's marker filled: told apart in grayscale too
                    ax.plot(x, ys, "--", color=MODEL_COLOURS[m], lw=0.8, marker=MODEL_MARKERS[m], ms=3,
                            markevery=(every // 2, every))
                if k == 0 and free_ok.any() and (~free_ok).any():
                    cross = np.flatnonzero(np.diff(free_ok.astype(int)))
                    for c in cross:
                        ax.axvline(x[c + 1], color=MODEL_COLOURS[m], lw=0.7, ls=(0, (1, 3)))
                        drawn["quarter"] = True
            # the axis holds every curve drawn, the dotted and the small-displacement ones too
            for v in (y, ys):
                if v is not None and np.any(np.isfinite(v)):
                    ymax[k] = max(ymax[k], float(np.nanmax(v)))
    for r in range(rows):
        for k, (_q, _qs, _f, lab, title) in enumerate(_PANELS):
            ax = axs[r, k]
            ax.set_ylabel(lab)
            ax.set_xlabel(xlabel)
            ax.grid(True, alpha=0.3)
            ax.set_title(title + (", log voltage axis" if r == 1 else ""), fontsize=8)
            if ymax[k] > 0:
                ax.set_ylim(0.0, 1.15 * ymax[k] if k < 2 else max(1.15 * ymax[k], 1.7))
        axs[r, 2].axhline(np.pi / 2, color="k", lw=0.6, ls="--")
    if var == "voltage":
        for ax in axs[0]:
            ax.set_xlim(0.0, None)
        for ax in axs[1]:
            ax.set_xscale("log")
    # legend entries only for what is drawn (a handle's style is that of its curves)
    handles = [Line2D([], [], label=m, **model_style(m, line=False, marker=True)) for m in MODELS3]
    handles += [Line2D([], [], color="0.35", ls="--", lw=0.8, label="small displacement, eq. (13)")]
    if drawn["dotted"]:
        handles.append(Line2D([], [], color="0.35", ls=":", lw=1.3, label="model assumption fails (kept)"))
    if drawn["quarter"]:
        handles.append(Line2D([], [], color="0.35", ls=(0, (1, 3)), lw=0.7, label="free strip at a quarter turn"))
    handles.append(Line2D([], [], color="k", ls="--", lw=0.6, label="θ = π/2 (panel c)"))
    # one legend for the figure, below the panels: never on a curve
    fig.legend(handles=handles, loc="lower center", ncol=2, fontsize=7, frameon=False)
    fixed = {"$L$": f"{base.length * 100:g} cm", "$2l$": f"{base.width * 1e3:g} mm",
             "$2e$": f"{base.thickness * 1e6:g} µm", r"$\varphi_0$": f"{base.voltage:g} V"}
    fixed.pop({"length": "$L$", "width": "$2l$", "thickness": "$2e$", "voltage": r"$\varphi_0$"}[var])
    t = f"Influence of {var}" + (f" (paper Fig. {fig_no})" if fig_no else "") + ";\nfixed " + \
        ", ".join(f"{k} = {v}" for k, v in fixed.items()) + f", $E$ = {_si(material.E, 'Pa')}"
    fig.suptitle(t, fontsize=8)
    print_fonts(fig)
    fig.tight_layout(rect=(0, 0.12, 1, 1))
    return savefig(fig, path)


def make_all(out_dir="figures", dpi=110, base: Strip | None = None, material: Material = NAFION_LI,
             quick=False, bench=None, log=None, fmt="png") -> dict:
    """Write the paper's figures (Figs 4-10) and the speed/accuracy plot: ``ipmc-asym figures``.

    Parameters
    ----------
    out_dir : str or path
        Directory of the PNG and CSV files (created if missing).
    dpi : int
        Resolution of the PNGs (and of the raster parts of a vector file).
    base : Strip, optional
        The strip the curves vary about (default: the nominal strip; lengths TOTAL).
    material : Material
    quick : bool
        Every third point of the influence curves, no speed/accuracy figure.
    bench : dict or callable, optional
        The bench result the speed/accuracy figure is drawn from (the dict of ``ipmc-asym
        bench --json``), or a function of no arguments returning one (a measurement, run at
        that step); without it the figure is skipped with a note.
    log : callable, optional
        Called with one progress line per figure (the CLI prints them on stderr).
    fmt : {"png", "pdf", "svg"}
        File format of the figures (``pdf`` and ``svg``: vector, for print).

    Returns
    -------
    dict
        ``{"files": [figure paths], "notes": [str], "layers": [layer widths per model]}``.

    Examples
    --------
    >>> import pathlib, tempfile
    >>> import ipmc_asym as ia
    >>> out = ia.figures(pathlib.Path(tempfile.mkdtemp()) / "figs", quick=True)
    >>> sorted(pathlib.Path(f).name for f in out["files"])[:3]
    ['influence_length.png', 'influence_thickness.png', 'influence_voltage.png']
    """
    log = log or (lambda msg: None)
    check_figure_format(fmt)
    n_total = 2 + len(INFLUENCE) + (0 if quick or bench is None else 1)
    step = iter(range(1, n_total + 1))
    os.makedirs(out_dir, exist_ok=True)
    base = Strip() if base is None else base
    files, notes = [], []
    log(f"[{next(step)}/{n_total}] profiles through the thickness (BVP, 3 models)")
    results = compute_all(strip=base, material=material)
    log(f"[{next(step)}/{n_total}] profile figures (Figs 4-7)")
    out = write_all(out_dir, strip=base, material=material, dpi=dpi, results=results, fmt=fmt)
    files += [f for f in out["files"] if f.endswith("." + fmt)]
    for var, spec in INFLUENCE.items():
        log(f"[{next(step)}/{n_total}] influence of {var}")
        vals = spec[0][::3] if quick else None
        p = os.path.join(out_dir, f"{spec[3]}.{fmt}")
        influence_figure(var, p, base, material, dpi, values=vals)
        files.append(p)
    if quick:
        notes.append(f"speed_accuracy.{fmt} skipped in quick mode")
    elif bench is None:
        notes.append(f"speed_accuracy.{fmt} skipped: no bench result (the `bench` command is not installed; "
                     "--bench FILE draws a saved `bench --json`)")
    else:
        measure = callable(bench)
        log(f"[{next(step)}/{n_total}] speed/accuracy " + ("(quick in-process measurement)" if measure else
                                                         "(from the saved bench)"))
        res = bench() if measure else bench
        files.append(plot_speed_accuracy(res, os.path.join(out_dir, f"speed_accuracy.{fmt}")))
    return {"files": files, "notes": notes, "layers": out["summaries"]}
