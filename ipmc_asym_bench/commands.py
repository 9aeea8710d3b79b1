"""Bench section ``commands``: wall time of the long commands, as a user runs them.

* ``ipmc-asym sweep --vary thickness=50um:500um:1000 --vary voltage=0.1V:3V:1000 --fidelity
  leading --out F.csv`` (10^6 rows, leading), target <= 3 s;
* ``ipmc-asym figures --out DIR``, target <= 15 s.

Each in a fresh process (the Numba cache warm: one untimed run first), best of ``repeats``.
Quick mode: a 10^4-row sweep only, one run without the warm-up, reported without a target.  Module-level imports are
stdlib and :mod:`ipmc_asym_bench.kernels` (which loads the kernels).
"""

from __future__ import annotations

import math
import os
import subprocess
import sys
import tempfile
import time

from ipmc_asym_bench.kernels import subprocess_env

__all__ = ["section", "command_seconds", "TARGETS"]

TARGETS = {"sweep_csv_1e6_s": 3.0, "figures_s": 15.0}
SWEEP_1E6 = ["sweep", "--vary", "thickness=50um:500um:1000", "--vary", "voltage=0.1V:3V:1000", "--fidelity",
             "leading", "--no-progress"]


def command_seconds(args, repeats: int = 2, warm: bool = True) -> float:
    """Best wall time of ``python -m ipmc_asym ARGS`` in fresh processes (after one warm-up run
    unless not ``warm``)."""
    env = subprocess_env()
    cmd = [sys.executable, "-m", "ipmc_asym", *args]
    best = math.inf
    first = 0 if warm else 1
    for k in range(first, 1 + max(1, int(repeats))):
        t0 = time.perf_counter()
        p = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=900)
        dt = time.perf_counter() - t0
        if p.returncode != 0:
            raise RuntimeError(f"bench: {' '.join(args[:1])} failed: {p.stderr.strip().splitlines()[-1:]}")
        if k:  # the first run warms the caches
            best = min(best, dt)
    return best


def _fig(what, value, unit, target, note=""):
    return {"what": what, "value": value, "unit": unit, "target": target,
            "pass": None if target is None else bool(value <= target), "note": note}


def section(quick: bool = False) -> dict:
    """The ``commands`` bench section (see the module docstring)."""
    with tempfile.TemporaryDirectory(prefix="ipmc_bench_cmd_") as d:
        if quick:
            args = ["sweep", "--vary", "thickness=50um:500um:100", "--vary", "voltage=0.1V:3V:100", "--fidelity",
                    "leading", "--no-progress", "--out", os.path.join(d, "s.csv")]
            t = command_seconds(args, repeats=1, warm=False)
            return {"figures": [_fig("10^4-row `sweep --out F.csv` (leading), fresh process", t, "s", None,
                                     "quick mode: the 10^6-row target is measured by the full bench")]}
        ts = command_seconds([*SWEEP_1E6, "--out", os.path.join(d, "s.csv")])
        tf = command_seconds(["figures", "--out", os.path.join(d, "figs")], repeats=2)
    return {"figures": [
        _fig("10^6-row `sweep --out F.csv` (leading), fresh process", ts, "s", TARGETS["sweep_csv_1e6_s"],
             "start-up, compute, compiled CSV formatting (computed one chunk ahead) and atomic write"),
        _fig("`figures --out DIR`, fresh process", tf, "s", TARGETS["figures_s"],
             "speed/accuracy panel from a quick in-process measurement (`--bench FILE` reuses a saved one)"),
    ]}
