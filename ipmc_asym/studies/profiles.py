"""Profiles through the thickness (seed paper section 6.1, Figs 4-7): ``ipmc-asym profiles``.

The profiles come from the full BVP (:func:`ipmc_asym.bvp.solver.solve`) on its graded mesh, so the
electrode layers (~1e-3 of the thickness) are resolved.  Distances are measured from the
face, in micrometres, with ``e`` the HALF thickness (``z = z_bar e``, ``z_bar in [-1, 1]``;
anode ``z_bar = -1``, cathode ``z_bar = +1``).

Layer widths (the toolkit's one set of definitions: :data:`LAYER_WIDTHS`, used by
``profiles``, ``validate`` and ``scenes``; thresholds in :mod:`ipmc_asym.base.settings`)
-----------------------------------------------------------------------------------
``depletion`` (anode)
    distance from the anode face to the first point where ``C_bar`` rises through
    ``settings.DEPLETION_LEVEL`` (1/2: half the mean concentration).
``devoid`` (anode)
    distance from the anode face to where ``C_bar`` rises through ``settings.DEVOID_LEVEL``
    (0.01): the paper's "zone presque totalement depourvue de cations" (section 6.1).  This
    is the width compared with the paper's anode-layer widths.
``accumulation`` (cathode)
    distance from the cathode face to the point where the excess ``C_bar - 1`` has fallen to
    ``settings.ACCUMULATION_FRACTION`` (1/e) of its face value ``B1 - 1``: the 1/e decay
    length of the accumulated charge.
``accumulation_half`` (cathode)
    same, with ``settings.ACCUMULATION_HALF_FRACTION`` (1/2; less sensitive to the tail).
``accumulation_1pct`` (cathode)
    distance from the cathode face to where ``C_bar - 1`` falls through ``settings.DEVOID_LEVEL``
    (0.01): the cathode's counterpart of ``devoid``, the zone where the concentration differs
    from ``C_moy`` by more than 1 %.  This is the width compared with the paper's "accumulation
    de cations sur une longueur caracteristique" (section 6.1: 0.2 / 2 / 2 um).

The anode is the face at the higher potential: ``z_bar = -1`` for a positive voltage,
``z_bar = +1`` for a negative one (the mirror image).

Layer rule: stdlib + numpy at import; SciPy (via bvp) is imported lazily; figures are drawn by
:mod:`ipmc_asym.plotting.profiles`.
"""

from __future__ import annotations

import csv
import time

import numpy as np

from ipmc_asym.base.registry import model_names
from ipmc_asym.base.settings import (
    ACCUMULATION_FRACTION,
    ACCUMULATION_HALF_FRACTION,
    DEPLETION_LEVEL,
    DEVOID_LEVEL,
)
from ipmc_asym.io.fileio import atomic_write
from ipmc_asym.model.params import NAFION_LI, Material, Strip
from ipmc_asym.model.permittivity import get_model

__all__ = ["QUANTITIES", "profile", "debye_hueckel_profile", "DH_MIN_A2", "layer_widths", "profile_summary",
           "transition_width", "TRANSITION_LEVELS", "write_csv", "compute_all", "PAPER_LAYERS", "LAYER_WIDTHS"]

#: quantity key -> (BVPResult attribute, axis label)
QUANTITIES = {
    "C": ("C", r"$\bar C = C/C_{moy}$"),
    "phi": ("phi", r"$\bar\varphi = \varphi/\varphi_0$"),
    "D": ("D", r"$\bar D$ (dimensionless induction)"),
    "E": ("E", r"$\bar E = -d\bar\varphi/d\bar z$"),
    "rhoZ": ("rhoZ", r"$\overline{\rho Z} = \bar C - 1$"),
    "p": ("p", r"$\bar p = \bar C/A_2 - A_3\bar\varphi$ ($B_2=0$)"),
}

