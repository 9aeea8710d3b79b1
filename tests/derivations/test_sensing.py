"""The sensing derivation: its generated kernels against the SymPy expressions at 30 digits."""

import pytest
import sympy as sp

from derivations import sensing as DS
from ipmc_asym.kernels import _generated_sensing as GS


def test_linear_kernel_matches_the_linear_solution():
    sig, voc = DS.linear_solution()
    for lam in (1e-3, 0.05, 0.7, 3.0):
        s, v = GS.sense_linear(0.01, lam)
        ref_s = sp.N((sig / DS.b).subs(DS.lam, sp.Float(lam, 40)), 30)
        ref_v = sp.N((voc / DS.b).subs(DS.lam, sp.Float(lam, 40)), 30)
        assert s == pytest.approx(float(ref_s), rel=1e-14)
        assert v == pytest.approx(float(ref_v), rel=1e-13)


def test_cubic_kernel_matches_the_series():
    c3 = DS.cubic_coefficient()
    for rho in (0.0, 5 / 1005, 1.0):
        for phi4 in (0.2, 0.38):
            ref = float(sp.N(c3.subs({DS.rho: rho, DS.phi4: phi4}), 30))
            assert GS.sense_cubic(rho, phi4) == pytest.approx(ref, rel=1e-14)


def test_reciprocity_ratio_is_the_same_with_the_pressure_term():
    assert sp.simplify(DS.reciprocity_ratio(False) - DS.reciprocity_ratio(True)) == 0


def test_plane_strain_variant():
    tr = DS.volumetric_strain("strain")
    assert sp.simplify(tr - (-DS.kappa * DS.z * (1 - 2 * DS.nu) / (1 - DS.nu))) == 0
