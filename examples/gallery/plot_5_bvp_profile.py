"""
Profiles through the thickness (BVP)
====================================

:func:`ipmc_asym.solve_bvp_profile` solves the full nonlinear boundary-value problem and
returns the dimensionless profiles on its mesh (``z`` = z/e from the anode at -1 to the
cathode at +1): concentration, potential, field, pressure.
"""

import matplotlib.pyplot as plt
import numpy as np

import ipmc_asym as ia

strip = ia.Strip()
res = ia.solve_bvp_profile(strip, "constant")
print(f"I = {res.I:.6g}, B1 = {res.B1:.5g}, {res.z.size} mesh nodes")

fig, axes = plt.subplots(1, 3, figsize=(11, 3.4))
axes[0].semilogy(res.z, res.C)
axes[0].set_ylabel("C / C_moy")
axes[1].plot(res.z, res.phi)
axes[1].set_ylabel("φ / φ0")
axes[2].plot(res.z, res.p)
axes[2].set_ylabel("pressure p̄")
for ax in axes:
    ax.set_xlabel("z / e")

# %%
# The layers are thin: a zoom at the cathode, in micrometres from the face.
fig, ax = plt.subplots(figsize=(5, 3.4))
near = res.z > 0.9
ax.semilogy(1e6 * (1 - res.z[near]) * strip.e, res.C[near])
ax.set_xlabel("distance from the cathode [µm]")
ax.set_ylabel("C / C_moy")
ax.set_xlim(0, 1e6 * 0.1 * strip.e)
fig.tight_layout()
plt.show()
