"""Sensing mode, small signal in the frequency domain: the linearised PNP with the bending as a source.

Every step is checked by SymPy here (``python -m derivations.sensing_dynamic``).  Conventions and
the static result are those of ``derivations/sensing.py``: ``z = e zeta`` across the thickness,
the reported electrode at ``zeta = -1``, ``b = (1 - 2 nu) kappa e/phi4_0``, ``lam = lambda_D/e``,
thermal potential ``psi = F phi/(R T)``.  Frequency ``W = omega e^2/D`` (the scaling of the
actuation's small signal, ``derivations/charge.py:small_signal``), ``s = i W``.

Assumptions (each named where it is used):

* the water is redistributed instantly through the thickness (the drained matrix follows the
  imposed bending kinematically, ``tr eps = -(1 - 2 nu) kappa z``, at every instant): the
  solution flux relative to the solid is the one that carries the volume change, and the pressure
  it needs (Darcy (4)) is small against the matrix stress.  That needs ``omega`` well below the
  poroelastic rate ``K M/(eta e^2)`` (``K`` intrinsic permeability, ``eta`` the water viscosity,
  ``M`` the drained P-wave modulus); the project has no source for ``K``, so this limit is stated,
  not computed;
* one-way coupling, as in the static derivation: the pressure of Darcy (4), ``p' = (C F - rho2 Z3) E``
  plus the viscous part, is not fed back on the strain.  Its relative size scales with the core
  field, i.e. with ``|V_oc(W)|``: ``(R T C_moy/E) |V_oc(W)/V_oc(0)|`` (the static estimate of
  ``docs/sensing.md`` times the growth of the core field);
* the cations are convected with the solvent (Nernst-Planck (5) is written for ``V1 - V2``) and
  the rest state is uniform, so at linear order the convection drops out of the balance of
  cations per solution volume: ``phi4 dC/dt = -dN/dz`` with ``N`` the flux relative to the
  solvent (the water's own balance ``d phi4/dt = -d q/dz`` cancels ``C0 d phi4/dt + C0 dq/dz``).
  The water flow therefore leaves ``C`` unchanged and moves the fixed charge per solution
  volume: ``C_moy(z, t)/C_moy_0 - 1 = m = b(t) zeta`` (``derivations.sensing:face_ratios`` at
  first order), an imposed source in Gauss' law;
* Nernst-Planck without its pressure term (the paper's model (19)), constant core permittivity
  at linear order (the rest state has no field, so ``delta eps E_0 = 0``), blocking electrodes.

Equations (``c = C/C_moy_0 - 1``, ``mu = c + psi`` the electrochemical potential):

    s c = mu'',     lam^2 psi'' = -(c - b zeta),     mu'(+-1) = 0,   psi(-1) - psi(1) = v,

with ``u = c``: ``u'' - k^2 u = -b zeta/lam^2``, ``k^2 = s + 1/lam^2`` (the actuation's ``k``).
Results (``sigma_hat = sigma/S``, ``S = eps R T/(F lambda_D)``, charge of the face ``zeta = -1``):

1. ``sigma_hat = Y v + G b`` with (tanh form, no overflow at ``k ~ 1/lam``)

       Y = i lam k^3 / (2 (i k^2 tanh k - W (k - tanh k)))
       v_oc/b = -G/Y = [2 i W (k^3 - 3 k + 3 tanh k) + 6 k^2 (k - tanh k)] / (3 k^5 lam^2)

   ``Y`` is the actuation's admittance: ``Z_area = (e/kappa) v/(i W lam Y v)`` equals
   ``(e/kappa) Zhat`` of ``derivations/charge.py`` (checked).
2. ``W -> 0``: the static closed forms, ``sigma_hat = -b (coth(1/lam) - lam)``,
   ``v_oc = 2 b (1 - lam tanh(1/lam))`` (checked).
3. The Thevenin form is exact (a linear one-port): the strip is the EMF ``V_oc(W)`` behind its own
   impedance ``Z``.  But its EMF is NOT the static Donnan value: at leading order in ``lam``
   (``k -> 1/lam`` at fixed ``W``)

       v_oc = 2 b (1 + i W/3 - lam) + O(lam^2 (1 + W)^2)

   The extra ``2 b i W/3`` is the streaming potential: the water that leaves the compressed half
   carries its cations (neutral solution), the fixed charge it leaves behind must be neutralised
   by cations migrating back through the core, and that ionic current (``~ omega b C_moy F e``,
   zero at the blocking faces) drops ``(R T/F) b omega e^2/D`` over the core's resistance.  So the
   "static EMF in series with Z" assumption holds only for ``omega << 3 D/e^2`` (a relative error
   ``W/3``), far below the layers' charging rate ``1/tau = D/(e lambda_D)``.
4. Short circuit: ``sigma_sc = G b = -Y v_oc``; at ``W -> 0`` the static charge.
"""

