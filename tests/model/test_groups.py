"""The derived quantities of ipmc_asym.model.groups: one home for their formulas (a source
scan of the package) and their values at the paper's nominal strip (section 4)."""

from __future__ import annotations

import ast
import re
from pathlib import Path

import numpy as np
import pytest

from ipmc_asym.base import registry
from ipmc_asym.integral import api as ia
from ipmc_asym.kernels._generated import b1_exact
from ipmc_asym.model import groups, params
from ipmc_asym.model.params import NAFION_LI, NOMINAL_STRIP
from ipmc_asym.model.permittivity import get_model

PKG = Path(__file__).resolve().parents[2] / "ipmc_asym"
HOME = PKG / "model" / "groups.py"

#: formula patterns (code, not prose: each needs the ``*`` of an expression)
_Q = r"(?:[A-Za-z_]\w*\.)?"  # an optional ``material.`` / ``m.`` qualifier
PATTERNS = {
    "A3 = -rho2 Z3/(C_moy F)": r"rho2\s*\*[^#\n]*Z3",
    "A2 = F |phi0|/(R T)": rf"/\s*\(\s*{_Q}R\s*\*\s*{_Q}T\s*\)",
    "R T / F": rf"\b{_Q}R\s*\*\s*{_Q}T\s*/\s*{_Q}F\b",
    "lambda = sqrt(eps R T/(e^2 phi4 F^2 C_moy))":
        rf"sqrt\([^#\n]*R\s*\*\s*{_Q}T\s*/|phi4\s*\*\s*{_Q}F\s*(?:\*\s*{_Q}F\b|\*\*\s*2)",
    "kappa = phi4 F^2 D C_moy/(R T)": rf"phi4\s*\*\s*{_Q}F\s*(?:\*\*\s*2\s*)?\*\s*{_Q}D\b",
}

#: functions allowed to hold a copy of a formula (none)
PENDING: set = set()


def _pending_lines(path: Path) -> set:
    rel = path.relative_to(PKG).as_posix()
    names = {f for p, f in PENDING if p == rel}
    if not names:
        return set()
    out = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)) and node.name in names:
            out.update(range(node.lineno, node.end_lineno + 1))
    return out


def _hits():
    found = []
    for path in sorted(PKG.rglob("*.py")):
        if path.name.startswith("_generated") or path == HOME:
            continue
        skip = _pending_lines(path)
        for i, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
            if i in skip:
                continue
            for what, pat in PATTERNS.items():
                if re.search(pat, line):
                    found.append(f"{path.relative_to(PKG)}:{i}: {what}: {line.strip()}")
    return found


def test_formulas_live_in_groups_only():
    assert not _hits(), "\n".join(_hits())


def test_patterns_match_the_home_module():
    text = HOME.read_text(encoding="utf-8")
    for what, pat in PATTERNS.items():
        if what == "R T / F":  # written as 1 / (F/(R T)) there
            continue
        assert re.search(pat, text), what


def test_pending_functions_exist():
    for rel, name in PENDING:
        assert _pending_lines(PKG / rel), f"{rel}:{name} is gone: drop it from PENDING"


# ---------------------------------------------------------------------------------------
# values at the nominal strip (paper section 4: 2e = 200 um, 2l = 5 mm, C_moy = 3082)
# ---------------------------------------------------------------------------------------
def test_nominal_values():
    m = NAFION_LI
    assert m.C_moy == 3082.0
    assert groups.A3(m) == pytest.approx(0.303, abs=5e-4)
    assert groups.A2(1.0, m) == pytest.approx(38.7, abs=0.05)
    assert groups.A5(NOMINAL_STRIP.width, NOMINAL_STRIP.thickness, 1.0, m) == pytest.approx(0.0446, rel=1e-3)
    assert groups.thermal_voltage(m) * groups.inverse_thermal_voltage(m) == pytest.approx(1.0, rel=1e-15)
    # kappa = phi4 F^2 D C_moy/(R T) ~ 0.44 S/m at D = 1e-10 m^2/s
    assert groups.kappa(m) == pytest.approx(m.phi4 * m.F**2 * m.D * m.C_moy / (m.R * m.T), rel=1e-14)


def test_parity_in_voltage():
    v = np.array([-2.0, -0.5, 0.0, 0.5, 2.0])
    th = NOMINAL_STRIP.thickness
    m = NAFION_LI
    for f in (lambda u: groups.A2(u, m), lambda u: groups.A0(th, u, 1e-3, m),
              lambda u: groups.A1(th, u, 5e-6, m), lambda u: groups.A5(5e-3, th, u, m)):
        y = f(v)
        np.testing.assert_array_equal(y, y[::-1])  # even: built on |phi0|
        assert y[2] == 0.0 and np.all(y >= 0)
        np.testing.assert_allclose(f(2.0 * v), 2.0 * y, rtol=1e-15)  # linear in |phi0|


