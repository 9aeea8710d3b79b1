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

thickness = np.array([100e-6, 200e-6, 300e-6, 400e-6])  # TOTAL thickness 2e (at 5 mm wide: 2l/2e >= 10 up to 500 um)
voltage = np.linspace(0.05, 1.5, 30)
rows = ia.sweep(vary={"thickness": thickness, "voltage": voltage}, model="constant", fidelity="corrected")
print(len(rows), "rows;", int(rows["valid"].sum()), "valid")

# %%
# Scaling with the thickness at 1 V: the slope of log|w_small| against log(2e), over the rows where
# the small-displacement deflection is given (past a full turn it is withheld: NaN). The exponent
# is -2: w_small = -M_A L^2/(2 E I_p), with M_A = A5 I, A5 ~ e^2 and I ~ lambda/e (the Debye
# layers' share of the thickness), so M_A ~ e, and I_p ~ e^3 at a fixed width. The rows outside a
# model assumption (thin strips curl past a quarter turn, thick ones are not slender) are hollow.
th = np.logspace(-4.5, -2.5, 40)
r2 = ia.sweep(vary={"thickness": th}, model="constant", fidelity="corrected", base=ia.Strip(voltage=1.0))
given = np.isfinite(r2["w_small"])
r2 = r2[given]
slope = np.gradient(np.log(np.abs(r2["w_small"])), np.log(r2["thickness"]))
print(f"local exponent of w_small in 2e over {given.sum()} of {given.size} rows: {slope.min():.4f} .. {slope.max():.4f}")

# %%
fig, axes = plt.subplots(1, 2, figsize=(9, 3.6))
styles = [("o", "-"), ("s", "--"), ("^", ":"), ("D", "-.")]
for (marker, line), t in zip(styles, thickness):
    r = rows[(rows["thickness"] == t) & rows["valid"]]
    axes[0].plot(r["voltage"], 1e3 * np.abs(r["w"]), marker=marker, linestyle=line, ms=3, color="k",
                 label=f"2e = {1e6 * t:g} µm")
axes[0].set_xlabel("voltage φ0 [V]")
axes[0].set_ylabel("tip deflection |w| [mm]")
axes[0].legend(fontsize=8)
axes[1].semilogx(1e6 * r2["thickness"], slope, "k-")
ok = r2["valid"]
axes[1].semilogx(1e6 * r2["thickness"][ok], slope[ok], "ko", ms=3, label="inside every assumption")
axes[1].semilogx(1e6 * r2["thickness"][~ok], slope[~ok], "o", ms=3, mfc="none", mec="k", label="flagged")
axes[1].set_ylim(-2.05, -1.95)
axes[1].ticklabel_format(axis="y", useOffset=False)
axes[1].set_xlabel("total thickness 2e [µm]")
axes[1].set_ylabel("d ln|w_small| / d ln(2e)")
axes[1].legend(fontsize=8)
fig.tight_layout()
plt.show()
