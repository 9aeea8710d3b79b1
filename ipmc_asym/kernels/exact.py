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

__all__ = ["moment_exact", "moment_exact_nodes", "make_exact_driver", "exact_frozen", "NODES"]

NODES = 10
_X, _W, _S = (np.ascontiguousarray(a) for a in gauss_legendre(NODES))

#: |y| where the core variable v hands over to y
Y_SWITCH = 0.5
#: below this |y| the integrand is 1 + O(y) to double precision: length in v taken exactly
Y_TINY = 1e-18
#: whole outer intervals (1/2 to 1, ..., to 2^9) whose nodes a sweep computes once (e^y stays
#: finite on the cathode side)
OUTER_CACHED = 10
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
        # |y| at v = V1 - d: ysw e^{-d} (1 - e^{-2v})/(1 - e^{-2 V1}); the ratio is 1.0 to the
        # bit where v > 20 (expm1(-40) rounds to -1): not formed there
        yd = ysw * math.exp(-d)
        if V1 - d <= 20.0:
            yd *= math.expm1(-2.0 * (V1 - d)) / em2V1
        if yd < Y_TINY:
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
def _accumulate(lam, F, G, Yn, H, npan, zeta, Wt, ST, moments, acc, cum):
    """Add ``npan`` panels to ``acc = [length, dlength, Y1, Y2]`` (``zeta`` = length so far).

    ``ST``: the transposed cumulative integration matrix, ``cum`` a work vector of the nodes'
    count.  The cumulative sums run column by column, so that the nodes' sums are independent
    chains (the processor overlaps them; row by row, each node's sum is a chain of dependent
    additions that sets the cost of the moment pass) and each is added in the same order.
    """
    n = Wt.shape[0]
    for p in range(npan):
        h = H[p]
        o = p * n
        if moments:
            for i in range(n):
                cum[i] = 0.0
            for jj in range(n):
                fj = F[o + jj]
                for i in range(n):
                    cum[i] += ST[jj, i] * fj
        for i in range(n):
            wf = Wt[i] * h * lam * F[o + i]
            acc[0] += wf
            acc[1] += Wt[i] * h * lam * G[o + i]
            if moments:
                acc[2] += wf * Yn[o + i]
                acc[3] += wf * Yn[o + i] * (zeta + h * lam * cum[i])
        zeta = acc[0]


