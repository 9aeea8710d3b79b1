"""``ipmc-asym figures``: the paper's Figs 4-10 plus the speed/accuracy plot, as PDF (vector, for
print; ``--format png|svg``)."""

from __future__ import annotations

import sys

from ipmc_asym.base.settings import MAX_DPI_CEILING
from ipmc_asym.cli import SUMMARIES, load_plugin
from ipmc_asym.cli.common import add_output_option, add_size_option, new_dir_removed_on_failure
from ipmc_asym.io.fileio import check_output_path, make_output_dir
from ipmc_asym.plotting.speed import load_bench

#: resolution of the figures: 600 dpi is print quality; the pixel count (and time) grows as dpi^2;
#: settable with --max-dpi
MAX_DPI = 600


def register(sub):
    p = sub.add_parser("figures", help=SUMMARIES["figures"])
    add_output_option(p, "--out", kind="dir", required=True, metavar="DIR",
                   help="output directory (required: no default that would depend on the working directory; "
                        "only its last level is created)")
    add_size_option(p, "--dpi", default=110, maximum=MAX_DPI, ceiling=MAX_DPI_CEILING, minimum=10,
                    help="resolution in dots per inch (>= 10)")
    p.add_argument("--format", default="pdf", choices=("pdf", "svg", "png"),
                   help="file format (default pdf: vector, one column 8.5 cm or a page 17 cm wide, fonts >= 7 pt)")
    p.add_argument("--quick", action="store_true", help="fewer points (for tests)")
    p.add_argument("--bench", default=None, metavar="FILE",
                   help="draw the speed/accuracy plot from a saved `ipmc-asym bench --json` "
                        "(default: a quick in-process measurement by the installed `bench` command; "
                        "without it the plot is skipped)")


def run(args) -> int:
    check_output_path(args.out, "dir")
    if args.bench:
        bench = load_bench(args.bench)
    else:  # the installed `bench` command measures, at the figure's step; none: skipped with a note
        bench = None if args.quick else getattr(load_plugin("bench"), "speed_accuracy_data", None)
    from ipmc_asym.plotting.figures import make_all  # deferred: matplotlib (start-up)

    with new_dir_removed_on_failure(args.out):
        make_output_dir(args.out)
        out = make_all(args.out, args.dpi, quick=args.quick, bench=bench, fmt=args.format,
                       log=lambda msg: print(f"figures: {msg}", file=sys.stderr, flush=True))
    for f in out["files"]:
        print("wrote", f)
    for n in out["notes"]:
        sys.stderr.write(f"note: {n}\n")
    return 0
