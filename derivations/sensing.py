"""Sensing mode, static (after relaxation): the charge and voltage of a strip bent by an imposed curvature.

Every step is checked by SymPy here (``python -m derivations.sensing``).  Conventions:
``z`` across the thickness, faces ``z = -e`` (the electrode whose charge is reported, where an
actuation voltage ``phi0 = phi(-e) - phi(e)`` is applied) and ``z = +e``; the curvature ``kappa``
is ``w''`` of the deflection ``w`` along ``+z``, so the solid's axial strain is
``eps_xx = -kappa z`` (Bernoulli, paper section 3).

Assumptions (each named where it is used):

* incompressible phases (paper section 2), small strain (paper section 2), so the solid volume
  of a material element is conserved: ``(1 - phi4)(1 + tr eps) = 1 - phi4_0``;
* the drained matrix follows the imposed bending kinematically: ``eps_yy = eps_zz = -nu eps_xx``
  (plane stress in the width and through the thickness, free faces), ``nu`` the DRAINED Poisson
  ratio (no source read for Nafion; ``nu = 0`` is the paper's own section 3 reading, where a
  volume at ``z`` becomes ``(|R| + z)/|R| dV``).  Plane strain in the width would replace
  ``1 - 2 nu`` by ``(1 - 2 nu)/(1 - nu)`` (:func:`volumetric_strain`).  The feedback of the
  electrochemical pressure on the strain is neglected (one-way coupling);
* after relaxation there is no flux: Darcy (4) gives ``p' = (C F - rho2 Z3) E`` and
  Nernst-Planck (5), its pressure term neglected as in the paper's model (19), gives
  ``C' = (F/RT) C E``: Boltzmann, ``C = C0 exp(-F phi/RT)`` with one constant ``C0``.  The
  pressure-term variant replaces ``F/RT`` by ``g0 F/RT`` at linear order
  (``derivations/pressure.py``: ``(ln C)' = A2 E (gamma - beta C)``, ``g0 = 1 - beta (1 + A3)``);
* blocking, impermeable electrodes; in short circuit they are at one potential, in open circuit
  they carry no charge.

Results (``c_m = C_moy(z)/C_moy_0``, ``b = (1 - 2 nu) kappa e / phi4_0``, ``lam = lambda_D/e``,
``S = sqrt(phi4 C_moy eps_core R T)`` the charge scale of ``derivations/charge.py``):

1. Solid incompressible + eq (17): ``C_moy(z) = C_moy_0 phi4_0/(phi4_0 + tr eps(z))``, with
   ``tr eps = -(1 - 2 nu) kappa z``: ``c_m(+e) = 1/(1 - b)``, ``c_m(-e) = 1/(1 + b)``.  Water leaves
   the compressed side, whose fixed charge per solution volume rises.  The solution fraction
   reaches 0 at ``b = 1`` (all water squeezed out of a face): the model ends there.
2. Core: quasi-neutral, ``C = C_moy(z)``: Donnan law ``phi_core = (RT/F) ln(C0/C_moy(z))``.
   Layers: ``Y(+-e) = ln(C(+-e)/C_moy(+-e))``, and in short circuit ``Y+ - Y- = Delta``,
   ``Delta = ln(c_m(-e)/c_m(e)) = ln((1 - b)/(1 + b)) = -2 artanh b``: the actuation's layer
   problem with ``A2`` replaced by ``Delta``, but with different core concentrations at the two
   faces.  Overall neutrality ``D(e) = D(-e)`` (21): ``S+ q(Y+; rho+) + S- q(Y-; rho-) = 0``,
   ``q = sign(Y) Dhat(Y)`` the layer charge of ``derivations/charge.py`` (``dq/dY = chat``),
   ``S+- = S sqrt(h e)`` with ``h = phi4 C_moy/(phi4_0 C_moy_0) = 1/(1 + tr eps)`` and
   ``e = eps_core/eps_moy = rho0 + (1 - rho0) c_m``, ``rho+- = rho0/e``.  The charge of the
   electrode at ``-e`` is ``sigma = D(-e) = -S- q(Y-)``.
3. Linear in kappa, any thickness (Debye-Hueckel, exact in lam): ``ln c_m = b z/e`` at first
   order, and the linearised Poisson-Boltzmann problem has the exact solution
   ``psi = -b z/e + b sinh(z/lambda_D)/sinh(1/lam)`` (short circuit, ``B = 0`` from (21)), so
   ``sigma = -S b (coth(1/lam) - lam)``;  the ``-lam`` is the core's own induction
   ``eps E_core``, ``E_core = (RT/F) (ln C_moy)'``, of order lam against the layers'.  Identical
   for the three permittivity models (they share ``eps_moy`` only through ``S`` and ``lam``):
   the models differ from the cubic order on.
4. Open circuit (``D(+-e) = 0``): ``V_oc = phi(-e) - phi(e) = -(RT/F) Delta (1 - lam tanh(1/lam))``
   at linear order; at leading order in lam for any ``b`` the layers carry no charge and
   ``V_oc = (RT/F) 2 artanh b``: the Donnan difference.  Thevenin: ``sigma = -C_d(0) V_oc`` with
   ``C_d(0) = eps/(2 lambda_D)`` (the layers in series) up to ``O(lam)``.
5. Cubic term (neutral core, lam -> 0): ``sigma/S = -b (1 + c3 b^2 + O(b^4))`` (odd by the
   mirror ``z -> -z``, which swaps the short-circuited electrodes), ``c3(rho0, phi4_0)`` from the
   series of the balance of 2.  Linearity in kappa ends where ``|c3| b^2`` reaches the stated
   tolerance.
6. Reciprocity.  A tip force on a cantilever gives ``kappa(x) = 3 w (L - x)/L^3``, so
   ``Q = 2l int_0^L sigma(kappa(x)) dx`` and at linear order ``dQ/dw = 3 l s1/L``,
   ``s1 = dsigma/dkappa``.  The actuation at small voltage: ``p = -C_moy F (1 + A3) phi``,
   ``M_A = 6 l int p z dz = 6 l C_moy F (1 + A3) phi0 e^2 lam (coth(1/lam) - lam)``, blocking
   force (14) ``3 M_A/(2 L)``.  Their ratio is ``(1 - 2 nu)/(3 (1 + A3))`` at every thickness,
   with or without the pressure term (:func:`reciprocity_ratio`): not 1.  The ``3`` is the
   paper's moment ``6 l int p z dz`` (eq (6), ``sigma_xx = 3 p``) where a pore pressure in a
   drained matrix with free faces gives ``sigma_xx = -(1 - 2 nu) p``; the ``1 + A3`` is the
   ``rho2 Z3`` term of Darcy (4), which drives the actuation pressure but has no counterpart in
   the swelling of the fixed charge.  With the moment ``2 l (1 - 2 nu) int p z dz`` and without
   ``A3`` the two sides agree.
"""

