"""A reference loop for the bench: what "a loop of 7 transcendental calls" costs per point.

The bench states the cost of the closed-form kernels against this yardstick (``leading``
<= 1.5x, ``corrected`` <= 2.0x, API included).  The loop reads two inputs per point and makes
seven independent libm calls (``exp``, ``log``, ``expm1``, ``log1p``, ``exp``, ``log``,
``expm1``) -- independent, so the processor overlaps them: the fastest way of spending seven
transcendental calls on a point -- and writes one output, like a kernel would.
"""

from __future__ import annotations

import math

from ipmc_asym.kernels.jit import jit

__all__ = ["seven_transcendentals"]


@jit
def seven_transcendentals(t, v, out):
    """``out[i] = exp(-v) + log(t) + expm1(-v) + log1p(t) + exp(t) + log(v) + expm1(t)`` (t, v > 0)."""
    for i in range(t.size):
        x = t[i]
        y = v[i]
        out[i] = (math.exp(-y) + math.log(x) + math.expm1(-y) + math.log1p(x)
                  + math.exp(x) + math.log(y) + math.expm1(x))
