"""The speed/accuracy figure of the fidelity ladder (from :func:`ipmc_asym.bench.suite.run_bench`)."""

from __future__ import annotations

from ipmc_asym.bench.suite import ERR_FLOOR, TARGETS, run_bench
from ipmc_asym.plotting import pyplot, savefig

__all__ = ["speed_accuracy_figure", "plot_speed_accuracy"]


def speed_accuracy_figure(path="figures/speed_accuracy.png", points: int = 10**5, bvp_points: int = 3,
                          bench: dict | None = None) -> str:
    """Draw the speed/accuracy figure from a bench result, or from a quick in-process run.

    Parameters
    ----------
    path : str
    points, bvp_points : int
        Size of the quick measurement (no compile subprocesses, no further sections) when
        ``bench`` is not given.
    bench : dict, optional
        A saved ``ipmc-asym bench --json`` result (:func:`ipmc_asym.bench.suite.load_bench`).
    """
    res = bench if bench is not None else run_bench(points, bvp_points, repeats=1, compile_times=False,
                                                    sections=[])
    return plot_speed_accuracy(res, path)


def plot_speed_accuracy(res: dict, path="figures/speed_accuracy.png") -> str:
    """Log time per point (x) vs log relative error against the BVP (y).

    Marker shape = fidelity, colour = model; the BVP is placed at its stated error estimate.

    Returns
    -------
    str
        The path written.
    """
    plt = pyplot()
    from matplotlib.lines import Line2D  # deferred: matplotlib is heavy and only figures need it

    markers = {"leading": "o", "corrected": "s", "quadrature": "^", "bvp": "D"}
    colours = {"constant": "tab:blue", "linear": "tab:orange", "affine": "tab:green"}
    fig, ax = plt.subplots(figsize=(7, 5))
    for r in res["results"]:
        x, y = r["seconds_per_point_serial"], r["rel_error_max"]
        if x is None or y is None:
            continue
        ax.scatter([x], [max(y, ERR_FLOOR)], marker=markers[r["fidelity"]], color=colours[r["model"]],
                   s=70, edgecolor="k", linewidth=0.6, zorder=3)
    for f, t in TARGETS.items():
        ax.axvline(t["seconds_per_point"], color="0.6", ls=":", lw=0.8)
        ax.text(t["seconds_per_point"], 0.5, f" {f} target", rotation=90, fontsize=7, color="0.4",
                va="top", transform=ax.get_xaxis_transform())
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("time per point, single thread [s]")
    ax.set_ylabel("max relative error of I vs BVP (BVP: its estimate)")
    ax.set_title(f"ipmc-asym: speed vs accuracy ({res['points']:.0e} points, "
                 f"{res['bvp_points']} BVP points/model)")
    ax.grid(True, which="major", alpha=0.3)
    h = [Line2D([], [], ls="", marker=m, color="0.3", label=f) for f, m in markers.items()]
    h += [Line2D([], [], ls="", marker="o", color=c, label=m) for m, c in colours.items()]
    ax.legend(handles=h, loc="best", fontsize=8, ncol=2)
    fig.tight_layout()
    return savefig(fig, path, dpi=120)
