"""Profile figures through the thickness (paper Figs 4-7) and the profiles CSV/PNG set."""

from __future__ import annotations

import os

import numpy as np

from ipmc_asym.base.registry import model_names
from ipmc_asym.model.params import NAFION_LI, Material, Strip
from ipmc_asym.plotting import COLUMN_WIDTH_IN, check_figure_format, model_style, print_fonts, pyplot, savefig
from ipmc_asym.studies.profiles import QUANTITIES, compute_all, profile_summary, write_csv

__all__ = ["plot_profiles", "write_all"]

#: the full-thickness panel's stretch: distances from a face below this (in units of e) get
#: about as much room as each decade above it (asinh scale), so the layers at the faces, some
#: 1e-4 e thick or less, are seen next to the neutral core instead of as spikes at z = +-1
STRETCH_D0 = 1e-4
#: left edge of the zoom panels (distance from the face, µm): 1 nm, the continuum scale (a few
#: Nafion ionic clusters, ~4-5 nm, are the smallest structure the model averages over)
ZOOM_MIN_UM = 1e-3


def _stretch(z):
    z = np.asarray(z, float)
    d = np.clip(1.0 - np.abs(z), 0.0, 1.0)
    return np.sign(z) * (1.0 - np.arcsinh(d / STRETCH_D0) / np.arcsinh(1.0 / STRETCH_D0))


def _unstretch(x):
    x = np.asarray(x, float)
    s = np.clip(1.0 - np.abs(x), 0.0, 1.0)
    return np.sign(x) * (1.0 - STRETCH_D0 * np.sinh(s * np.arcsinh(1.0 / STRETCH_D0)))


def _zoom_curve(dist, f, grid):
    """The profile against the distance from a face, on the zoom's log axis.

    The BVP meshes differ per model: where a model's first node off the face lies beyond the
    axis' left edge, the curve is continued to that edge by linear interpolation in the
    distance between the face value and that node (the profile is smooth there), so every
    model's curve starts at the same offset.
    """
    o = np.argsort(dist)
    dist, f = dist[o], f[o]
    pos = dist > 0
    first = dist[pos][0] if pos.any() else np.inf
    extra = grid[grid < first]
    x = np.concatenate([extra, dist[pos]])
    return x, np.interp(x, dist, f)


