"""
Fitting your own measurements
=============================

:func:`ipmc_asym.read_fit_data` reads a CSV of measurements (header row; SI numbers or values
with units; measured ``deflection`` and/or ``blocking_force``, optional ``sigma_*`` columns)
and :func:`ipmc_asym.fit` estimates the free parameters with standard errors and 95 %
profile-likelihood intervals.  The file here is synthetic (``examples/fit_synthetic.csv``).
"""

import pathlib

import matplotlib.pyplot as plt
import numpy as np

import ipmc_asym as ia

try:
    here = pathlib.Path(__file__).resolve().parent
except NameError:  # run interactively
    here = pathlib.Path.cwd()
csv = here.parent / "fit_synthetic.csv"

data = ia.read_fit_data(csv)
res = ia.fit(data, "modulus", fidelity="corrected")
p = res.parameters["modulus"]
print(f"{res.n_points} measured values, chi2_red = {res.chi2_red:.3g}")
print(f"modulus = {p['value'] / 1e6:.4g} MPa +- {p['stderr'] / 1e6:.2g} MPa, "
      f"95 % interval [{p['ci95'][0] / 1e6:.4g}, {p['ci95'][1] / 1e6:.4g}] MPa")

# %%
# Data with their one-sigma error bars, and the fitted model, for each total thickness.
v = data.geometry["voltage"]
th = data.geometry["thickness"]
fig, axes = plt.subplots(1, 2, figsize=(9, 3.6))
for ax, key, unit in zip(axes, ("deflection", "blocking_force"), ("mm", "mN")):
    for j, t in enumerate(np.unique(th)):
        s = th == t
        o = np.argsort(v[s])
        ax.errorbar(v[s], 1e3 * data.measured[key][s], yerr=1e3 * data.sigma[key][s], fmt="o", ms=4,
                    color=f"C{j}", label=f"data, 2e = {1e6 * t:g} µm")
        ax.plot(v[s][o], 1e3 * res.predictions[key][s][o], "-", color=f"C{j}", label="fitted model" if j == 0 else None)
    ax.set_xlabel("voltage φ0 [V]")
    ax.set_ylabel(f"{key.replace('_', ' ')} [{unit}]")
    ax.legend(fontsize=8)
fig.tight_layout()
plt.show()
