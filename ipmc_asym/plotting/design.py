"""The Pareto front of a design (``ipmc-asym design SPEC.toml --plot F.png``)."""

from __future__ import annotations

import numpy as np

from ipmc_asym.base.quantities import BY_NAME, axis_label
from ipmc_asym.plotting import COLUMN_WIDTH_IN, print_fonts, pyplot, savefig

__all__ = ["plot_design"]

#: display scale of each output's unit
_SCALE = {"m": (1e3, "mm"), "N": (1e3, "mN"), "N m": (1e6, "µN m"), "rad": (1.0, "rad"), "1": (1.0, "")}


def plot_design(result, path) -> str:
    """The front (magnitudes of the two outputs of ``[pareto]``), coloured by the TOTAL
    thickness, and the optimum of the objective.

    Parameters
    ----------
    result : ipmc_asym.studies.design.DesignResult
    path : str   PNG path (written atomically)
    """
    from ipmc_asym.studies.design import OUTPUTS  # deferred: the names only; plotting sits above studies

    plt = pyplot()
    sp = result.spec
    if sp.pareto is None or not result.pareto:
        raise ValueError("--plot needs a [pareto] table in the spec (x, y, points) with a non-empty front")
    xn, yn, _ = sp.pareto
    fx, ux = _SCALE.get(OUTPUTS[xn], (1.0, OUTPUTS[xn]))
    fy, uy = _SCALE.get(OUTPUTS[yn], (1.0, OUTPUTS[yn]))
    x = [p["outputs"][xn] * fx for p in result.pareto]
    y = [p["outputs"][yn] * fy for p in result.pareto]
    th = [p["inputs"]["thickness"] * 1e6 for p in result.pareto]
    fig, ax = plt.subplots(figsize=(COLUMN_WIDTH_IN, 2.9))
    spread = (max(th) - min(th)) / max(th)
    if spread > 0.02:
        sc = ax.scatter(x, y, c=th, s=8, cmap="viridis")
        fig.colorbar(sc, ax=ax, label="total thickness $2e$ [µm]")
        same = ""
    else:  # a colour bar over a sliver (e.g. 397.5-400 µm) would suggest a variation that is not there
        ax.scatter(x, y, s=8, color="C0")
        same = f"; $2e$ = {np.median(th):.4g} µm along the front"
    o = result.optimum["outputs"]
    if o.get(xn) is not None and o.get(yn) is not None:
        ax.plot([abs(o[xn]) * fx], [abs(o[yn]) * fy], "r*", ms=14,
                label=f"optimum: {result.objective['sense']} {result.objective['name']}")
        ax.legend(loc="best", fontsize=7)
    ax.set_xlabel("|" + axis_label(BY_NAME[xn].name, ux) + "|" if xn in BY_NAME else f"|{xn}| [{ux}]")
    ax.set_ylabel("|" + axis_label(BY_NAME[yn].name, uy) + "|" if yn in BY_NAME else f"|{yn}| [{uy}]")
    ax.grid(alpha=0.3)
    ax.set_title(f"Pareto front ({len(result.pareto)} points), model {sp.model},\nmaterial {sp.material.name}{same}",
                 fontsize=8)
    print_fonts(fig)
    fig.tight_layout()
    return savefig(fig, path, dpi=110)
