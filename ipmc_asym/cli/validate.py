"""``ipmc-asym validate``: each claim of the paper against our numbers, with a verdict."""

from __future__ import annotations

from ipmc_asym.base.jsonio import dumps
from ipmc_asym.cli import SUMMARIES
from ipmc_asym.cli.common import add_output_option
from ipmc_asym.io.fileio import atomic_write, check_output_path
from ipmc_asym.validation.validate import claims, tally_text, to_markdown


def register(sub):
    """Add the ``validate`` subcommand."""
    p = sub.add_parser("validate", help=SUMMARIES["validate"])
    p.add_argument("--json", action="store_true", help='print {"claims": [...]}')
    add_output_option(p, "--out", formats=(".md",), default=None, metavar="F.md", help="write a Markdown report to this file (.md)")
    p.add_argument("--measurements", action="store_true",
                   help="instead of the paper's claims: the model against published measurements (deflection, "
                        "blocking force, time constant, conductivity; bare membrane and platinum layers), with "
                        "the source, the measured value, the model's and the ratio (docs/measurements.md)")


def run(args) -> int:
    """Run ``ipmc-asym validate``."""
    if args.out:
        check_output_path(args.out, "file", formats=(".md",))
    if args.measurements:
        return _measurements(args)
    rows = claims()
    if args.out:
        with atomic_write(args.out) as fh:
            fh.write(to_markdown(rows))
    if args.json:
        print(dumps({"claims": [{k: r[k] for k in JSON_KEYS} for r in rows]}, indent=2))
    else:
        pad = " " * 4
        for r in rows:
            print(f"[{r['verdict']}] {r['section']}  {r['claim']}\n{pad}paper:     {r['paper']}\n"
                  f"{pad}ours:      {r['ours']}\n{pad}criterion: {r['criterion']} ({r['reason']})")
            for k, a in r["alternatives"].items():
                print(f"{pad}alternative ({k}): {a['verdict']}")
        print("summary: " + tally_text(rows))
    return 0


#: the keys of a JSON claim row
JSON_KEYS = ("claim", "section", "paper", "ours", "verdict", "key", "kind", "criterion", "reason", "value",
             "alternatives")


def _measurements(args) -> int:
    """``validate --measurements``: the comparison table (text, JSON or Markdown)."""
    from ipmc_asym.validation.measurements import (  # deferred: only --measurements needs the forward model
        compare,
        cross_prediction,
        to_markdown,
    )

    rows, cross = compare(), cross_prediction()
    if args.out:
        with atomic_write(args.out) as fh:
            fh.write(to_markdown(rows, cross))
    if args.json:
        print(dumps({"measurements": rows, "cross_prediction": cross}, indent=2))
        return 0
    for r in rows:
        meas = r["measured"]
        ms = f"{meas[0]:.3g} to {meas[1]:.3g}" if isinstance(meas, list) else f"{meas:.3g}"
        print(f"{r['quantity']} [{r['strip']}]\n    measured: {ms} {r['unit']}  ({r['source']})\n    model, "
              f"{r['beam']}: " + ", ".join(f"{m} {v:.3g} (ratio {r['ratio'][m]:.3g})" for m, v in r["model"].items()))
    print(f"calibrated on the measured conductivity: D = {cross['D']:.3g} m^2/s -> time constant "
          + ", ".join(f"{m} {v:.3g} s" for m, v in cross["model"].items()) + f" against ~1 s ({cross['note']})")
    return 0
