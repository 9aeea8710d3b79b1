"""``ipmc-asym estimate``: tip deflection, rotation, moment, blocking force of one strip."""

from __future__ import annotations

from ..estimate import estimate_rows, model_list
from ..jsonio import dumps
from ..registry import fidelity_names, model_choices
from ..units import fmt_length
from . import SUMMARIES
from .common import (
    add_strip_options,
    first_run_notice,
    material_from_args,
    strip_from_args,
    tol_type,
)


def register(sub):
    p = sub.add_parser("estimate", help=SUMMARIES["estimate"])
    add_strip_options(p)
    p.add_argument("--model", default="all", choices=model_choices(),
                   help="permittivity model (default all three)")
    p.add_argument("--fidelity", default="quadrature", choices=fidelity_names(),
                   help="rung of the fidelity ladder (default quadrature)")
    p.add_argument("--tol", type=tol_type, default=None,
                   help="relative tolerance: warn when the error estimate exceeds it; also the threshold "
                        "for calling a displacement 'small' (default 1%%)")
    p.add_argument("--json", action="store_true", help="print one JSON object")


def run(args):
    material = material_from_args(args)
    strip = strip_from_args(args)
    if args.fidelity != "bvp":
        first_run_notice()
    rows = estimate_rows(strip, model_list(args.model), args.fidelity, material, args.tol)
    inputs = {
        "length": strip.length, "width_total": strip.width, "thickness_total": strip.thickness,
        "half_thickness_e": strip.e, "half_width_l": strip.l, "voltage": strip.voltage,
        "modulus": material.E, "c_moy": material.C_moy, "c_moy_source": str(material.c_moy),
        "I_p": strip.I_p, "material": material.name,
    }
    if args.json:
        print(dumps({"inputs": inputs, "results": rows}, indent=2))
        return 0
    print(f"IPMC strip: L = {fmt_length(strip.length)}, total width 2l = {fmt_length(strip.width)}, "
          f"total thickness 2e = {fmt_length(strip.thickness)} (half thickness e = {fmt_length(strip.e)}), "
          f"phi0 = {strip.voltage:g} V, E = {material.E:.3g} Pa, C_moy = {material.C_moy:.6g} mol/m^3 "
          f"({material.c_moy})")
    hdr = (f"{'model':9s} {'fidelity':10s} {'I':>11s} {'M_A [N m]':>11s} {'theta [rad]':>11s} "
           f"{'w [mm]':>9s} {'w_small[mm]':>11s} {'F_block[mN]':>11s} {'F_small[mN]':>11s} {'rel.err':>8s} regime")
    print(hdr)

    def mm(x):
        return f"{x * 1e3:9.4g}" if x is not None else f"{'n/a':>9s}"

    def mN(x):
        return f"{x * 1e3:11.4g}" if x is not None else f"{'n/a':>11s}"

    for r in rows:
        print(f"{r['model']:9s} {r['fidelity']:10s} {r['I']:11.5g} {r['M_A']:11.4g} {r['theta']:11.4g} "
              f"{mm(r['w'])} {mm(r['w_small']):>11s} {mN(r['F_block'])} {mN(r['F_block_small'])} "
              f"{r['error_estimate']:8.1e} {r['regime']}")
    for r in rows:
        for w in r["warnings"]:
            print(f"warning [{r['model']}]: {w}")
    return 0
