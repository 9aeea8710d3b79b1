"""``ipmc-asym estimate``: tip deflection, rotation, moment, blocking force of one strip."""

from __future__ import annotations

from ipmc_asym.base.jsonio import dumps
from ipmc_asym.base.registry import fidelity_names, model_choices
from ipmc_asym.base.units import fmt_length
from ipmc_asym.cli import SUMMARIES
from ipmc_asym.cli.common import (
    add_document_out,
    add_strip_options,
    c_moy_label,
    first_run_notice,
    fmt_num,
    spread_count,
    strip_and_material,
    strip_rows,
    tol_type,
    write_document,
)
from ipmc_asym.forward.estimate import SPREAD_NOTE, estimate_document
from ipmc_asym.integral.api import interpret_small


def register(sub):
    p = sub.add_parser("estimate", help=SUMMARIES["estimate"])
    add_strip_options(p)
    p.add_argument("--model", default="all", choices=model_choices(),
                   help="permittivity model: constant, linear, affine or all (default all three)")
    p.add_argument("--fidelity", default="quadrature", choices=fidelity_names(),
                   help="cheapest rung of the fidelity ladder to try (default quadrature); a rung that is "
                        "not valid for this strip is escalated to the next valid one (said per row)")
    p.add_argument("--no-escalate", action="store_true",
                   help="use --fidelity only: exit 2 where it is not valid instead of escalating")
    p.add_argument("--tol", type=tol_type, default=None,
                   help="relative accuracy required of I (escalate until the error bound meets it) and the "
                        "threshold for calling a displacement 'small', e.g. 1e-3 or 0.1%% (default 1%%)")
    p.add_argument("--pressure-term", action="store_true",
                   help="keep the pressure term of the Nernst-Planck law (paper eq. 5, dropped by the paper): "
                        "I from the exact or bvp rung, beta = (v1 - M1 v2/M2) C_moy from the material")
    p.add_argument("--json", action="store_true", help="print one JSON object {inputs, results}")
    add_document_out(p, "model")
    p.add_argument("--compiled", action="store_true",
                   help="run the compiled kernels even for these few points (loads them from Numba's cache, "
                        "compiling them on the first run after install: use it to warm the cache); by default "
                        "a few points run interpreted, the same code and results, without the ~0.5 s load")


#: printed under the table: what its columns are (paper's notation; lengths of the strip are TOTAL)
LEGEND = (
    "legend: I = the paper's moment integral (dimensionless, M_A = A5 I); M_A = active bending moment; "
    "theta = tip rotation;",
    "  w, w_small = tip deflection, large / small displacements; F_block, F_small = blocking force, large / small "
    "displacements;",
    "  rel.err = stated relative error of I at the fidelity used; regime = beam regime: small (the small-displacement "
    "w within 1 %), large (|theta| <= pi/2), past-quarter-turn, multi-turn",
)


def run(args):
    strip, material, note = strip_and_material(args)
    if args.compiled:
        if args.fidelity != "bvp":
            first_run_notice()
    else:
        interpret_small()
    # the rows, the model-form spread and the inputs echoed, from one checked request
    doc = estimate_document(strip, material, args.model, args.fidelity, args.tol, escalate=not args.no_escalate,
                            pressure_term=args.pressure_term, thickness_note=note)
    rows, spread, inputs = doc["results"], doc["model_spread"], doc["inputs"]
    for r in rows:
        if r["I"] is None:  # no rung valid: refuse the whole command, one line
            raise ValueError(r["warnings"][-1])
    if args.out is not None:
        write_document(args.out, doc, strip_rows(inputs, rows), {k: v for k, v in doc.items() if k != "results"})
    if args.json:
        print(dumps(doc, indent=2))
        return 0
    print(f"IPMC strip: L = {fmt_length(strip.length)}, total width 2l = {fmt_length(strip.width)}, "
          f"total thickness 2e = {fmt_length(strip.thickness)} (half thickness e = {fmt_length(strip.e)}), "
          f"phi0 = {fmt_num(strip.voltage)} V, E = {material.E:.3g} Pa, C_moy = {c_moy_label(material)}")
    print(f"material set {material.name} ({len(material.sources)} sources: --cite, ipmc-asym materials)")
    if note:
        print(note)
    print(f"beam: {inputs['beam']}, EI = {inputs['bending_stiffness']:.4g} N m^2")
    hdr = (f"{'model':9s} {'fidelity':10s} {'I':>11s} {'M_A [N m]':>11s} {'theta [rad]':>11s} "
           f"{'w [mm]':>9s} {'w_small[mm]':>11s} {'F_block[mN]':>11s} {'F_small[mN]':>11s} {'rel.err':>8s} regime")
    print(hdr)

    def sc(x, k):
        return None if x is None else x * k

    for r in rows:
        fid = r["fidelity_used"] + ("*" if r["escalated"] else "")
        print(f"{r['model']:9s} {fid:10s} {fmt_num(r['I'], '.5g'):>11s} {fmt_num(r['M_A'], '.4g'):>11s} "
              f"{fmt_num(r['theta'], '.4g'):>11s} {fmt_num(sc(r['w'], 1e3), '.4g'):>9s} "
              f"{fmt_num(sc(r['w_small'], 1e3), '.4g'):>11s} {fmt_num(sc(r['F_block'], 1e3), '.4g'):>11s} "
              f"{fmt_num(sc(r['F_block_small'], 1e3), '.4g'):>11s} {fmt_num(r['error_estimate'], '8.1e')} "
              f"{r['regime']}")
    for line in LEGEND:
        print(line)
    if any(r["escalated"] for r in rows):
        print("* escalated: the requested fidelity is not valid here; the first valid rung was used")
    _print_spread(spread)
    for n in doc["notes"]:
        print(f"note: {n}")
    for r in rows:
        for w in r["warnings"]:
            print(f"warning [{r['model']}]: {w}")
        if not r["valid"]:
            failed = ", ".join(k for k, ok in r["checks"].items() if not ok)
            held = ", ".join(r["withheld"]) or "none"
            print(f"not valid [{r['model']}]: failed check(s) {failed} (model assumptions: numbers kept, flagged); "
                  f"withheld (n/a): {held}")
    if args.out is not None:
        print(f"wrote {args.out}")
    return 0


def _print_spread(spread):
    """The model-form spread beside the numerical error: one line per output."""
    q = spread["quantities"]
    print(f"model-form spread over {len(spread['variants'])} variants ({'; '.join(spread['over'])}):")
    units = {"M_A": ("N m", 1.0), "theta": ("rad", 1.0), "w": ("mm", 1e3), "w_small": ("mm", 1e3),
             "F_block": ("mN", 1e3), "F_block_small": ("mN", 1e3)}
    for k, (u, f) in units.items():
        d = q[k]
        if d["min"] is None:
            print(f"  {k:14s} n/a")
            continue
        ratio = "" if d["ratio"] is None else f" (x{d['ratio']:.3g})"
        print(f"  {k + ' [' + u + ']':18s} {fmt_num(d['min'] * f, '.4g'):>10s} .. {fmt_num(d['max'] * f, '.4g'):<10s}"
              f"{ratio}   numerical rel.err <= {fmt_num(d['numerical_error'], '.1e')}{spread_count(d)}")
    print("  note: " + SPREAD_NOTE)
