"""``ipmc-asym scene``: a TOML scene at the cheapest fidelity meeting its tolerance."""

from __future__ import annotations

import sys

from ipmc_asym.base.jsonio import dumps
from ipmc_asym.base.units import fmt_length
from ipmc_asym.cli import SUMMARIES
from ipmc_asym.cli.common import add_material_options, fmt_num, scene_with_material
from ipmc_asym.forward.model import FLAGS
from ipmc_asym.studies.scenes import run_scene

#: scene output -> the forward model's output name (which model assumptions concern it: FLAGS)
_KEY = {"I": "I", "moment": "M_A", "rotation": "theta", "tip_deflection": "w", "blocking_force": "F_block"}


def register(sub):
    """Add the ``scene`` subcommand."""
    p = sub.add_parser("scene", help=SUMMARIES["scene"])
    p.add_argument("file", help="scene TOML file (see examples/*.toml)")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    add_material_options(p)
    p.set_defaults(material=None)  # default: the scene's [material]


def run(args) -> int:
    """Run ``ipmc-asym scene``."""
    res = run_scene(scene_with_material(args.file, args))
    if args.cite:
        m = res["material"]
        lines = [f"material set: {m['name']}"] + [f"  [{i}] {c}" for i, c in enumerate(m.get("sources", []), 1)]
        (sys.stderr if args.json else sys.stdout).write("\n".join(lines) + "\n")
    if args.json:
        print(dumps(res, indent=2))
        return 0
    print(f"scene {res['scene']!r}: model {res['model']}, tolerance {res['tolerance']:g}, "
          f"{len(res['points'])} point(s), swept: {', '.join(res['swept']) or 'nothing'}")
    for k, x in res.get("defaults_used", {}).items():
        label = {"thickness": "total thickness 2e", "width": "total width 2l"}.get(k, k)
        print(f"  note: [strip].{k} not given: using the default {label} = {fmt_length(x)}")
    for note in res.get("notes", []):
        print(f"  note: {note}")
    lab = {"length": "L", "width": "2l", "thickness": "2e", "voltage": "phi0"}

    def where(i):
        p = res["points"][i]
        keys = res["swept"] or []
        return ", ".join(f"{lab[k]}={fmt_length(p[k]) if k != 'voltage' else fmt_num(p[k]) + ' V'}" for k in keys)

    for k, o in res["outputs"].items():
        if k == "scaling_fit":
            for q, f in o["fits"].items():
                print(f"  scaling_fit {q} ~ {o['variable']}^{f['exponent']:.4f} "
                      f"(prefactor {f['prefactor']:.4g}, r = {f['correlation']:.6f})")
            continue
        if k == "profiles":
            for i, pr in enumerate(o["values"]):
                print(f"  profiles[{where(i) or i}]: B1 = {pr['B1']:.6g}, anode layer "
                      f"{pr['anode_layer']['width_m']:.3g} m, cathode layer {pr['cathode_layer']['width_m']:.3g} m (bvp)")
            continue
        for i, v in enumerate(o["values"]):
            beam = f", beam {o['beam'][i]}" if "beam" in o else ""
            unit = "" if o["unit"] == "dimensionless" else o["unit"]
            c = res.get("checks", [{}] * (i + 1))[i]
            if v is None:
                print(f"  {k}[{where(i) or i}] = n/a (withheld: the free strip winds past a full turn)")
                continue
            failed = [n for n, keys in FLAGS.items() if _KEY.get(k) in keys and not c.get(n, True)]
            flag = f"; flagged: {', '.join(failed)}" if failed else ""
            print(f"  {k}[{where(i) or i}] = {fmt_num(v, '.6g')} {unit}  ({o['fidelity'][i]}, rel. err <= "
                  f"{o['error_estimate'][i]:.2g}{beam}{flag})")
    for w in res.get("warnings", []):
        print(f"  warning: {w}")
    sys.stdout.flush()
    return 0
