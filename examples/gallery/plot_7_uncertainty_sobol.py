"""
Uncertainty and Sobol' indices
==============================

:func:`ipmc_asym.uq` pushes a scene's ``[uncertain]`` inputs through the model (here
``examples/uq_nominal.toml``: scatter of thickness, length, voltage, modulus and mean
concentration) and returns quantiles, moments and Sobol' first and total indices with
95 % intervals.  A few thousand samples are enough for a first look.
"""

import pathlib

import matplotlib.pyplot as plt
import numpy as np

import ipmc_asym as ia

try:
    here = pathlib.Path(__file__).resolve().parent
except NameError:  # run interactively
    here = pathlib.Path.cwd()
res = ia.uq(here.parent / "uq_nominal.toml", 2**10, seed=0)
print(f"{res.n_samples} model runs, fidelity {res.fidelity}")
for out in ("tip_deflection", "blocking_force"):
    s = res.summary[out]
    print(f"{out:15s} median {s['q50']:.4g} {s['unit']}, 95 % range [{s['q2.5']:.4g}, {s['q97.5']:.4g}]")

# %%
# First-order (S1) and total (ST) indices of the tip deflection, with their 95 % intervals.
idx = res.sobol["tip_deflection"]
names = list(idx)
x = np.arange(len(names))
fig, ax = plt.subplots(figsize=(6, 3.6))
ax.bar(x - 0.2, [idx[n]["S1"] for n in names], 0.4, yerr=[idx[n]["S1_conf"] for n in names], label="S1")
ax.bar(x + 0.2, [idx[n]["ST"] for n in names], 0.4, yerr=[idx[n]["ST_conf"] for n in names], label="ST")
ax.set_xticks(x, names)
ax.set_ylabel("Sobol' index")
ax.set_title("tip deflection", fontsize=10)
ax.legend()
fig.tight_layout()
plt.show()
