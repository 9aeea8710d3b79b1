"""
The paper's figures 4-10
========================

:func:`ipmc_asym.figures` writes the paper's figures again from the toolkit's models: the
profiles through the thickness (Figs 4-7, full BVP, with zooms at each electrode) and the
influence of the length, the thickness and the voltage on the deflection, the blocking force
and the rotation (Figs 8-10), the three permittivity models side by side.  ``quick=True``
takes every third point of the influence curves (the command ``ipmc-asym figures --out DIR``
draws them all).  The files are PNGs; here two of them are shown.
"""

import pathlib
import tempfile

import matplotlib.pyplot as plt

import ipmc_asym as ia

out = pathlib.Path(tempfile.mkdtemp()) / "figures"
result = ia.figures(out, quick=True, log=print)
for f in result["files"]:
    print(pathlib.Path(f).name)

# %%
# Fig. 4, the cation concentration: the full thickness on a stretched axis (left), the
# depleted anode layer and the cathode's accumulation layer against the distance from each face.
for name in ("profile_C.png", "influence_voltage.png"):
    img = plt.imread(out / name)
    fig, ax = plt.subplots(figsize=(11, 11 * img.shape[0] / img.shape[1]))
    ax.imshow(img)
    ax.set_axis_off()
    fig.tight_layout(pad=0)
plt.show()