@jit
def _frozen_layout(ell, ends, lay_m, lay_d, lay_v, zm):
    """Core layouts ``(m, d_m, V1)`` of both sides at ``ell`` into ``lay_m``, ``lay_d``, ``lay_v``;
    True where both are frozen: every core node at ``v > 20`` (``y = ysw e^{-d}``,
    ``tanh^2 v = 1``) and ``V1`` in the range where :func:`_asinh_scaled` is ``ell + ln(2 ysw)``
    exactly.  ``zm``: the ``meta`` of the sweep's frozen cores (``m < 0``: none), whose layout
    :func:`_core_layout` returns wherever ``V1 - d_m > 20`` at ``|y| = 1/2``."""
    out = True
    for s in range(2):
        ysw = min(Y_SWITCH, ends[s])
        V1 = _asinh_scaled(ysw, ell)
        if ysw == Y_SWITCH and zm[s, 1] > 0.0 and V1 - zm[s, 2] > 20.0:
            m = int(zm[s, 1])
            dm = zm[s, 2]
        else:
            m, dm = _core_layout(ysw, V1)
        lay_m[s] = m
        lay_d[s] = dm
        lay_v[s] = V1
        out = out and V1 - dm > 20.0 and ell + math.log(ysw) > 18.0
    return out


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
    core_fill, outer_fill, solve, frozen_cores
        ``solve(lam, Yc, Ya, lo, par, X, Wt, S, split, with_moments, fz=None) -> (ell, niter, res)``:
        ``res[s] = (length, dlength/dell, int w dz, int w zeta dz, zeta at |y| = 1)`` of the
        cathode (``s = 0``) and anode side at the root of the length ``= 2`` (dimensionless:
        units of ``e``), ``lo`` a lower bound of the root; ``niter`` the passes, -1 if the
        constraint was not met to ``LENGTH_TOL``.  ``with_moments`` False: the length alone
        (``res[:, 2:4]`` unused), with the core nodes refilled at every pass and Newton on
        ``ln L`` throughout.  ``fz``: ``frozen_cores(par, X, Wt, split)``, the core nodes that every
        thick point of a sweep shares (None: filled per point).
    """

    @jit
    def core_fill(ysw, sgn, V1, m, par, X, split, F, G, Yn, H, asym, ZF, ZG, ZY, mz):
        """``F``, ``dF/dell - sech^2 v``, ``w`` at the core nodes, bottom-up; returns the count.

        ``asym``: every node has ``v > 20``, so ``y = ysw e^{-d}`` and ``tanh^2 v = 1`` to
        double precision (no kappa dependence left).  ``ZF, ZG, ZY``: the frozen cores' nodes
        (``mz`` panels at ``ysw = 1/2``; 0: none): a panel whose nodes all have ``v > 20`` has
        their ``y`` and ``tanh^2 v = 1`` to the bit (``1 - e^{-2v}`` and ``1 + e^{-2v}`` round to
        1), so its ``F``, ``w`` are copied and only ``sech^2 v`` is formed.
        """
        n = X.shape[0]
        # y = ysw e^{-d} (1 - e^{-2v})/(1 - e^{-2 V1}): the point-independent factor once
        scale = sgn * ysw / -math.expm1(-2.0 * V1)
        p = 0
        for j in range(m, 0, -1):  # panel j spans d in [d_{j-1}, d_j]
            d_lo = 0.0 if j == 1 else (1.0 if j == 2 else 2.0 ** (j - 2))
            d_hi = min(1.0 if j == 1 else 2.0 ** (j - 1), V1)
            hs = (d_hi - d_lo) / split
            reuse = not asym and j <= mz and V1 - d_hi > 20.0
            for k in range(split):
                top = d_hi - k * hs  # this sub-panel's lower edge in v
                h = 0.5 * hs
                H[p] = h
                if reuse:
                    zo = ((mz - j) * split + k) * n  # the frozen cores are bottom-up too
                    for i in range(n):
                        e2v = math.exp(-2.0 * (V1 - (top - h * (X[i] + 1.0))))
                        r = 1.0 / (1.0 + e2v)
                        F[p * n + i] = ZF[zo + i]
                        G[p * n + i] = ZG[zo + i] - 4.0 * e2v * r * r
                        Yn[p * n + i] = ZY[zo + i]
                    p += 1
                    continue
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
    def outer_fill(Yend, sgn, par, X, split, E, S2, Yn, H, OZ, nz):
        """``(ehat, s2, w)`` at the y-nodes (1/2, 1, 2, 4, ... Yend); returns the count of panels.

        ``OZ[k]``: ``(ehat, s2, w)`` of the first ``nz`` whole intervals (1/2 to 1, 1 to 2, ...),
        copied where an interval is whole (the same nodes for every point of a sweep).
        """
        n = X.shape[0]
        p = 0
        j = 0
        a = Y_SWITCH
        while a < Yend:
            b = min(2.0 * a, Yend)
            hs = (b - a) / split
            for k in range(split):
                lo = a + k * hs
                h = 0.5 * hs
                H[p] = h
                if j < nz and b == 2.0 * a:
                    for i in range(n):
                        E[p * n + i] = OZ[0, p * n + i]
                        S2[p * n + i] = OZ[1, p * n + i]
                        Yn[p * n + i] = OZ[2, p * n + i]
                else:
                    for i in range(n):
                        y = sgn * (lo + h * (X[i] + 1.0))
                        e, s2, w = outer_point(y, par)
                        E[p * n + i] = e
                        S2[p * n + i] = s2
                        Yn[p * n + i] = w
                p += 1
            a = b
            j += 1
        return p

    @jit
    def core_constant(ysw, sgn, par, X, Wt):
        """``int_0^ysw (F(y, 1) - 1) dy/y`` on the side of ``sgn`` (one Gauss-Legendre panel)."""
        c = 0.0
        for i in range(X.shape[0]):
            u = 0.5 * ysw * (X[i] + 1.0)
            f, g, w = core_point(sgn * u, 1.0, par)
            c += Wt[i] * (f - 1.0) / u
        return 0.5 * ysw * c

    @jit
    def _neutral_guess(lam, ends, sgns, par, X, Wt, npo, OE, OS2, OH, fz):
        """The root ``ell`` of the thickness constraint as ``kappa -> 0`` (a neutral core).

        Each side's length is then ``lam (ell + ln(2 ysw) + c + o)`` up to ``O(kappa)``: ``v`` runs
        to ``asinh(ysw/kappa) = ell + ln(2 ysw)``, the core adds ``c = int_0^ysw (F(y, 1) - 1) dy/y``
        (``F = 1 + O(y)``: a smooth integrand, one Gauss-Legendre panel) and the layer beyond
        ``|y| = 1/2`` its length at ``kappa = 0``, ``o = int ehat dy/sqrt(s2)`` on the outer nodes
        (the paper's model: :func:`ipmc_asym.kernels.charge_exact.kappa_neutral_log` in closed
        form).  The layers' width is what the bare ``1/lam`` misses: ell ~ 10 against 20 at
        ``lam = 0.05``, ``A2 = 190``; from here Newton needs one or two passes, from ``1/lam``
        three to six (measured on 1 um - 10 mm x 1e-4 - 20 V).
        """
        n = X.shape[0]
        total = 0.0
        for s in range(2):
            ysw = min(Y_SWITCH, ends[s])
            c = math.nan
            if fz is not None:
                if ysw == Y_SWITCH:
                    c = fz[1][s, 3]
            if math.isnan(c):
                c = core_constant(ysw, sgns[s], par, X, Wt)
            o = 0.0
            for q in range(npo[s] * n):
                o += Wt[q % n] * OH[s, q // n] * OE[s, q] / math.sqrt(OS2[s, q])
            total += math.log(2.0 * ysw) + c + o
        return 1.0 / lam - 0.5 * total

    @jit
    def solve(lam, Yc, Ya, lo, par, X, Wt, S, split, with_moments, fz=None):
        """Root ``ell`` of the thickness constraint and the sides' integrals there (see above)."""
        n = X.shape[0]
        ends = (Yc, -Ya)
        sgns = (1.0, -1.0)
        # the working arrays: views of one float, one integer and one flag buffer (an allocation
        # costs about as much as a few nodes)
        nout = max(_outer_count(Yc), _outer_count(-Ya)) * split * n + 1
        # core nodes: depend on kappa unless every node has v > 20 (then y = ysw e^{-d}, t2 = 1)
        ncore = 80 * split * n
        # the length alone refills the cores at every pass: one set of buffers serves both sides
        # (half the working set of the Newton loop)
        nbuf = 2 if with_moments else 1
        buf = np.empty(10 * nout + 4 * nbuf * ncore + n * n + n + 24)
        OE = buf[0:2 * nout].reshape((2, nout))
        OS2 = buf[2 * nout:4 * nout].reshape((2, nout))
        OY = buf[4 * nout:6 * nout].reshape((2, nout))
        OH = buf[6 * nout:8 * nout].reshape((2, nout))
        OF = buf[8 * nout:9 * nout]
        OG = buf[9 * nout:10 * nout]
        o = 10 * nout
        CF = buf[o:o + nbuf * ncore].reshape((nbuf, ncore))
        CG = buf[o + nbuf * ncore:o + 2 * nbuf * ncore].reshape((nbuf, ncore))
        CY = buf[o + 2 * nbuf * ncore:o + 3 * nbuf * ncore].reshape((nbuf, ncore))
        CH = buf[o + 3 * nbuf * ncore:o + 4 * nbuf * ncore].reshape((nbuf, ncore))
        o += 4 * nbuf * ncore
        ST = buf[o:o + n * n].reshape((n, n))
        for i in range(n):
            for j in range(n):
                ST[j, i] = S[i, j]
        o += n * n
        cum = buf[o:o + n]
        acc = buf[o + n:o + n + 4]
        lay_d = buf[o + n + 4:o + n + 6]
        lay_v = buf[o + n + 6:o + n + 8]
        ib = np.zeros(6, dtype=np.int64)
        npo = ib[0:2]
        npc = ib[2:4]
        lay_m = ib[4:6]
        fb = np.zeros(4, dtype=np.bool_)
        frozen = fb[0:2]
        fzs = fb[2:4]  # frozen, from ``fz``
        res = np.empty((2, 5))  # per side: length, dlength, Y1, Y2, zeta1 (returned)
        for s in range(2):
            if fz is not None:
                npo[s] = outer_fill(ends[s], sgns[s], par, X, split, OE[s], OS2[s], OY[s], OH[s], fz[2][s],
                                    OUTER_CACHED)
            else:
                npo[s] = outer_fill(ends[s], sgns[s], par, X, split, OE[s], OS2[s], OY[s], OH[s], OE, 0)
        ell = _neutral_guess(lam, ends, sgns, par, X, Wt, npo, OE, OS2, OH, fz)
        lo_done = False
        ell = min(max(ell, lo), 1e7) if ell == ell else lo  # a start that is not a number: the bound
        hi = math.inf
        niter = -1
        moments = False
        stalled = False
        r_prev = math.inf
        zm = buf[o + n + 8:o + n + 16].reshape((2, 4))
        zm[:] = -1.0
        if fz is not None:
            zm = fz[1]
        for it in range(100):
            kappa2 = math.exp(-2.0 * ell)
            both = _frozen_layout(ell, ends, lay_m, lay_d, lay_v, zm)
            # both cores frozen: the length is linear in ell and the moments are taken on this
            # pass, then moved to the root (below): one pass.  Past ell = 20 (kappa < 2e-9) the
            # neutral-core start is the root to ~1e-15 (measured on 1 um - 10 mm x 1e-4 - 20 V):
            # the moments on the first pass there too
            moments = moments or (with_moments and (both or (it == 0 and ell > 20.0)))
            for s in range(2):
                ysw = min(Y_SWITCH, ends[s])
                V1 = lay_v[s]
                m = lay_m[s]
                dm = lay_d[s]
                v_bottom = V1 - dm
                asym = v_bottom > 20.0
                c = s if with_moments else 0
                acc[0] = lam * v_bottom
                acc[1] = lam * math.tanh(V1)  # int sech^2 dv over the core; the rest is G - sech^2
                acc[2] = 0.0
                acc[3] = 0.0
                cached = False
                if fz is not None:  # the frozen cores computed once for the caller's sweep
                    Z, meta, _ = fz
                    cached = asym and ysw == Y_SWITCH and m == meta[s, 1] and dm == meta[s, 2]
                    if cached:
                        fzs[s] = with_moments
                        _accumulate(lam, Z[0, s], Z[1, s], Z[2, s], Z[3, s], int(meta[s, 0]), acc[0], Wt, ST,
                                    moments, acc, cum)
                if not cached:
                    if not (asym and frozen[s]):
                        if fz is not None and ysw == Y_SWITCH:
                            Z = fz[0]
                            npc[s] = core_fill(ysw, sgns[s], V1, m, par, X, split, CF[c], CG[c], CY[c], CH[c],
                                               asym, Z[0, s], Z[1, s], Z[2, s], int(zm[s, 1]))
                        else:
                            npc[s] = core_fill(ysw, sgns[s], V1, m, par, X, split, CF[c], CG[c], CY[c], CH[c],
                                               asym, CF[c], CG[c], CY[c], 0)
                        frozen[s] = asym and with_moments
                    _accumulate(lam, CF[c], CG[c], CY[c], CH[c], npc[s], acc[0], Wt, ST, moments, acc, cum)
                zeta1 = acc[0]
                # outer panels: F, G from the cached (ehat, s2)
                for q in range(npo[s] * n):
                    f, g = exact_outer(OE[s, q], OS2[s, q], kappa2)
                    OF[q] = f
                    OG[q] = g
                first = min(split, npo[s]) if ends[s] > 1.0 else npo[s]
                _accumulate(lam, OF, OG, OY[s], OH[s], first, acc[0], Wt, ST, moments, acc, cum)
                zeta1 = acc[0]
                _accumulate(lam, OF[first * n:], OG[first * n:], OY[s, first * n:], OH[s, first:],
                            npo[s] - first, acc[0], Wt, ST, moments, acc, cum)
                for k in range(4):
                    res[s, k] = acc[k]
                res[s, 4] = zeta1
            L = res[0, 0] + res[1, 0]
            if moments and both and L != 2.0:
                # frozen cores: every node is independent of ell but the core's bottom, so the
                # exact Newton step only lengthens each side's core by lam d, which moves every
                # zeta by lam d: Y2 by lam d Y1 (valid where the step keeps the layout)
                d = (2.0 - L) / (2.0 * lam)
                m0, m1, d0, d1 = lay_m[0], lay_m[1], lay_d[0], lay_d[1]
                if _frozen_layout(ell + d, ends, lay_m, lay_d, lay_v, zm) and m0 == lay_m[0] and m1 == lay_m[1] \
                        and d0 == lay_d[0] and d1 == lay_d[1]:
                    for s in range(2):
                        res[s, 0] += lam * d
                        res[s, 3] += lam * d * res[s, 2]
                        res[s, 4] += lam * d
                    ell += d
                    L = res[0, 0] + res[1, 0]
            r = math.log(0.5 * L)  # the length grows with ell
            # converged (or Newton stalled in round-off: 100x the tolerance, still ~1e-12 on I)
            if (moments or not with_moments) and (abs(r) <= LENGTH_TOL or (stalled and abs(r) <= 100.0 * LENGTH_TOL)):
                niter = it + 1
                break
            if abs(r) <= LENGTH_TOL:  # at the root without the moments: take them here
                moments = True
                continue
            if r < 0.0:
                lo = max(lo, ell)
                lo_done = True
            else:
                hi = min(hi, ell)
            linear = (frozen[0] or fzs[0]) and (frozen[1] or fzs[1])
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

    @jit
    def frozen_cores(par, X, Wt, split):
        """``fz`` for :func:`solve`: the frozen core nodes of both sides at ``|y| = 1/2``, the same
        for every point of a sweep with this ``par``.

        Frozen (every core node at ``v > 20``: ``y = ysw e^{-d}``, ``tanh^2 v = 1``), the core
        layout and nodes depend on neither ``kappa`` nor the point (:func:`_core_layout` stops at
        ``|y| < Y_TINY`` before ``d`` nears ``V1``), so :func:`solve` takes them from here, bit for
        bit what it would fill, where a thick strip's core costs most of its one pass.
        Returns ``(Z, meta, O)``: ``Z[k, s]`` the ``(F, G, w, H)`` of side ``s`` (cathode 0),
        ``meta[s] = (panel count, m, d_m, core constant of the neutral guess)``, ``O[s]`` the
        ``(ehat, s2, w)`` of the outer nodes of the first ``OUTER_CACHED`` whole intervals.
        """
        n = X.shape[0]
        ncore = 80 * split * n
        Z = np.empty((4, 2, ncore))
        meta = np.empty((2, 4))
        V1 = 1e3  # any V1 with V1 - d_m > 20 gives this layout
        O = np.empty((2, 3, OUTER_CACHED * split * n))
        H = np.empty(OUTER_CACHED * split)
        for s in range(2):
            outer_fill(Y_SWITCH * 2.0 ** OUTER_CACHED, 1.0 - 2.0 * s, par, X, split, O[s, 0], O[s, 1], O[s, 2], H,
                       O[s], 0)
            m, dm = _core_layout(Y_SWITCH, V1)
            meta[s, 0] = core_fill(Y_SWITCH, 1.0 - 2.0 * s, V1, m, par, X, split, Z[0, s], Z[1, s], Z[2, s],
                                   Z[3, s], True, Z[0, s], Z[1, s], Z[2, s], 0)
            meta[s, 1] = m
            meta[s, 2] = dm
            meta[s, 3] = core_constant(Y_SWITCH, 1.0 - 2.0 * s, par, X, Wt)
        return Z, meta, O

    return core_fill, outer_fill, solve, frozen_cores


