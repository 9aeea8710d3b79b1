"""The small-voltage (Debye-Hueckel) branch of every rung: the series of ``_generated_dh``.

Below ``DH_A2`` the rungs' own kernels lose ~``eps/A2`` relative digits (they divide
quantities of order ``A2`` by ``A2``) and fail outright in the subnormal range; the series of
``derivations/debye_hueckel.py`` is exact as ``A2 -> 0`` and carries its own remainder bound
``2 (K4A + K4B |A3|) n(u) A2^4`` (``n = I0/(1 + A3)``, ``u = 1/lam``).  At ``A2 = 0`` every
result is 0 (the callers test that first).
"""

from __future__ import annotations

from ipmc_asym.kernels import _generated_dh as G
from ipmc_asym.kernels.jit import jit

__all__ = ["DH_A2", "dh_exact", "dh_layer"]

#: the rungs use the series below this ``A2`` (``derivations/debye_hueckel.py``)
DH_A2 = G.DH_A2


@jit
def _remainder(lam, A2, A3):
    """Bound on the neglected ``A2^4`` and higher terms of ``I`` (absolute, dimensionless)."""
    a4 = A2 * A2
    a4 = a4 * a4  # underflows to 0 for tiny A2: the series is then exact to rounding
    return 2.0 * (G.DH_K4A + G.DH_K4B * abs(A3)) * G.dh_norm(1.0 / lam) * a4


@jit
def dh_exact(lam, A2, A3, rho):
    """``(I, relative error bound, B1)`` of the full problem (any ``lam``; ``0 < A2 < DH_A2``)."""
    I = G.dh_moment(1.0 / lam, A2, A3, rho)
    r = _remainder(lam, A2, A3)
    return I, r / abs(I) if I != 0.0 else (0.0 if r == 0.0 else 1.0e300), G.dh_b1(A2, rho)


@jit
def dh_layer(lam, A2, A3, rho, order):
    """``(I, relative error bound, B1, core)`` of the layer rungs (``0 < A2 < DH_A2``).

    ``order`` 1: ``I = lam J1`` (``leading``), whose neglected ``lam^2 J2`` enters the bound as in
    :func:`ipmc_asym.kernels.closed.closed_finish`; otherwise ``lam J1 + lam^2 J2``.  The core
    interaction (exponentially small in ``1/lam``) is the callers' to add, as for the closed
    forms; ``core`` follows :func:`~ipmc_asym.kernels.closed.closed_finish` (no depletion zone
    at these voltages: ``2 - 20 lam``).
    """
    J1, J2 = G.dh_layer_j(A2, A3, rho)
    r = _remainder(lam, A2, A3)
    if order == 1:
        I = lam * J1
        a = abs(lam * lam * J2) + r
        d = abs(I) - a
        err = a / d if d > 0.0 else 1.0e300
    else:
        I = lam * J1 + lam * lam * J2
        err = r / abs(I) if I != 0.0 else 1.0e300
    return I, err, G.dh_b1(A2, rho), 2.0 - 20.0 * lam
