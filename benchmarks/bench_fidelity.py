"""Speed/accuracy benchmark of the fidelity ladder (same code as ``ipmc-asym bench``).

Usage::

    PYTHONPATH=. python benchmarks/bench_fidelity.py [--json] [--points N]
"""

import sys

from ipmc_asym.cli import main

if __name__ == "__main__":
    sys.exit(main(["bench", *sys.argv[1:]]))
