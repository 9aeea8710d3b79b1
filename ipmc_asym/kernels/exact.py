"""The exact moment integral at any thickness (fidelity ``exact``).

Derivation in ``derivations/exact.py``; the integrands and the assembly are generated into
``_generated_exact.py``.  Nothing is neglected: the core need not be neutral, the layers may
overlap.  For one point ``(lam, A2, A3, rho)``:

1. ``B1`` from its exact quadratic (electroneutrality holds for any ``K``).
2. ``kappa`` (``K = lam^2 kappa^2/2``, the first-integral constant) from the thickness
   constraint ``lam int ehat dy/sqrt(y^2 Qhat + kappa^2) = 2`` by safeguarded Newton on
   ``ell = -ln kappa`` inside a bracket that every step tightens.  ``ell`` runs from ~-3
   (1 um strips, overlapping layers) to ~6000 (``kappa ~ 1e-2600``): ``kappa`` itself is never
   formed where it would underflow.
3. Each side of the profile (cathode ``0 < y < Yc``, anode ``Ya < y < 0``) is integrated by
   composite Gauss-Legendre panels: in ``v`` (``y = kappa sinh v``) for ``|y| < 1/2`` and in
   ``y`` beyond.  In ``v`` the integrand ``F`` is smooth and ``1 + O(y)`` for every
   ``kappa``: panels are laid from ``|y| = 1/2`` down (widths 1, 1, 2, 4, 8 ... in ``v``) until
   ``|y| < 1e-18``; the rest of the core contributes its length in ``v`` exactly.  In ``y`` the
   breakpoints double (1/2, 1, 2, 4, ...): the integrand's complex singularities are at a
   distance comparable to ``|y|`` (zeros of ``Qhat``, ``|y| >= 6``).  The distance ``zeta``
   from the point ``y = 0`` comes at every node from the panel's spectral cumulative
   integration matrix, so the moment ``int y z dz`` costs no extra evaluations.
"""

from __future__ import annotations

import math

import numpy as np

from ipmc_asym.kernels._generated import b1_exact, dhat
from ipmc_asym.kernels._generated_exact import assemble_exact, exact_core, exact_outer, exact_outer_parts
from ipmc_asym.kernels.jit import jit
from ipmc_asym.kernels.special import gauss_legendre

__all__ = ["moment_exact", "moment_exact_nodes", "make_exact_driver", "NODES"]

NODES = 10
_X, _W, _S = (np.ascontiguousarray(a) for a in gauss_legendre(NODES))

#: |y| where the core variable v hands over to y
Y_SWITCH = 0.5
#: below this |y| the integrand is 1 + O(y) to double precision: length in v taken exactly
Y_TINY = 1e-18
#: relative tolerance on the thickness constraint (length 2)
LENGTH_TOL = 1e-14

_LN2 = math.log(2.0)


@jit
def _asinh_scaled(Yabs, ell):
    """``asinh(Yabs e^ell)`` without forming ``e^ell`` when it would overflow."""
    x = ell + math.log(Yabs)
    if x > 18.0:  # asinh(e^x) = x + ln 2 + e^{-2x}/4 + ...; the last term < 6e-17
        return x + _LN2
    return math.asinh(Yabs * math.exp(ell))


@jit
def _core_layout(ysw, V1):
    """Number ``m`` of core panels and the depth ``d_m`` of the lowest (``d = V1 - v``).

    Breakpoints in ``d``: 0, 1, 2, 4, 8, ... down to ``V1`` or to where ``|y| < Y_TINY``.
    """
    em2V1 = math.expm1(-2.0 * V1)
    m = 0
    d = 0.0
    while d < V1:
        m += 1
        d = 1.0 if m == 1 else 2.0 * d
        if d >= V1:
            d = V1
            break
        # |y| at v = V1 - d: ysw e^{-d} (1 - e^{-2v})/(1 - e^{-2 V1})
        if ysw * math.exp(-d) * (math.expm1(-2.0 * (V1 - d)) / em2V1) < Y_TINY:
            break
    return m, d


@jit
def _outer_count(Yend):
    c = 0
    a = Y_SWITCH
    while a < Yend:
        c += 1
        a = 2.0 * a
    return c


