"""``ipmc-asym bench``: time and accuracy of each fidelity, side by side in one run.

A command of ``ipmc-asym`` found through the entry point group ``ipmc_asym.commands``
(``bench = "ipmc_asym_bench.cli"`` in pyproject.toml): :data:`SUMMARY`, :func:`register`
and :func:`run` as the command modules of :mod:`ipmc_asym.cli`, and
:func:`speed_accuracy_data`, the measurement ``ipmc-asym figures`` draws its
speed/accuracy plot from when it is given no ``--bench FILE``.
"""

from __future__ import annotations

from ipmc_asym.cli.common import add_size_option
from ipmc_asym.io.fileio import FIGURE_FORMATS, check_output_path
from ipmc_asym.io.jsonio import dumps
from ipmc_asym_bench.sections import MAX_BVP_POINTS, MAX_POINTS, SECTIONS

__all__ = ["SUMMARY", "register", "run", "speed_accuracy_data"]

#: ``--quick`` sizes where ``--points`` / ``--bvp-points`` are left at their defaults
QUICK_POINTS = 2000
QUICK_BVP_POINTS = 1
DEFAULT_POINTS = 10**6
DEFAULT_BVP_POINTS = 5

#: one line in ``ipmc-asym --help``
SUMMARY = "time and accuracy of each fidelity, side by side in one run"


def register(sub):
    p = sub.add_parser("bench", help=SUMMARY)
    p.add_argument("--json", action="store_true", help="print one JSON object")
    add_size_option(p, "--points", default=DEFAULT_POINTS, maximum=MAX_POINTS, help="sweep size N")
    add_size_option(p, "--bvp-points", default=DEFAULT_BVP_POINTS, maximum=MAX_BVP_POINTS, help="BVP sample per model")
    p.add_argument("--no-compile", action="store_true", help="skip the compile-time subprocesses")
    p.add_argument("--layout", default="grid", choices=["grid", "random"],
                   help="sweep points on a log grid (default) or drawn at random")
    p.add_argument("--section", action="append", default=None, choices=list(SECTIONS), metavar="NAME",
                   help=f"run only these further sections (repeatable; one of {', '.join(SECTIONS)}; "
                        "default all)")
    p.add_argument("--quick", action="store_true",
                   help=f"the smallest sizes: N = {QUICK_POINTS} and {QUICK_BVP_POINTS} BVP point per model unless "
                        "given, one repeat, the sections' smallest samples")
    p.add_argument("--figure", default=None, metavar="F.png",
                   help="draw the speed/accuracy plot to this file (.png, .pdf, .svg; default: no figure)")


def run(args) -> int:
    from ipmc_asym_bench.suite import (  # deferred: numba and the compiled kernels (start-up of --help)
        format_table,
        run_bench,
    )

    if args.figure:
        check_output_path(args.figure, "file", "--figure", formats=FIGURE_FORMATS)
    points, bvp_points = args.points, args.bvp_points
    if args.quick:
        points = QUICK_POINTS if points == DEFAULT_POINTS else points
        bvp_points = QUICK_BVP_POINTS if bvp_points == DEFAULT_BVP_POINTS else bvp_points
    res = run_bench(points, bvp_points, compile_times=not args.no_compile, layout=args.layout,
                    sections=args.section, quick=args.quick)
    if args.figure:
        from ipmc_asym.plotting.speed import (
            plot_speed_accuracy,  # deferred: matplotlib (start-up)
        )

        res["figure"] = plot_speed_accuracy(res, args.figure)
    if args.json:
        print(dumps(res, indent=2))
    else:
        print(format_table(res))
        if args.figure:
            print(f"figure: {res['figure']}")
    return 0


def speed_accuracy_data(points: int = 10**5, bvp_points: int = 3) -> dict:
    """A quick in-process bench result (no compile subprocesses, no further sections), in the
    format of ``ipmc-asym bench --json``."""
    from ipmc_asym_bench.suite import quick_bench  # deferred: numba and the compiled kernels

    return quick_bench(points, bvp_points)