def plot_profiles(results: dict, quantity: str, path, e: float, dpi: int = 110, title: str | None = None):
    """Full thickness (stretched near the faces) + zooms at the anode and the cathode.

    ``results``: model name -> BVPResult; ``e`` HALF thickness (m).  The zooms plot against
    the distance from the face in µm on a log axis, each with its own y-range.
    """
    plt = pyplot()
    attr, label = QUANTITIES[quantity]
    # print layout: the three panels stacked, one column (8.5 cm) wide
    fig, axs = plt.subplots(3, 1, figsize=(COLUMN_WIDTH_IN, 6.6), dpi=dpi)
    log_y = quantity == "E"
    grid = np.geomspace(ZOOM_MIN_UM, e * 1e6, 400)
    panel_max = [0.0, 0.0, 0.0]
    for name, res in results.items():
        z = np.asarray(res.z)
        f = np.asarray(getattr(res, attr))
        if log_y:
            # the linear model's field spikes to ~1e17 at the anode (eps -> 0 there): on a
            # linear axis it flattens every other curve, so |E| is drawn on a log axis
            f = np.where(np.abs(f) > 0, np.abs(f), np.nan)
        st = model_style(name)
        axs[0].plot(z, f, label=name, **st)
        panel_max[0] = max(panel_max[0], float(np.nanmax(f)))
        for k, (side, dist) in enumerate((((z < 0), (z + 1.0) * e * 1e6), ((z > 0), (1.0 - z) * e * 1e6)), 1):
            x, y = _zoom_curve(dist[side], f[side], grid)   # the face itself is at distance 0
            keep = x >= ZOOM_MIN_UM
            axs[k].plot(x[keep], y[keep], label=name, **st)
            if np.any(np.isfinite(y[keep])):
                panel_max[k] = max(panel_max[k], float(np.nanmax(y[keep])))
    axs[0].set_xscale("function", functions=(_stretch, _unstretch))
    ticks = [-1.0, -0.999, -0.99, -0.9, 0.0, 0.9, 0.99, 0.999, 1.0]
    axs[0].set_xticks(ticks, [f"{t:g}" for t in ticks], fontsize=7, rotation=45)
    axs[0].set_xlim(-1.0, 1.0)
    axs[0].set_xlabel(r"$\bar z = z/e$ ($e$ = HALF thickness = %.4g µm)" % (e * 1e6))
    axs[0].set_title("full thickness, stretched near the faces", fontsize=8)
    # the anode is the face at the higher potential: z_bar = -1 for a positive voltage, +1 for a negative one
    neg = any(getattr(getattr(r, "groups", None), "sign", 1.0) < 0 for r in results.values())
    lo_face, hi_face = ("cathode", "anode") if neg else ("anode", "cathode")
    for ax, side in ((axs[1], f"{lo_face} ($\\bar z=-1$)"), (axs[2], f"{hi_face} ($\\bar z=+1$)")):
        ax.set_xscale("log")
        ax.set_xlim(ZOOM_MIN_UM, e * 1e6)
        ax.set_xlabel(f"distance from the {side.split(' ')[0]} face (µm)")
        ax.set_title(f"zoom at the {side}, from 1 nm (continuum scale)", fontsize=8)
    if quantity == "C":  # the cathode's accumulation spans decades
        axs[1 if neg else 2].set_yscale("log")
    if log_y:
        for ax, top in zip(axs, panel_max):
            ax.set_yscale("log")
            # the neutral core's field is exponentially small (down to 1e-300): each panel
            # shows its own largest value down to 1e-6 (where the layers end)
            ax.set_ylim(1e-6, 10.0 * top)
        label = f"|{label}| (log)"
    for ax in axs:
        ax.set_ylabel(label)
        ax.grid(True, alpha=0.3)
    axs[0].legend(fontsize=7)
    fig.suptitle(title or f"{quantity} profile through the thickness (nominal strip, full BVP)", fontsize=8, wrap=True)
    print_fonts(fig)
    fig.tight_layout()
    savefig(fig, path)


def write_all(out_dir, models=model_names(), strip: Strip | None = None, material: Material = NAFION_LI,
              dpi: int = 110, quantities=tuple(QUANTITIES), results=None, fmt: str = "png") -> dict:
    """CSV per model + one figure per quantity (``fmt``: png, pdf or svg); returns
    ``{"summaries": [...], "files": [...]}``."""
    check_figure_format(fmt)
    strip = Strip() if strip is None else strip
    os.makedirs(out_dir, exist_ok=True)
    results = compute_all(models, strip, material) if results is None else results
    files = []
    for m, res in results.items():
        p = os.path.join(out_dir, f"profiles_{m}.csv")
        write_csv(res, p, strip.e)
        files.append(p)
    figno = {"C": 4, "phi": 5, "D": 6, "p": 7}
    # below the BVP's floor the profiles are the Debye-Hueckel solution (studies.profiles.profile)
    dh = any(r.message.startswith("Debye-Hueckel") for r in results.values())
    how = "Debye-Hückel solution (below the BVP's floor)" if dh else "full BVP"
    for q in quantities:
        p = os.path.join(out_dir, f"profile_{q}.{fmt}")
        t = f"{q} profile (paper Fig. {figno[q]})" if q in figno else f"{q} profile"
        t += "\n"
        plot_profiles(results, q, p, strip.e, dpi=dpi,
                      title=f"{t}$L$ = {strip.length*100:g} cm, $2e$ = {strip.thickness*1e6:g} µm, "
                            f"$\\varphi_0$ = {strip.voltage:g} V, {how}")
        files.append(p)
    sums = [profile_summary(m, strip, material, res=r) for m, r in results.items()]
    return {"summaries": sums, "files": files}
