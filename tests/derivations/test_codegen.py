"""The derivation reproduces the committed kernels; SymPy expressions agree with the kernels."""

import math

import mpmath as mp
import numpy as np
import pytest
import sympy as sp

from derivations import codegen, scaling
from derivations import model as M
from ipmc_asym.kernels import _generated as G
from ipmc_asym.kernels.quadrature import layer_functions


def test_generated_header():
    text = codegen.TARGET.read_text()
    assert "GENERATED" in text and "DO NOT EDIT" in text and f"SymPy {sp.__version__}" in text


def test_first_integral_and_b1_limits():
    assert M.check_first_integral()
    lims = M.b1_limits()
    assert sp.simplify(lims["constant"] - M.A2 / (1 - sp.exp(-M.A2))) == 0


rng = np.random.default_rng(1)


@pytest.mark.parametrize("i", range(8))
def test_b1_kernel_matches_sympy_root(i):
    A2 = float(10 ** rng.uniform(-3, 2.8))
    rho = float(rng.choice([0.0, 1.0, rng.uniform(0, 1)]))
    eq = M.electroneutrality_equation().subs({M.A0: 1 - rho, M.A1: rho, M.A2: A2})
    roots = [complex(r) for r in sp.Poly(eq, M.B1).nroots(n=30)]
    pos = [r.real for r in roots if abs(r.imag) < 1e-12 and r.real > 0]
    assert G.b1_exact(A2, rho) == pytest.approx(max(pos), rel=1e-11)


@pytest.mark.parametrize("i", range(10))
def test_w_and_dhat_kernels_match_sympy(i):
    w, _ = M.w_layer()
    wf = w.subs({M.exprel(M.y): M.EXPREL_DEF, M.e2rel(M.y): M.E2REL_DEF})
    y = float(rng.uniform(-30, 6))
    rho = float(rng.uniform(0, 1))
    ref = complex(wf.subs({M.y: sp.Float(y, 40), M.rho: sp.Float(rho, 40)}).evalf(30)).real
    assert G.w_layer(y, rho) == pytest.approx(ref, rel=1e-12)
    d = M.dhat_stable().subs({M.exprel(M.Y): M.EXPREL_DEF.subs(M.y, M.Y), M.e2rel(M.Y): M.E2REL_DEF.subs(M.y, M.Y)})
    refd = complex(d.subs({M.Y: sp.Float(y, 40), M.rho: sp.Float(rho, 40)}).evalf(30)).real
    assert G.dhat(y, rho) == pytest.approx(refd, rel=1e-12)


def test_linear_model_exact_polylogs_against_quadrature():
    for Y in (-38.0, -5.0, -0.2, 0.4, 0.69):
        W0, W1, _ = layer_functions(Y, 0.0)
        assert G.w0_linear_exact(Y) == pytest.approx(W0, rel=1e-13)
        assert G.w1_linear_exact(Y) == pytest.approx(W1, rel=1e-13)


def test_depletion_constants_linear_are_zetas():
    """rho = 0: K0 = zeta(2), K1 = zeta(3) exactly (W0 -> -Li2(1), W1 -> -Li3(1))."""
    assert G.K0_LINEAR == pytest.approx(math.pi**2 / 6, rel=1e-14)
    assert G.K1_LINEAR == pytest.approx(float(mp.zeta(3)), rel=1e-14)


def test_factor_three_between_sections():
    assert scaling.factor_three() == {"theta": 3, "w_small": 3, "F_block": 3}


def test_linear_exact_solution():
    # the derivation asserts the ODE, the BCs and electroneutrality; check B1 numerically
    # against the constant-free limit of the electroneutrality root (A1 = 0)
    Cz, b1, _ = M.linear_exact_solution()
    for A2 in (1e-3, 1.0, 38.7):
        assert float(b1.subs(M.A2, A2)) == pytest.approx(2 / (1 + math.exp(-A2)), rel=1e-14)


# ---- every generated kernel against its SymPy expression at random points -------------------
_DOMAINS = {  # argument name -> sampler (the physical range of each argument)
    "A2": lambda r: float(10 ** r.uniform(-3, 2.8)),
    "A3": lambda r: float(r.uniform(0.1, 0.5)),
    "rho": lambda r: float(r.uniform(0, 1)),
    "B1": lambda r: float(r.uniform(1.01, 40)),
    "c_minus": lambda r: float(r.uniform(0, 1e-3)),
    "Dhat_c": lambda r: float(r.uniform(0, 10)),
    "W0c": lambda r: float(r.uniform(0, 5)),
    "W0a": lambda r: float(r.uniform(-50, 0)),
    "W1c": lambda r: float(r.uniform(0, 5)),
    "W1a": lambda r: float(r.uniform(-300, 0)),
    "y": lambda r: float(r.uniform(-30, 6)),
    "C": lambda r: float(r.uniform(1.7, 40)),
}
_Y_DOMAIN = {"depletion": (-200.0, -31.0), "accumulation": (9.0, 30.0), "dhat_from_c": None}


