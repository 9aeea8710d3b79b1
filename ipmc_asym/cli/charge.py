"""``ipmc-asym charge``: electrode charge, differential capacitance, apparent permittivity."""

from __future__ import annotations

from ipmc_asym.base.registry import fidelity_names, model_choices
from ipmc_asym.base.settings import VALIDITY_LIMIT
from ipmc_asym.base.units import fmt_length
from ipmc_asym.cli import SUMMARIES
from ipmc_asym.cli.common import add_strip_options, first_run_notice, material_from_args, strip_from_args, warn
from ipmc_asym.dynamics.electrode import charge_escalated
from ipmc_asym.forward.estimate import model_list
from ipmc_asym.forward.model import voltage_reason
from ipmc_asym.io.jsonio import dumps


def register(sub):
    p = sub.add_parser("charge", help=SUMMARIES["charge"])
    add_strip_options(p, mechanics=False)
    p.add_argument("--model", default="all", choices=model_choices(), help="permittivity model (default all three)")
    p.add_argument("--fidelity", default="corrected", choices=fidelity_names(),
                   help="rung of the fidelity ladder to start from (default corrected); a rung not valid for "
                        "this strip is escalated to the next valid one (said per row)")
    p.add_argument("--json", action="store_true", help="print one JSON object")


def run(args):
    material = material_from_args(args)
    strip = strip_from_args(args)
    if args.fidelity != "bvp":
        first_run_notice()
    rows = []
    for m in model_list(args.model):
        r = charge_escalated(strip.thickness, strip.voltage, m, args.fidelity, width=strip.width,
                             length=strip.length, material=material)
        rows.append({"model": m, "fidelity": args.fidelity, "fidelity_used": r.fidelity,
                     "escalated": r.fidelity != args.fidelity, "sigma": float(r.sigma), "Q": float(r.Q),
                     "C_diff": float(r.C_diff), "eps_app": float(r.eps_app), "error_estimate": float(r.error),
                     "error_estimate_C_diff": float(r.error_C_diff), "check_voltage": bool(r.check_voltage),
                     "valid": bool(r.valid)})
    warnings = []
    if not all(r["check_voltage"] for r in rows):
        warnings.append(voltage_reason(strip.voltage))
    inaccurate = [r["model"] for r in rows if r["check_voltage"] and not r["valid"]]
    if inaccurate:
        warnings.append(f"{', '.join(inaccurate)}: relative error estimate above {VALIDITY_LIMIT:g} (sigma or Q "
                        f"subnormal at {strip.voltage:g} V: doubles round it); kept, flagged valid = false")
    for w in warnings:
        warn(w)
    inputs = {"length": strip.length, "width_total": strip.width, "thickness_total": strip.thickness,
              "half_thickness_e": strip.e, "voltage": strip.voltage, "c_moy": material.C_moy}
    notes = ["sigma: charge per area of the face z = -e where phi0 is applied (the other face carries -sigma); "
             "Q = sigma * 2l * L; C_diff = dsigma/dphi0 per area; eps_app = C_diff * 2e (TOTAL thickness), "
             "what a parallel-plate reading of a capacitance measurement would give"]
    if args.json:
        print(dumps({"inputs": inputs, "results": rows, "notes": notes, "warnings": warnings}, indent=2))
        return 0
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
    print("note: " + notes[0])
    return 0
