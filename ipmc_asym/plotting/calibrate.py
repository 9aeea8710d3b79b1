"""Data vs fitted model with residuals (``ipmc-asym fit --plot F.png``)."""

from __future__ import annotations

import numpy as np

from . import pyplot, savefig

__all__ = ["plot_fit"]

_LABEL = {"deflection": ("tip deflection |w| [mm]", 1e3), "blocking_force": ("blocking force |F| [mN]", 1e3)}


def plot_fit(result, path) -> str:
    """One column per measured quantity: data (with 1-sigma bars if given) and the fitted
    model against the row's voltage (colour = total thickness 2e); below, the normalised
    residuals ``(data - model)/sigma`` (relative residuals without sigma columns).

    Parameters
    ----------
    result : ipmc_asym.calibrate.CalibrationResult
    path : str   PNG path (written atomically)
    """
    plt = pyplot()
    d = result.data
    keys = list(d.measured)
    fig, axes = plt.subplots(2, len(keys), figsize=(5.2 * len(keys), 5.6), squeeze=False,
                             gridspec_kw={"height_ratios": [3, 1.3]}, sharex="col")
    th = d.geometry["thickness"]
    uniq = np.unique(th)
    colours = {t: f"C{i % 10}" for i, t in enumerate(uniq)}
    v = d.geometry["voltage"]
    for j, k in enumerate(keys):
        lab, f = _LABEL[k]
        ax, axr = axes[0, j], axes[1, j]
        m = np.isfinite(d.measured[k])
        y = d.measured[k]
        pred = result.predictions[k]
        sig = d.sigma[k]
        for t in uniq:
            s = m & (th == t)
            c = colours[t]
            o = np.argsort(v[s])
            ax.errorbar(v[s], f * y[s], yerr=None if sig is None else f * sig[s], fmt="o", ms=4, color=c,
                        label=f"data, 2e = {t * 1e6:.4g} µm")
            ax.plot(v[s][o], f * pred[s][o], "-", color=c, lw=1.2)
            res = (y[s] - pred[s]) / (sig[s] if sig is not None else y[s])
            axr.plot(v[s], res, "o", ms=4, color=c)
        ax.set_ylabel(lab)
        ax.set_title(f"{k.replace('_', ' ')}: data (points) vs fit (lines)", fontsize=10)
        ax.legend(fontsize=7)
        axr.axhline(0, color="k", lw=0.8)
        axr.set_ylabel("(data − fit)/σ" if sig is not None else "(data − fit)/data")
        axr.set_xlabel("voltage φ0 [V]")
    pars = ", ".join(
        f"{n} = {p['value']:.4g}" + (f" ± {p['stderr']:.2g}" if p["identifiable"] else " (not identifiable)")
        for n, p in result.parameters.items())
    fig.suptitle(f"fit [{result.model}, {result.fidelity}]: {pars}; χ²_red = {result.chi2_red:.3g}", fontsize=10)
    fig.tight_layout()
    return savefig(fig, path, dpi=120)
