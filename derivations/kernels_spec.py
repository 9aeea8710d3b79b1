"""Which derived expressions become kernels (collected by ``codegen.build_source``)."""

from __future__ import annotations

import sympy as sp
from sympy.codegen.cfunctions import expm1

from . import model as M
from .codegen import Kernel


def base_kernels():
    A2, A3, rho, Y, y, B1, lam = M.A2, M.A3, M.rho, M.Y, M.y, M.B1, M.lam
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


def all_kernels():
    kernels = list(base_kernels())
    from . import closed_forms

    ck, constants, tables = closed_forms.kernels()
    kernels.extend(ck)
    return kernels, constants, tables