#: the layer widths: key of :func:`layer_widths` -> (face, what it measures)
LAYER_WIDTHS = {
    "depletion_um": ("anode", f"C_bar rises through {DEPLETION_LEVEL:g} from the anode face"),
    "devoid_um": ("anode", f"C_bar rises through {DEVOID_LEVEL:g} from the anode face"),
    "accumulation_um": ("cathode", f"C_bar - 1 falls to {ACCUMULATION_FRACTION:.4g} (B1 - 1) from the "
                                   "cathode face"),
    "accumulation_half_um": ("cathode", f"C_bar - 1 falls to {ACCUMULATION_HALF_FRACTION:g} (B1 - 1) "
                                        "from the cathode face"),
    "accumulation_1pct_um": ("cathode", f"C_bar - 1 falls through {DEVOID_LEVEL:g} from the cathode face"),
}

#: the paper's statements (section 6.1), micrometres
PAPER_LAYERS = {
    ("constant", "depletion"): 0.2, ("affine", "depletion"): 0.07,
    ("constant", "accumulation"): 0.2, ("linear", "accumulation"): 2.0, ("affine", "accumulation"): 2.0,
}


#: below this A2 (|phi0| ~ 2.6e-292 V) the Debye-Hueckel profiles are not computed: their
#: ``C - 1 = A2 s`` would leave the normal doubles, and ``p = C/A2`` (B2 = 0) overflows near 1e-308
DH_MIN_A2 = 1e-290


def profile(model="constant", strip: Strip | None = None, material: Material = NAFION_LI):
    """Profiles (a :class:`ipmc_asym.bvp.solver.BVPResult`) at ``strip`` (default nominal): the
    full BVP, and below the voltage it resolves (:func:`ipmc_asym.bvp.solver.min_voltage`) the
    Debye-Hueckel solution (:func:`debye_hueckel_profile`; its ``message`` says so)."""
    from ipmc_asym.bvp.solver import min_voltage, solve  # deferred: SciPy's solve_bvp (start-up)

    strip = Strip() if strip is None else strip
    if 0.0 < abs(strip.voltage) < min_voltage(material):
        return debye_hueckel_profile(model, strip, material)
    res = solve(strip, model, material)
    if not res.success:
        # the solver converges over the nominal strips; where it does not, the usual cause is a
        # strip far thinner or thicker than its Debye length, which the message says
        lam_m = float(res.groups.debye) * 0.5 * strip.thickness
        raise RuntimeError(
            f"BVP for the {res.model} profiles did not converge ({res.message.rstrip('.')}) at thickness "
            f"{strip.thickness:.3g} m = {strip.thickness / lam_m:.3g} Debye lengths ({lam_m:.3g} m at C_moy "
            f"{float(material.C_moy):.3g} mol/m^3), {strip.voltage:g} V: a thickness, C_moy or voltage nearer "
            "the nominal (200 um, some 6e3 Debye lengths) or another model")
    return res


