"""Command line: ``ipmc-asym <command>`` (also ``python -m ipmc_asym``).

Commands register themselves through small ``register(subparsers)`` / ``run(args)``
functions in their own modules; imports are lazy so that ``estimate --fidelity leading``
never loads SymPy, SciPy's BVP solver or matplotlib.  Bad input exits with status 2 and a
one-line message, never a traceback.
"""

from __future__ import annotations

import argparse
import importlib
import sys

from .jsonio import dumps as _jdumps

__all__ = ["main", "UsageError"]

#: command name -> module providing register(sub) and run(args)
COMMANDS = {
    "estimate": "ipmc_asym.cli",
    "derive": "ipmc_asym.cli",
    "laws": "ipmc_asym.laws",
    "bench": "ipmc_asym.bench",
    "scene": "ipmc_asym.scenes",
    "profiles": "ipmc_asym.profiles",
    "sweep": "ipmc_asym.sweeps",
    "validate": "ipmc_asym.validate",
    "figures": "ipmc_asym.figures",
}


class UsageError(Exception):
    """Bad input at the command line (exit status 2)."""


class _Parser(argparse.ArgumentParser):
    def error(self, message):  # one line, exit 2
        sys.stderr.write(f"{self.prog}: error: {message}\n")
        raise SystemExit(2)


def _positive(name, kind, example):
    """argparse type: a quantity of ``kind`` ("length", "pressure") with units, > 0."""
    from . import units

    parse = {"length": units.parse_length, "pressure": units.parse_pressure}[kind]

    def f(text):
        v = parse(name, text)
        if v <= 0:
            raise argparse.ArgumentTypeError(f"{name} must be > 0 (e.g. {example}); got {text!r}")
        return v

    f.__name__ = name
    return f


def _len(name):
    return _positive(name, "length", "200um, 2cm")


def _pos(name):
    return _positive(name, "pressure", "130MPa")


def _tol(text):
    try:
        v = float(text)
    except ValueError:
        raise ValueError(f"--tol must be a number in (0, 1); got {text!r}") from None
    if not 0.0 < v < 1.0:
        raise ValueError(f"--tol must be a number in (0, 1); got {text!r}")
    return v


def _volt(text):
    from .units import parse_voltage

    return parse_voltage("voltage", text)


def _wrap(conv):
    def f(text):
        try:
            return conv(text)
        except ValueError as exc:
            raise argparse.ArgumentTypeError(str(exc)) from None

    f.__name__ = getattr(conv, "__name__", "value")
    return f


def add_strip_options(p, *, voltage=True):
    """The strip/material options shared by several commands (SI or with units)."""
    p.add_argument("--length", type=_wrap(_len("length")), default=0.02, help="strip length L (default 2cm)")
    p.add_argument("--width", type=_wrap(_len("width")), default=5e-3, help="TOTAL width 2l (default 5mm)")
    p.add_argument("--thickness", type=_wrap(_len("thickness")), default=200e-6,
                   help="TOTAL thickness 2e (default 200um)")
    if voltage:
        p.add_argument("--voltage", type=_wrap(_volt), default=1.0, help="voltage phi0 (default 1V; sign = direction)")
    p.add_argument("--modulus", type=_wrap(_pos("modulus")), default=1.3e8, help="Young's modulus E (default 1.3e8 Pa)")
    p.add_argument("--c-moy", default="paper", help="C_moy: paper (3082), formula (~3162) or a value in mol/m^3")


def material_from_args(args):
    from .params import NAFION_LI

    cm = args.c_moy
    if cm not in ("paper", "formula"):
        try:
            cm = float(cm)
        except ValueError:
            raise UsageError(f"--c-moy must be paper, formula or a number > 0 mol/m^3; got {args.c_moy!r}") from None
    return NAFION_LI.with_(E=args.modulus, c_moy=cm)


def strip_from_args(args):
    from .params import Strip

    return Strip(length=args.length, width=args.width, thickness=args.thickness,
                 voltage=getattr(args, "voltage", 1.0))


# ---- estimate ----------------------------------------------------------------------------
def _register_estimate(sub):
    p = sub.add_parser("estimate", help="tip deflection, rotation, moment, blocking force of one strip")
    add_strip_options(p)
    p.add_argument("--model", default="all", choices=["constant", "linear", "affine", "all"])
    p.add_argument("--fidelity", default="quadrature", choices=["leading", "corrected", "quadrature", "bvp"])
    p.add_argument("--tol", type=_wrap(_tol), default=None,
                   help="relative tolerance: warn when the error estimate exceeds it; also the threshold "
                        "for calling a displacement 'small' (default 1%%)")
    p.add_argument("--json", action="store_true", help="print one JSON object")


