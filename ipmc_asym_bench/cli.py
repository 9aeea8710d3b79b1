"""``ipmc-asym bench``: time and accuracy of each fidelity, side by side in one run.

A command of ``ipmc-asym`` found through the entry point group ``ipmc_asym.commands``
(``bench = "ipmc_asym_bench.cli"`` in pyproject.toml): :data:`SUMMARY`, :func:`register`
and :func:`run` as the command modules of :mod:`ipmc_asym.cli`, and
:func:`speed_accuracy_data`, the measurement ``ipmc-asym figures`` draws its
speed/accuracy plot from when it is given no ``--bench FILE``.
"""

from __future__ import annotations

import argparse
import json
import math
import os

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
    _size_option(p, "--points", default=DEFAULT_POINTS, maximum=MAX_POINTS, help="sweep size N")
    _size_option(p, "--bvp-points", default=DEFAULT_BVP_POINTS, maximum=MAX_BVP_POINTS, help="BVP sample per model")
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

    _check_caps(args)
    if args.figure:
        _check_figure_path(args.figure)
    points, bvp_points = args.points, args.bvp_points
    if args.quick:
        points = QUICK_POINTS if points == DEFAULT_POINTS else points
        bvp_points = QUICK_BVP_POINTS if bvp_points == DEFAULT_BVP_POINTS else bvp_points
    res = run_bench(points, bvp_points, compile_times=not args.no_compile, layout=args.layout,
                    sections=args.section, quick=args.quick)
    if args.figure:
        from ipmc_asym import plot_speed_accuracy  # deferred: matplotlib (start-up)

        res["figure"] = plot_speed_accuracy(res, args.figure)
    if args.json:
        print(json.dumps(_clean(res), indent=2, allow_nan=False))
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


# ---- the bench's own option helpers: it uses the library's public face only, so the few lines of
# argument parsing a plugin command needs live here rather than in the CLI's internals


def _count(flag):
    """An integer >= 1, also written ``1e6`` or ``1_000_000`` (argparse type, one-line message)."""

    def conv(text):
        try:
            v = float(str(text).replace("_", ""))
        except ValueError:
            v = float("nan")
        if not (v.is_integer() and v >= 1):
            raise argparse.ArgumentTypeError(f"{flag} must be an integer >= 1 (e.g. 1000000 or 1e6); got {text!r}")
        return int(v)

    conv.__name__ = flag
    return conv


#: size option -> its cap option, checked by :func:`run` before any work
_CAPS = {}


def _size_option(p, flag, *, default, maximum, help):
    """``flag`` and its cap ``--max-<name>``: a size that would exhaust memory or time is refused in one line."""
    cap = "--max-" + flag.lstrip("-")
    p.add_argument(flag, type=_count(flag), default=default,
                   help=f"{help} (default {default:g}; at most {cap}, default {maximum:g})")
    p.add_argument(cap, type=_count(cap), default=maximum,
                   help=f"refuse {flag} above this (default {maximum:g}: memory and time stay bounded)")
    _CAPS[flag] = cap


def _dest(flag):
    return flag.lstrip("-").replace("-", "_")


def _check_caps(args):
    for flag, cap in _CAPS.items():
        v, m = getattr(args, _dest(flag)), getattr(args, _dest(cap))
        if v > m:
            raise ValueError(f"{flag} {v:.6g} is above {cap} {m:.6g} (the cap bounding memory and time); "
                             f"lower {flag} or raise {cap}")


#: what ``--figure`` can write (matplotlib picks the format from the extension)
FIGURE_FORMATS = (".png", ".pdf", ".svg")


def _check_figure_path(path):
    """Refuse, before the timings, a figure path that cannot be written (one line)."""
    ext = os.path.splitext(path)[1].lower()
    if ext not in FIGURE_FORMATS:
        got = f"extension {ext!r}" if ext else "no extension"
        raise ValueError(f"--figure {path!r}: {got}; the format follows the extension, "
                         f"allowed: {', '.join(FIGURE_FORMATS)}")
    if os.path.isdir(path):
        raise ValueError(f"--figure {path!r} is a directory; give a file name")
    d = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(d):
        raise ValueError(f"--figure {path!r}: directory {os.path.dirname(path) or d!r} does not exist")
    if not os.access(d, os.W_OK) or (os.path.exists(path) and not os.access(path, os.W_OK)):
        raise ValueError(f"--figure {path!r}: not writable")


def _clean(obj):
    """Strict JSON (as every ``--json`` of ipmc-asym): numpy to Python, a non-finite float to null."""
    if isinstance(obj, dict):
        return {str(k): _clean(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_clean(v) for v in obj]
    if hasattr(obj, "tolist"):  # numpy arrays and scalars
        return _clean(obj.tolist())
    if isinstance(obj, float):
        return obj if math.isfinite(obj) else None
    return obj