@jit(inline="always")  # a node of the driver's inner loop: no call per node
def _exact_core_point(y, t2, rho):
    f, g = exact_core(y, t2, rho)
    return f, g, y


@jit(inline="always")  # a node of the driver's inner loop: no call per node
def _exact_outer_point(y, rho):
    e, s2 = exact_outer_parts(y, rho)
    return e, s2, y


#: the paper's model: moment weight ``y``, ``par = rho``
_core_fill, _outer_fill, _solve, _frozen_cores = make_exact_driver(_exact_core_point, _exact_outer_point)


@jit
def exact_frozen(rho, wanted):
    """The frozen cores of the paper's model for a sweep at ``rho`` (``frozen_cores`` of
    :func:`make_exact_driver`): the ``fz`` of :func:`moment_exact`.  Not ``wanted`` (a sweep of
    another rung): empty, of the same type, matching no layout."""
    if wanted:
        return _frozen_cores(rho, _X, _W, 1)
    return np.empty((4, 2, 0)), np.full((2, 4), -1.0), np.empty((2, 3, 0))


@jit
def moment_exact_nodes(lam, A2, A3, rho, X, Wt, S, split, fz=None):
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
    ell, niter, res = _solve(lam, Yc, Ya, lo, rho, X, Wt, S, split, True, fz)
    Lc = res[0, 0]
    La = res[1, 0]
    z0 = 0.5 * (La - Lc)  # y = 0 sits at z0; the sides end at -+(La + Lc)/2 = -+1
    kappa2 = math.exp(-2.0 * ell)
    I = assemble_exact(lam, A2, A3, rho, B1, cm, dhat(Yc, rho), kappa2, z0,
                       res[0, 2], res[1, 2], res[0, 3], res[1, 3])
    return I, B1, ell, res[0, 4] + res[1, 4], niter


@jit
def moment_exact(lam, A2, A3, rho, fz=None):
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
    return moment_exact_nodes(lam, A2, A3, rho, _X, _W, _S, 1, fz)
