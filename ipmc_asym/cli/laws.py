"""``ipmc-asym laws``: the analytic scaling laws (leading order) and where they hold."""

from __future__ import annotations

from ipmc_asym.base.jsonio import dumps
from ipmc_asym.base.registry import model_choices, model_names
from ipmc_asym.cli import SUMMARIES
from ipmc_asym.studies.laws import HOLD_TOL, factor_three, law_ranges, law_table


def register(sub):
    p = sub.add_parser("laws", help=SUMMARIES["laws"])
    p.add_argument("--model", default="all", choices=model_choices(), help="permittivity model (default all)")
    p.add_argument("--json", action="store_true", help="print one JSON object (laws, local exponents, ranges)")
    p.add_argument("--latex", action="store_true", help="print LaTeX for every quantity (default: for I only)")


def run(args):
    models = model_names() if args.model == "all" else (args.model,)
    factor = factor_three()
    data = {"factor_sections_3_4_over_6_2": factor, "models": {}}
    for m in models:
        data["models"][m] = {"laws": law_table(m), "ranges": law_ranges(m)}
    if args.json:
        print(dumps(data, indent=2))
        return 0
    print("Leading-order scaling laws (SI; e = HALF thickness, l = HALF width; M_A = A5 I).")
    ratios = ", ".join(f"{k} x{v}" for k, v in factor.items())
    print(f"Prefactors from sections 3-4 over the paper's section 6.2 ones: {ratios}; we use sections 3-4.")
    for m in models:
        print(f"\n== {m} ==")
        for r in data["models"][m]["laws"]:
            ex = "  ".join(f"{k}^{v}" for k, v in r["exponents"].items())
            print(f"  [{r['regime']}] {r['quantity']:8s} ~ {ex:38s} = {r['formula']}")
            if args.latex or r["quantity"] == "I":
                print(f"      LaTeX: {r['latex_name']} = {r['latex']}")
        rg = data["models"][m]["ranges"]
        ep, ee = rg["exponent_phi0"], rg["exponent_e"]
        print(f"  local d ln I/d ln phi0 over 1 mV-10 V (2e = 200 um): {ep['min']:+.3f} .. {ep['max']:+.3f} "
              f"({ep['at_1V']:+.3f} at 1 V)")
        print(f"  local d ln I/d ln e over 2e = 10 um-4 mm (1 V): {ee['min']:+.4f} .. {ee['max']:+.4f} "
              f"({ee['at_200um']:+.4f} at 200 um)")
        for k, spans in {**rg["voltage"], **rg["thickness"]}.items():
            thick = "e^" in k
            unit = "m (total thickness 2e)" if thick else "V"
            where = "2e = 10 um - 4 mm" if thick else "1 mV - 10 V"
            if spans:
                txt = ", ".join(f"{a:.3g}-{b:.3g}" for a, b in spans)
                print(f"  {k}: holds (|exponent error| < {HOLD_TOL}) for {txt} {unit}")
            else:
                print(f"  {k}: does not hold anywhere in {where} (|exponent error| >= {HOLD_TOL} throughout)")
    return 0
