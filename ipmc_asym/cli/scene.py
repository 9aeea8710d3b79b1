"""``ipmc-asym scene``: a TOML scene at the cheapest fidelity meeting its tolerance."""

from __future__ import annotations

import sys

from ..jsonio import dumps
from ..scenes import run_scene
from . import SUMMARIES


def register(sub):
    """Add the ``scene`` subcommand."""
    p = sub.add_parser("scene", help=SUMMARIES["scene"])
    p.add_argument("file", help="scene TOML file (see examples/*.toml)")
    p.add_argument("--json", action="store_true", help="print one JSON object")


def run(args) -> int:
    """Run ``ipmc-asym scene``."""
    res = run_scene(args.file)
    if args.json:
        print(dumps(res, indent=2))
        return 0
    print(f"scene {res['scene']!r}: model {res['model']}, tolerance {res['tolerance']:g}, "
          f"{len(res['points'])} point(s), swept: {', '.join(res['swept']) or 'nothing'}")
    for k, o in res["outputs"].items():
        if k == "scaling_fit":
            for q, f in o["fits"].items():
                print(f"  scaling_fit {q} ~ {o['variable']}^{f['exponent']:.4f} "
                      f"(prefactor {f['prefactor']:.4g}, r = {f['correlation']:.6f})")
            continue
        if k == "profiles":
            for i, pr in enumerate(o["values"]):
                print(f"  profiles[{i}]: B1 = {pr['B1']:.6g}, anode layer {pr['anode_layer']['width_m']:.3g} m, "
                      f"cathode layer {pr['cathode_layer']['width_m']:.3g} m (bvp)")
            continue
        for i, v in enumerate(o["values"]):
            beam = f", beam {o['beam'][i]}" if "beam" in o else ""
            print(f"  {k}[{i}] = {v:.6g} {'' if o['unit'] == 'dimensionless' else o['unit']}  ({o['fidelity'][i]}, rel. err <= "
                  f"{o['error_estimate'][i]:.2g}{beam})")
    sys.stdout.flush()
    return 0
