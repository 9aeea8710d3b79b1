"""Write the generated kernel modules from the SymPy derivations: one table of targets
(:data:`TARGETS`: path, header, source) and one renderer (:func:`render`).

Deterministic: kernels sorted by name, CSE temporaries named ``t0, t1, ...`` per kernel,
floats printed with 17 significant digits.  Run ``python -m derivations`` (or
``ipmc-asym derive``); ``--check`` regenerates in memory and fails on any difference with the
committed files.
"""

from __future__ import annotations

import difflib
import sys
from pathlib import Path
from typing import Callable, NamedTuple

import sympy as sp
from sympy.printing.numpy import NumPyPrinter
from sympy.printing.pycode import PythonCodePrinter

from . import charge, debye_hueckel, exact, kernels_spec, pressure, sensing
from .kernel import Kernel

ROOT = Path(__file__).resolve().parents[1]
KERNELS = ROOT / "ipmc_asym" / "kernels"
PINNED_SYMPY = "1.14.0"

#: functions implemented in ipmc_asym/kernels/special.py
SPECIAL = ("exprel", "e2rel", "li2", "li3")


class _Printer(PythonCodePrinter):
    #: wrap every unrolled integer power in parentheses (``x*(t*t)``); False: only where
    #: the grammar needs it, the lone factor of a denominator (``x/(t*t)``)
    group_powers = False

    def __init__(self):
        super().__init__({"fully_qualified_modules": True, "standard": "python3"})

    def _print_Function(self, expr):
        name = expr.func.__name__
        if name in SPECIAL:
            return f"{name}({', '.join(self._print(a) for a in expr.args)})"
        return super()._print_Function(expr)

    def _print_Float(self, expr):
        return repr(float(expr))

    def _print_Rational(self, expr):
        return f"{expr.p}.0/{expr.q}.0" if expr.q != 1 else f"{expr.p}.0"

    def _print_Integer(self, expr):
        return f"{int(expr)}.0"

    @staticmethod
    def _unrolled(expr) -> bool:
        """True where :meth:`_print_Pow` prints ``expr`` as a product ``b*b*...`` (a string of
        the precedence of a product, not of a power)."""
        base, exp = expr.as_base_exp()
        return bool(expr.is_Pow and exp.is_Integer and 1 < int(exp) <= 4 and not base.is_Number)

    def _print_Pow(self, expr, rational=False):
        base, exp = expr.as_base_exp()
        if base.is_Number and exp.is_Rational:  # e.g. sqrt(402): a literal, not a call
            return repr(float(expr.evalf(25)))
        if exp == sp.S.Half:
            return f"math.sqrt({self._print(base)})"
        if exp == -sp.S.Half:
            return f"(1.0/math.sqrt({self._print(base)}))"
        if exp in (sp.Rational(3, 2), sp.Rational(-3, 2)):  # b*sqrt(b): one sqrt, no pow()
            b = self._print(base)
            inner = f"({b})*math.sqrt({b})"
            return f"({inner})" if exp > 0 else f"(1.0/({inner}))"
        if self._unrolled(expr):
            b = self.parenthesize(base, sp.printing.precedence.PRECEDENCE["Pow"])
            out = "*".join([b] * int(exp))
            return f"({out})" if self.group_powers else out
        if exp.is_Integer and -4 <= int(exp) < 0:
            b = self.parenthesize(base, sp.printing.precedence.PRECEDENCE["Pow"])
            return "(1.0/(" + "*".join([b] * (-int(exp))) + "))"
        return super()._print_Pow(expr, rational)

    def _print_Mul(self, expr):
        # SymPy's Mul printer writes a lone denominator factor as ``num/den`` without
        # parentheses, by the precedence of a power; an unrolled power is a product there
        # (``x/t*t`` would be ``(x/t)*t``): group it.  Numerators are left as SymPy orders them.
        out = super()._print_Mul(expr)
        if self.group_powers:
            return out
        den = [f for f in sp.Mul.make_args(expr)
               if f.is_commutative and f.is_Pow and f.exp.is_Rational and f.exp.is_negative]
        if len(den) == 1 and den[0].exp != -1:
            d = sp.Pow(den[0].base, -den[0].exp, evaluate=False)
            if self._unrolled(d):
                tail = "/" + self.parenthesize(d, sp.printing.precedence.precedence(expr))
                if out.endswith(tail):
                    return out[:-len(tail)] + "/(" + tail[1:] + ")"
        return out


