"""
The strip as a curvature sensor (static)
========================================

:func:`ipmc_asym.sense` bends the strip (here a tip force on the cantilever) and returns the
charge that flows between short-circuited electrodes once water and cations have relaxed, and
the open-circuit voltage.  The three permittivity models of the paper share the linear response
up to their core permittivity (``docs/sensing.md``): the constant model's layers hold ~14 times
less charge (linear and affine nearly coincide), while the open-circuit voltage -- the Donnan difference of the fixed charge
between the faces -- is the same for all three.  Lines are told apart by style and marker.
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
plt.show()