from __future__ import annotations

import sympy as sp

from .kernel import Kernel

# ---- symbols -------------------------------------------------------------------------
z, e, kappa = sp.symbols("z e kappa", real=True)
nu = sp.symbols("nu", real=True)
phi4 = sp.symbols("phi4", positive=True)  # solution volume fraction at rest, phi4_0
t = sp.symbols("t", real=True)  # volumetric strain tr eps
b = sp.symbols("b", real=True)  # (1 - 2 nu) kappa e / phi4_0
lam = sp.symbols("lam", positive=True)  # lambda_D / e
rho = sp.symbols("rho", nonnegative=True)  # eps0/eps_moy at rest
Y = sp.symbols("Y", real=True)
A3 = sp.symbols("A3", real=True)
g0 = sp.symbols("g0", positive=True)


def volumetric_strain(width: str = "stress"):
    """``tr eps`` at ``z`` from ``eps_xx = -kappa z`` and the drained Poisson ratio ``nu``.

    ``width="stress"``: ``eps_yy = eps_zz = -nu eps_xx``; ``"strain"``: ``eps_yy = 0`` and
    ``sigma_zz = 0`` give ``eps_zz = -nu/(1 - nu) eps_xx`` (isotropic Hooke, eq (3) drained).
    """
    exx = -kappa * z
    if width == "stress":
        return exx * (1 - 2 * nu)
    lame, G = sp.symbols("lambda_L G", positive=True)
    ezz = sp.symbols("ezz")
    # sigma_zz = lambda tr eps + 2 G eps_zz = 0 with eps_yy = 0
    sol = sp.solve(sp.Eq(lame * (exx + ezz) + 2 * G * ezz, 0), ezz)[0]
    # lambda/(2 (lambda + G)) = nu/(1 - nu) for isotropic Hooke: lambda = 2 G nu/(1 - 2 nu)
    sol = sp.simplify(sol.subs(lame, 2 * G * nu / (1 - 2 * nu)))
    assert sp.simplify(sol - (-nu / (1 - nu) * exx)) == 0
    return sp.simplify(exx + sol)


