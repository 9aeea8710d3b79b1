"""Data vs fitted model with residuals (``ipmc-asym fit --plot F.png``; several files: :func:`plot_fit_dynamic`)."""

from __future__ import annotations

import numpy as np

from ipmc_asym.base.quantities import unit_and_long_name
from ipmc_asym.plotting import COLUMN_WIDTH_IN, PAGE_WIDTH_IN, print_fonts, pyplot, savefig

__all__ = ["plot_fit", "plot_fit_dynamic"]

#: geometry column -> (display scale, unit, label)
_AXIS = {"voltage": (1.0, "V", r"voltage $\varphi_0$"), "thickness": (1e6, "µm", "total thickness $2e$"),
         "length": (1e3, "mm", "length $L$"), "width": (1e3, "mm", "total width $2l$")}
#: SI unit -> (display scale, display unit) of the fitted parameters in the title
_DISPLAY = {"Pa": (1e-6, "MPa"), "mol/m^3": (1.0, "mol/m³"), "F/m": (1.0, "F/m")}
_LABEL = {"deflection": ("tip deflection |w| [mm]", 1e3), "blocking_force": ("blocking force |F| [mN]", 1e3)}



#: the paper's symbols of the free parameters, for the annotations
_SYMBOL = {"modulus": "$E$", "c_moy": "$C_{moy}$", "eps0": r"$\varepsilon_0$", "deps": r"$\Delta\varepsilon$",
           "diffusion": "$D$", "viscous_modulus": r"$\eta_E$", "sheet_resistance": "$R_s$"}


