"""``ipmc-asym materials [NAME] [--json]``: the material sets, every value with its source."""

from __future__ import annotations

from ipmc_asym.base.jsonio import dumps
from ipmc_asym.cli import SUMMARIES
from ipmc_asym.model import materials


def register(sub):
    p = sub.add_parser("materials", help=SUMMARIES["materials"],
                       description="Without NAME: the built-in material sets. With NAME (a set or a file "
                                   "FILE.toml of the same schema): every value, its unit, source and range.")
    p.add_argument("name", nargs="?", metavar="NAME|FILE.toml", help="a set (or a material file) to show")
    p.add_argument("--json", action="store_true", help="print one JSON object")


def run(args):
    if args.name is None:
        sets = [materials.info(n) for n in materials.names()]
        if args.json:
            print(dumps({"materials": [{"name": s["name"], "title": s["title"], "membrane": s["membrane"],
                                        "cation": s["cation"], "c_moy": s["used"]["C_moy"], "sources": s["sources"],
                                        "fallbacks": s["fallbacks"]} for s in sets],
                         "not_offered": list(materials.NOT_OFFERED)}, indent=2))
            return 0
        print("Material sets (ipmc-asym materials NAME shows every value with its source; --material NAME uses one):")
        for s in sets:
            fb = f"; fallback: {', '.join(s['fallbacks'])}" if s["fallbacks"] else ""
            print(f"  {s['name']:20s} {s['title']} (C_moy = {s['used']['C_moy']:.6g} mol/m^3{fb})")
        for line in materials.NOT_OFFERED:
            print(f"  {line}")
        return 0
    if args.json:
        print(dumps(materials.info(args.name), indent=2))
    else:
        print(materials.describe(args.name))
    return 0
