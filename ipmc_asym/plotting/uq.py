"""Histograms of the UQ outputs with their quantiles (``ipmc-asym uq --plot F.png``)."""

from __future__ import annotations

import numpy as np

from ipmc_asym.base.quantities import axis_label
from ipmc_asym.plotting import COLUMN_WIDTH_IN, print_fonts, pyplot, savefig, symbols

__all__ = ["plot_uq"]

#: display scale of each output's unit
_SCALE = {"m": (1e3, "mm"), "N": (1e3, "mN"), "N m": (1e6, "µN m"), "rad": (1.0, "rad"), "1": (1.0, "")}


def plot_uq(result, path) -> str:
    """One panel per output: histogram (density), the 2.5/50/97.5 % quantiles (dashed), and
    the Sobol' total indices of the two most influential inputs in the title.

    The histogram is of the runs kept per sample (``result.outputs``: the first whole groups
    of the design, all of them unless ``n_stored < n_samples``); the quantiles, mean and sd
    are the statistics of every run.

    Parameters
    ----------
    result : ipmc_asym.studies.uq.UQResult
    path : str   PNG path (written atomically)
    """
    plt = pyplot()
    from matplotlib.ticker import MaxNLocator  # deferred: matplotlib is heavy and only figures need it

    outs = list(result.outputs)
    n = len(outs)
    cols = min(n, 2)
    rows = -(-n // cols)
    fig, axes = plt.subplots(rows, cols, figsize=(COLUMN_WIDTH_IN * cols, 2.4 * rows + 0.8), squeeze=False)
    for ax, o in zip(axes.flat, outs):
        s = result.summary[o]
        f, u = _SCALE.get(s["unit"], (1.0, s["unit"]))
        y = result.outputs[o] * f
        # the samples of the statistics: inside every model assumption unless kept (keep_invalid)
        valid = getattr(result, "valid", None)
        if valid is not None and not getattr(result, "keep_invalid", True):
            y = y[valid]
        y = y[np.isfinite(y)]
        # numpy's "auto" rule (the larger of Sturges and Freedman-Diaconis: ~10 bins at 256
        # samples), at most 50
        bins = min(50, max(1, len(np.histogram_bin_edges(y, "auto")) - 1)) if y.size else 10
        ax.hist(y, bins=bins, density=True, color="C0", alpha=0.75)
        for q in ("q2.5", "q50", "q97.5"):
            ax.axvline(s[q] * f, color="k", ls="--" if q != "q50" else "-", lw=0.9)
        ax.set_xlabel(symbols(axis_label(o, u or "1")))
        # at most four ticks: values such as 0.002345 overlap at matplotlib's default count
        ax.xaxis.set_major_locator(MaxNLocator(4))
        # density=True: counts per unit of the (scaled) output
        ax.set_ylabel(f"probability density [1/{u}]" if u not in ("", "1") else "probability density [1]")
        sob = result.sobol.get(o)
        if sob:
            top = sorted(sob.items(), key=lambda kv: -kv[1]["ST"])[:2]
            ax.set_title(", ".join(f"$S_T$({k}) = {v['ST']:.2f}" for k, v in top), fontsize=8)
        ax.text(0.02, 0.95, f"mean {s['mean'] * f:.4g} {u}\nsd {s['sd'] * f:.3g} {u}", transform=ax.transAxes,
                va="top", fontsize=7, bbox={"facecolor": "white", "edgecolor": "none", "alpha": 0.85, "pad": 1.5})
    for ax in list(axes.flat)[n:]:
        ax.set_visible(False)
    outside = getattr(result, "n_outside", 0)
    note = (f" ({outside} outside a model assumption, " + ("kept)" if getattr(result, "keep_invalid", False)
                                                             else "left out)")) if outside else ""
    stored = getattr(result, "n_stored", result.n_samples)
    hist = f"; histogram of the first {stored}" if stored < result.n_samples else ""
    fig.suptitle(f"UQ of scene {result.scene!r} [{result.model}]: {result.n_samples} runs{note}{hist}"
                 "\ndashed: 2.5 / 97.5 %, solid: median (thickness = total $2e$)", fontsize=8, wrap=True)
    print_fonts(fig)
    fig.tight_layout()
    return savefig(fig, path, dpi=300)  # print resolution when the file is a PNG
