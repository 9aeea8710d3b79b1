"""
Fitting a step series and an impedance spectrum together
========================================================

One strip, two experiments: the current and tip deflection after a 0.5 V step
(``examples/dynamic_step.csv``, the columns ``ipmc-asym step --out`` writes: ``phi0`` in V,
``current_density`` in A/m², the paper's signed ``w`` in m, read as they are) and its impedance
spectrum about 0 V (``examples/dynamic_spectrum.csv``: ``f`` in Hz, ``Z_abs`` in Ohm,
``Z_phase`` in degrees).  Both files are synthetic, made by the toolkit with seeded noise
(``examples/make_dynamic_fit_data.py``) from D = 3e-10 m²/s and C_moy = 2600 mol/m³; the
fit starts from the material's D = 1e-10 m²/s and C_moy = 3082 mol/m³.

:func:`ipmc_asym.fit` takes paths (or data sets) of every kind: time series and spectra go
to the dynamic fit (the step through the reduced circuit, checked against the PNP solver at
the optimum; the spectrum through the exact linearised PNP).  The strip is the one the data
were taken on (the per-area columns are multiplied by its electrode area 2l L).
"""

import pathlib

import matplotlib.pyplot as plt
import numpy as np

import ipmc_asym as ia

try:
    here = pathlib.Path(__file__).resolve().parent
except NameError:  # run interactively
    here = pathlib.Path.cwd()
files = [here.parent / "dynamic_step.csv", here.parent / "dynamic_spectrum.csv"]

strip = ia.Strip(length=0.02, width=5e-3, thickness=200e-6)
res = ia.fit(files, "D,c_moy", strip=strip)
print(f"{res.n_points} measured values; fidelity: {res.fidelity}")
print(f"noise scale s = {res.noise_scale:.3g} (relative, estimated: the files carry no sigma_ columns)")
for name, unit in (("diffusion", "m^2/s"), ("c_moy", "mol/m^3")):
    p = res.parameters[name]
    print(f"{name:9s} = {p['value']:.4g} {unit}, 95 % interval [{p['ci95'][0]:.4g}, {p['ci95'][1]:.4g}]")

# %%
# Data and fitted model: the step's current and tip deflection (the fit's ``deflection`` is
# ``-w``, positive in the direction a positive voltage bends the strip), the spectrum's ``|Z|`` and
# phase.  ``res.data`` and ``res.predictions`` hold one entry per file, in SI units.
step, spec = res.data
p_step, p_spec = res.predictions
fig, ax = plt.subplots(2, 2, figsize=(8.5, 5.6))
t_ms = 1e3 * step.t
ax[0, 0].plot(t_ms, 1e3 * step.measured["current"], "o", ms=3.5, mfc="none", label="data")
ax[0, 0].plot(t_ms, 1e3 * p_step["current"], "-", label="fitted model")
ax[0, 0].set(xlabel="time t [ms]", ylabel="current I [mA]")
ax[0, 1].plot(t_ms, 1e3 * step.measured["deflection"], "s", ms=3.5, mfc="none", label="data")
ax[0, 1].plot(t_ms, 1e3 * p_step["deflection"], "-", label="fitted model")
ax[0, 1].set(xlabel="time t [ms]", ylabel="tip deflection −w [mm]")
ax[1, 0].loglog(spec.f, spec.measured["Z_abs"], "o", ms=3.5, mfc="none", label="data")
ax[1, 0].loglog(spec.f, p_spec["Z_abs"], "-", label="fitted model")
ax[1, 0].set(xlabel="frequency f [Hz]", ylabel="|Z| [Ω]")
ax[1, 1].semilogx(spec.f, np.degrees(spec.measured["Z_phase"]), "^", ms=3.5, mfc="none", label="data")
ax[1, 1].semilogx(spec.f, np.degrees(p_spec["Z_phase"]), "-", label="fitted model")
ax[1, 1].set(xlabel="frequency f [Hz]", ylabel="phase of Z [deg]")
for a in ax.flat:
    a.legend(fontsize=8)
fig.tight_layout()
plt.show()
