"""BVP mesh and initial guess: the graded mesh, its first spacings, the layer-profile guess.

The electrode layers are ~1e-3 of the thickness or thinner; the mesh is graded
geometrically towards both faces from first spacings set by the local scales (and kept
above the rounding floor of solve_bvp's residual), and the initial guess glues two
half-infinite layer profiles from the first integral (paper section 5).
Layer rule: moment layer; numpy, params and bvp_problems only.
"""

from __future__ import annotations

import math

import numpy as np

from ipmc_asym.bvp.problems import AffineProblem, H, cumtrapz
from ipmc_asym.model.params import Groups

__all__ = ["make_mesh", "first_spacings", "layer_profile", "initial_guess"]


def make_mesh(h0_a: float, h0_c: float, *, ratio: float = 1.06, h_core: float = 0.02) -> np.ndarray:
    """Mesh on ``[-1, 1]`` graded geometrically towards both faces.

    Parameters
    ----------
    h0_a, h0_c : float
        First spacing (dimensionless) at the anode (``z = -1``) and at the cathode (``z = 1``).
    ratio : float
        Growth factor of consecutive spacings.
    h_core : float
        Largest spacing (in the neutral core).

    Returns
    -------
    ndarray, shape (n,)
        Strictly increasing nodes with ``z[0] = -1``, ``z[-1] = 1``.
    """

    def side(h0):
        h0 = min(max(h0, 1e-13), h_core)
        n_geo = int(math.ceil(math.log(h_core / h0) / math.log(ratio))) + 1
        hs = np.minimum(h0 * ratio ** np.arange(n_geo), h_core)
        d = np.concatenate(([0.0], np.cumsum(hs)))
        if d[-1] < 1.0:
            d = np.concatenate((d, d[-1] + h_core * np.arange(1, int((1.0 - d[-1]) / h_core) + 2)))
        return d

    za = -1.0 + side(h0_a)
    zc = 1.0 - side(h0_c)
    # each side reaches the spacing h_core before z = 0 (the geometric part spans
    # h_core / (ratio - 1) < 1), so the two halves join at 0 with that spacing
    z = np.union1d(za[za < -0.5 * h_core], zc[zc > 0.5 * h_core])
    z = np.union1d(z, [-1.0, 0.0, 1.0])
    return z[(z >= -1.0) & (z <= 1.0)]


# ---------------------------------------------------------------------------------------
# scales, initial guess
# ---------------------------------------------------------------------------------------
def first_spacings(g: Groups, eps_of_C, b: float, tol: float, custom: bool):
    """First mesh spacings at the anode and the cathode, and the core Debye length.

    Physical part: ``1e-3`` of the thinnest local scale (cathode: local Debye length
    ``sqrt(eps(B1) / (A2 B1))``; anode: wall scale ``eps_w / (A2 D_w)`` of ``ln C``, floored
    at ``1e-3`` of the core Debye length because ``s`` stays smooth where ``eps -> 0``).
    Rounding floor: solve_bvp's relative residual ``|u' - f| / (1 + |f|)`` of a spline
    through node values rounded to ``eps_mach |u|`` is ``~ eps_mach |u| / h``; the first
    spacing is kept above ``30 eps_mach / tol * max_i |u_i| / (1 + |f_i|)`` at each wall so
    that refinement is never asked to beat rounding.
    """
    A0, A1, A2 = max(g.A0, 0.0), max(g.A1, 0.0), g.A2
    lam = math.sqrt(max(float(eps_of_C(np.array([1.0]))[0]), 1e-300) / A2)
    B1 = math.exp(b)
    cw = math.exp(b - A2)
    eps_c = float(eps_of_C(np.array([B1]))[0])
    eps_w = float(eps_of_C(np.array([cw]))[0])
    if A0 == 0.0 and A1 == 0.0:
        A1 = eps_c
    Dw = math.sqrt(2.0 * max(float(H(np.array([b]), A0, A1)[0]), 1e-300) / A2)
    h_c = min(lam, math.sqrt(eps_c / (A2 * B1)))
    if custom and eps_w / (A2 * Dw) < 1e-10:
        raise ValueError(
            "custom permittivity eps(C) is too small at the anode (eps(C -> 0) ~ "
            f"{eps_w:.3g} in units of e^2 phi4 F C_moy/|phi0|): ln C would vary on a scale "
            f"~{eps_w / (A2 * Dw):.1e} e, which double precision cannot resolve; use the "
            "built-in 'linear'/'affine' models (solved in s = A0 C + A1 ln C) or give eps a "
            "positive floor eps(0) > 0"
        )
    h_a = min(lam, Dw, max(eps_w / (A2 * Dw), 1e-3 * lam))
    floor = 30.0 * np.finfo(float).eps / tol
    if custom:
        ua, uc = abs(b - A2), abs(b)
        fa, fc = A2 * Dw / eps_w, A2 * Dw / eps_c
    else:
        ua = abs(A0 * cw + A1 * (b - A2))
        uc = abs(A0 * B1 + A1 * b)
        fa = fc = A2 * Dw
    ra = max(ua / (1.0 + fa), Dw / (2.0 - cw))
    rc = max(uc / (1.0 + fc), Dw / B1)
    return max(1e-3 * h_a, floor * ra), max(1e-3 * h_c, floor * rc), lam


def layer_profile(yw: float, eps_of_C, A0: float, A1: float, A2: float, n: int = 600):
    """Half-infinite layer profile ``y(delta)`` from the first integral (guess only).

    ``d delta = eps / sqrt(2 A2 H(y)) |dy|`` integrated from the wall value ``yw``
    towards 0, in ``t = ln(y / yw)`` (:func:`initial_guess` continues it by ``exp(-delta / lam)``).
    """
    if yw == 0.0:
        return np.array([0.0, 1.0]), np.array([0.0, 0.0])
    t = np.linspace(0.0, math.log(1e-5), n)
    y = yw * np.exp(t)
    Hy = np.maximum(H(y, A0, A1), 1e-300)
    w = eps_of_C(np.exp(y)) * np.abs(y) / np.sqrt(2.0 * A2 * Hy)
    delta = cumtrapz(w, -t)
    return delta, y


def initial_guess(z: np.ndarray, g: Groups, prob, b: float, lam: float):
    """Initial ``(y, D)`` on ``z`` from two independent layer profiles."""
    A0e = prob.A0 if isinstance(prob, AffineProblem) else g.A0
    A1e = prob.A1 if isinstance(prob, AffineProblem) else g.A1
    if A0e == 0.0 and A1e == 0.0:
        A1e = float(prob.eps_of_C(np.array([1.0]))[0])
    y = np.zeros_like(z)
    for yw, dist in ((b, 1.0 - z), (b - g.A2, 1.0 + z)):
        dl, yl = layer_profile(yw, prob.eps_of_C, A0e, A1e, g.A2)
        inside = dist <= dl[-1]
        yy = np.empty_like(z)
        yy[inside] = np.interp(dist[inside], dl, yl)
        yy[~inside] = yl[-1] * np.exp(-np.minimum((dist[~inside] - dl[-1]) / lam, 700.0))
        y += yy
    y = np.clip(y, b - g.A2, b)
    D = np.sqrt(2.0 * np.maximum(H(y, A0e, A1e), 0.0) / g.A2)
    return y, D
