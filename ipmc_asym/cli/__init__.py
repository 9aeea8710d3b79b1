"""Command line: ``ipmc-asym <command>`` (also ``python -m ipmc_asym``).

One module per command in this package, each with ``register(subparsers)`` and
``run(args)``: argparse wiring and printing only; the work is done by the library.  Only
this package imports it.  Bad input exits with status 2 and a one-line message, never a
traceback.
"""

from __future__ import annotations

import importlib
import sys

from ipmc_asym import __version__
from ipmc_asym.cli.common import Parser, UsageError, join_negative_values

__all__ = ["main", "build_parser", "COMMANDS", "UsageError"]

#: command name -> module in this package providing register(sub) and run(args).
#: Only the module of the command being run is imported (start-up time); the others
#: are listed in ``--help`` by their one-line summary, the docstring's first line.
COMMANDS = {
    "estimate": "estimate",
    "derive": "derive",
    "laws": "laws",
    "bench": "bench",
    "scene": "scene",
    "profiles": "profiles",
    "sweep": "sweep",
    "validate": "validate",
    "figures": "figures",
    "fit": "fit",
    "uq": "uq",
    "charge": "charge",
    "step": "step",
    "freq": "freq",
}

#: one-line summaries for ``ipmc-asym --help`` without importing every command module
SUMMARIES = {
    "estimate": "tip deflection, rotation, moment, blocking force of one strip",
    "derive": "regenerate the Numba kernels from the SymPy derivation",
    "laws": "analytic scaling laws (leading order) and where they hold",
    "bench": "time and accuracy of each fidelity, side by side in one run",
    "scene": "evaluate a TOML scene at the cheapest fidelity meeting its tolerance",
    "profiles": "C, phi, D, E, rhoZ, p through the thickness (paper Figs 4-7)",
    "sweep": "evaluate the strip on a grid of parameters",
    "validate": "each claim of the paper vs our numbers, with a verdict",
    "figures": "regenerate the paper's Figs 4-10 (+ speed/accuracy) as PNG",
    "fit": "calibrate modulus, c_moy, permittivity on measured deflection/force (profile intervals)",
    "uq": "uncertainty quantiles and Sobol' indices of a scene's [uncertain] inputs",
    "charge": "electrode charge, differential capacitance and apparent permittivity (static)",
    "step": "charging transient after a voltage step: sigma, current, moment, w vs time",
    "freq": "small-signal impedance and tip-deflection/voltage transfer function",
}


def build_parser(only: str | None = None):
    """The parser: the full options of command ``only`` (its module imported), the others listed."""

    ap = Parser(prog="ipmc-asym", description="Electromechanics of IPMC strips (Tixier & Pouget model).")
    ap.add_argument("--version", action="version", version=f"ipmc-asym {__version__}")
    sub = ap.add_subparsers(dest="command", metavar="COMMAND", parser_class=Parser)
    sub.required = True
    handlers = {}
    for name, modname in COMMANDS.items():
        if name != only:
            sub.add_parser(name, help=SUMMARIES.get(name, ""), add_help=False)
            continue
        mod = importlib.import_module(f"{__name__}.{modname}")
        mod.register(sub)
        handlers[name] = mod.run
    return ap, handlers


def main(argv=None) -> int:
    """Run one command; exit status 0, 2 (bad input or no valid result: one line), 130 (Ctrl-C)."""
    argv = sys.argv[1:] if argv is None else list(argv)
    argv = join_negative_values(argv)
    only = next((a for a in argv if not a.startswith("-")), None)
    command = only if only in COMMANDS else "?"
    try:
        ap, handlers = build_parser(only if only in COMMANDS else None)
        args = ap.parse_args(argv)
        command = args.command
        rc = handlers[args.command](args)
    except (ValueError, UsageError, OverflowError, ArithmeticError) as exc:
        msg = str(exc).splitlines()[0] if str(exc) else exc.__class__.__name__
        sys.stderr.write(f"ipmc-asym {command}: error: {msg}\n")
        return 2
    except RuntimeError as exc:  # a solver failure the library could not turn into a refusal
        sys.stderr.write(f"ipmc-asym {command}: error: {str(exc).splitlines()[0]}\n")
        return 2
    except OSError as exc:
        if isinstance(exc, BrokenPipeError):
            return 0
        sys.stderr.write(f"ipmc-asym {command}: error: {exc.strerror or exc} ({exc.filename or ''})\n")
        return 2
    except KeyboardInterrupt:
        # every file is written through fileio.atomic_write/atomic_path: nothing partial is left
        sys.stderr.write(f"ipmc-asym {command}: interrupted (Ctrl-C); no partial output file left\n")
        return 130
    return int(rc or 0)


if __name__ == "__main__":
    sys.exit(main())