def _unit(name):
    """The unit of a free parameter (``studies.calibrate.FREE_PARAMETERS``), for the annotations."""
    from ipmc_asym.studies.calibrate import FREE_PARAMETERS  # deferred: the names only

    return FREE_PARAMETERS.get(name, ("",))[0].replace("^3", "³").replace("^2", "²")

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
    fig, axes = plt.subplots(2, len(keys), figsize=(min(PAGE_WIDTH_IN, COLUMN_WIDTH_IN * len(keys)), 4.2), squeeze=False,
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
            i = list(uniq).index(t)
            # colour, marker and line style per group: told apart in grayscale too
            c, mk, ls = f"C{i % 10}", "os^Dv"[i % 5], ("-", "--", "-.", ":")[i % 4]
            o = np.argsort(v[s])
            lab_c = "data" if ck is None else f"data, {_AXIS[ck][2]} = {t * _AXIS[ck][0]:.4g} {_AXIS[ck][1]}"
            ax.errorbar(xs * v[s], f * y[s], yerr=None if sig is None else f * sig[s], fmt=mk, ms=4, color=c,
                        mfc="white", label=lab_c)
            ax.plot(xs * v[s][o], f * pred[s][o], ls, color=c, lw=1.2)
            res = (y[s] - pred[s]) / (sig[s] if sig is not None else y[s])
            axr.plot(xs * v[s], res, mk, ms=4, color=c, mfc="white")
        ax.set_ylabel(lab)
        ax.set_title(f"{k.replace('_', ' ')}: data (points) vs fit (lines)", fontsize=8)
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

    pars = ", ".join(f"{_SYMBOL.get(n, n)} = {p['value']:.4g}{label(p)} {_unit(n)}" for n, p in result.parameters.items())
    gof = _goodness(result)
    fig.suptitle(f"fit [{result.model}, {result.fidelity}]: {pars};\n{gof}", fontsize=8, wrap=True)
    print_fonts(fig)
    fig.tight_layout()
    return savefig(fig, path, dpi=300)  # print resolution when the file is a PNG


#: measured column -> (label, display scale) of the time series and spectra
_DYN_LABEL = {"current": ("current [mA]", 1e3), "charge": ("charge [µC]", 1e6),
              "deflection": ("tip deflection [mm]", 1e3), "blocking_force": ("blocking force [mN]", 1e3),
              "Z_re": ("Re Z [Ω]", 1.0), "Z_im": ("Im Z [Ω]", 1.0), "Z_abs": ("|Z| [Ω]", 1.0),
              "Z_phase": ("phase of Z [deg]", 180.0 / np.pi)}


def plot_fit_dynamic(result, path) -> str:
    """Every file of a joint fit (:func:`ipmc_asym.studies.calibrate_dynamic.fit_dynamic`): one column
    per measured quantity of each file, data (points, 1-sigma bars if given) and the fitted model
    (line) against the time (ms), the frequency (Hz, log) or the voltage (static rows); below, the
    weighted residuals.

    Parameters
    ----------
    result : ipmc_asym.studies.calibrate.CalibrationResult   (``data``, ``predictions``: lists)
    path : str   PNG path (written atomically)
    """
    plt = pyplot()
    panels = []
    for d, pr in zip(result.data, result.predictions):
        for k in d.measured:
            panels.append((d, k, pr[k]))
    n = len(panels)
    # sharex: the residuals below share (and label) the data's abscissa
    fig, axes = plt.subplots(2, n, figsize=(min(PAGE_WIDTH_IN, COLUMN_WIDTH_IN * n), 4.2), squeeze=False, sharex="col",
                             gridspec_kw={"height_ratios": [3, 1.3]})
    for j, (d, k, pred) in enumerate(panels):
        ax, axr = axes[0, j], axes[1, j]
        y = d.measured[k]
        m = np.isfinite(y)
        if hasattr(d, "t"):
            x, xl, logx = d.t[m] * 1e3, "time t [ms]", False
        elif hasattr(d, "f"):
            x, xl, logx = d.f[m], "frequency f [Hz]", True
        else:
            x, xl, logx = d.geometry["voltage"][m], r"voltage $\varphi_0$ [V]", False
        lab, f = _DYN_LABEL.get(k, _LABEL.get(k, (k, 1.0)))
        sig = d.sigma[k]
        o = np.argsort(x)
        ax.errorbar(x, f * y[m], yerr=None if sig is None else f * sig[m], fmt="o", ms=3, color="C0", mfc="white",
                    label="data")
        ax.plot(x[o], f * pred[o], "-", color="C3", lw=1.2, label="fit")
        # the fit's own weights: sigma, else the relative scale of each kind (calibrate_dynamic docstring)
        if sig is not None:
            scale = sig[m]
        elif k in ("Z_re", "Z_im"):
            scale = np.hypot(d.measured["Z_re"], d.measured["Z_im"])[m]
        elif k == "Z_phase":
            scale = np.ones(x.size)
        elif hasattr(d, "t"):
            scale = np.full(x.size, np.sqrt(np.mean(y[m] ** 2)))
        else:
            scale = np.abs(y[m])
        axr.plot(x, (y[m] - pred) / scale, "o", ms=3, color="C0")
        axr.axhline(0, color="k", lw=0.8)
        if logx:
            ax.set_xscale("log")
            axr.set_xscale("log")
        if k == "Z_abs":
            ax.set_yscale("log")
        ax.set_ylabel(lab)
        ax.set_title(f"{d.source}: {k.replace('_', ' ')}", fontsize=8)
        ax.legend(fontsize=7)
        axr.set_ylabel("(data − fit)/σ" if sig is not None else "(data − fit)/weight")
        axr.set_xlabel(xl)
    pars = ", ".join(f"{_SYMBOL.get(nm, nm)} = {p['value']:.4g} {_unit(nm)}" + ("" if p["status"] == "ok" else f" ({p['status']})")
                     for nm, p in result.parameters.items())
    gof = _goodness(result)
    fig.suptitle(f"fit [{result.model}]: {pars};\n{gof}", fontsize=8, wrap=True)
    print_fonts(fig)
    fig.tight_layout()
    return savefig(fig, path, dpi=300)  # print resolution when the file is a PNG


def _goodness(result) -> str:
    """The suptitle's goodness-of-fit phrase: chi2_red with sigma, the noise scale without, and
    neither where no degree of freedom is left (n = p)."""
    if result.chi2_red is not None:
        return f"χ²_red = {result.chi2_red:.3g}"
    if result.noise_scale is not None:
        return f"noise s = {result.noise_scale:.2g} (relative, estimated)"
    return "n = p: no goodness of fit"