class _GroupedPrinter(_Printer):
    """:class:`_Printer` with every unrolled integer power parenthesised: ``x*(t*t)``, ``x/(t*t*t*t)``."""

    group_powers = True


def render_kernel(k: Kernel, printer=None) -> str:
    pr = _Printer() if printer is None else printer
    temps = sp.numbered_symbols("t")
    repl, reduced = sp.cse(list(k.outputs), symbols=temps, optimizations="basic", order="canonical")
    lines = ["", "", "@jit", f"def {k.name}({', '.join(str(a) for a in k.args)}):"]
    lines.append(f'    """{k.doc}')
    lines.append("")
    lines.append(f"    Derived in ``{k.source}``.")
    lines.append('    """')
    for sym, ex in repl:
        lines.append(f"    {sym} = {pr.doprint(ex)}")
    outs = [pr.doprint(e) for e in reduced]
    lines.append("    return " + (outs[0] if len(outs) == 1 else "(" + ", ".join(outs) + ")"))
    return "\n".join(lines)


_PREAMBLE = '''
# fmt: off
# flake8: noqa

import math
'''

#: module docstrings and imports of the generated modules; ``{ver}`` is the SymPy version,
#: ``{consts}`` the source's constants (empty where it has none)
HEADER = '''"""Closed forms and layer integrands of the IPMC moment integral.

GENERATED by ``derivations/codegen.py`` (``python -m derivations``) with SymPy {ver}.
DO NOT EDIT: change the derivation and regenerate; ``python -m derivations --check``
fails on any difference.
"""''' + _PREAMBLE + '''
import numpy as np

from ipmc_asym.kernels.jit import jit
from ipmc_asym.kernels.special import e2rel, exprel, li2, li3  # noqa: F401
{consts}'''

EXACT_HEADER = '''"""Integrands and assembly of the exact moment integral (fidelity ``exact``).

GENERATED by ``derivations/codegen.py`` (``python -m derivations``) with SymPy {ver}
from ``derivations/exact.py``.
DO NOT EDIT: change the derivation and regenerate; ``python -m derivations --check``
fails on any difference.
"""''' + _PREAMBLE + '''
from ipmc_asym.kernels.jit import jit
from ipmc_asym.kernels.special import e2rel, exprel  # noqa: F401
'''

CHARGE_HEADER = '''"""Electrode charge, layer capacitance and small-signal closed forms.

GENERATED by ``derivations/codegen.py`` from ``derivations/charge.py`` (``python -m derivations``)
with SymPy {ver}.  DO NOT EDIT: change the derivation and regenerate; ``python -m derivations
--check`` fails on any difference.
"""''' + _PREAMBLE + '''
import numpy as np

from ipmc_asym.kernels.jit import jit
from ipmc_asym.kernels.special import e2rel, exprel  # noqa: F401
'''

PRESSURE_HEADER = EXACT_HEADER.replace(
    "Integrands and assembly of the exact moment integral (fidelity ``exact``).",
    "Pressure term of the Nernst-Planck law: integrands of the ``exact`` rung with it.").replace(
    "derivations/exact.py", "derivations/pressure.py")

SENSING_HEADER = '''"""Static sensing response: the linear closed form and the cubic coefficient of its error bound.

GENERATED by ``derivations/codegen.py`` from ``derivations/sensing.py`` (``python -m derivations``)
with SymPy {ver}.  DO NOT EDIT: change the derivation and regenerate; ``python -m derivations
--check`` fails on any difference.
"""''' + _PREAMBLE + '''
from ipmc_asym.kernels.jit import jit
'''

DH_HEADER = '''"""Small-voltage (Debye-Hueckel) series of the moment integral, with its remainder constants,
and the leading-order profiles.

GENERATED by ``derivations/codegen.py`` from ``derivations/debye_hueckel.py`` (``python -m
derivations``) with SymPy {ver}.  DO NOT EDIT: change the derivation and regenerate; ``python -m
derivations --check`` fails on any difference.
"""''' + _PREAMBLE + '''
import numpy as np

from ipmc_asym.kernels.jit import jit
{consts}'''