def debye_hueckel_profile(model="constant", strip: Strip | None = None, material: Material = NAFION_LI,
                          nodes: int = 4001):
    """The profiles at a small voltage: the Debye-Hueckel solution, leading order in ``A2``.

    The BVP of :mod:`ipmc_asym.bvp.solver` linearised about rest (``C = 1 + A2 c``, ``eps`` at
    ``C = 1``: the first order ``x_1`` of ``derivations/debye_hueckel.py``, ``profile_leading``,
    whose overflow-free form is generated), with ``u = phi - 1/2``,
    ``u'' = u / lam^2``, ``u(-+1) = +-1/2`` and neutrality::

        phi = 1/2 - S,   C - 1 = A2 S,   E = lam S',   D = (A2 lam^2) E,
        S = sinh(z/lam) / (2 sinh(1/lam)),   B1 = 1 + A2/2

    (``lam`` the core Debye length over ``e``, ``groups.debye``), written with ``expm1`` so that no
    ``sinh`` overflows at thick strips nor cancels at thin ones.  The terms left out are of relative
    order ``A2`` (< 1e-6 below the BVP's floor; the tests hold the profiles to ``A2`` against the
    BVP just above it).  ``I`` is the moment integral's own small-voltage series
    (:func:`ipmc_asym.integral.api.moment_integral`, exact rung).

    Parameters
    ----------
    model : str or Permittivity
    strip : Strip
        ``0 < A2 = |phi0|/V_T`` (``A2 >= DH_MIN_A2``); a negative voltage is the mirror image.
    material : Material
    nodes : int
        Mesh nodes per half thickness, graded towards the faces from ``1e-4 lam``.

    Returns
    -------
    BVPResult
        On the same conventions as the BVP's (``status`` 0, no spline ``sol``).
    """
    from ipmc_asym.bvp.solver import BVPResult  # deferred: SciPy's solve_bvp (start-up)
    from ipmc_asym.integral.api import moment_integral  # deferred: the compiled kernels (start-up)
    from ipmc_asym.kernels._generated_dh import dh_profile_e, dh_profile_s  # deferred: loads Numba (start-up)

    t0 = time.perf_counter()
    strip = Strip() if strip is None else strip
    perm = get_model(model)
    g = perm.groups(strip, material)
    A2, A3, lam = float(g.A2), float(g.A3), float(g.debye)
    if not A2 >= DH_MIN_A2:
        raise ValueError(f"voltage |phi0| = {abs(float(strip.voltage)):.3g} V is too small for profiles: C - 1 "
                         f"~ A2 = {A2:.3g} leaves the normal doubles below A2 = {DH_MIN_A2:g} (and p = C/A2 "
                         f"overflows); the moment integral is answered at any voltage (ipmc-asym estimate)")
    # the mesh: from each face, geometric from 1e-4 lam up to the mid-plane
    d = np.concatenate(([0.0], np.geomspace(min(1e-4 * lam, 1e-6), 1.0, nodes - 1)))
    z = np.concatenate((d - 1.0, (1.0 - d)[-2::-1]))
    k, a = 1.0 / lam, np.abs(z) / lam
    # S = sinh(z/lam)/(2 sinh(1/lam)) and E = cosh(z/lam)/(2 lam sinh(1/lam)), overflow-free (generated)
    S = np.sign(z) * dh_profile_s(a, k)
    E = dh_profile_e(a, k)
    phi = 0.5 - S
    rho = A2 * S
    D = (A2 * lam * lam) * E  # eps at C = 1 is A2 lam^2 (the core Debye length)
    if g.sign < 0:  # mirror image z -> -z, potential referenced to the face z = +1 (as the BVP)
        z, rho, D, E, phi = -z[::-1], rho[::-1], -D[::-1], -E[::-1], phi[::-1] - 1.0
    B1 = 1.0 + float(rho[-1])  # C at the face z = +1 (1 + A2/2, or its mirror)
    C = 1.0 + rho
    I = float(moment_integral(strip.thickness, strip.voltage, perm, "exact", material=material))
    return BVPResult(z=z, C=C, phi=phi, E=E, D=D, rhoZ=rho, p=C / A2 - A3 * phi, y=np.log1p(rho), B1=B1, I=I,
                     groups=g, model=perm.name, success=True, status=0,
                     message=(f"Debye-Hueckel solution (|phi0| below the BVP's floor): leading order in A2, "
                              f"relative error about A2 = {A2:.2g}"),
                     niter=0, n_nodes=int(z.size), max_rms_residual=0.0, bc_residual=0.0,
                     seconds=time.perf_counter() - t0)


def _crossing(d, f, level):
    """First distance ``d`` (increasing) where ``f - level`` changes sign (linear interp.)."""
    g = f - level
    s = np.nonzero(np.sign(g[:-1]) != np.sign(g[1:]))[0]
    if s.size == 0:
        return float("nan")
    k = s[0]
    if g[k + 1] == g[k]:
        return float(d[k])
    return float(d[k] + (d[k + 1] - d[k]) * (-g[k]) / (g[k + 1] - g[k]))


