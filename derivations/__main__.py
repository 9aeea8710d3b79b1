"""``python -m derivations [--check] [--print]``: regenerate (or check) the kernels."""

from __future__ import annotations

import argparse
import sys

from . import codegen, model


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m derivations", description=__doc__)
    ap.add_argument("--check", action="store_true", help="regenerate into a temp dir; exit 1 on any difference")
    ap.add_argument("--print", action="store_true", help="print the derivation summary (first integral, B1, laws)")
    args = ap.parse_args(argv)

    if args.print:

        model.main()
        if not args.check:  # printing never rewrites the kernels (e.g. inside site-packages)
            return 0
    if args.check:
        return codegen.check()
    for path in codegen.write():
        print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