from __future__ import annotations

import functools

import sympy as sp

from . import charge as CH
from .sensing import b as b_static
from .sensing import lam as lam_static
from .sensing import linear_solution

zeta = sp.symbols("zeta", real=True)
b, v = sp.symbols("b v")
lam = sp.symbols("lam", positive=True)
W = sp.symbols("W", positive=True)
k = sp.symbols("k")


@functools.lru_cache(maxsize=None)
def solve():
    """``(Y, v_oc/b)`` of the linear problem in the module docstring, in terms of ``k``, ``W``, ``lam``.

    The source ``b zeta`` and the voltage are odd in ``zeta``: the solution is odd (gauge
    ``psi(0) = 0``), ``u = b zeta/(lam^2 k^2) + A sinh(k zeta)``,
    ``mu = s (b zeta^3/(6 lam^2 k^2) + A sinh(k zeta)/k^2) + C1 zeta``.

    ``s`` stays a symbol until the end (``s = i W`` there): the solution is rational in ``s``,
    ``k``, ``sinh k``, ``cosh k``, so ``cancel`` over the rationals proves each identity (with
    ``i`` in the coefficients the same cancel works over the Gaussian rationals, ~30 times
    slower).  Cached: every check below starts from it.
    """
    s = sp.symbols("s")
    A, C1 = sp.symbols("A C1")
    u = b * zeta / (lam**2 * k**2) + A * sp.sinh(k * zeta)
    mu = s * (b * zeta**3 / (6 * lam**2 * k**2) + A * sp.sinh(k * zeta) / k**2) + C1 * zeta
    psi = mu - u
    # the three equations: NP (s c = mu''), Gauss (lam^2 psi'' = -(c - b zeta)) with k^2 = s + 1/lam^2
    assert sp.simplify(sp.diff(mu, zeta, 2) - s * u) == 0
    assert sp.simplify(sp.diff(u, zeta, 2) - k**2 * u + b * zeta / lam**2) == 0
    gauss = (lam**2 * sp.diff(psi, zeta, 2) + u - b * zeta).subs(k, sp.sqrt(s + 1 / lam**2))
    assert sp.simplify(gauss) == 0
    # blocking faces (mu' even: one face suffices), the voltage psi(-1) - psi(1) = -2 psi(1) = v
    sol = sp.solve([sp.diff(mu, zeta).subs(zeta, 1), -2 * psi.subs(zeta, 1) - v], [A, C1], dict=True)[0]
    assert sp.cancel((psi.subs(sol).subs(zeta, -1) - psi.subs(sol).subs(zeta, 1)) - v) == 0
    # face charge: sigma = D(-e) = -eps phi'(-e); over S = eps R T/(F lambda_D): -lam psi'(-1)
    sig = sp.cancel((-lam * sp.diff(psi, zeta)).subs(sol).subs(zeta, -1))
    Y = sp.cancel(sp.diff(sig, v))
    G = sp.cancel(sp.diff(sig, b))
    assert sp.cancel(sig - Y * v - G * b) == 0
    Y, voc = Y.subs(s, sp.I * W), sp.cancel(-G / Y).subs(s, sp.I * W)
    # the tanh forms of the module docstring
    th = sp.tanh(k)
    Y_t = sp.I * lam * k**3 / (2 * (sp.I * k**2 * th - W * (k - th)))
    voc_t = (2 * sp.I * W * (k**3 - 3 * k + 3 * th) + 6 * k**2 * (k - th)) / (3 * k**5 * lam**2)
    for kv, wv, lv in ((sp.Rational(3, 2) + sp.I / 3, sp.Rational(7, 3), sp.Rational(1, 5)),
                       (sp.Integer(4) + 2 * sp.I, sp.Rational(1, 2), sp.Rational(1, 9))):
        sub = {k: kv, W: wv, lam: lv}
        assert abs(complex(sp.N((Y - Y_t).subs(sub), 30))) < 1e-20
        assert abs(complex(sp.N((voc - voc_t).subs(sub), 30))) < 1e-20
    return Y_t, voc_t


