"""Data vs fitted model with residuals (``ipmc-asym fit --plot F.png``)."""

from __future__ import annotations

import numpy as np

from ipmc_asym.base.quantities import unit_and_long_name
from ipmc_asym.plotting import pyplot, savefig

__all__ = ["plot_fit"]

#: geometry column -> (display scale, unit, label)
_AXIS = {"voltage": (1.0, "V", "voltage φ0"), "thickness": (1e6, "µm", "total thickness 2e"),
         "length": (1e3, "mm", "length L"), "width": (1e3, "mm", "total width 2l")}
#: SI unit -> (display scale, display unit) of the fitted parameters in the title
_DISPLAY = {"Pa": (1e-6, "MPa"), "mol/m^3": (1.0, "mol/m³"), "F/m": (1.0, "F/m")}
_LABEL = {"deflection": ("tip deflection |w| [mm]", 1e3), "blocking_force": ("blocking force |F| [mN]", 1e3)}


def _parameter_text(name, p) -> str:
    """``modulus = 130 MPa ± 2.1 MPa``: the value with its unit from the output vocabulary."""
    unit = unit_and_long_name(name)[0]
    scale, shown = _DISPLAY.get(unit, (1.0, unit))
    txt = f"{name} = {p['value'] * scale:.4g} {shown}".rstrip()
    if p.get("stderr") is not None and p.get("identifiable"):
        return txt + f" ± {p['stderr'] * scale:.2g} {shown}".rstrip()
    return txt + ("" if p.get("identifiable") else " (not identifiable)")


def plot_fit(result, path) -> str:
    """One column per measured quantity: data (with 1-sigma bars if given) and the fitted
    model against the row's voltage (colour = total thickness 2e); below, the normalised
    residuals ``(data - model)/sigma`` (relative residuals without sigma columns).

    Parameters
    ----------
    result : ipmc_asym.studies.calibrate.CalibrationResult
    path : str   PNG path (written atomically)
    """
    plt = pyplot()
    d = result.data
    keys = list(d.measured)
    fig, axes = plt.subplots(2, len(keys), figsize=(5.2 * len(keys), 5.6), squeeze=False,
                             gridspec_kw={"height_ratios": [3, 1.3]}, sharex="col")
    # x axis: the first of voltage, thickness, length, width that varies; colour: the next
    varying = [k for k in ("voltage", "thickness", "length", "width") if np.unique(d.geometry[k]).size > 1]
    xk = varying[0] if varying else "voltage"
    ck = varying[1] if len(varying) > 1 else None
    v = d.geometry[xk]
    th = d.geometry[ck] if ck else np.zeros(d.n_rows)
    uniq = np.unique(th)
    xs, xu, xl = _AXIS[xk]
    for j, k in enumerate(keys):
        lab, f = _LABEL[k]
        ax, axr = axes[0, j], axes[1, j]
        m = np.isfinite(d.measured[k])
        y = d.measured[k]
        pred = result.predictions[k]
        sig = d.sigma[k]
        for t in uniq:
            s = m & (th == t)
            c = f"C{list(uniq).index(t) % 10}"
            o = np.argsort(v[s])
            lab_c = "data" if ck is None else f"data, {_AXIS[ck][2]} = {t * _AXIS[ck][0]:.4g} {_AXIS[ck][1]}"
            ax.errorbar(xs * v[s], f * y[s], yerr=None if sig is None else f * sig[s], fmt="o", ms=4, color=c,
                        label=lab_c)
            ax.plot(xs * v[s][o], f * pred[s][o], "-", color=c, lw=1.2)
            res = (y[s] - pred[s]) / (sig[s] if sig is not None else y[s])
            axr.plot(xs * v[s], res, "o", ms=4, color=c)
        ax.set_ylabel(lab)
        ax.set_title(f"{k.replace('_', ' ')}: data (points) vs fit (lines)", fontsize=10)
        ax.legend(fontsize=7)
        axr.axhline(0, color="k", lw=0.8)
        axr.set_ylabel("(data − fit)/σ" if sig is not None else "(data − fit)/data")
        axr.set_xlabel(f"{xl} [{xu}]")
    def label(p):
        if p.get("status") == "at_bound":
            return " (at the bound)"
        if not p["identifiable"]:
            return " (not identifiable)"
        if p["stderr"] is not None:
            return f" ± {p['stderr']:.2g}"
        return f" [{p['ci95'][0]:.4g}, {p['ci95'][1]:.4g}]"

    pars = ", ".join(f"{n} = {p['value']:.4g}{label(p)}" for n, p in result.parameters.items())
    gof = (f"χ²_red = {result.chi2_red:.3g}" if result.chi2_red is not None
           else f"noise s = {result.noise_scale:.2g} (relative, estimated)")
    fig.suptitle(f"fit [{result.model}, {result.fidelity}]: {pars}; {gof}", fontsize=10)
    fig.tight_layout()
    return savefig(fig, path, dpi=120)
