"""Command line: ``ipmc-asym <command>`` (also ``python -m ipmc_asym``).

One module per command in this package, each with ``register(subparsers)`` and
``run(args)``: argparse wiring and printing only; the work is done by the library.  Only
this package imports it.  Bad input exits with status 2 and a one-line message, never a
traceback.

Other installed packages add commands through the entry point group
``ipmc_asym.commands`` (:func:`plugin_commands`): each entry point names a module with
``register(subparsers)``, ``run(args)`` and ``SUMMARY`` (its line in ``--help``), e.g.
``bench`` from the benchmark package beside the library.
"""

from __future__ import annotations

import importlib
import sys
from importlib.metadata import entry_points

from ipmc_asym import __version__
from ipmc_asym.base.inputs import MAX_INPUT_BYTES, input_size_cap, max_input_bytes, parse_size
from ipmc_asym.base.interrupt import check as check_interrupted
from ipmc_asym.base.interrupt import exit_status, handling_signals
from ipmc_asym.base.settings import MAX_INPUT_BYTES_CEILING

__all__ = ["main", "build_parser", "COMMANDS", "UsageError", "PLUGIN_GROUP", "plugin_commands", "load_plugin"]

#: entry point group of the commands other packages add
PLUGIN_GROUP = "ipmc_asym.commands"

#: command name -> module in this package providing register(sub) and run(args).
#: Only the module of the command being run is imported (start-up time); the others
#: are listed in ``--help`` by their one-line summary, the docstring's first line.
COMMANDS = {
    "estimate": "estimate",
    "derive": "derive",
    "laws": "laws",
    "scene": "scene",
    "profiles": "profiles",
    "sweep": "sweep",
    "validate": "validate",
    "figures": "figures",
    "fit": "fit",
    "uq": "uq",
    "charge": "charge",
    "sense": "sense",
    "step": "step",
    "freq": "freq",
    "materials": "materials",
    "design": "design",
    "drive": "drive",
    "warmup": "warmup",
}

#: one-line summaries for ``ipmc-asym --help`` without importing every command module
SUMMARIES = {
    "estimate": "tip deflection, rotation, moment, blocking force of one strip",
    "derive": "regenerate the Numba kernels from the SymPy derivation",
    "laws": "analytic scaling laws (leading order) and where they hold",
    "scene": "evaluate a TOML scene at the cheapest fidelity meeting its tolerance",
    "profiles": "C, phi, D, E, rhoZ, p through the thickness (paper Figs 4-7)",
    "sweep": "evaluate the strip on a grid of parameters",
    "validate": "each claim of the paper vs our numbers, with a verdict",
    "figures": "regenerate the paper's Figs 4-10 (+ speed/accuracy) as PDF, SVG or PNG",
    "fit": "calibrate modulus, c_moy, permittivity, D, damping, sheet resistance on deflection/force, time series "
           "and impedance spectra (profile intervals)",
    "uq": "uncertainty quantiles and Sobol' indices of a scene's [uncertain] inputs",
    "charge": "electrode charge, differential capacitance and apparent permittivity (static)",
    "sense": "the strip as a sensor at rest: charge and open-circuit voltage of an imposed bending",
    "step": "charging transient after a voltage step: sigma, current, moment, w vs time",
    "freq": "small-signal impedance and tip-deflection/voltage transfer function",
    "materials": "the material sets: every value with its unit, source and range",
    "design": "choose length, width, thickness, voltage to meet a target (optimum, active constraints, Pareto front)",
    "drive": "response to any voltage waveform (step, ramp, sine, square, triangle, sums, CSV), streamed",
    "warmup": "compile every Numba kernel once (later runs load them from the cache)",
}


def __getattr__(name):
    # ``UsageError`` lives in cli.common, imported by main only once the signal handlers are in
    # place (its imports load NumPy and Numba: a Ctrl-C there ends cleanly, no traceback)
    if name == "UsageError":
        from ipmc_asym.cli.common import UsageError  # deferred: cli.common loads NumPy and Numba (start-up)

        return UsageError
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def plugin_commands() -> dict:
    """``{name: entry point}`` of the commands installed packages declare in :data:`PLUGIN_GROUP`
    (a name of this package's own commands is not taken over)."""
    return {ep.name: ep for ep in entry_points(group=PLUGIN_GROUP) if ep.name not in COMMANDS}


def load_plugin(name: str):
    """The module of the installed command ``name``, or None if no package provides it."""
    ep = plugin_commands().get(name)
    return None if ep is None else ep.load()


