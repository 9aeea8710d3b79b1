"""
Profiles through the thickness (BVP)
====================================

:func:`ipmc_asym.solve_bvp_profile` solves the full nonlinear boundary-value problem and
returns the dimensionless profiles on its mesh (``z`` = z/e from the anode at -1 to the
cathode at +1): concentration, potential, field, pressure.
"""

import matplotlib.pyplot as plt

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
# The layers are thin: concentration against the distance from each face, in micrometres,
# on logarithmic axes.  Near the anode the cations are depleted: the curve is drawn where
# C / C_moy stays above 1e-12.
fig, ax = plt.subplots(figsize=(5, 3.4))
d_cathode = (1 - res.z) * strip.e
d_anode = (1 + res.z) * strip.e
near_c, near_a = (d_cathode > 0) & (res.z > 0), (d_anode > 0) & (res.z < 0) & (res.C > 1e-12)
ax.loglog(1e6 * d_cathode[near_c], res.C[near_c], label="from the cathode (z = +e)")
ax.loglog(1e6 * d_anode[near_a], res.C[near_a], label="from the anode (z = -e)")
ax.set_xlabel("distance from the face [µm]")
ax.set_ylabel("C / C_moy")
ax.set_xlim(1e-4, 1e6 * strip.e)
ax.legend(fontsize=8)
fig.tight_layout()
plt.show()