def _table(name, rows) -> str:
    out = [f"{name} = np.array(["]
    for row in rows:
        vals = ", ".join(repr(float(v)) for v in row)
        out.append(f"    [{vals}],")
    out.append("])")
    return "\n".join(out)


def _horner_lines(var: str, coefs: str, n: int, x: str) -> list:
    """Straight-line Horner of ``coefs[0..n-1]`` at ``x`` into ``var`` (the loop
    ``acc = acc * x + c[k]`` unrolled: the same operations, so the same bits)."""
    lines = [f"    {var} = {coefs}[{n - 1}]"]
    lines += [f"    {var} = {var} * {x} + {coefs}[{k}]" for k in range(n - 2, -1, -1)]
    return lines


def render_horner(spec: dict) -> str:
    """Unrolled evaluators of the patch tables and of the sqrt(Qhat) series.

    Why: a Horner loop over a run-time count cost ~2x the straight-line code (loop control
    on every step, no overlap across steps); the counts are known here, so the code is too.
    """
    out = []
    for name in sorted(spec):
        n = spec[name]
        if name.startswith("patch_"):
            n0, n1 = n
            out += ["", "", "@jit", f"def {name}(t0, t1, row, h):",
                    '    """(W0, W1) from row ``row`` of the patch tables ``t0``, ``t1`` at ``h = Y - centre``:',
                    f'    {n0} and {n1} coefficients, unrolled Horner."""',
                    "    a = t0[row]", "    b = t1[row]"]
            out += _horner_lines("w0", "a", n0, "h") + _horner_lines("w1", "b", n1, "h")
            out.append("    return w0, w1")
        else:
            out += ["", "", "@jit", f"def {name}(c, x):",
                    f'    """The sqrt(Qhat) series ``c`` at ``x``: {n} coefficients, unrolled Horner."""']
            out += _horner_lines("s", "c", n, "x")
            out.append("    return s")
    return "\n".join(out) + "\n"


def render_numpy_function(name, args, expr, doc, source) -> str:
    """A vectorised (complex-capable) NumPy function, not jitted."""

    pr = NumPyPrinter({"fully_qualified_modules": True})
    temps = sp.numbered_symbols("t")
    repl, reduced = sp.cse([expr], symbols=temps, optimizations="basic", order="canonical")
    lines = ["", "", f"def {name}({', '.join(str(a) for a in args)}):", f'    """{doc}', "",
             f"    Derived in ``{source}``.  Vectorised NumPy (complex); not jitted.", '    """']
    lines += [f"    {s} = {pr.doprint(e)}" for s, e in repl]
    lines.append(f"    return {pr.doprint(reduced[0])}")
    return "\n".join(lines).replace("numpy.", "np.")


def _constants(constants: dict) -> str:
    return "\n" + "\n".join(f"{k} = {float(v)!r}" for k, v in sorted(constants.items())) + "\n"


class Module(NamedTuple):
    """What a derivation contributes to one generated module.

    Attributes
    ----------
    kernels : list of Kernel   jitted kernels (rendered sorted by name)
    consts : str   text put at the header's ``{consts}`` (constants, tables)
    numpy_functions : tuple of (name, args, expr, doc)   vectorised NumPy functions after the kernels
    numpy_source : str   where the NumPy functions are derived (their docstrings say it)
    tail : str   code after everything else (the unrolled Horner evaluators)
    printer : type   the SymPy printer of the kernels
    """

    kernels: list
    consts: str = ""
    numpy_functions: tuple = ()
    numpy_source: str = ""
    tail: str = ""
    printer: type = _Printer


def _closed_forms() -> Module:
    kernels, constants, tables = kernels_spec.all_kernels()
    consts = _constants(constants) if constants else ""
    if tables:
        consts += ("\n# Taylor patches about Y = c = PATCH_STEP k, k = K_MIN..K_MAX, each used on |Y - c| <= "
                   "PATCH_STEP/2:\n# rows = patches, columns = powers of (Y - c)\n")
        consts += f"K_MIN = {tables['_kmin']}\nK_MAX = {tables['_kmax']}\nPATCH_STEP = {tables['_step']}\n"
        consts += "\n# Taylor coefficients of sqrt(Qhat(Y)) at Y = 0 (Dhat = |Y| sqrt(Qhat)), |Y| <= 1/2\n"
        for name in sorted(tables["_sqrtq"]):
            vals = ", ".join(repr(float(v)) for v in tables["_sqrtq"][name])
            consts += f"SQRTQ_{name.upper()} = np.array([{vals}])\n"
        for name in sorted(k for k in tables if not k.startswith("_")):
            w0, w1 = tables[name]
            consts += "\n" + _table(f"PATCH_W0_{name.upper()}", w0) + "\n"
            consts += _table(f"PATCH_W1_{name.upper()}", w1) + "\n"
    tail = render_horner(tables["_horner"]) if tables and "_horner" in tables else ""
    return Module(kernels, consts, tail=tail)