def layer_widths(res, e: float) -> dict:
    """The layer widths of :data:`LAYER_WIDTHS`, in micrometres, from a BVP profile.

    Parameters
    ----------
    res : BVPResult (or anything with ``z``, ``C`` arrays of shape (n,), and ``groups.sign``)
        Profiles on ``z_bar in [-1, 1]``; for a negative voltage (``groups.sign < 0``) the
        anode is at ``z_bar = +1`` and the profile is mirrored first.
    e : float
        HALF thickness (m).

    Returns
    -------
    dict
        ``depletion_um``, ``devoid_um``, ``accumulation_um``, ``accumulation_half_um``,
        ``accumulation_1pct_um`` (NaN where the level is never crossed).
    """
    z, C = np.asarray(res.z, dtype=float), np.asarray(res.C, dtype=float)
    # C - 1 from rhoZ where the result has it: C itself rounds to 1 at a small voltage
    rz = getattr(res, "rhoZ", None)
    Cm1 = np.asarray(rz, dtype=float) if rz is not None else C - 1.0
    if getattr(getattr(res, "groups", None), "sign", 1.0) < 0:
        z, C, Cm1 = -z[::-1], C[::-1], Cm1[::-1]
    da = (z + 1.0) * e * 1e6  # from the anode, µm, increasing
    dc = ((1.0 - z) * e * 1e6)[::-1]  # from the cathode, increasing
    Cc = Cm1[::-1]
    B1m1 = Cc[0]
    return {"depletion_um": _crossing(da, C, DEPLETION_LEVEL),
            "devoid_um": _crossing(da, C, DEVOID_LEVEL),
            "accumulation_um": _crossing(dc, Cc, ACCUMULATION_FRACTION * B1m1),
            "accumulation_half_um": _crossing(dc, Cc, ACCUMULATION_HALF_FRACTION * B1m1),
            "accumulation_1pct_um": _crossing(dc, Cc, DEVOID_LEVEL)}


#: the levels of :func:`transition_width`: the 90-10 % width of a face layer
TRANSITION_LEVELS = (0.9, 0.1)


def transition_width(res, e: float, quantity: str = "D", face: str = "anode",
                     levels=TRANSITION_LEVELS) -> float:
    """Width (µm) over which a profile falls from ``levels[0]`` to ``levels[1]`` of its face layer.

    The face layer of ``quantity`` is its change from the core value (at ``z_bar = 0``) to the
    face value; the width is the distance between the first crossings, from the face, of the
    two levels of that change (a rise time's 90-10 % reading of "how steep", which does not
    depend on the mesh as a face derivative of a steep profile does).

    Parameters
    ----------
    res : BVPResult (or anything with ``z`` and ``quantity`` arrays of shape (n,) on [-1, 1])
    e : float
        HALF thickness (m).
    quantity : str
        ``"C"``, ``"phi"``, ``"D"``, ``"E"``, ``"p"`` or ``"rhoZ"``.
    face : str
        ``"anode"`` (``z_bar = -1`` for a positive voltage) or ``"cathode"`` (``+1``).
    levels : (float, float)
        Fractions of the face layer's change, first the one nearer the face.

    Returns
    -------
    float
        Width in µm (NaN where a level is never crossed or the layer has no change).

    Examples
    --------
    >>> import numpy as np
    >>> from types import SimpleNamespace
    >>> z = np.linspace(-1, 1, 200001)
    >>> r = SimpleNamespace(z=z, D=np.exp(-(z + 1) / 0.01))
    >>> round(transition_width(r, 1e-6, "D", "anode") / (0.01 * np.log(9)), 4)
    1.0
    """
    if face not in ("anode", "cathode"):
        raise ValueError(f"face must be 'anode' or 'cathode'; got {face!r}")
    z, f = np.asarray(res.z, dtype=float), np.asarray(getattr(res, quantity), dtype=float)
    if getattr(getattr(res, "groups", None), "sign", 1.0) < 0:
        z, f = -z[::-1], f[::-1]
    if face == "cathode":
        z, f = -z[::-1], f[::-1]
    d = (z + 1.0) * e * 1e6
    core = float(np.interp(0.0, z, f))
    change = f[0] - core
    if change == 0.0 or not np.isfinite(change):
        return float("nan")
    g = (f - core) / change
    return _crossing(d, g, levels[1]) - _crossing(d, g, levels[0])