def build_parser(only: str | None = None, plugins: dict | None = None):
    """The parser: the full options of command ``only`` (its module imported), the others listed.

    Installed commands (``plugins``, default :func:`plugin_commands`) are imported for their
    summary, listed after this package's own.
    """
    from ipmc_asym.cli.common import Parser, UsageError  # deferred: see __getattr__

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
        _add_input_cap(sub.choices[name])
        handlers[name] = mod.run
    for name, ep in (plugin_commands() if plugins is None else plugins).items():
        try:
            mod = ep.load()
        except ImportError as exc:  # a broken installed package must not break the other commands
            if name == only:
                raise UsageError(f"command {name!r} ({ep.value}) cannot be loaded: {exc}") from None
            sub.add_parser(name, help=f"(cannot be loaded: {exc.__class__.__name__})", add_help=False)
            continue
        if name != only:
            sub.add_parser(name, help=getattr(mod, "SUMMARY", ""), add_help=False)
            continue
        mod.register(sub)
        _add_input_cap(sub.choices[name])
        handlers[name] = mod.run
    return ap, handlers


def _add_input_cap(p):
    """``--max-input-size``, the one cap on every input file a command reads (base.inputs)."""
    from ipmc_asym.cli.common import arg_type  # deferred: cli.common loads NumPy and Numba (start-up)

    if "--max-input-size" in p._option_string_actions:
        return
    def size(text):
        return parse_size(text, "--max-input-size", MAX_INPUT_BYTES_CEILING)

    p.add_argument("--max-input-size", type=arg_type(size, "--max-input-size"), default=MAX_INPUT_BYTES,
                   metavar="SIZE", help=f"refuse an input file larger than this (e.g. 64MB, 1GiB; default "
                                        f"{MAX_INPUT_BYTES // 2**20} MiB, at most {MAX_INPUT_BYTES_CEILING // 2**30} GiB): "
                                        "memory stays bounded")


def main(argv=None) -> int:
    """Run one command; exit status 0, 2 (bad input or no valid result: one line), 130 (Ctrl-C),
    143 (SIGTERM), 129 (SIGHUP).

    The three signals end the command alike (``base.interrupt``): the temporary files of the
    atomic writers are removed, no traceback; the previous handlers are restored on return.
    """
    command = "?"
    with handling_signals():
        try:
            from ipmc_asym.cli.common import UsageError, join_negative_values  # deferred: under the handlers

            argv = join_negative_values(sys.argv[1:] if argv is None else list(argv))
            only = next((a for a in argv if not a.startswith("-")), None)
            plugins = plugin_commands()
            known = only in COMMANDS or only in plugins
            command = only if known else "?"
            rc = _run(argv, only if known else None, plugins, UsageError)
            check_interrupted()  # a signal that arrived inside the JIT's callbacks (only flagged there)
            return rc
        except KeyboardInterrupt as exc:
            # every file is written through fileio.atomic_write/atomic_path: nothing partial is left
            how = "Ctrl-C" if exit_status(exc) == 130 else getattr(exc, "name", "signal")
            sys.stderr.write(f"ipmc-asym {command}: interrupted ({how}); no partial output file left\n")
            return exit_status(exc)


def _run(argv, only, plugins, usage_error) -> int:
    from ipmc_asym.cli.common import check_outputs, check_size_caps  # deferred: as in main (start-up)

    command = only or "?"
    try:
        ap, handlers = build_parser(only, plugins)
        args = ap.parse_args(argv)
        command = args.command
        check_size_caps(args)  # every size-like option against its cap, before any work
        check_outputs(args)  # every output option: format from its extension, writable, before any work
        with input_size_cap(getattr(args, "max_input_size", None) or max_input_bytes()):
            rc = handlers[args.command](args)
    except (ValueError, usage_error, OverflowError, ArithmeticError) as exc:
        msg = str(exc).splitlines()[0] if str(exc) else exc.__class__.__name__
        sys.stderr.write(f"ipmc-asym {command}: error: {msg}\n")
        return 2
    except MemoryError as exc:  # sizes within their caps that this machine still cannot hold
        why = str(exc).splitlines()[0] if str(exc) else "no detail"
        sys.stderr.write(f"ipmc-asym {command}: error: out of memory ({why}); lower the sizes asked for\n")
        return 2
    except RuntimeError as exc:  # a solver failure the library could not turn into a refusal
        sys.stderr.write(f"ipmc-asym {command}: error: {str(exc).splitlines()[0]}\n")
        return 2
    except OSError as exc:
        if isinstance(exc, BrokenPipeError):
            return 0
        sys.stderr.write(f"ipmc-asym {command}: error: {exc.strerror or exc} ({exc.filename or ''})\n")
        return 2
    return int(rc or 0)


if __name__ == "__main__":
    sys.exit(main())