def test_debye_length_is_sqrt_groups_ratio():
    th = np.array([[50e-6], [200e-6]])
    v = np.array([0.3, 1.0, 3.0])
    m = NAFION_LI
    eps0, deps = 5e-6, 1e-3
    lam = groups.debye_length(th, eps0 + deps, m)
    assert lam.shape == (2, 1)
    ratio = np.sqrt((groups.A0(th, v, deps, m) + groups.A1(th, v, eps0, m)) / groups.A2(v, m))
    np.testing.assert_allclose(ratio, np.broadcast_to(lam, ratio.shape), rtol=1e-14)
    np.testing.assert_allclose(groups.debye_length_m(eps0 + deps, m), lam * 0.5 * th, rtol=1e-15)
    # C_g / C_d(0) = lambda with C_d(0) = eps_core / (2 lambda_D)
    cd0 = (eps0 + deps) / (2.0 * groups.debye_length_m(eps0 + deps, m))
    np.testing.assert_allclose(groups.geometric_capacitance(th, eps0 + deps) / cd0, lam, rtol=1e-14)


def test_c_moy_array_broadcasts():
    C = np.array([2500.0, 3082.0, 3500.0])
    a3 = groups.A3(NAFION_LI, C)
    assert a3.shape == (3,) and a3[1] == pytest.approx(float(groups.A3(NAFION_LI)), rel=1e-15)
    np.testing.assert_allclose(a3 * C, a3[1] * 3082.0, rtol=1e-15)  # A3 ~ 1/C_moy


def test_make_groups_and_reexports():
    assert params.Groups is groups.Groups and params.make_groups is groups.make_groups
    assert params.debye_length is groups.debye_length and params.moment_scale is groups.moment_scale
    s = NOMINAL_STRIP.with_(voltage=-1.0)
    g = get_model("affine").groups(s, NAFION_LI)
    assert g.sign == -1.0 and g.A2 == pytest.approx(38.7, abs=0.05)
    assert g.debye == pytest.approx(np.sqrt((g.A0 + g.A1) / g.A2), rel=1e-14)
    assert g.A5 == pytest.approx(0.0446, rel=1e-3) and g.A3 == pytest.approx(0.303, abs=5e-4)


def test_secant_of_a_custom_law():
    perm = get_model(lambda C: 5e-6 + 1e-3 * C / 3082.0)
    e0, de = perm.secant(3082.0)
    assert e0 == pytest.approx(5e-6, rel=1e-12) and de == pytest.approx(1e-3, rel=1e-12)
    assert get_model("affine").secant(3082.0) == (5e-6, 1e-3)


@pytest.mark.parametrize("rho", [0.0, 5.0 / 1005.0, 0.3, 1.0])
def test_b1_neutral_root(rho):
    A2 = np.array([1e-6, 0.1, 1.0, 5.0, 38.7, 200.0])
    B = groups.b1_neutral(A2, rho)
    em = np.exp(-A2)
    # G(B1) = G(B1 e^{-A2}), G(C) = (1 - rho) C^2/2 + (2 rho - 1) C - rho ln C
    t1 = -0.5 * (1 - rho) * B**2 * np.expm1(-2.0 * A2)
    t2 = -(2 * rho - 1) * B * np.expm1(-A2)
    assert np.all(np.abs(t1 + t2 - rho * A2) <= 1e-13 * (np.abs(t1) + np.abs(t2) + rho * A2))
    assert np.all(B >= 1.0) and groups.b1_neutral(0.0, rho) == 1.0
    if rho == 1.0:
        np.testing.assert_allclose(B, A2 / -np.expm1(-A2), rtol=1e-15)
    if rho == 0.0:
        np.testing.assert_allclose(B, 2.0 / (1.0 + em), rtol=1e-15)


def test_b1_neutral_matches_the_compiled_root():
    for A2 in (0.05, 1.0, 38.7):
        for rho in (0.0, 5.0 / 1005.0, 0.5, 1.0):
            assert float(groups.b1_neutral(A2, rho)) == pytest.approx(b1_exact(A2, rho), rel=1e-13)


def test_registry_flags():
    for name, f in registry.FIDELITIES.items():
        assert f.compiled == (f.kernel_code is not None), name
        assert f.order == (f.kernel_code if f.compiled else -1)
    assert ia.ANY_THICKNESS == ("exact", "bvp")
    assert ia.FIDELITIES == tuple(registry.FIDELITIES)
    assert registry.compiled_fidelities() == ("leading", "corrected", "quadrature", "exact")
    assert registry.is_compiled("exact") and not registry.is_compiled("bvp")
    assert not registry.is_compiled("nope") and not registry.is_compiled(None)


def test_pressure_beta_and_its_parameters():
    from ipmc_asym.model.groups import pressure_beta
    from ipmc_asym.model.params import NAFION_LI, V1_LI_DEFAULT, Material

    # beta = (v1 - M1 v2/M2) C_moy with v2 = M2/rho2 (dilute water): (v1 - M1/rho2) C_moy
    assert float(pressure_beta(NAFION_LI)) == pytest.approx((V1_LI_DEFAULT - 6.941e-3 / 1000.0) * 3082.0, rel=1e-12)
    assert float(pressure_beta(NAFION_LI.with_(v1=NAFION_LI.M1 * NAFION_LI.v2 / NAFION_LI.M2))) == 0.0
    for bad in ({"v2": -1.0}, {"M1": 0.0}, {"v1": float("nan")}):
        with pytest.raises(ValueError, match=next(iter(bad))):
            Material(**bad)
