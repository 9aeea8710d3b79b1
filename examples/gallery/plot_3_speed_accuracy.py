"""
Speed against accuracy
======================

:func:`ipmc_asym.moment_integral` at each closed-form or quadrature fidelity on 10^5
thicknesses, timed, and its error against ``fidelity="exact"``.  The first call of each
fidelity loads its compiled kernel, so each is timed after a first call (``exact`` on the call
after the reference), best of three.  Times depend on the machine and its load.
"""

import time

import matplotlib.pyplot as plt
import numpy as np

import ipmc_asym as ia

thickness = np.logspace(-4.5, -2.5, 10**5)  # TOTAL thickness 2e, 32 µm .. 3.2 mm
voltage = 1.0
ref = ia.moment_integral(thickness, voltage, model="constant", fidelity="exact")

seconds, errors = {}, {}
for fid in ("leading", "corrected", "quadrature", "exact"):
    if fid != "exact":
        ia.moment_integral(thickness, voltage, model="constant", fidelity=fid)
    best = float("inf")
    for _ in range(1 if fid == "exact" else 3):  # best of 3: the machine may be busy
        t0 = time.perf_counter()
        val = ia.moment_integral(thickness, voltage, model="constant", fidelity=fid)
        best = min(best, time.perf_counter() - t0)
    seconds[fid] = best
    errors[fid] = float(np.max(np.abs(val / ref - 1)))
    ns = 1e9 * seconds[fid] / thickness.size
    print(f"{fid:10s} {ns:8.1f} ns a point   max rel. error vs exact {errors[fid]:.2e}")

# %%
fig, ax = plt.subplots(figsize=(5, 3.6))
for fid in seconds:
    ax.loglog(1e9 * seconds[fid] / thickness.size, max(errors[fid], 1e-17), "o")
    ax.annotate(fid, (1e9 * seconds[fid] / thickness.size, max(errors[fid], 1e-17)),
                textcoords="offset points", xytext=(5, 5))
ax.set_ylim(top=1.0)
ax.set_xlabel("time per point [ns]")
ax.set_ylabel("max relative error vs exact\n(exact itself drawn at 1e-17)")
ax.set_title("moment integral, constant model, φ0 = 1 V", fontsize=10)
fig.tight_layout()
plt.show()
