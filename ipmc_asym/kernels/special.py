"""Numerically careful special functions used by the generated kernels.

These are numerics primitives, not results of the model: the derivation
(``derivations/``) writes its formulas in terms of them so that the generated code
never suffers cancellation or overflow.

* ``exprel(y) = (e^y - 1) / y``            (1 at y = 0)
* ``e2rel(y)  = 2 (e^y - 1 - y) / y^2``    (1 at y = 0)
* ``li2(u)``, ``li3(u)``: real polylogarithms for ``u <= 1``.
* ``gauss_legendre(n)``: nodes, weights and the cumulative-integration matrix.
"""

from __future__ import annotations

import math

import numpy as np

from ipmc_asym.kernels.jit import jit
from ipmc_asym.kernels.quadrature_nodes import leggauss

__all__ = ["exprel", "e2rel", "li2", "li3", "gauss_legendre", "ZETA2", "ZETA3"]

ZETA2 = math.pi**2 / 6.0
ZETA3 = 1.2020569031595942853997381615114499907649862923405


@jit
def exprel(y):
    """``(e^y - 1)/y`` without cancellation (``math.expm1``); 1 at ``y = 0``."""
    if y == 0.0:
        return 1.0
    if y > 700.0:
        return math.inf
    return math.expm1(y) / y


_E2REL_TAYLOR = np.array([2.0 / math.factorial(k + 2) for k in range(15)])


@jit
def e2rel(y):
    """``2 (e^y - 1 - y) / y^2``, accurate for all real ``y <= 700``.

    For ``|y| < 0.5`` a Taylor series (``2 sum y^k/(k+2)!``) avoids the cancellation of
    ``e^y - 1 - y``; elsewhere ``expm1(y) - y`` has no cancellation.
    """
    if abs(y) < 0.5:
        # 2 * sum_{k>=0} y^k / (k+2)!  by Horner (15 terms: error < 0.5^15/17! ~ 1e-19)
        acc = _E2REL_TAYLOR[14]
        for k in range(13, -1, -1):
            acc = acc * y + _E2REL_TAYLOR[k]
        return acc
    if y > 700.0:
        return math.inf
    return 2.0 * (math.expm1(y) - y) / (y * y)


# zeta(-n) for n = 0..: zeta(-n) = -B_{n+1}/(n+1); only needed for the log-series below.
_ZETA_NEG = np.array([
    -0.5, -1.0 / 12.0, 0.0, 1.0 / 120.0, 0.0, -1.0 / 252.0, 0.0, 1.0 / 240.0, 0.0,
    -1.0 / 132.0, 0.0, 691.0 / 32760.0, 0.0, -1.0 / 12.0, 0.0, 3617.0 / 8160.0, 0.0,
    -43867.0 / 14364.0, 0.0, 174611.0 / 6600.0, 0.0,
])


@jit
def _li_series(u, s):
    # sum u^k / k^s for |u| <= 0.5 (error < 0.5^60)
    total = 0.0
    p = u
    for k in range(1, 60):
        total += p / float(k) ** s
        p *= u
    return total


@jit
def _li2_log(mu):
    # Li2(e^mu) for -1.4 <= mu <= 0: zeta(2) + mu (1 - ln(-mu)) + sum_{k>=2} zeta(2-k) mu^k / k!
    if mu == 0.0:
        return ZETA2
    total = ZETA2 + mu * (1.0 - math.log(-mu))
    fact = 1.0
    p = mu
    for k in range(2, 21):
        fact *= k
        p *= mu
        total += _ZETA_NEG[k - 2] * p / fact
    return total


@jit
def _li3_log(mu):
    # Li3(e^mu) = zeta(3) + zeta(2) mu + mu^2/2 (3/2 - ln(-mu)) + sum_{k>=3} zeta(3-k) mu^k/k!
    if mu == 0.0:
        return ZETA3
    total = ZETA3 + ZETA2 * mu + 0.5 * mu * mu * (1.5 - math.log(-mu))
    fact = 2.0
    p = mu * mu
    for k in range(3, 22):
        fact *= k
        p *= mu
        total += _ZETA_NEG[k - 3] * p / fact
    return total


@jit
def li2(u):
    """Real dilogarithm ``Li2(u)`` for ``u <= 1`` (relative error ~1e-15)."""
    if u > 1.0:
        return math.nan
    if u == 1.0:
        return ZETA2
    if abs(u) <= 0.5:
        return _li_series(u, 2.0)
    if u > 0.5:
        return _li2_log(math.log(u))
    if u >= -1.0:
        # duplication: Li2(u) = Li2(u^2)/2 - Li2(-u), with u^2, -u in (0.25, 1]
        return 0.5 * li2(u * u) - li2(-u)
    # u < -1: inversion Li2(u) = -zeta(2) - ln^2(-u)/2 - Li2(1/u)
    lg = math.log(-u)
    return -ZETA2 - 0.5 * lg * lg - li2(1.0 / u)


@jit
def li3(u):
    """Real trilogarithm ``Li3(u)`` for ``u <= 1`` (relative error ~1e-15)."""
    if u > 1.0:
        return math.nan
    if u == 1.0:
        return ZETA3
    if abs(u) <= 0.5:
        return _li_series(u, 3.0)
    if u > 0.5:
        return _li3_log(math.log(u))
    if u >= -1.0:
        # duplication: Li3(u) = Li3(u^2)/4 - Li3(-u)
        return 0.25 * li3(u * u) - li3(-u)
    # u < -1: inversion Li3(u) = Li3(1/u) - ln^3(-u)/6 - zeta(2) ln(-u)
    lg = math.log(-u)
    return li3(1.0 / u) - lg * lg * lg / 6.0 - ZETA2 * lg


def gauss_legendre(n: int):
    """Gauss-Legendre nodes ``x`` on [-1, 1], weights ``w`` and the cumulative matrix ``S``.

    ``S[i, j] = integral_{-1}^{x_i} l_j(x) dx`` where ``l_j`` is the Lagrange basis on the
    nodes, so ``S @ f(x)`` integrates the interpolant of ``f`` from -1 to each node.
    """
    x, w = (a.copy() for a in leggauss(n))
    # Lagrange basis l_j in the Legendre basis: V c = I  with V[i, k] = P_k(x_i)
    V = np.polynomial.legendre.legvander(x, n - 1)
    C = np.linalg.solve(V, np.eye(n))  # column j: Legendre coefficients of l_j
    S = np.empty((n, n))
    for j in range(n):
        cint = np.polynomial.legendre.legint(C[:, j], lbnd=-1.0)
        S[:, j] = np.polynomial.legendre.legval(x, cint)
    return x, w, S