def profile_summary(model="constant", strip: Strip | None = None, material: Material = NAFION_LI,
                    res=None) -> dict:
    """Layer widths and face values of the profiles for one model (SI / µm / dimensionless).

    Returns
    -------
    dict
        ``model``, ``B1`` (= C_bar at the cathode), ``C_anode``, ``depletion_um``, ``devoid_um``,
        ``accumulation_um``, ``accumulation_half_um``, ``accumulation_1pct_um``, ``D_face`` (D_bar at the faces, equal by
        electroneutrality), ``D_core`` (``|D_bar|`` max over the central half), ``p_anode``,
        ``p_cathode``, ``E_anode``, ``E_cathode``, ``I``, ``cathode_charge`` (F B1 C_moy, C/m^3),
        ``debye_um`` (core Debye length), ``e_um`` (HALF thickness), ``n_nodes``.

    Examples
    --------
    >>> r = profile_summary("constant")
    >>> r["model"], r["e_um"]
    ('constant', 100.0)
    """
    strip = Strip() if strip is None else strip
    if res is None:
        res = profile(model, strip, material)
    e = strip.e
    w = layer_widths(res, e)
    g = res.groups
    core = np.abs(res.z) < 0.5
    # the anode is the face at the higher potential: z_bar = -1 for a positive voltage, +1 for a
    # negative one (the BVP's B1 is C_bar at z_bar = +1 whatever the sign)
    a, c = (-1, 0) if g.sign < 0 else (0, -1)
    b1 = float(res.B1) if g.sign > 0 else float(res.C[c])
    out = {
        "model": res.model,
        "B1": b1,
        "C_anode": float(res.C[a]),
        **w,
        "D_face": float(res.D[c]),
        "D_core": float(np.max(np.abs(res.D[core]))),
        "p_anode": float(res.p[a]),
        "p_cathode": float(res.p[c]),
        "E_anode": float(res.E[a]),
        "E_cathode": float(res.E[c]),
        "I": float(res.I),
        "cathode_charge": float(material.F * b1 * g.C_moy),
        "debye_um": float(g.debye * e * 1e6),
        "e_um": e * 1e6,
        "n_nodes": int(res.n_nodes),
    }
    return out


def write_csv(res, path, e: float):
    """One row per mesh node: z_bar, z (m), distances from anode/cathode (m), and all profiles."""
    # the anode at z_bar = -1 for a positive voltage, +1 for a negative one
    s = 1.0 if getattr(getattr(res, "groups", None), "sign", 1.0) > 0 else -1.0
    with atomic_write(path) as fh:
        wr = csv.writer(fh)
        wr.writerow(["z_bar", "z_m", "dist_anode_m", "dist_cathode_m", "C_bar", "phi_bar", "D_bar",
                     "E_bar", "rhoZ_bar", "p_bar"])
        for i in range(len(res.z)):
            z = float(res.z[i])
            wr.writerow([f"{z:.17g}", f"{z * e:.10g}", f"{(1 + s * z) * e:.10g}", f"{(1 - s * z) * e:.10g}",
                         f"{res.C[i]:.12g}", f"{res.phi[i]:.12g}", f"{res.D[i]:.12g}",
                         f"{res.E[i]:.12g}", f"{res.rhoZ[i]:.12g}", f"{res.p[i]:.12g}"])


def compute_all(models=model_names(), strip: Strip | None = None, material: Material = NAFION_LI):
    strip = Strip() if strip is None else strip
    return {m: profile(m, strip, material) for m in models}
