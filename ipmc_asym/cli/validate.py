"""``ipmc-asym validate``: each claim of the paper against our numbers, with a verdict."""

from __future__ import annotations

from ipmc_asym.cli import SUMMARIES
from ipmc_asym.cli.common import add_output_option
from ipmc_asym.io.fileio import atomic_write, check_output_path
from ipmc_asym.io.jsonio import dumps
from ipmc_asym.validation.validate import VERDICTS, claims, to_markdown


def register(sub):
    """Add the ``validate`` subcommand."""
    p = sub.add_parser("validate", help=SUMMARIES["validate"])
    p.add_argument("--json", action="store_true", help='print {"claims": [...]}')
    add_output_option(p, "--out", formats=(".md",), default=None, metavar="F.md", help="write a Markdown report to this file (.md)")


def run(args) -> int:
    """Run ``ipmc-asym validate``."""
    if args.out:
        check_output_path(args.out, "file", formats=(".md",))
    rows = claims()
    if args.out:
        with atomic_write(args.out) as fh:
            fh.write(to_markdown(rows))
    if args.json:
        print(dumps({"claims": [{k: r[k] for k in JSON_KEYS} for r in rows]}, indent=2))
    else:
        pad = " " * 4
        for r in rows:
            print(f"[{r['verdict']}] {r['section']}  {r['claim']}\n{pad}paper:     {r['paper']}\n"
                  f"{pad}ours:      {r['ours']}\n{pad}criterion: {r['criterion']} ({r['reason']})")
            for k, a in r["alternatives"].items():
                print(f"{pad}alternative ({k}): {a['verdict']}")
        n = {v: sum(r["verdict"] == v for r in rows) for v in VERDICTS}
        print("summary: " + ", ".join(f"{k} {v}" for k, v in n.items()))
    return 0


#: the keys of a JSON claim row
JSON_KEYS = ("claim", "section", "paper", "ours", "verdict", "key", "criterion", "reason", "value", "alternatives")
