"""Which derived expressions become kernels (collected by ``codegen.TARGETS``)."""

from __future__ import annotations

import functools

import sympy as sp
from sympy.codegen.cfunctions import expm1

from . import closed_forms
from . import model as M
from .kernel import Kernel


def base_kernels():
    A2, A3, rho, Y, y, B1 = M.A2, M.A3, M.rho, M.Y, M.y, M.B1
    q, a, b, c = M.b1_quadratic_rho()
    qv = -expm1(-A2)
    disc = b**2 - 4 * a * c
    # the positive root without cancellation (citardauq when b >= 0)
    root = sp.Piecewise((-2 * c / (b + sp.sqrt(disc)), b >= 0), ((-b + sp.sqrt(disc)) / (2 * a), True))
    ks = [
        Kernel(
            "b1_exact",
            (A2, rho),
            (root.subs(q, qv),),
            "Exact B1 from electroneutrality H(ln B1) = H(ln B1 - A2) (all A2 > 0, rho in [0, 1]).",
            "derivations.model:b1_quadratic_rho",
        )
    ]
    w, Q = M.w_layer()
    ks.append(
        Kernel(
            "w_layer",
            (y, rho),
            (w,),
            "Layer integrand w(y) = ehat/sqrt(Qhat); dz = lambda w dy / |y| in a layer.",
            "derivations.model:w_layer",
        )
    )
    ks.append(
        Kernel(
            "dhat",
            (Y, rho),
            (M.dhat_stable(),),
            "Dhat(Y) = sqrt(2 Hhat(Y)); D(1) = lambda Dhat(ln B1).",
            "derivations.model:dhat_stable",
        )
    )
    (W0c, W0a, W1c, W1a, Dc, cm), J1, J2 = M.moment_assembly()
    ks.append(
        Kernel(
            "assemble_j",
            (A2, A3, rho, B1, cm, Dc, W0c, W0a, W1c, W1a),
            (J1, J2),
            "(J1, J2) with I = lam J1 + lam^2 J2 from the four layer functions.",
            "derivations.model:moment_assembly",
        )
    )
    return ks


#: exact rho = A1/(A0 + A1) of the paper's models (eps0 = 5e-6, eps_moy - eps0 = 1e-3 F/m)
MODEL_RHO = {"constant": sp.Integer(1), "linear": sp.Integer(0), "affine": sp.Rational(5, 1005)}


def model_kernels():
    """The same expressions with rho fixed per model (fewer operations on the hot path)."""
    A2, A3, Y, B1 = M.A2, M.A3, M.Y, M.B1
    q, a, b, c = M.b1_quadratic_rho()
    (W0c, W0a, W1c, W1a, Dc, cm), J1, J2 = M.moment_assembly()
    ks = []
    for name, r in MODEL_RHO.items():
        ar, br, cr = (sp.simplify(v.subs(M.rho, r)) for v in (a, b, c))
        if ar == 0:  # constant model: linear equation b B1 + c = 0
            root = -cr / br
        elif cr == 0:  # linear model: B1 (a B1 + b) = 0, positive root
            root = -br / ar
        else:  # b < 0 for rho < 1/2: no cancellation in (-b + sqrt(disc)) / (2a)
            assert r < sp.Rational(1, 2)
            root = (-br + sp.sqrt(br**2 - 4 * ar * cr)) / (2 * ar)
        em1 = sp.Symbol("em1")  # expm1(-A2), computed once by the caller (also gives e^{-A2})
        root = (sp.simplify(root) if ar == 0 or cr == 0 else root).subs(q, -em1)
        ks.append(Kernel(f"b1_{name}", (A2, em1), (root,),
                         f"Exact B1, {name} model (rho = {r}); em1 = expm1(-A2).",
                         "derivations.model:b1_quadratic_rho"))
        # per-model Dhat(Y): used by the electrode charge (sigma = lam Dhat(ln B1))
        dh = sp.simplify(M.dhat_stable().subs(M.rho, r))
        if r == 0:
            dh = sp.Abs(expm1(Y))  # |Y| exprel(Y) = |e^Y - 1|
        ks.append(Kernel(f"dhat_{name}", (Y,), (dh,), f"Dhat(Y) = sqrt(2 Hhat(Y)), {name} model.",
                         "derivations.model:dhat_stable"))
        # the same Dhat from C = B1 directly (no exp): sqrt(2 Hhat(C)), fine when C - 1 is not small
        Cs = sp.Symbol("C", positive=True)
        Hc = M.H_of_C(Cs).subs({M.A0: 1 - r, M.A1: r})
        ks.append(Kernel(f"dhat_from_c_{name}", (Cs, Y), (sp.sqrt(2 * Hc).subs(sp.log(Cs), Y),),
                         f"Dhat = sqrt(2 Hhat(C)) with C = e^Y given (use when |Y| > 1/2), {name} model.",
                         "derivations.model:H_of_C"))
        ks.append(Kernel(f"assemble_j_{name}", (A2, A3, B1, cm, Dc, W0c, W0a, W1c, W1a),
                         (J1.subs(M.rho, r), sp.expand(J2.subs(M.rho, r))),
                         f"(J1, J2), {name} model.", "derivations.model:moment_assembly"))
    return ks


@functools.lru_cache(maxsize=1)
def kernels_and_constants():
    """(kernels, constants) of ``_generated.py``, without its tables; cached: the derivation
    takes seconds and both ``codegen.check`` and the kernel-vs-SymPy tests need it (treat as
    read-only)."""
    kernels = list(base_kernels()) + model_kernels()
    ck, constants = closed_forms.kernels()
    kernels.extend(ck)
    return kernels, constants


@functools.lru_cache(maxsize=1)
def all_kernels():
    """(kernels, constants, tables) of ``_generated.py``; cached as :func:`kernels_and_constants`."""
    kernels, constants = kernels_and_constants()
    return kernels, constants, closed_forms.tables()
