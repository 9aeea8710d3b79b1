"""``ipmc-asym validate``: each claim of the paper against our numbers, with a verdict."""

from __future__ import annotations

from ..fileio import atomic_write, check_output_path
from ..jsonio import dumps
from ..validate import claims, to_markdown
from . import SUMMARIES


def register(sub):
    p = sub.add_parser("validate", help=SUMMARIES["validate"])
    p.add_argument("--json", action="store_true", help='print {"claims": [...]}')
    p.add_argument("--out", default=None, help="write a Markdown report to this file")


def run(args) -> int:
    if args.out:
        check_output_path(args.out, "file")
    rows = claims()
    if args.out:
        with atomic_write(args.out) as fh:
            fh.write(to_markdown(rows))
    if args.json:
        print(dumps({"claims": [{k: r[k] for k in ("claim", "section", "paper", "ours", "verdict", "key")}
                                     for r in rows]}, indent=2))
    else:
        for r in rows:
            print(f"[{r['verdict']:>16s}] {r['section']:>18s}  {r['claim']}\n{'':38s}paper: {r['paper']}\n"
                  f"{'':38s}ours:  {r['ours']}")
    return 0
