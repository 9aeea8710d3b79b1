"""``ipmc-asym charge``: electrode charge, differential capacitance, apparent permittivity."""

from __future__ import annotations

from ipmc_asym.base.jsonio import dumps
from ipmc_asym.base.registry import fidelity_names, model_choices
from ipmc_asym.base.units import fmt_length
from ipmc_asym.cli import SUMMARIES
from ipmc_asym.cli.common import (
    add_document_out,
    add_strip_options,
    first_run_notice,
    spread_count,
    strip_and_material,
    strip_rows,
    warn,
    write_document,
)
from ipmc_asym.forward.charge import charge_report


def register(sub):
    p = sub.add_parser("charge", help=SUMMARIES["charge"])
    add_strip_options(p, mechanics=False)
    p.add_argument("--model", default="all", choices=model_choices(), help="permittivity model (default all three)")
    p.add_argument("--fidelity", default="corrected", choices=fidelity_names(),
                   help="rung of the fidelity ladder to start from (default corrected); a rung not valid for "
                        "this strip is escalated to the next valid one (said per row)")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    add_document_out(p, "model")


def run(args):
    strip, material, _ = strip_and_material(args)
    if args.fidelity != "bvp":
        first_run_notice()
    doc = charge_report(strip, material, args.model, args.fidelity)
    for w in doc["warnings"]:
        warn(w)
    if args.out is not None:
        write_document(args.out, doc, strip_rows(doc["inputs"], doc["results"]),
                       {k: v for k, v in doc.items() if k != "results"})
    if args.json:
        print(dumps(doc, indent=2))
        return 0
    rows, spread = doc["results"], doc["model_spread"]
    print(f"IPMC strip: L = {fmt_length(strip.length)}, total width 2l = {fmt_length(strip.width)}, total thickness "
          f"2e = {fmt_length(strip.thickness)} (half e = {fmt_length(strip.e)}), phi0 = {strip.voltage:g} V")
    print(f"{'model':9s} {'fidelity':10s} {'sigma [C/m^2]':>14s} {'Q [C]':>11s} {'C_diff [F/m^2]':>15s} "
          f"{'eps_app [F/m]':>14s} {'rel.err':>8s}")
    for r in rows:
        fid = r["fidelity_used"] + ("*" if r["escalated"] else "")
        print(f"{r['model']:9s} {fid:10s} {r['sigma']:14.6g} {r['Q']:11.4g} {r['C_diff']:15.6g} "
              f"{r['eps_app']:14.4g} {max(r['error_estimate'], r['error_estimate_C_diff']):8.1e}"
              + ("" if r["valid"] else "  not valid (see warning)"))
    if any(r["escalated"] for r in rows):
        print("* escalated: the requested fidelity is not valid here; the first valid rung was used")
    for n in doc["notes"]:
        print("note: " + n)
    print(f"model-form spread over {len(spread['variants'])} variants ({'; '.join(spread['over'])}):")
    for k, d in spread["quantities"].items():
        if d["min"] is None:
            print(f"  {k:8s} n/a")
            continue
        ratio = "" if d["ratio"] is None else f" (x{d['ratio']:.3g})"
        print(f"  {k:8s} {d['min']:.4g} .. {d['max']:.4g}{ratio}   numerical rel.err <= {d['numerical_error']:.1e}"
              + spread_count(d))
    print("  note: " + spread["note"])
    if args.out is not None:
        print(f"wrote {args.out}")
    return 0
