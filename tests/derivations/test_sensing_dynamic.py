"""The frequency-domain sensing derivation: the library's closed form against the SymPy expression
at 30 digits, and the derivation's own checks (admittance, static limit, leading order)."""

import numpy as np
import pytest
import sympy as sp

from derivations import sensing_dynamic as DD
from ipmc_asym.dynamics.sensing import voc_hat


def test_library_voc_is_the_derived_one():
    _, voc = DD.solve()
    for W in (0.0, 0.7, 40.0, 5e3):
        for lam in (3e-4, 0.02, 0.3):
            kk = sp.sqrt(sp.I * sp.Float(W, 40) + 1 / sp.Float(lam, 40) ** 2)
            ref = complex(sp.N(voc.subs(DD.k, kk).subs({DD.W: sp.Float(W, 40), DD.lam: sp.Float(lam, 40)}), 30))
            got = complex(voc_hat(np.array([W]), lam)[0])
            assert abs(got - ref) <= 1e-12 * abs(ref)


@pytest.mark.slow
def test_derivation_checks():
    assert DD.check_admittance()
    DD.static_limit()
    lead, lin = DD.leading_order()
    assert sp.simplify(lead - 2 * (1 + sp.I * DD.W / 3)) == 0 and lin == -2