def _charge() -> Module:
    return Module(charge.kernels(), numpy_functions=tuple(charge.small_signal_kernels() + charge.linear_static_kernels()),
                  numpy_source="derivations.charge")


def _debye_hueckel() -> Module:
    ks, constants = debye_hueckel.kernels()
    return Module(ks, _constants(constants), numpy_functions=tuple(debye_hueckel.profile_leading()),
                  numpy_source="derivations.debye_hueckel:profile_leading", printer=_GroupedPrinter)


class Target(NamedTuple):
    """One generated module: where it goes, its header (a template of ``{ver}`` and
    ``{consts}``) and the derivation that supplies its contents."""

    path: Path
    header: str
    source: Callable[[], Module]

    @property
    def name(self) -> str:
        return self.path.name


#: every generated module, in the order they are written and checked
TARGETS = (
    Target(KERNELS / "_generated.py", HEADER, _closed_forms),
    Target(KERNELS / "_generated_exact.py", EXACT_HEADER, lambda: Module(exact.kernels())),
    Target(KERNELS / "_generated_charge.py", CHARGE_HEADER, _charge),
    Target(KERNELS / "_generated_pressure.py", PRESSURE_HEADER, lambda: Module(pressure.kernels())),
    Target(KERNELS / "_generated_dh.py", DH_HEADER, _debye_hueckel),
    Target(KERNELS / "_generated_sensing.py", SENSING_HEADER, lambda: Module(sensing.kernels())),
)

#: the closed-form kernels' module (the first target)
TARGET = TARGETS[0].path


def render(target: Target) -> str:
    """The source text of ``target``: header, kernels sorted by name, NumPy functions, tail."""
    m = target.source()
    body = target.header.format(ver=sp.__version__, consts=m.consts)
    for k in sorted(m.kernels, key=lambda k: k.name):
        body += render_kernel(k, m.printer()) + "\n"
    for name, args, expr, doc in m.numpy_functions:
        body += render_numpy_function(name, args, expr, doc, m.numpy_source) + "\n"
    return body + m.tail


def _pin_warning():
    if sp.__version__ != PINNED_SYMPY:
        print(
            f"warning: SymPy {sp.__version__} is not the pinned {PINNED_SYMPY}; "
            "the output may differ textually",
            file=sys.stderr,
        )


def write() -> list:
    """Write every target; returns the paths written."""
    _pin_warning()
    out = []
    for t in TARGETS:
        t.path.parent.mkdir(parents=True, exist_ok=True)
        t.path.write_text(render(t), encoding="utf-8")
        out.append(t.path)
    return out


def check(only=None) -> int:
    """Regenerate every target (or those named in ``only``, file names such as
    ``"_generated_exact.py"``) in memory; 0 if all are identical to the files, else diff and 1."""
    _pin_warning()
    status = 0
    if only is not None:
        unknown = set(only) - {t.name for t in TARGETS}
        if unknown:
            raise ValueError(f"no generated module named {', '.join(sorted(unknown))}; "
                             f"one of {', '.join(t.name for t in TARGETS)}")
    for t in TARGETS:
        if only is not None and t.name not in only:
            continue
        fresh = render(t)
        rel = t.path.relative_to(ROOT)
        try:
            old = t.path.read_text(encoding="utf-8")
        except FileNotFoundError:
            print(f"{rel} is missing; run `python -m derivations`", file=sys.stderr)
            status = 1
            continue
        if old == fresh:
            print(f"{rel} is up to date")
            continue
        diff = difflib.unified_diff(
            old.splitlines(), fresh.splitlines(), "committed", "regenerated", lineterm="", n=1
        )
        print("\n".join(list(diff)[:80]), file=sys.stderr)
        print(f"{rel} differs from the derivation: regenerate it", file=sys.stderr)
        status = 1
    return status
