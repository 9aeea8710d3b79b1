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
from ipmc_asym.plotting import MODEL_COLOURS, pyplot, savefig
from ipmc_asym.plotting.profiles import write_all
from ipmc_asym.plotting.speed import plot_speed_accuracy
from ipmc_asym.studies.profiles import compute_all
from ipmc_asym.studies.sweeps import sweep, withhold

__all__ = ["influence_figure", "make_all", "INFLUENCE"]

MODELS3 = model_names()
_COL = MODEL_COLOURS

#: variable -> (values SI, axis scale to display, axis label, file stem, paper fig)
INFLUENCE = {
    "length": (np.linspace(0.005, 0.04, 36), 1e2, "length L (cm)", "influence_length", 8),
    "thickness": (np.linspace(50e-6, 400e-6, 36), 1e6, "TOTAL thickness 2e (µm)", "influence_thickness", 9),
    # log-spaced: I(phi0) changes regime around 0.1 V (Debye-Hueckel -> layers); a linear
    # 0.05 V step drew kinks there
    "voltage": (np.geomspace(0.01, 3.0, 90), 1.0, r"voltage $\varphi_0$ (V)", "influence_voltage", 10),
    "width": (np.linspace(1e-3, 10e-3, 19), 1e3, "TOTAL width 2l (mm)", "influence_width", None),
}


def influence_figure(var, path, base: Strip | None = None, material: Material = NAFION_LI, dpi=110,
                     values=None):
    """Three panels (|w|, F^p, |theta|) vs ``var`` for the three models (quadrature fidelity)."""
    plt = pyplot()
    vals, sc, xlabel, _stem, fig_no = INFLUENCE[var]
    vals = vals if values is None else np.asarray(values, float)
    base = Strip() if base is None else base
    arr = withhold(sweep({var: vals}, list(MODELS3), "quadrature", base, material))
    fig, axs = plt.subplots(1, 3, figsize=(13, 4.0), dpi=dpi)
    handles = []
    ymax = [0.0, 0.0, 0.0]
    for m in MODELS3:
        a = arr[arr["model"] == m]
        x = a[var] * sc
        for k, (ax, q, qs, fac) in enumerate(((axs[0], "w", "w_small", 1e3),
                                              (axs[1], "F_block", "F_block_small", 1e3),
                                              (axs[2], "theta", None, 1.0))):
            # the estimate's rule (forward.model.flag_mask): dotted where an assumption concerning q fails
            out = flag_mask(lambda c: a["check_" + c], q)
            inside = ~out
            y = np.abs(a[q]) * fac
            yi = np.where(inside, y, np.nan)
            (h,) = ax.plot(x, yi, "-", color=_COL[m], label=f"{m}")
            if k == 0:
                handles.append(h)
            if np.any(np.isfinite(yi)):
                ymax[k] = max(ymax[k], float(np.nanmax(yi)))
            if out.any():
                # outside a model assumption: kept, drawn dotted (joined to the solid part)
                yo = np.where(out | np.roll(out, -1) | np.roll(out, 1), y, np.nan)
                ax.plot(x, yo, ":", color=_COL[m], alpha=0.8)
                if k == 0 and inside.any() and out.any():
                    xq = x[np.flatnonzero(out)[0]] if out[-1] else x[np.flatnonzero(out)[-1]]
                    ax.axvline(xq, color=_COL[m], lw=0.6, ls=":", alpha=0.6)
            if qs is not None and q == "w":
                # small-displacement formula: only where the strip is inside the model
                ax.plot(x, np.where(inside, np.abs(a[qs]) * fac, np.nan), "--", color=_COL[m], lw=0.8, alpha=0.6)
    for k, ax in enumerate(axs):
        if ymax[k] > 0:
            ax.set_ylim(0.0, 1.15 * ymax[k] if k < 2 else max(1.15 * ymax[k], 1.7))
    axs[0].set_ylabel("tip deflection |w| (mm)")
    axs[0].set_title("(a) deflection (dashed: small displ.; dotted: outside the model)", fontsize=9)
    axs[1].set_ylabel(r"blocking force $F^p$ (mN)")
    axs[1].set_title("(b) blocking force (large displacements)", fontsize=9)
    axs[2].set_ylabel(r"rotation $|\theta|$ (rad)")
    axs[2].axhline(np.pi / 2, color="k", lw=0.6, ls="--")
    axs[2].set_title(r"(c) rotation ($\pi/2$ dashed: quarter turn)", fontsize=9)
    for ax in axs:
        ax.set_xlabel(xlabel)
        ax.grid(True, alpha=0.3)
    if var == "voltage":
        for ax in axs:
            ax.set_xscale("log")
    # one legend for the figure, below the panels: never on a curve or the pi/2 line
    fig.legend(handles, [h.get_label() for h in handles], loc="lower center", ncol=3, fontsize=8,
               frameon=False)
    fixed = {k: v for k, v in (("L", f"{base.length * 100:g} cm"), ("2l", f"{base.width * 1e3:g} mm"),
                                ("2e", f"{base.thickness * 1e6:g} µm"), ("phi0", f"{base.voltage:g} V"))}
    var_key = {"length": "L", "width": "2l", "thickness": "2e", "voltage": "phi0"}[var]
    fixed.pop(var_key)
    t = f"Influence of {var}" + (f" (paper Fig. {fig_no})" if fig_no else "") + "; fixed " + \
        ", ".join(f"{k}={v}" for k, v in fixed.items()) + f", E={material.E:.3g} Pa"
    fig.suptitle(t, fontsize=10)
    fig.tight_layout(rect=(0, 0.06, 1, 1))
    return savefig(fig, path)


