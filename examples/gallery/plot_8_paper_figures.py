"""
The paper's figures 4-10
========================

:func:`ipmc_asym.figures` writes the paper's figures again from the toolkit's models: the
profiles through the thickness (Figs 4-7, full BVP, with zooms at each electrode) and the
influence of the length, the thickness and the voltage on the deflection, the blocking force
and the rotation (Figs 8-10), the three permittivity models side by side.  ``quick=True``
takes every third point of the influence curves (the command ``ipmc-asym figures --out DIR``
draws them all, as PDF for print by default).  Here the files are PNGs (the library's default
format) and two of them are shown.
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
# Fig. 4, the cation concentration: the full thickness on a stretched axis (top), the
# depleted anode layer and the cathode's accumulation layer against the distance from each face,
# from 1 nm (the continuum scale); then Fig. 10, the influence of the voltage.
for name in ("profile_C.png", "influence_voltage.png"):
    img = plt.imread(out / name)
    width = 4.5 if img.shape[1] < img.shape[0] else 9.0
    fig, ax = plt.subplots(figsize=(width, width * img.shape[0] / img.shape[1]))
    ax.imshow(img)
    ax.set_axis_off()
    fig.tight_layout(pad=0)
plt.show()
