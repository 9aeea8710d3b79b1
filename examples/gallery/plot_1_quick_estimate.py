"""
Quick estimate for your strip
=============================

Put your strip's geometry and voltage in :class:`ipmc_asym.Strip` (SI; ``thickness`` and
``width`` are TOTAL) and :func:`ipmc_asym.evaluate` returns every output, with the fidelity
that was used and the four validity checks.
"""

import matplotlib.pyplot as plt

import ipmc_asym as ia

strip = ia.Strip(length=0.02, width=5e-3, thickness=200e-6, voltage=1.0)
results = {m: ia.evaluate(strip, m, "corrected") for m in ia.MODELS}

for m, r in results.items():
    print(f"{m:9s} I = {r['I']:.5g}  M_A = {r['M_A']:.4g} N m  tip deflection = {1e3 * abs(r['w']):.4g} mm  "
          f"blocking force = {1e3 * abs(r['F_block']):.4g} mN  fidelity {r['fidelity_used']}  valid {r['valid']}")

# %%
# The three permittivity models side by side.
fig, axes = plt.subplots(1, 2, figsize=(8, 3.2))
names = list(results)
axes[0].bar(names, [1e3 * abs(results[m]["w"]) for m in names], color="C0")
axes[0].set_ylabel("tip deflection |w| [mm]")
axes[1].bar(names, [1e3 * abs(results[m]["F_block"]) for m in names], color="C1")
axes[1].set_ylabel("blocking force |F| [mN]")
fig.suptitle(f"L = {1e3 * strip.length:g} mm, 2e = {1e6 * strip.thickness:g} µm, φ0 = {strip.voltage:g} V")
fig.tight_layout()
plt.show()