@jit
def _accumulate(lam, F, G, Yn, H, npan, zeta, Wt, S, moments, acc):
    """Add ``npan`` panels to ``acc = [length, dlength, Y1, Y2]`` (``zeta`` = length so far)."""
    n = Wt.shape[0]
    for p in range(npan):
        h = H[p]
        o = p * n
        for i in range(n):
            wf = Wt[i] * h * lam * F[o + i]
            acc[0] += wf
            acc[1] += Wt[i] * h * lam * G[o + i]
            if moments:
                cum = 0.0
                for jj in range(n):
                    cum += S[i, jj] * F[o + jj]
                acc[2] += wf * Yn[o + i]
                acc[3] += wf * Yn[o + i] * (zeta + h * lam * cum)
        zeta = acc[0]


def make_exact_driver(core_point, outer_point):
    """The exact rung's panels and Newton on ``ell = -ln kappa`` for one integrand: compiled per
    ``(core_point, outer_point)`` (the paper's model here, the pressure term in
    :mod:`ipmc_asym.kernels.pressure`, the electrode charge in :mod:`ipmc_asym.kernels.charge_exact`).

    Parameters
    ----------
    core_point : jitted ``(y, t2, par) -> (F, dF/dell, w)``
        In the core variable ``v`` (``y = kappa sinh v``, ``t2 = tanh^2 v``): the length element
        ``F``, its derivative in ``ell`` (before the ``sech^2 v`` this driver integrates exactly)
        and the moment weight ``w`` (``I ~ int w z dz``) at one node.
    outer_point : jitted ``(y, par) -> (ehat, s2, w)``
        Beyond ``|y| = 1/2``: ``(ehat, s2)`` for ``exact_outer(ehat, s2, kappa^2)`` and ``w``.

    Returns
    -------
    core_fill, outer_fill, solve
        ``solve(lam, Yc, Ya, lo, par, X, Wt, S, split, with_moments) -> (ell, niter, res)``:
        ``res[s] = (length, dlength/dell, int w dz, int w zeta dz, zeta at |y| = 1)`` of the
        cathode (``s = 0``) and anode side at the root of the length ``= 2`` (dimensionless:
        units of ``e``), ``lo`` a lower bound of the root; ``niter`` the passes, -1 if the
        constraint was not met to ``LENGTH_TOL``.  ``with_moments`` False: the length alone
        (``res[:, 2:4]`` unused), with the core nodes refilled at every pass and Newton on
        ``ln L`` throughout.
    """

    @jit
    def core_fill(ysw, sgn, V1, m, par, X, split, F, G, Yn, H, asym):
        """``F``, ``dF/dell - sech^2 v``, ``w`` at the core nodes, bottom-up; returns the count.

        ``asym``: every node has ``v > 20``, so ``y = ysw e^{-d}`` and ``tanh^2 v = 1`` to
        double precision (no kappa dependence left).
        """
        n = X.shape[0]
        # y = ysw e^{-d} (1 - e^{-2v})/(1 - e^{-2 V1}): the point-independent factor once
        scale = sgn * ysw / -math.expm1(-2.0 * V1)
        p = 0
        for j in range(m, 0, -1):  # panel j spans d in [d_{j-1}, d_j]
            d_lo = 0.0 if j == 1 else (1.0 if j == 2 else 2.0 ** (j - 2))
            d_hi = min(1.0 if j == 1 else 2.0 ** (j - 1), V1)
            hs = (d_hi - d_lo) / split
            for k in range(split):
                top = d_hi - k * hs  # this sub-panel's lower edge in v
                h = 0.5 * hs
                H[p] = h
                for i in range(n):
                    dd = top - h * (X[i] + 1.0)
                    sech2 = 0.0
                    if asym:
                        y = sgn * ysw * math.exp(-dd)
                        t2 = 1.0
                    else:
                        vv = V1 - dd
                        e2v = math.exp(-2.0 * vv)
                        # 1 - e^{-2v}: subtracted directly where e^{-2v} <= 1/2 (the difference is
                        # >= 1/2, so exp's rounding reaches it at most once: <= 2 ulp), expm1 only
                        # near v = 0 where the subtraction would cancel
                        em = 1.0 - e2v if e2v <= 0.5 else -math.expm1(-2.0 * vv)
                        y = scale * math.exp(-dd) * em
                        r = 1.0 / (1.0 + e2v)
                        th = em * r
                        t2 = th * th
                        sech2 = 4.0 * e2v * r * r
                    f, g, w = core_point(y, t2, par)
                    F[p * n + i] = f
                    # dF/dell ~ sech^2 v where y is tiny: integrate sech^2 exactly (tanh V1) and
                    # only the smooth remainder numerically (the deep core panels are wide)
                    G[p * n + i] = g - sech2
                    Yn[p * n + i] = w
                p += 1
        return p

    @jit
    def outer_fill(Yend, sgn, par, X, split, E, S2, Yn, H):
        """``(ehat, s2, w)`` at the y-nodes (1/2, 1, 2, 4, ... Yend); returns the count of panels."""
        n = X.shape[0]
        p = 0
        a = Y_SWITCH
        while a < Yend:
            b = min(2.0 * a, Yend)
            hs = (b - a) / split
            for k in range(split):
                lo = a + k * hs
                h = 0.5 * hs
                H[p] = h
                for i in range(n):
                    y = sgn * (lo + h * (X[i] + 1.0))
                    e, s2, w = outer_point(y, par)
                    E[p * n + i] = e
                    S2[p * n + i] = s2
                    Yn[p * n + i] = w
                p += 1
            a = b
        return p

    @jit
    def solve(lam, Yc, Ya, lo, par, X, Wt, S, split, with_moments):
        """Root ``ell`` of the thickness constraint and the sides' integrals there (see above)."""
        n = X.shape[0]
        ends = (Yc, -Ya)
        sgns = (1.0, -1.0)
        # outer nodes: fixed in y, computed once
        nout = max(_outer_count(Yc), _outer_count(-Ya)) * split * n + 1
        OE = np.empty((2, nout))
        OS2 = np.empty((2, nout))
        OY = np.empty((2, nout))
        OH = np.empty((2, nout))
        npo = np.zeros(2, dtype=np.int64)
        for s in range(2):
            npo[s] = outer_fill(ends[s], sgns[s], par, X, split, OE[s], OS2[s], OY[s], OH[s])
        OF = np.empty(nout)
        OG = np.empty(nout)
        # core nodes: depend on kappa unless every node has v > 20 (then y = ysw e^{-d}, t2 = 1)
        ncore = 80 * split * n
        # the length alone refills the cores at every pass: one set of buffers serves both sides
        # (half the working set of the Newton loop)
        nbuf = 2 if with_moments else 1
        CF = np.empty((nbuf, ncore))
        CG = np.empty((nbuf, ncore))
        CY = np.empty((nbuf, ncore))
        CH = np.empty((nbuf, ncore))
        npc = np.zeros(2, dtype=np.int64)
        frozen = np.zeros(2, dtype=np.bool_)
        acc = np.empty(4)
        res = np.empty((2, 5))  # per side: length, dlength, Y1, Y2, zeta1
        # neutral-core guess: each side is ~ lam (ell + ln(2 min(|Y|, 1/2)) + O(1))
        ell = 1.0 / lam - 0.5 * (math.log(2.0 * min(Yc, Y_SWITCH)) + math.log(2.0 * min(-Ya, Y_SWITCH)))
        lo_done = False
        ell = min(max(ell, lo), 1e7)
        hi = math.inf
        niter = -1
        moments = False
        stalled = False
        r_prev = math.inf
        for it in range(100):
            kappa2 = math.exp(-2.0 * ell)
            for s in range(2):
                ysw = min(Y_SWITCH, ends[s])
                V1 = _asinh_scaled(ysw, ell)
                m, dm = _core_layout(ysw, V1)
                v_bottom = V1 - dm
                asym = v_bottom > 20.0
                c = s if with_moments else 0
                if not (asym and frozen[s]):
                    npc[s] = core_fill(ysw, sgns[s], V1, m, par, X, split, CF[c], CG[c], CY[c], CH[c], asym)
                    frozen[s] = asym and with_moments
                acc[0] = lam * v_bottom
                acc[1] = lam * math.tanh(V1)  # int sech^2 dv over the core; the rest is G - sech^2
                acc[2] = 0.0
                acc[3] = 0.0
                _accumulate(lam, CF[c], CG[c], CY[c], CH[c], npc[s], acc[0], Wt, S, moments, acc)
                zeta1 = acc[0]
                # outer panels: F, G from the cached (ehat, s2)
                for q in range(npo[s] * n):
                    f, g = exact_outer(OE[s, q], OS2[s, q], kappa2)
                    OF[q] = f
                    OG[q] = g
                first = min(split, npo[s]) if ends[s] > 1.0 else npo[s]
                _accumulate(lam, OF, OG, OY[s], OH[s], first, acc[0], Wt, S, moments, acc)
                zeta1 = acc[0]
                _accumulate(lam, OF[first * n:], OG[first * n:], OY[s, first * n:], OH[s, first:],
                            npo[s] - first, acc[0], Wt, S, moments, acc)
                for k in range(4):
                    res[s, k] = acc[k]
                res[s, 4] = zeta1
            L = res[0, 0] + res[1, 0]
            r = math.log(0.5 * L)  # the length grows with ell
            # converged (or Newton stalled in round-off: 100x the tolerance, still ~1e-12 on I)
            if (moments or not with_moments) and (abs(r) <= LENGTH_TOL or (stalled and abs(r) <= 100.0 * LENGTH_TOL)):
                niter = it + 1
                break
            if r < 0.0:
                lo = max(lo, ell)
                lo_done = True
            else:
                hi = min(hi, ell)
            linear = frozen[0] and frozen[1]
            # L(ell) is exactly linear once the core nodes are frozen (Newton on L is then
            # exact); otherwise Newton on ln L, about linear both for kappa >> 1 and kappa << 1
            new = ell - ((L - 2.0) if linear else r * L) / (res[0, 1] + res[1, 1])
            if not (lo < new < hi):
                if not lo_done:  # L(lo) <= 2 and ln L is concave: Newton from lo is monotone
                    new = lo
                elif hi == math.inf:
                    new = ell + max(1.0, 2.0 * (ell - lo))
                else:
                    new = 0.5 * (lo + hi)
            # the moments are needed at the last step only: once Newton is in its quadratic
            # range, or where the length is linear in ell (kappa < 1e-20: core nodes frozen)
            moments = with_moments and (abs(r) < 1e-7 or linear or abs(r) >= r_prev)
            r_prev = abs(r)
            if new == ell:
                moments = with_moments
                stalled = True
            ell = new
        return ell, niter, res

    return core_fill, outer_fill, solve


