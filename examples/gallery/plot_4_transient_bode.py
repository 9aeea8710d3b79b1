"""
Charging transient and Bode plot
================================

:func:`ipmc_asym.step_response` gives the charging transient after a voltage step (reduced
circuit model), :func:`ipmc_asym.frequency_response` the impedance and the tip-deflection
transfer function about zero volts.
"""

import matplotlib.pyplot as plt
import numpy as np

import ipmc_asym as ia

strip = ia.Strip()
step = ia.step_response(1.0, strip=strip, points=300)
print(f"time constant tau = {step.tau:.4g} s")

freq = np.logspace(-3, 3, 120) / step.tau
fr = ia.frequency_response(freq, strip=strip)

fig, axes = plt.subplots(1, 3, figsize=(11, 3.4))
axes[0].plot(step.t / step.tau, 1e3 * np.abs(step.w))
axes[0].set_xlabel("t / tau")
axes[0].set_ylabel("tip deflection |w| [mm]")
axes[0].set_title("step of 1 V", fontsize=10)
axes[1].loglog(fr.f, np.abs(fr.H_w) * 1e3)
axes[1].set_xlabel("frequency [Hz]")
axes[1].set_ylabel("|H_w| [mm/V]")
axes[1].set_title("deflection / voltage", fontsize=10)
axes[2].semilogx(fr.f, np.degrees(np.angle(fr.H_w)))
axes[2].set_xlabel("frequency [Hz]")
axes[2].set_ylabel("phase [deg]")
fig.tight_layout()
plt.show()
