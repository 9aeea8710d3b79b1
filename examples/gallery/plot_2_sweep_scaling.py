"""
Thickness and voltage sweep, and scaling
========================================

:func:`ipmc_asym.sweep` evaluates the grid spanned by ``vary`` (name -> 1-D values, SI) and
returns one row per point (a NumPy structured array).  Here: tip deflection against voltage for
four total thicknesses, and the local power-law exponent of the deflection in the thickness.
Only the rows inside every model assumption (``valid``) are drawn: the others are kept in
``rows``, flagged (``check_*``; past a quarter turn the free strip curls back).
"""

import matplotlib.pyplot as plt
import numpy as np

import ipmc_asym as ia

thickness = np.array([100e-6, 200e-6, 400e-6, 800e-6])  # TOTAL thickness 2e
voltage = np.linspace(0.05, 1.5, 30)
rows = ia.sweep(vary={"thickness": thickness, "voltage": voltage}, model="constant", fidelity="corrected")
print(len(rows), "rows;", int(rows["valid"].sum()), "valid")

# %%
# Scaling with the thickness at 1 V: the slope of log|w_small| against log(2e).
th = np.logspace(-4.5, -2.5, 40)
r2 = ia.sweep(vary={"thickness": th}, model="constant", fidelity="corrected", base=ia.Strip(voltage=1.0))
slope = np.gradient(np.log(np.abs(r2["w_small"])), np.log(r2["thickness"]))
print(f"local exponent of w_small in 2e: {slope.min():.3f} .. {slope.max():.3f}")

# %%
fig, axes = plt.subplots(1, 2, figsize=(9, 3.6))
for t in thickness:
    r = rows[(rows["thickness"] == t) & rows["valid"]]
    axes[0].plot(r["voltage"], 1e3 * np.abs(r["w"]), "o-", ms=3, label=f"2e = {1e6 * t:g} µm")
axes[0].set_xlabel("voltage φ0 [V]")
axes[0].set_ylabel("tip deflection |w| [mm]")
axes[0].legend(fontsize=8)
axes[1].semilogx(1e6 * r2["thickness"], slope)
axes[1].set_xlabel("total thickness 2e [µm]")
axes[1].set_ylabel("d ln|w_small| / d ln(2e)")
fig.tight_layout()
plt.show()
