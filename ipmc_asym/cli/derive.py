"""``ipmc-asym derive``: regenerate the Numba kernels from the SymPy derivation."""

from __future__ import annotations

from ipmc_asym.cli import SUMMARIES
from ipmc_asym.cli.common import UsageError


def register(sub):
    p = sub.add_parser("derive", help=SUMMARIES["derive"])
    p.add_argument("--check", action="store_true", help="regenerate into a temp dir; exit 1 on any difference")
    p.add_argument("--print", action="store_true", help="print the derivation summary")


def run(args):
    try:
        import ipmc_asym_derivations.__main__ as dm  # deferred: SymPy (start-up of the other commands)
    except ImportError:
        raise UsageError("the derivations/ package is not importable (run from a source checkout)") from None
    argv = (["--check"] if args.check else []) + (["--print"] if args.print else [])
    return dm.main(argv)