def _first_run_notice():
    """Numba compiles on the first run after install: say so instead of hanging silently."""
    import os

    from ._jit import CACHE_DIR

    if not (os.path.isdir(CACHE_DIR) and any(f.endswith(".nbi") for _, _, fs in os.walk(CACHE_DIR) for f in fs)):
        sys.stderr.write("ipmc-asym: compiling the Numba kernels (first run after install, ~10-30 s)...\n")


def _run_estimate(args):
    from .estimate import estimate_rows, model_list

    material = material_from_args(args)
    strip = strip_from_args(args)
    if args.fidelity != "bvp":
        _first_run_notice()
    rows = estimate_rows(strip, model_list(args.model), args.fidelity, material, args.tol)
    inputs = {
        "length": strip.length, "width_total": strip.width, "thickness_total": strip.thickness,
        "half_thickness_e": strip.e, "half_width_l": strip.l, "voltage": strip.voltage,
        "modulus": material.E, "c_moy": material.C_moy, "c_moy_source": str(material.c_moy),
        "I_p": strip.I_p, "material": material.name,
    }
    if args.json:
        print(_jdumps({"inputs": inputs, "results": rows}, indent=2))
        return 0
    from .units import fmt_length

    print(f"IPMC strip: L = {fmt_length(strip.length)}, total width 2l = {fmt_length(strip.width)}, "
          f"total thickness 2e = {fmt_length(strip.thickness)} (half thickness e = {fmt_length(strip.e)}), "
          f"phi0 = {strip.voltage:g} V, E = {material.E:.3g} Pa, C_moy = {material.C_moy:.6g} mol/m^3 "
          f"({material.c_moy})")
    hdr = (f"{'model':9s} {'fidelity':10s} {'I':>11s} {'M_A [N m]':>11s} {'theta [rad]':>11s} "
           f"{'w [mm]':>9s} {'w_small[mm]':>11s} {'F_block[mN]':>11s} {'F_small[mN]':>11s} {'rel.err':>8s} regime")
    print(hdr)
    for r in rows:
        def mm(x):
            return f"{x * 1e3:9.4g}" if x is not None else f"{'n/a':>9s}"

        def mN(x):
            return f"{x * 1e3:11.4g}" if x is not None else f"{'n/a':>11s}"

        print(f"{r['model']:9s} {r['fidelity']:10s} {r['I']:11.5g} {r['M_A']:11.4g} {r['theta']:11.4g} "
              f"{mm(r['w'])} {mm(r['w_small']):>11s} {mN(r['F_block'])} {mN(r['F_block_small'])} "
              f"{r['error_estimate']:8.1e} {r['regime']}")
    for r in rows:
        for w in r["warnings"]:
            print(f"warning [{r['model']}]: {w}")
    return 0


# ---- derive --------------------------------------------------------------------------------
def _register_derive(sub):
    p = sub.add_parser("derive", help="regenerate the Numba kernels from the SymPy derivation")
    p.add_argument("--check", action="store_true", help="regenerate into a temp dir; exit 1 on any difference")
    p.add_argument("--print", action="store_true", help="print the derivation summary")


def _run_derive(args):
    try:
        import derivations.__main__ as dm
    except ImportError:
        raise UsageError("the derivations/ package is not importable (run from a source checkout)") from None
    argv = (["--check"] if args.check else []) + (["--print"] if args.print else [])
    return dm.main(argv)


_LOCAL = {"estimate": (_register_estimate, _run_estimate), "derive": (_register_derive, _run_derive)}


def build_parser():
    ap = _Parser(prog="ipmc-asym", description="Static bending of IPMC strips (Tixier & Pouget model).")
    sub = ap.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    sub.required = True
    handlers = {}
    for name, modname in COMMANDS.items():
        if name in _LOCAL:
            reg, run = _LOCAL[name]
        else:
            # command modules import only stdlib + numpy at module level (fast start-up)
            mod = importlib.import_module(modname)
            reg, run = mod.register, mod.run
        reg(sub)
        handlers[name] = run
    return ap, handlers


def main(argv=None) -> int:
    ap, handlers = build_parser()
    args = ap.parse_args(argv)
    try:
        rc = handlers[args.command](args)
    except (ValueError, UsageError) as exc:
        msg = str(exc).splitlines()[0] if str(exc) else exc.__class__.__name__
        sys.stderr.write(f"ipmc-asym {args.command}: error: {msg}\n")
        return 2
    except RuntimeError as exc:  # e.g. BVP non-convergence: message + suggestion
        sys.stderr.write(f"ipmc-asym {args.command}: {str(exc).splitlines()[0]}\n")
        return 1
    except BrokenPipeError:
        return 0
    return int(rc or 0)


if __name__ == "__main__":
    sys.exit(main())