def make_all(out_dir="figures", dpi=110, base: Strip | None = None, material: Material = NAFION_LI,
             quick=False, bench=None, log=None) -> dict:
    """Write every figure; returns {"files": [...], "notes": [...], "layers": [...]}.

    Parameters
    ----------
    quick : bool
        Fewer points, no speed/accuracy figure (tests).
    bench : dict or callable, optional
        The bench result the speed/accuracy figure is drawn from (the dict of ``ipmc-asym
        bench --json``), or a function of no arguments returning one (a measurement, run at
        that step); without it the figure is skipped with a note.
    log : callable, optional
        Called with one progress line per figure (the CLI prints them on stderr).
    """
    log = log or (lambda msg: None)
    n_total = 2 + len(INFLUENCE) + (0 if quick or bench is None else 1)
    step = iter(range(1, n_total + 1))
    os.makedirs(out_dir, exist_ok=True)
    base = Strip() if base is None else base
    files, notes = [], []
    log(f"[{next(step)}/{n_total}] profiles through the thickness (BVP, 3 models)")
    results = compute_all(strip=base, material=material)
    log(f"[{next(step)}/{n_total}] profile figures (Figs 4-7)")
    out = write_all(out_dir, strip=base, material=material, dpi=dpi, results=results)
    files += [f for f in out["files"] if f.endswith(".png")]
    for var, spec in INFLUENCE.items():
        log(f"[{next(step)}/{n_total}] influence of {var}")
        vals = spec[0][::3] if quick else None
        p = os.path.join(out_dir, spec[3] + ".png")
        influence_figure(var, p, base, material, dpi, values=vals)
        files.append(p)
    if quick:
        notes.append("speed_accuracy.png skipped in quick mode")
    elif bench is None:
        notes.append("speed_accuracy.png skipped: no bench result (the `bench` command is not installed; "
                     "--bench FILE draws a saved `bench --json`)")
    else:
        measure = callable(bench)
        log(f"[{next(step)}/{n_total}] speed/accuracy " + ("(quick in-process measurement)" if measure else
                                                         "(from the saved bench)"))
        res = bench() if measure else bench
        files.append(plot_speed_accuracy(res, os.path.join(out_dir, "speed_accuracy.png")))
    return {"files": files, "notes": notes, "layers": out["summaries"]}
