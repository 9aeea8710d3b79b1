"""``ipmc-asym charge``: electrode charge, differential capacitance, apparent permittivity."""

from __future__ import annotations

from ipmc_asym.base.jsonio import dumps
from ipmc_asym.base.registry import fidelity_names, model_choices
from ipmc_asym.base.settings import VALIDITY_LIMIT
from ipmc_asym.base.units import fmt_length
from ipmc_asym.cli import SUMMARIES
from ipmc_asym.cli.common import add_strip_options, first_run_notice, material_from_args, strip_from_args, warn
from ipmc_asym.dynamics.electrode import charge_escalated
from ipmc_asym.forward.estimate import SPREAD_NOTE, model_list, spread_of, spread_variants
from ipmc_asym.forward.model import voltage_reason
from ipmc_asym.model.permittivity import MODELS


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
    spread = _spread(strip, material, args, rows)
    if args.json:
        print(dumps({"inputs": inputs, "results": rows, "notes": notes, "warnings": warnings, "model_spread": spread},
                    indent=2))
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
    print(f"model-form spread over {len(spread['variants'])} variants ({'; '.join(spread['over'])}):")
    for k, d in spread["quantities"].items():
        ratio = "" if d["ratio"] is None else f" (x{d['ratio']:.3g})"
        print(f"  {k:8s} {d['min']:.4g} .. {d['max']:.4g}{ratio}   numerical rel.err <= {d['numerical_error']:.1e}")
    print("  note: " + SPREAD_NOTE)
    return 0


#: the charge outputs that depend on the permittivity model (and C_moy)
_SPREAD_KEYS = ("sigma", "Q", "C_diff", "eps_app")


def _spread(strip, material, args, rows):
    """The range of each charge output over the three permittivity models (and C_moy paper /
    formula for the paper's sets): the model-form spread beside the numerical error."""
    done = {r["model"]: r for r in rows}
    out = {}
    variants = spread_variants(material)
    for cm, mat in variants:
        for m in MODELS:
            r = done.get(m) if mat.c_moy == material.c_moy else None
            if r is None:
                c = charge_escalated(strip.thickness, strip.voltage, m, args.fidelity, width=strip.width,
                                     length=strip.length, material=mat)
                r = {"sigma": float(c.sigma), "Q": float(c.Q), "C_diff": float(c.C_diff),
                     "eps_app": float(c.eps_app), "error_estimate": float(c.error),
                     "error_estimate_C_diff": float(c.error_C_diff)}
            out[m if cm is None else f"{m}/{cm}"] = r
    err = max(max(r["error_estimate"], r["error_estimate_C_diff"]) for r in out.values())
    over = ["permittivity model: " + ", ".join(MODELS)]
    if len(variants) > 1:
        over.append("C_moy: paper and formula (eq. (17))")
    return {"over": over, "variants": list(out),
            "quantities": {k: spread_of({lab: r[k] for lab, r in out.items()}, err) for k in _SPREAD_KEYS},
            "note": SPREAD_NOTE}
