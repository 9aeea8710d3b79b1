"""The Pareto front of a design (``ipmc-asym design SPEC.toml --plot F.png``)."""

from __future__ import annotations

import numpy as np

from ipmc_asym.plotting import COLUMN_WIDTH_IN, print_fonts, pyplot, savefig

__all__ = ["plot_design"]

#: short axis names of the design outputs (the paper's symbols)
_SHORT = {"tip_deflection": "tip deflection $|w|$", "blocking_force": "blocking force $|F|$",
          "rotation": r"tip rotation $|\theta|$", "moment": "moment $|M_A|$", "I": "moment integral $I$",
          "work": "work $|F|\\,|w|$", "max_strain": "largest strain", "first_resonance": "first resonance"}

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
        name = result.objective["name"]
        ax.plot([abs(o[xn]) * fx], [abs(o[yn]) * fy], "r*", ms=10, mec="k", mew=0.5,
                label=f"optimum: {result.objective['sense']} {_SHORT.get(name, name)}")
        ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.2), fontsize=7, frameon=False)  # off the front
    ax.margins(0.08)  # the optimum, often at an end of the front, stays inside the axes
    ax.set_xlabel(f"{_SHORT.get(xn, xn)} [{ux}]" if ux else _SHORT.get(xn, xn))
    ax.set_ylabel(f"{_SHORT.get(yn, yn)} [{uy}]" if uy else _SHORT.get(yn, yn))
    ax.grid(alpha=0.3)
    ax.set_title(f"Pareto front ({len(result.pareto)} points), model {sp.model},\nmaterial {sp.material.name}{same}",
                 fontsize=8)
    print_fonts(fig)
    fig.tight_layout()
    return savefig(fig, path, dpi=300)  # print resolution when the file is a PNG