def check_admittance():
    """``Y`` is the actuation's admittance: ``1/(i W lam Y) = Zhat`` of ``derivations/charge.py``."""
    Y, _ = solve()
    kc, Zref, _ = CH.small_signal()
    Zmine = 1 / (sp.I * W * lam * Y)
    for wv, lv in ((sp.Rational(7, 3), sp.Rational(1, 5)), (sp.Rational(1, 2), sp.Rational(1, 9)), (50, sp.Rational(1, 30))):
        kv = sp.sqrt(sp.I * wv + 1 / lv**2)
        r = (Zmine.subs(k, kv) - Zref.subs(kc, kv)).subs({W: wv, lam: lv})
        assert abs(complex(sp.N(r, 30))) < 1e-20 * abs(complex(sp.N(Zref.subs(kc, kv).subs({W: wv, lam: lv}), 30)))
    return True


def static_limit():
    """``W -> 0`` gives the static closed forms of ``derivations.sensing:linear_solution``."""
    Y, voc = solve()
    sig_static, voc_static = (x.subs(b_static, 1).subs(lam_static, lam) for x in linear_solution())
    k0 = 1 / lam
    v0 = sp.simplify(voc.subs(W, 0).subs(k, k0))
    s0 = sp.simplify((-Y * voc).subs(W, 0).subs(k, k0))
    for lv in (sp.Rational(1, 3), sp.Rational(1, 20), sp.Integer(2)):
        assert abs(sp.N((v0 - voc_static).subs(lam, lv), 30)) < 1e-25
        assert abs(sp.N((s0 - sig_static).subs(lam, lv), 30)) < 1e-25
    return v0, s0


def leading_order():
    """``v_oc/b = 2 (1 + i W/3 - lam) + ...`` as ``lam -> 0`` at fixed ``W`` (the streaming potential).

    ``tanh k -> 1`` exponentially (``Re k > 1/lam``): with ``tanh k = 1`` the remainder is
    ``O(lam)``; the series in ``lam`` is taken with ``k = sqrt(i W + 1/lam^2)``.
    """
    _, voc = solve()
    kk = sp.sqrt(sp.I * W + 1 / lam**2)
    v1 = voc.subs(sp.tanh(k), 1).subs(k, kk)
    lead = sp.limit(v1, lam, 0)
    assert sp.simplify(lead - 2 * (1 + sp.I * W / 3)) == 0
    # the first correction is -2 lam, independent of W (the remainder, O(lam^2 (1 + W)^2), is
    # measured in tests/dynamics/test_sensing.py)
    lin = sp.simplify(sp.limit((v1 - lead) / lam, lam, 0))
    assert lin == -2
    return lead, lin


def main():
    Y, voc = solve()
    print("Y =", Y)
    print("v_oc/b =", voc)
    print("admittance = the actuation's:", check_admittance())
    print("static limit (v_oc/b, sigma/b):", static_limit())
    lead, lin = leading_order()
    print("leading order in lam: v_oc/b =", lead, "; O(lam) coefficient:", lin)


if __name__ == "__main__":
    main()
