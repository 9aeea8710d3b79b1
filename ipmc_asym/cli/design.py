"""``ipmc-asym design SPEC.toml [--json] [--plot F.png]``: the strip that meets a target."""

from __future__ import annotations

from ipmc_asym.base.jsonio import dumps
from ipmc_asym.cli import SUMMARIES
from ipmc_asym.cli.common import (
    add_electrode_options,
    add_material_options,
    add_output_option,
    electrode_spec,
    first_run_notice,
    print_citations,
)
from ipmc_asym.forward.model import CHECKS
from ipmc_asym.io.fileio import FIGURE_FORMATS, check_output_path
from ipmc_asym.model.params import material_from_spec
from ipmc_asym.studies.design import INPUTS, OUTPUTS, design, load_spec


def register(sub):
    p = sub.add_parser("design", help=SUMMARIES["design"],
                       description="Choose length, width, TOTAL thickness and voltage within the bounds of "
                                   "[vary] to maximise or minimise an output subject to [constraints]; the "
                                   "optimum with every output, its checks and the active constraints, and the "
                                   "Pareto front of [pareto] (examples/design_*.toml).")
    p.add_argument("spec", metavar="SPEC.toml", help="design specification (examples/design_blocking_force.toml)")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    add_output_option(p, "--plot", formats=FIGURE_FORMATS, default=None, metavar="F.png",
                      help=f"the Pareto front of [pareto] (default: tip_deflection vs blocking_force, 200 points); "
                           f"format from the extension ({', '.join(FIGURE_FORMATS)})")
    add_material_options(p)
    add_electrode_options(p)
    p.set_defaults(material=None)


_SCALE = {"m": (1e3, "mm"), "N": (1e3, "mN"), "N m": (1e6, "uN m"), "rad": (1.0, "rad"), "1": (1.0, ""),
          "V": (1.0, "V"), "m^2": (1e4, "cm^2")}


def _fmt(v, unit):
    if v is None:
        return "n/a"
    f, u = _SCALE.get(unit, (1.0, unit))
    return f"{v * f:.6g} {u}".rstrip()


def run(args) -> int:
    if args.plot:
        check_output_path(args.plot, "file", "--plot", formats=FIGURE_FORMATS)
    spec = load_spec(args.spec)
    if args.material is not None:
        spec["material"] = args.material
    layer = electrode_spec(args)
    if layer:  # the layers on the spec's (or --material's) set: one Material for the design
        spec["material"] = material_from_spec({"preset": spec.get("material", "nafion-li"), **layer},
                                              labels={k: "--" + k.replace("_", "-") for k in layer})
    if args.plot and "pareto" not in spec:  # the plot is the front: force vs deflection by default
        spec["pareto"] = {"x": "tip_deflection", "y": "blocking_force", "points": 200}
    name = args.spec.rsplit("/", 1)[-1].removesuffix(".toml")
    spec.setdefault("name", name)
    first_run_notice("design")
    res = design(spec)
    if args.cite:
        print_citations(res.spec.material, json_mode=args.json)
    if args.plot:
        from ipmc_asym.plotting.design import plot_design  # deferred: matplotlib (start-up)

        plot_design(res, args.plot)
    if args.json:
        print(dumps(res.as_dict(), indent=2))
        return 0
    d = res.as_dict()
    o = res.optimum
    print(f"design {res.spec.name!r} [{d['model']}, material {d['material']}]: {d['objective']['sense']} "
          f"{d['objective']['name']} = {_fmt(d['objective']['value'], d['objective']['unit'])}; "
          f"{res.evaluations} candidates{f' x {res.spec.samples} samples' if res.robust else ''} through the forward model "
          f"in {res.seconds:.3g} s")
    print("  inputs (thickness and width TOTAL):  " + ", ".join(
        f"{k} = {_fmt(o['inputs'][k], 'V' if k == 'voltage' else 'm')}" for k in INPUTS))
    print("  outputs (signed as the model gives them):")
    for k, v in o["outputs"].items():
        print(f"    {k:15s} {_fmt(v, OUTPUTS.get(k, 'm^2'))}")
    ch = o["checks"]
    print("  checks: " + ", ".join(f"{k} {'ok' if ch[k] else 'FAILED'}" for k in (*CHECKS, "valid"))
          + f"; fidelity used {ch['fidelity_used']}{' (escalated)' if ch['escalated'] else ''}")
    if res.active_constraints:
        print("  active constraints:")
        for a in res.active_constraints:
            unit = OUTPUTS.get(a["name"], "V" if a["name"] == "voltage" else "m^2" if a["name"] == "footprint" else "m")
            kind = f" ({a['kind']})" if "kind" in a else ""
            print(f"    {a['name']} {'>=' if a['bound'] == 'min' else '<='} {_fmt(a['limit'], unit)}{kind}")
    else:
        print("  active constraints: none (an interior optimum)")
    if res.robust:
        print(f"  robust: {res.robust['note']} ({res.robust['samples']} samples)")
    if res.pareto:
        xn, yn, _ = res.spec.pareto
        p0, p1 = res.pareto[0]["outputs"], res.pareto[-1]["outputs"]
        print(f"  Pareto front ({xn} vs {yn}, both maximised): {len(res.pareto)} points from "
              f"({_fmt(p0[xn], OUTPUTS[xn])}, {_fmt(p0[yn], OUTPUTS[yn])}) to "
              f"({_fmt(p1[xn], OUTPUTS[xn])}, {_fmt(p1[yn], OUTPUTS[yn])})" + (f"; plot {args.plot}" if args.plot else ""))
    for n in res.notes:
        print(f"  note: {n}")
    print(f"  material sources: {len(d['material_sources'])} (--cite, or ipmc-asym materials {d['material']})")
    return 0
