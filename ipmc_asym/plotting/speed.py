"""The speed/accuracy figure of the fidelity ladder, drawn from a bench result.

The data is the dict ``ipmc-asym bench --json`` prints (:func:`load_bench` reads a saved
one): ``points``, ``bvp_points``, ``targets`` (``{fidelity: {"seconds_per_point", ...}}``)
and ``results`` (one row per model and fidelity with ``seconds_per_point_serial`` and
``rel_error_max``).
"""

from __future__ import annotations

import json

from ipmc_asym.base.inputs import read_input_text
from ipmc_asym.plotting import COLUMN_WIDTH_IN, MODEL_COLOURS, print_fonts, pyplot, savefig

__all__ = ["plot_speed_accuracy", "load_bench", "ERR_FLOOR"]

#: relative errors below this are drawn at this value (log axis)
ERR_FLOOR = 1e-16


def load_bench(path) -> dict:
    """A saved ``ipmc-asym bench --json`` result, checked; one-line ``ValueError`` otherwise."""
    try:
        res = json.loads(read_input_text(path, "--bench"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise ValueError(f"--bench {path!r}: cannot read a bench JSON file ({exc.__class__.__name__}: {exc})") from None
    if not isinstance(res, dict) or not isinstance(res.get("results"), list) or "points" not in res:
        raise ValueError(f"--bench {path!r}: not the output of `ipmc-asym bench --json` (no 'results' list)")
    return res


def plot_speed_accuracy(res: dict, path) -> str:
    """Log time per point (x) vs log relative error against the BVP (y).

    Marker shape = fidelity (``leading``, ``corrected``, ``quadrature``, ``exact``, ``bvp``),
    colour = model; the BVP is placed at its stated error estimate.  A grey dotted vertical
    line marks each fidelity's target time per point (the bench's ``targets``: the speed a
    sweep of that fidelity is held to); a point left of its line meets it.

    Returns
    -------
    str
        The path written.
    """
    plt = pyplot()
    from matplotlib.lines import Line2D  # deferred: matplotlib is heavy and only figures need it

    markers = {"leading": "o", "corrected": "s", "quadrature": "^", "exact": "P", "bvp": "D"}
    fig, ax = plt.subplots(figsize=(COLUMN_WIDTH_IN, 3.6))
    for r in res["results"]:
        x, y = r["seconds_per_point_serial"], r["rel_error_max"]
        if x is None or y is None or r["fidelity"] not in markers:
            continue
        ax.scatter([x], [max(y, ERR_FLOOR)], marker=markers[r["fidelity"]], color=MODEL_COLOURS.get(r["model"], "k"),
                   s=30, edgecolor="k", linewidth=0.5, zorder=3)
    for f, t in res.get("targets", {}).items():
        ax.axvline(t["seconds_per_point"], color="0.6", ls=":", lw=0.8)
        ax.text(t["seconds_per_point"], 0.5, f" target time of {f}", rotation=90, fontsize=7, color="0.4",
                va="top", transform=ax.get_xaxis_transform())
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("time per point, single thread [s]")
    ax.set_ylabel("max relative error of I vs the BVP\n(BVP: its stated estimate; floor %.0e)" % ERR_FLOOR)
    ax.set_title(f"moment integral: speed vs accuracy\n({res['points']:.0e} points, "
                 f"{res['bvp_points']} BVP points per model)", fontsize=8)
    ax.grid(True, which="major", alpha=0.3)
    h = [Line2D([], [], ls="", marker=m, color="0.3", label=f) for f, m in markers.items()]
    h += [Line2D([], [], ls="", marker="o", color=c, label=m) for m, c in MODEL_COLOURS.items()]
    if res.get("targets"):
        h += [Line2D([], [], ls=":", color="0.6", label="target time per point")]
    # below the axes: never on a point
    ax.legend(handles=h, loc="upper center", bbox_to_anchor=(0.5, -0.28), fontsize=7, ncol=3, frameon=False)
    print_fonts(fig)
    fig.tight_layout()
    return savefig(fig, path, dpi=300)  # print resolution when the file is a PNG
