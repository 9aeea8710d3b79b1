"""Profile figures through the thickness (paper Figs 4-7) and the profiles CSV/PNG set."""

from __future__ import annotations

import os

import numpy as np

from ipmc_asym.base.registry import model_names
from ipmc_asym.model.params import NAFION_LI, Material, Strip
from ipmc_asym.plotting import MODEL_COLOURS, pyplot, savefig
from ipmc_asym.studies.profiles import QUANTITIES, compute_all, profile_summary, write_csv

__all__ = ["plot_profiles", "write_all"]

def plot_profiles(results: dict, quantity: str, path, e: float, dpi: int = 110, title: str | None = None):
    """Full-width panel + zooms at the anode and the cathode (log distance from the face, µm).

    ``results``: model name -> BVPResult; ``e`` HALF thickness (m).
    """
    plt = pyplot()
    attr, label = QUANTITIES[quantity]
    fig, axs = plt.subplots(1, 3, figsize=(13, 4.0), dpi=dpi)
    fmax = 0.0
    for name, res in results.items():
        z = np.asarray(res.z)
        f = np.asarray(getattr(res, attr))
        if quantity == "E":
            # the linear model's field spikes to ~1e17 at the anode (eps -> 0 there): on a
            # linear axis it flattens every other curve, so |E| is drawn on a log axis
            f = np.where(np.abs(f) > 0, np.abs(f), np.nan)
            fmax = max(fmax, float(np.nanmax(f)))
        c = MODEL_COLOURS.get(name, None)
        axs[0].plot(z, f, color=c, label=name)
        da = (z + 1.0) * e * 1e6
        m = (da > 0) & (z < 0)
        axs[1].plot(da[m], f[m], color=c, label=name)
        dc = (1.0 - z) * e * 1e6
        m = (dc > 0) & (z > 0)
        axs[2].plot(dc[m], f[m], color=c, label=name)
    axs[0].set_xlabel(r"$\bar z = z/e$ ($e$ = HALF thickness = %.4g µm)" % (e * 1e6))
    axs[0].set_title("full thickness (anode $\\bar z=-1$, cathode $+1$)", fontsize=9)
    for ax, side in ((axs[1], "anode ($\\bar z=-1$)"), (axs[2], "cathode ($\\bar z=+1$)")):
        ax.set_xscale("log")
        ax.set_xlim(1e-4, e * 1e6)
        ax.set_xlabel(f"distance from the {side.split(' ')[0]} face (µm, log)")
        ax.set_title(f"zoom at the {side}", fontsize=9)
    if quantity == "C":
        axs[2].set_yscale("log")
    if quantity == "E":
        for ax in axs:
            ax.set_yscale("log")
            # the neutral core's field is exponentially small (down to 1e-300): show 12 decades
            # below the smallest face value, where the layers are
            ax.set_ylim(1e-6, 10.0 * fmax)
        label = f"|{label}| (log)"
    for ax in axs:
        ax.set_ylabel(label)
        ax.grid(True, alpha=0.3)
    axs[0].legend(fontsize=8)
    fig.suptitle(title or f"{quantity} profile through the thickness (nominal strip, full BVP)", fontsize=10)
    fig.tight_layout()
    savefig(fig, path)


def write_all(out_dir, models=model_names(), strip: Strip | None = None, material: Material = NAFION_LI,
              dpi: int = 110, quantities=tuple(QUANTITIES), results=None) -> dict:
    """CSV per model + one PNG per quantity; returns {"summaries": [...], "files": [...]}."""
    strip = Strip() if strip is None else strip
    os.makedirs(out_dir, exist_ok=True)
    results = compute_all(models, strip, material) if results is None else results
    files = []
    for m, res in results.items():
        p = os.path.join(out_dir, f"profiles_{m}.csv")
        write_csv(res, p, strip.e)
        files.append(p)
    figno = {"C": 4, "phi": 5, "D": 6, "p": 7}
    for q in quantities:
        p = os.path.join(out_dir, f"profile_{q}.png")
        t = f"{q} profile (paper Fig. {figno[q]})" if q in figno else f"{q} profile"
        plot_profiles(results, q, p, strip.e, dpi=dpi,
                      title=f"{t}: L={strip.length*100:g} cm, 2e={strip.thickness*1e6:g} µm, "
                            f"phi0={strip.voltage:g} V, full BVP")
        files.append(p)
    sums = [profile_summary(m, strip, material, res=r) for m, r in results.items()]
    return {"summaries": sums, "files": files}