def fixed_charge_ratio():
    """``c_m = C_moy(t)/C_moy_0`` from eq (17) with a conserved solid volume (solid incompressible)."""
    rho3, Z3, F = sp.symbols("rho3 Z3 F", real=True)
    phi4_t = 1 - (1 - phi4) / (1 + t)  # (1 - phi4)(1 + t) = 1 - phi4_0
    cmoy = lambda p4: -(1 - p4) * rho3 * Z3 / (p4 * F)  # noqa: E731  eq (17)
    ratio = sp.simplify(cmoy(phi4_t) / cmoy(phi4))
    assert sp.simplify(ratio - phi4 / (phi4 + t)) == 0
    # phi4 C_moy (the fixed charge per total volume over F) scales as 1/(1 + t)
    assert sp.simplify(phi4_t * cmoy(phi4_t) / (phi4 * cmoy(phi4)) - 1 / (1 + t)) == 0
    return phi4 / (phi4 + t)


def face_ratios():
    """``(c_m(+e), c_m(-e), Delta)`` in terms of ``b`` (plane stress in the width)."""
    cm = fixed_charge_ratio()
    tr = volumetric_strain("stress")
    sub_b = {kappa: b * phi4 / ((1 - 2 * nu) * e)}
    cp = sp.simplify(cm.subs(t, tr.subs(z, e)).subs(sub_b))
    cn = sp.simplify(cm.subs(t, tr.subs(z, -e)).subs(sub_b))
    assert sp.simplify(cp - 1 / (1 - b)) == 0 and sp.simplify(cn - 1 / (1 + b)) == 0
    delta = sp.log((1 - b) / (1 + b))
    assert sp.simplify(sp.diff(delta + 2 * sp.atanh(b), b)) == 0 and (delta + 2 * sp.atanh(b)).subs(b, 0) == 0
    return cp, cn, delta


def linear_solution():
    """Linearised Poisson-Boltzmann with ``ln c_m = b zb`` (``zb = z/e``): the exact solution.

    Thermal potential ``psi = F phi/RT``, ``ln C/C_moy_0 = c - psi``; Gauss ``psi'' = (psi - c + b zb)/lam^2``
    (``zb`` units).  Short circuit ``psi(+-1) = 0`` with (21) ``psi'(1) = psi'(-1)``; open circuit
    ``psi'(+-1) = 0``, ``psi(1) = 0``.  Returns ``(sigma_hat, v_oc_hat)``: ``sigma/S`` (face -1)
    and ``V_oc F/RT``, checked against the ODE and boundary conditions.
    """
    zb = sp.symbols("zb", real=True)
    c, A, B = sp.symbols("c A B", real=True)
    psi = c - b * zb + A * sp.sinh(zb / lam) + B * sp.cosh(zb / lam)
    assert sp.simplify(sp.diff(psi, zb, 2) - (psi - c + b * zb) / lam**2) == 0
    dpsi = sp.diff(psi, zb)
    sol = sp.solve([psi.subs(zb, 1), psi.subs(zb, -1), dpsi.subs(zb, 1) - dpsi.subs(zb, -1)], [c, A, B], dict=True)[0]
    # D = eps E = -eps (RT/F) psi'/e; S = eps RT/(F lambda_D) = eps RT/(F lam e): D/S = -lam psi'
    sig = sp.simplify((-lam * dpsi).subs(sol).subs(zb, -1))
    ref = -b * (1 / sp.tanh(1 / lam) - lam)
    assert sp.simplify((sig - ref).rewrite(sp.exp)) == 0
    solo = sp.solve([dpsi.subs(zb, 1), dpsi.subs(zb, -1), psi.subs(zb, 1)], [c, A, B], dict=True)[0]
    voc = sp.simplify((psi.subs(solo).subs(zb, -1) - psi.subs(solo).subs(zb, 1)))
    refo = 2 * b * (1 - lam * sp.tanh(1 / lam))
    assert sp.simplify((voc - refo).rewrite(sp.exp)) == 0
    # Thevenin: sigma = -C_d(0) V_oc at leading order, C_d(0) = S F/(2 RT): sigma_hat = -v_oc_hat/2
    assert sp.limit(sig / refo, lam, 0) == -sp.Rational(1, 2)
    return ref, refo


def _q_series(order):
    """``q(Y; rho) = sign(Y) sqrt(2 Hhat(Y))`` as a power series in ``Y`` (analytic at 0)."""
    Hhat = (1 - rho) * (sp.exp(Y) - 1) ** 2 / 2 + rho * (sp.exp(Y) - 1 - Y)  # derivations/charge.py
    g = sp.series(2 * Hhat / Y**2, Y, 0, order).removeO()
    return sp.expand(sp.series(Y * sp.sqrt(g), Y, 0, order + 1).removeO())


