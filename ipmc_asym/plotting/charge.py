"""Charge figures: sigma(phi0) and C_d(phi0) per model, a step response, a Bode plot."""

from __future__ import annotations

import numpy as np

from ipmc_asym.dynamics.circuit import frequency_response, step_response, time_constant
from ipmc_asym.dynamics.electrode import charge
from ipmc_asym.model.params import NAFION_LI, Strip
from ipmc_asym.plotting import MODEL_COLOURS, MODEL_MARKERS, PAGE_WIDTH_IN, model_style, print_fonts, pyplot, savefig

__all__ = ["plot_charge_capacitance", "plot_step", "plot_bode"]

MODELS3 = ("constant", "linear", "affine")


def plot_charge_capacitance(path, strip: Strip | None = None, material=NAFION_LI) -> str:
    """sigma(phi0) and C_d(phi0) for the three models (closed form; BVP points overlaid)."""
    s = Strip() if strip is None else strip
    plt = pyplot()
    v = np.linspace(0.0, 3.0, 301)
    vb = np.array([0.05, 0.5, 1.0, 2.0, 3.0])
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(PAGE_WIDTH_IN, 2.8))
    for m in MODELS3:
        r = charge(s.thickness, v, m, "corrected", material=material)
        c = MODEL_COLOURS[m]
        a1.plot(v, r.sigma, label=m, **model_style(m))
        a2.semilogy(v, r.C_diff, label=m, **model_style(m))
        rb = charge(s.thickness, vb, m, "bvp", material=material)
        a1.plot(vb, rb.sigma, MODEL_MARKERS[m], color=c, mfc="none")
        ok = rb.valid
        a2.semilogy(vb[ok], rb.C_diff[ok], MODEL_MARKERS[m], color=c, mfc="none")
    a1.set_xlabel("φ0 [V]")
    a1.set_ylabel("σ [C/m²] (face z = −e)")
    a1.set_title(f"electrode charge (total 2e = {s.thickness * 1e6:.0f} µm); o = BVP")
    a2.set_xlabel("φ0 [V]")
    a2.set_ylabel("C_d = dσ/dφ0 [F/m²]")
    a2.set_title("differential capacitance (analytic); o = BVP difference")
    a2.set_ylim(1e-3, 3e3)
    for a in (a1, a2):
        a.grid(alpha=0.3)
        a.legend()
    print_fonts(fig)
    fig.tight_layout()
    return savefig(fig, path, dpi=110)


def plot_step(path, voltage=1.0, strip: Strip | None = None, material=NAFION_LI) -> str:
    """sigma and w against t/tau after a step: reduced model (line) and PNP solver (markers)."""
    s = Strip() if strip is None else strip
    plt = pyplot()
    tau = float(time_constant(s.thickness, "constant", material))
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(PAGE_WIDTH_IN, 2.8))
    for m, c in MODEL_COLOURS.items():
        tm = float(time_constant(s.thickness, m, material))
        rc = step_response(voltage, 6 * tm, strip=s, model=m, material=material, points=600)
        rp = step_response(voltage, 6 * tm, strip=s, model=m, material=material, fidelity="pnp", points=31)
        a1.plot(rc.t / tm, rc.sigma, label=f"{m}: circuit (τ = {tm:.3g} s)", **model_style(m))
        a1.plot(rp.t / tm, rp.sigma, MODEL_MARKERS[m], color=c, mfc="none", label=f"{m}: PNP")
        a2.plot(rc.t / tm, rc.w * 1e3, label=f"{m}: circuit", **model_style(m))
        a2.plot(rp.t / tm, rp.w * 1e3, MODEL_MARKERS[m], color=c, mfc="none", label=f"{m}: PNP")
    a1.set_xlabel("t / τ")
    a1.set_ylabel("σ [C/m²]")
    a1.set_title(f"{voltage:g} V step, total 2e = {s.thickness * 1e6:.0f} µm, D = {material.D:.2g} m²/s")
    a2.set_xlabel("t / τ")
    a2.set_ylabel("tip deflection w [mm] (quasi-static, no inertia)")
    a2.set_title("w from the layers' charge; no water transport")
    for a in (a1, a2):
        a.grid(alpha=0.3)
        a.legend(fontsize=7)
    print_fonts(fig)
    fig.tight_layout()
    del tau
    return savefig(fig, path, dpi=110)


def plot_bode(path, strip: Strip | None = None, material=NAFION_LI) -> str:
    """``|Z|``, arg Z and ``|w|``/V, arg w: exact linearised PNP (lines) and the circuit (dashed)."""
    s = Strip() if strip is None else strip
    plt = pyplot()
    fig, ax = plt.subplots(2, 2, figsize=(PAGE_WIDTH_IN, 4.4), sharex=True)
    for m in ("constant", "affine"):
        tau = float(time_constant(s.thickness, m, material))
        f = np.geomspace(1e-3 / tau, 1e4 / tau, 300)
        c = MODEL_COLOURS[m]
        for meth, ls in (("pnp-linear", "-"), ("circuit", "--")):
            r = frequency_response(f, strip=s, model=m, material=material, method=meth)
            lab = f"{m}, {meth}"
            # line style = method, marker = model (black-and-white print)
            mk = {"color": c, "marker": MODEL_MARKERS[m], "markevery": 30, "ms": 4, "mfc": "white"}
            ax[0, 0].loglog(f, np.abs(r.Z), ls, label=lab, **mk)
            ax[1, 0].semilogx(f, np.degrees(np.angle(r.Z)), ls, label=lab, **mk)
            ax[0, 1].loglog(f, r.w_amp * 1e3, ls, label=lab, **mk)
            ax[1, 1].semilogx(f, np.degrees(r.w_phase), ls, label=lab, **mk)
    ax[0, 0].set_ylabel("|Z| [Ohm] (electrode area 2l L)")
    ax[1, 0].set_ylabel("arg Z [deg]")
    ax[0, 1].set_ylabel("|w| / V [mm/V]")
    ax[1, 1].set_ylabel("arg w [deg]")
    for a in ax[1]:
        a.set_xlabel("f [Hz]")
    for a in ax.ravel():
        a.grid(alpha=0.3, which="both")
    ax[0, 0].legend(fontsize=7)
    ax[0, 0].set_title("impedance about 0 V")
    ax[0, 1].set_title("tip deflection / voltage (layers' moment)")
    print_fonts(fig)
    fig.tight_layout()
    return savefig(fig, path, dpi=110)