@__import__("functools").lru_cache(maxsize=1)
def _kernel_cases():
    from derivations import kernels_spec

    return kernels_spec.kernels_and_constants()  # not the tables: the kernels are checked here


@pytest.mark.slow
@pytest.mark.parametrize("seed", range(3))
def test_all_generated_kernels_match_sympy(seed):
    kernels, constants = _kernel_cases()
    r = np.random.default_rng(100 + seed)
    subs_const = {sp.Symbol(k): sp.Float(float(v), 30) for k, v in constants.items()}
    special = {"exprel": lambda x: mp.expm1(x) / x, "e2rel": lambda x: 2 * (mp.expm1(x) - x) / x**2,
               "li2": lambda x: mp.polylog(2, x), "li3": lambda x: mp.polylog(3, x),
               "expm1": mp.expm1}
    for k in kernels:
        fn = getattr(G, k.name)
        vals = {}
        for a in k.args:
            name = str(a)
            if name == "em1":
                continue  # set below from A2
            if name == "Y":
                lo, hi = next((v for p, v in _Y_DOMAIN.items() if k.name.startswith(p) and v), (-30.0, 6.0))
                vals[a] = float(r.uniform(lo, hi))
            else:
                vals[a] = _DOMAINS[name](r)
        if "em1" in [str(a) for a in k.args]:  # em1 = expm1(-A2) by contract
            vals[k.args[1]] = math.expm1(-vals[k.args[0]])
        if k.name.startswith("dhat_from_c"):  # C = e^Y by contract
            vals[k.args[1]] = math.log(vals[k.args[0]])
        got = fn(*[vals[a] for a in k.args])
        got = got if isinstance(got, tuple) else (got,)
        for out, g in zip(k.outputs, got):
            ex = out.subs(subs_const)
            f = sp.lambdify(k.args, ex, modules=[special, "mpmath"])
            with mp.workdps(30):
                ref = complex(f(*[mp.mpf(vals[a]) for a in k.args]))
            assert abs(ref.imag) < 1e-20 * max(1.0, abs(ref.real))
            assert g == pytest.approx(ref.real, rel=1e-11, abs=1e-13), (k.name, vals)


_x, _t, _y = sp.symbols("x t y")
#: integer powers in every position the printer unrolls them (numerator, lone or shared
#: denominator factor, under a root, negative exponents, sums as bases)
_POW_CASES = [_x / _t**4, _x / _t**2, _x * _y / _t**3, -_x / _t**2, 2 * _x / (_t + 1) ** 2, _x / (_t * _y) ** 2,
              _x / (_t**2 * _y), sp.sqrt(_x / _t**4), _t**4 / _x, _x * _t**2, 1 / _t**2, (_x / _t**2) ** 3,
              sp.exp(_x) / _t**3, _x / _t ** sp.Rational(3, 2), -1 / _t**3, _x / (_y + _t**2) ** 4,
              (_x + 1) ** 2 / (_y - _t) ** 3 - _x / _t**2]


@pytest.mark.parametrize("printer", [codegen._Printer, codegen._GroupedPrinter])
def test_printed_powers_evaluate_as_sympy(printer):
    pr = printer()
    r = np.random.default_rng(7)
    for ex in _POW_CASES:
        code = pr.doprint(ex)
        ref = sp.lambdify((_x, _t, _y), ex, "math")
        for _ in range(20):
            x, t, y = (float(v) for v in r.uniform(0.3, 3.0, 3))
            got = eval(code, {"math": math}, {"x": x, "t": t, "y": y})
            assert got == pytest.approx(ref(x, t, y), rel=1e-13), (ex, code)


#: the Debye-Hueckel module needs the order-4 perturbation solution (~1 min of SymPy unless kept
#: on disk; its remainder constants), the charge module ~13 s, the closed-form moment module ~11 s
#: and the sensing module ~5 s: slow (the full run checks them); each other one in seconds.
#: Every module is checked here once (``derive --check`` is this same comparison for all of them:
#: tests/cli/test_commands.py checks that the command runs it)
_SLOW_TARGETS = ("_generated_dh.py", "_generated_charge.py", "_generated.py", "_generated_sensing.py")
_TARGETS = [pytest.param(t.name, marks=pytest.mark.slow) if t.name in _SLOW_TARGETS else t.name
            for t in codegen.TARGETS]


@pytest.mark.parametrize("name", _TARGETS)
def test_generated_module_matches_its_derivation(name):
    """Regenerated in memory, the module is the committed file to the character."""
    assert codegen.check([name]) == 0


def test_check_names_unknown_module():
    with pytest.raises(ValueError, match="no generated module named nope.py"):
        codegen.check(["nope.py"])
