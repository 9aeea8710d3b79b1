"""Layer quadrature: the exact layer integrals with a neutral core (fidelity ``quadrature``).

The layer functions (``derivations/model.py``)

    W0(Y) = int_0^Y w(y) dy,        W1(Y) = int_0^Y (w(y)/y) W0(y) dy

are integrated with composite Gauss-Legendre panels whose breakpoints double
(0, 1/2, 1, 2, 4, ... ``|Y|``): ``w`` is analytic with its nearest complex singularities at a
distance comparable to ``|y|``, so each panel converges geometrically.  ``W0`` at the
nodes comes from the spectral cumulative-integration matrix of the panel, so ``W1`` costs
no extra evaluations of ``w``.  Along the way the distance from the wall to the point where
``|y| = 1`` is accumulated (``int w/|y| dy``): the layer width used by the validity check.
"""

from __future__ import annotations

import math

import numpy as np

from ipmc_asym.kernels._generated import assemble_j, b1_exact, dhat, w_layer
from ipmc_asym.kernels.jit import jit
from ipmc_asym.kernels.special import gauss_legendre

__all__ = ["layer_functions", "moment_quadrature", "doubling_panels", "NODES"]

NODES = 10
_X, _W, _S = gauss_legendre(NODES)
_X = np.ascontiguousarray(_X)
_W = np.ascontiguousarray(_W)
_S = np.ascontiguousarray(_S)


def doubling_panels(integrand):
    """``int_0^T f(u) du`` on Gauss-Legendre panels with breakpoints 0, 1/2, 1, 2, 4, ... ``T``
    (the layer scheme above), compiled for one ``integrand``.

    ``integrand(u, sgn, par, wt)`` returns ``wt f(u)``, the node's weight applied by the
    integrand (where it enters the rounding is the integrand's); ``sgn`` and ``par`` are passed
    on (``y = sgn u``).  Returns the jitted ``panels(T, sgn, par, X, Wt)`` (``T > 0``; NaN for a ``T`` not finite; ``X``,
    ``Wt`` the nodes and weights on [-1, 1]).
    """

    @jit
    def panels(T, sgn, par, X, Wt):
        if not T < math.inf:  # NaN would never meet the end test below (b >= T), inf gives junk
            return math.nan
        total = 0.0
        a = 0.0
        b = min(0.5, T)
        while True:
            hm = 0.5 * (b - a)
            xm = 0.5 * (a + b)
            s = 0.0
            for j in range(X.shape[0]):
                s += integrand(xm + hm * X[j], sgn, par, Wt[j])
            total += hm * s
            if b >= T:
                break
            a = b
            b = min(2.0 * b, T)
        return total

    return panels


@jit
def _layer(Y, rho, X, Wt, S):
    """Return (W0(Y), W1(Y), width) where width = int_{``|y|``>=1} w/``|y|`` dy (units of lambda)."""
    n = X.shape[0]
    sgn = 1.0 if Y >= 0.0 else -1.0
    T = abs(Y)
    f = np.empty(n)
    W0 = 0.0
    W1 = 0.0
    width = 0.0
    a = 0.0
    b = 0.5
    while a < T:
        if b > T:
            b = T
        h = 0.5 * (b - a)
        for i in range(n):
            s = a + h * (X[i] + 1.0)
            f[i] = w_layer(sgn * s, rho)
        # cumulative W0 at the nodes, then W1 increment
        acc1 = 0.0
        accw = 0.0
        for i in range(n):
            cum = 0.0
            for j in range(n):
                cum += S[i, j] * f[j]
            s = a + h * (X[i] + 1.0)
            w0_i = sgn * (W0 + h * cum)
            acc1 += Wt[i] * (f[i] / s) * w0_i
            accw += Wt[i] * f[i] / s
        tot = 0.0
        for i in range(n):
            tot += Wt[i] * f[i]
        W0 += h * tot
        W1 += h * acc1
        if a >= 1.0:
            width += h * accw
        a = b
        b = 2.0 * b if b >= 1.0 else b + 0.5
    return sgn * W0, W1, width


@jit
def layer_functions(Y, rho):
    """``(W0(Y), W1(Y), width)`` by composite Gauss-Legendre (see module docstring)."""
    return _layer(Y, rho, _X, _W, _S)


@jit
def moment_quadrature(lam, A2, A3, rho):
    """Moment integral ``I`` (for ``|phi0|``) with the core neutral.

    Parameters
    ----------
    lam : float  core Debye length / e, ``sqrt((A0 + A1)/A2)``
    A2, A3 : float  dimensionless groups (``A2 > 0``)
    rho : float  ``A1/(A0 + A1)`` in [0, 1]

    Returns
    -------
    I, J1, J2, B1, core : floats
        ``I = lam J1 + lam^2 J2``; ``core`` is the length of the core left between the two
        layers (``2 - widths``, in units of e), used for the validity check.
    """
    B1 = b1_exact(A2, rho)
    Yc = math.log(B1)
    Ya = Yc - A2
    cm = B1 * math.exp(-A2)
    W0c, W1c, wc = layer_functions(Yc, rho)
    W0a, W1a, wa = layer_functions(Ya, rho)
    J1, J2 = assemble_j(A2, A3, rho, B1, cm, dhat(Yc, rho), W0c, W0a, W1c, W1a)
    core = 2.0 - lam * (wc + wa)
    return lam * J1 + lam * lam * J2, J1, J2, B1, core
