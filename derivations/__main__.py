"""``python -m derivations [--check] [--print]``: regenerate (or check) the kernels."""

from __future__ import annotations

import argparse
import sys


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m derivations", description=__doc__)
    ap.add_argument("--check", action="store_true", help="regenerate into a temp dir; exit 1 on any difference")
    ap.add_argument("--print", action="store_true", help="print the derivation summary (first integral, B1, laws)")
    args = ap.parse_args(argv)
    from . import codegen

    if args.print:
        from . import model

        model.main()
        if not args.check:  # printing never rewrites the kernels (e.g. inside site-packages)
            return 0
    if args.check:
        rc = codegen.check()
        return codegen.check_charge() or rc  # issue 11: the charge kernels too
    path = codegen.write()
    print(f"wrote {path}")
    print(f"wrote {codegen.write_charge()}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
