"""
The strip as a curvature sensor and a harvester
================================================

:func:`ipmc_asym.sense` bends the strip (here a tip force on the cantilever) and returns the
charge that flows between short-circuited electrodes once water and cations have relaxed, and
the open-circuit voltage.  The three permittivity models of the paper share the linear response
up to their core permittivity (``docs/sensing.md``): the constant model's layers hold ~14 times
less charge (linear and affine nearly coincide), while the open-circuit voltage -- the Donnan difference of the fixed charge
between the faces -- is the same for all three.  Lines are told apart by style and marker.

Then the small signal (:func:`ipmc_asym.sensing_response`): the tip moved sinusoidally.  The
short-circuit charge per tip displacement is the static one only below
``f_stream = 3 D/(2 pi e^2)`` (4.8 mHz here): above it the water that the bending moves drives a
streaming potential, and past twice the static one-way coupling estimate (about 8 mHz) the model
flags its own numbers (plotted thin, after the vertical line).  Last, the harvester: the mean
power into a resistance at 5 mHz, largest at ``R = |Z|``.  Not at the first resonance (22.5 Hz):
the model does not hold there (``docs/sensing.md``).
"""

import matplotlib.pyplot as plt
import numpy as np

import ipmc_asym as ia

strip = ia.Strip(thickness=200e-6)
w = np.geomspace(0.05e-3, 2e-3, 25)
styles = {"constant": ("-", "o"), "linear": ("--", "s"), "affine": (":", "^")}

fig, (ax_q, ax_v) = plt.subplots(1, 2, figsize=(10, 3.8))
for k, (model, (ls, mk)) in enumerate(styles.items()):
    r = ia.sense(strip, tip_displacement=w, support="tip-force", model=model, fidelity="exact")
    # Q is odd in w (and negative for w > 0: the electrode z = -e); its magnitude on log axes
    ax_q.loglog(1e3 * w, 1e6 * np.abs(r.Q), ls, marker=mk, markevery=(2 * k, 6), color="k", label=model)
    ax_v.plot(1e3 * w, 1e6 * r.V_oc, ls, marker=mk, markevery=(2 * k, 6), color="k", label=model)
    print(f"{model:8s} Q/w = {r.Q_per_w[-1]:.4g} C/m, V_oc/w = {r.V_oc[-1] / w[-1]:.4g} V/m, "
          f"largest error bound {max(r.error.max(), r.error_V_oc.max()):.1e}")
ax_q.set_xlabel("tip displacement w [mm]")
ax_q.set_ylabel("short-circuit charge |Q| [µC]")
ax_v.set_xlabel("tip displacement w [mm]")
ax_v.set_ylabel("open-circuit voltage V_oc [µV]")
for ax in (ax_q, ax_v):
    ax.legend(fontsize=8)
fig.suptitle("Nafion-Li strip, L = 2 cm, 2l = 5 mm, 2e = 200 µm, tip force, drained ν = 0 (assumption)")
fig.tight_layout()

# the frequency response per tip displacement (tip force)
f = np.geomspace(1e-5, 1.0, 120)
fig2, (ax_fq, ax_fv) = plt.subplots(1, 2, figsize=(10, 3.8))
for k, (model, (ls, mk)) in enumerate(styles.items()):
    r = ia.sensing_response(f, strip, model=model, support="tip-force")
    ok = r.valid
    for ax, y in ((ax_fq, np.abs(r.Q_per_w)), (ax_fv, np.abs(r.V_oc_per_w))):
        ax.loglog(f[ok], y[ok], ls, marker=mk, markevery=(3 * k, 12), color="k", label=model)
        ax.loglog(f[~ok], y[~ok], ls, color="k", lw=0.6)
f_bad = f[~r.check_one_way][0]
for ax in (ax_fq, ax_fv):
    ax.axvline(f_bad, color="0.5", lw=0.8)
    ax.axvline(r.f_stream, color="0.5", lw=0.8, ls="-.")
    ax.set_xlabel("frequency f [Hz]")
    ax.legend(fontsize=8)
ax_fq.set_ylabel("|Q/w| short circuit [C/m]")
ax_fv.set_ylabel("|V_oc/w| open circuit [V/m]")
ax_fv.text(r.f_stream, ax_fv.get_ylim()[1], " f_stream", va="top", fontsize=8)
ax_fv.text(f_bad, ax_fv.get_ylim()[0], " one-way bound", va="bottom", fontsize=8)
fig2.suptitle("small signal, tip force: thick markers where the model holds, thin lines where it flags itself")
fig2.tight_layout()

# the harvester: mean power into R at 5 mHz, tip amplitude 1 mm
R = np.geomspace(10.0, 1e6, 200)
fig3, ax_p = plt.subplots(figsize=(5.5, 3.8))
for k, (model, (ls, mk)) in enumerate(styles.items()):
    r = ia.sensing_response([5e-3], strip, model=model, amplitude=1e-3)
    P = r.power_at(R)[0]
    ax_p.loglog(R, P, ls, marker=mk, markevery=(5 * k, 25), color="k", label=model)
    Zm = abs(r.Z[0])
    ax_p.plot([Zm], [r.power_at([Zm])[0, 0]], marker=mk, ms=9, mfc="w", color="k")
    print(f"{model:8s} at 5 mHz: |Z| = {Zm:.4g} Ohm, P(R = |Z|) = {r.power_at([Zm])[0, 0]:.3g} W, valid {bool(r.valid[0])}")
ax_p.set_xlabel("load resistance R [Ohm]")
ax_p.set_ylabel("mean power P [W]")
ax_p.legend(fontsize=8, title="open marker: R = |Z|", title_fontsize=8)
ax_p.set_title("harvester at 5 mHz, tip amplitude 1 mm", fontsize=10)
fig3.tight_layout()
plt.show()