def cubic_coefficient():
    """``c3(rho0, phi4_0)``: ``sigma/S = -b (1 + c3 b^2 + O(b^4))`` of the neutral-core balance."""
    order = 4
    qs = _q_series(order)
    d1, d2, d3 = sp.symbols("d1 d2 d3")
    cp, cn, delta = face_ratios()
    tp, tn = -phi4 * b, phi4 * b  # tr eps at +e, -e
    def side(cm, tr, Yv):
        ev = rho + (1 - rho) * cm
        S = sp.sqrt(ev / (1 + tr))
        return S * qs.subs(rho, rho / ev).subs(Y, Yv)
    Ym = d1 * b + d2 * b**2 + d3 * b**3
    Yp = Ym + delta
    bal = sp.expand(sp.series(side(cp, tp, Yp) + side(cn, tn, Ym), b, 0, 4).removeO())
    s1 = sp.solve(bal.coeff(b, 1), d1)[0]
    assert s1 == 1  # Y- = b, Y+ = -b: the linear solution's sigma = -S b
    bal = sp.expand(bal.subs(d1, s1))
    s2 = sp.solve(bal.coeff(b, 2), d2)[0]
    s3 = sp.solve(sp.expand(bal.subs(d2, s2)).coeff(b, 3), d3)[0]
    sig = -side(cn, tn, Ym.subs({d1: s1, d2: s2, d3: s3}))
    ser = sp.expand(sp.series(sig, b, 0, 4).removeO())
    assert sp.simplify(ser.coeff(b, 1) + 1) == 0 and sp.simplify(ser.coeff(b, 2)) == 0
    c3 = sp.simplify(-ser.coeff(b, 3))
    return c3


def reciprocity_ratio(pressure_term: bool = False):
    """``(dQ/dw at V = 0)/(dF_block/dV at w = 0)`` of the linear two-port (tip-force cantilever).

    ``F, C_moy, e, l, L`` cancel; the result is ``(1 - 2 nu)/(3 (1 + A3))`` with or without the
    pressure term (``g0``: ``lam -> lam/sqrt(g0)``, thermal voltage ``-> RT/(F g0)``).
    """
    F, Cm, l, L, x, w = sp.symbols("F C_moy l L x w", positive=True)
    lb = lam / sp.sqrt(g0) if pressure_term else lam
    sig_hat, _ = linear_solution()
    # sigma = S sigma_hat, S = lam e phi4 F C_moy; pressure term: S b/sqrt(g0) with lam -> lam_b
    S = lam * e * phi4 * F * Cm
    pref = 1 / sp.sqrt(g0) if pressure_term else 1
    s1 = sp.diff(S * pref * sig_hat.subs(lam, lb).subs(b, (1 - 2 * nu) * kappa * e / phi4), kappa)
    kx = 3 * w * (L - x) / L**3  # tip force on a cantilever: M = P (L - x), w = P L^3/(3 E I)
    dQdw = sp.diff(2 * l * sp.integrate(s1 * kx, (x, 0, L)), w)
    # actuation, small voltage: M_A = 6 l C_moy F (1 + A3) phi0 e^2 lam_b (coth(1/lam_b) - lam_b)
    # (design.md, Debye-Hueckel series I0); the strip's force on the blocker is -3 M_A/(2 L) along z
    M_per_V = 6 * l * Cm * F * (1 + A3) * e**2 * lb * (1 / sp.tanh(1 / lb) - lb)
    dFdV = -3 * M_per_V / (2 * L)
    ratio = sp.simplify(dQdw / dFdV)
    assert sp.simplify(ratio - (1 - 2 * nu) / (3 * (1 + A3))) == 0
    return ratio


def kernels():
    """Generated kernels of the static sensing response."""
    sig, voc = linear_solution()
    c3 = cubic_coefficient()
    return [
        Kernel("sense_linear", (b, lam), (sig / b, voc / b),
               "(sigma/(S b), V_oc F/(R T b)) at linear order in b = (1 - 2 nu) kappa e/phi4_0, any lam = lambda_D/e.",
               "derivations.sensing:linear_solution"),
        Kernel("sense_cubic", (rho, phi4), (c3,),
               "c3: sigma/S = -b (1 + c3 b^2 + O(b^4)) of the neutral-core layer balance (lam -> 0).",
               "derivations.sensing:cubic_coefficient"),
    ]


def main():
    print("tr eps (plane stress) =", volumetric_strain("stress"), "; plane strain =", volumetric_strain("strain"))
    print("C_moy(t)/C_moy_0 =", fixed_charge_ratio())
    cp, cn, d = face_ratios()
    print("c_m(+e) =", cp, " c_m(-e) =", cn, " Delta =", d)
    s, v = linear_solution()
    print("sigma/S =", s, "  V_oc F/RT =", v)
    print("c3 =", cubic_coefficient())
    print("reciprocity ratio =", reciprocity_ratio(), " (pressure term:", reciprocity_ratio(True), ")")


if __name__ == "__main__":
    main()
