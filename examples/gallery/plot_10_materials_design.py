"""
Material sets and design for a target
=====================================

:data:`ipmc_asym.materials` holds named material sets, one file each, every value with the
source it was read from (``ipmc-asym materials NAME`` shows them; ``--material NAME`` or a
TOML file of your own uses one).  Here the paper's Nafion Li\\ :sup:`+` set and the DuPont
N-117 (H\\ :sup:`+`) set bend the nominal strip, and :func:`ipmc_asym.design` picks the
length and total thickness that give the largest blocking force while the free strip still
deflects 2 mm, with the force/deflection Pareto front.  Every candidate goes through the one
forward model (with escalation), so no design rests on an invalid number.
"""

import matplotlib.pyplot as plt
import numpy as np

import ipmc_asym as ia

print(ia.materials.names())
for name in ("nafion-li", "nafion-117-h"):
    m = ia.materials.get(name)
    r = ia.evaluate(ia.Strip(), "constant", "corrected", material=m)
    print(f"{name:14s} C_moy = {m.C_moy:7.1f} mol/m^3, E = {m.E / 1e6:5.0f} MPa: "
          f"w = {r['w'] * 1e3:6.2f} mm, F_block = {r['F_block'] * 1e3:5.3f} mN")
print(ia.materials.bibliography(ia.materials.get("nafion-117-h")))

# %%
spec = {"model": "constant",
        "strip": {"width": "5mm", "voltage": "1V"},              # fixed; width is TOTAL 2l
        "vary": {"length": ["1cm", "4cm"], "thickness": ["100um", "400um"]},  # thickness TOTAL 2e
        "objective": {"maximize": "blocking_force"},
        "constraints": {"tip_deflection": {"min": "2mm"}},
        "pareto": {"x": "tip_deflection", "y": "blocking_force", "points": 60}}
res = ia.design(spec)
opt = res.optimum
print({k: f"{v:.4g}" for k, v in opt["inputs"].items()})
print(f"F_block = {abs(opt['outputs']['blocking_force']) * 1e3:.4g} mN, "
      f"|w| = {abs(opt['outputs']['tip_deflection']) * 1e3:.4g} mm; active: "
      f"{[a['name'] for a in res.active_constraints]}")

# %%
front = np.array([[abs(p["outputs"]["tip_deflection"]), abs(p["outputs"]["blocking_force"])] for p in res.pareto])
fig, ax = plt.subplots(figsize=(5.5, 3.8))
ax.plot(front[:, 0] * 1e3, front[:, 1] * 1e3, "o-", ms=3, mfc="white", label="Pareto front")
ax.plot(abs(opt["outputs"]["tip_deflection"]) * 1e3, abs(opt["outputs"]["blocking_force"]) * 1e3, "*", ms=14,
        label="optimum (|w| ≥ 2 mm)")
ax.axvline(2.0, color="0.5", ls=":", lw=1)
ax.set_xlabel("tip deflection |w| [mm]")
ax.set_ylabel("blocking force |F| [mN]")
ax.set_title("L in 1-4 cm, total thickness 2e in 100-400 µm, 1 V", fontsize=10)
ax.grid(alpha=0.3)
ax.legend(fontsize=8)
fig.tight_layout()
plt.show()