@jit(inline="always")  # a node of the driver's inner loop: no call per node
def _exact_core_point(y, t2, rho):
    f, g = exact_core(y, t2, rho)
    return f, g, y


@jit(inline="always")  # a node of the driver's inner loop: no call per node
def _exact_outer_point(y, rho):
    e, s2 = exact_outer_parts(y, rho)
    return e, s2, y


#: the paper's model: moment weight ``y``, ``par = rho``
_core_fill, _outer_fill, _solve = make_exact_driver(_exact_core_point, _exact_outer_point)


@jit
def moment_exact_nodes(lam, A2, A3, rho, X, Wt, S, split):
    """:func:`moment_exact` with given Gauss-Legendre nodes and panels split ``split`` times.

    Returns ``(I, B1, ell, core, niter)``; see :func:`moment_exact`.
    """
    B1 = b1_exact(A2, rho)
    Yc = math.log(B1)
    Ya = Yc - A2
    cm = B1 * math.exp(-A2)
    # sqrt(s^2 + kappa^2) >= kappa: L <= lam e^ell int ehat dy, so the root lies above
    # ln(2/(lam int ehat dy)), with int ehat dy = (1 - rho)(B1 - cm) + rho A2 exactly
    lo = max(math.log(2.0 / (lam * ((1.0 - rho) * (B1 - cm) + rho * A2))), -300.0)
    ell, niter, res = _solve(lam, Yc, Ya, lo, rho, X, Wt, S, split, True)
    Lc = res[0, 0]
    La = res[1, 0]
    z0 = 0.5 * (La - Lc)  # y = 0 sits at z0; the sides end at -+(La + Lc)/2 = -+1
    kappa2 = math.exp(-2.0 * ell)
    I = assemble_exact(lam, A2, A3, rho, B1, cm, dhat(Yc, rho), kappa2, z0,
                       res[0, 2], res[1, 2], res[0, 3], res[1, 3])
    return I, B1, ell, res[0, 4] + res[1, 4], niter


@jit
def moment_exact(lam, A2, A3, rho):
    """Exact moment integral ``I`` (for ``|phi0|``) at any thickness.

    Parameters
    ----------
    lam : float  core Debye length / e, ``sqrt((A0 + A1)/A2)`` (any value > 0)
    A2, A3 : float  dimensionless groups (``A2 > 0``)
    rho : float  ``A1/(A0 + A1)`` in [0, 1]

    Returns
    -------
    I, B1, ell, core, niter
        ``ell = -ln kappa`` with ``K = lam^2 kappa^2 / 2`` the first-integral constant;
        ``core`` the distance in ``z`` between the points where ``|y| = 1`` (units of ``e``);
        ``niter`` the number of passes, -1 if the thickness constraint was not met to
        ``LENGTH_TOL`` (then ``I`` must not be reported).
    """
    return moment_exact_nodes(lam, A2, A3, rho, _X, _W, _S, 1)
