"""Bench helpers: each fidelity through the public API, the yardstick loop, compile / cached-load
and start-up times in fresh processes, and the BVP sample the errors are measured against.

Only names of ``ipmc_asym.__all__`` are used: a fidelity's cost per point is the cost of
``ia.moment_integral(thickness, voltage, model, fidelity, on_invalid="nan")`` on arrays (groups,
kernel, sign and validity in one compiled pass; ``I`` out), which is what a user's sweep pays.
"""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
import tempfile
import time

import numba
import numpy as np

import ipmc_asym as ia
from ipmc_asym_bench.timing import cpu_best, threads, wall_best

__all__ = ["time_api", "seven_transcendentals", "compile_seconds", "startup_time", "bvp_sample",
           "subprocess_env", "STARTUP_TARGET_S", "ROOT"]

#: the directory holding ``ipmc_asym`` and ``ipmc_asym_bench`` (PYTHONPATH of the subprocesses)
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

#: a quick estimate in a fresh process, Numba cache warm
STARTUP_TARGET_S = 1.5


@numba.njit(cache=False, fastmath=False, error_model="numpy")
def seven_transcendentals(t, v, out):
    """The yardstick of the closed forms: ``out[i] = exp(-v) + log(t) + expm1(-v) + log1p(t)
    + exp(t) + log(v) + expm1(t)`` (``t, v > 0``).

    Two inputs read, seven *independent* libm calls (the processor overlaps them: the fastest
    way of spending seven transcendental calls on a point), one output written, like a kernel.
    Compiled here, not in the library: it is a measuring stick, not a model kernel (the
    library's strict flags: no fast-math, numpy error model).
    """
    for i in range(t.size):
        x = t[i]
        y = v[i]
        out[i] = (math.exp(-y) + math.log(x) + math.expm1(-y) + math.log1p(x)
                  + math.exp(x) + math.log(y) + math.expm1(x))


def time_api(fidelity, model, th, v, n_threads, repeats):
    """Seconds per point of ``ia.moment_integral`` on the arrays ``th``, ``v`` with ``n_threads``
    Numba threads (1: least CPU time; more: least wall time), and the number of non-finite ``I``
    (invalid points are NaN)."""
    out = {}

    def call():
        out["I"] = ia.moment_integral(th, v, model, fidelity, on_invalid="nan")

    with threads(n_threads):
        call()  # warm-up (compile or load from the cache)
        s = (cpu_best if n_threads == 1 else wall_best)(call, repeats)
    return s / th.size, int(np.count_nonzero(~np.isfinite(out["I"])))


def subprocess_env(**extra) -> dict:
    """This environment with :data:`ROOT` first on ``PYTHONPATH`` (and ``extra`` set)."""
    env = dict(os.environ)
    env["PYTHONPATH"] = ROOT + (os.pathsep + env["PYTHONPATH"] if env.get("PYTHONPATH") else "")
    env.update(extra)
    return env


COMPILE_SNIPPET = """
import json, time
t0 = time.perf_counter()
import ipmc_asym as ia
ia.moment
t1 = time.perf_counter()
ia.moment(2e-4, 1.0, "constant", {fid!r})
t2 = time.perf_counter()
print(json.dumps({{"import": t1 - t0, "first_call": t2 - t1}}))
"""


def compile_seconds(fidelity_group: str):
    """(compile s, cached-load s) of the driver used by ``fidelity_group`` in fresh processes
    (wall clock: the compiler's time is what a first run waits)."""
    code = COMPILE_SNIPPET.format(fid=fidelity_group)
    out = []
    with tempfile.TemporaryDirectory(prefix="ipmc_bench_cache_") as d:
        env = subprocess_env(NUMBA_CACHE_DIR=d)
        for _ in range(2):
            p = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True,
                               timeout=600)
            if p.returncode != 0:
                raise RuntimeError(f"bench: compile-time subprocess failed: {p.stderr.strip().splitlines()[-1:]}")
            out.append(json.loads(p.stdout.strip().splitlines()[-1])["first_call"])
    return out[0], out[1]


def startup_time(repeats: int = 3, warm: bool = True) -> dict:
    """Wall time of ``ipmc-asym estimate --fidelity leading`` in a fresh process (cache warm).

    One untimed run first fills the cache (``warm``; without it a cold cache shows in the
    figure); the best of ``repeats`` timed runs is reported,
    with the heavy modules that process imported (must not include SymPy, SciPy's
    ``integrate`` or matplotlib).
    """
    env = subprocess_env()
    code = ("import sys; from ipmc_asym.cli import main; rc = main(['estimate', '--fidelity', 'leading']); "
            "print('MODULES', ','.join(m for m in ('sympy', 'scipy.integrate', 'matplotlib') if m in sys.modules))")
    cmd = [sys.executable, "-c", code]
    if warm:
        subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=600)  # warm the cache
    best, heavy = math.inf, ""
    for _ in range(max(1, int(repeats))):
        t0 = time.perf_counter()
        p = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=600)
        best = min(best, time.perf_counter() - t0)
        if p.returncode != 0:
            raise RuntimeError(f"bench: estimate subprocess failed: {p.stderr.strip().splitlines()[-1:]}")
        heavy = p.stdout.strip().splitlines()[-1].split(" ", 1)[-1] if "MODULES" in p.stdout else "?"
    return {"estimate_leading_wall_s": best, "target_s": STARTUP_TARGET_S, "pass": best <= STARTUP_TARGET_S,
            "heavy_modules_imported": [m for m in heavy.split(",") if m.strip() and m != "MODULES"]}


def bvp_sample(model, th, v):
    """CPU seconds and ``I`` of ``ia.solve_bvp_profile`` on the sample (after one untimed solve);
    points where it fails are dropped.  Returns ``(times, I, kept indices)``."""
    times, I, keep = [], [], []
    try:  # untimed: SciPy's imports and first calls are not a solve's cost
        ia.solve_bvp_profile(ia.Strip(thickness=float(th[0]), voltage=float(v[0])), model, ia.NAFION_LI)
    except (ValueError, RuntimeError, FloatingPointError):
        pass
    for k, (t, u) in enumerate(zip(th, v)):
        t0 = time.process_time()
        try:
            r = ia.solve_bvp_profile(ia.Strip(thickness=float(t), voltage=float(u)), model, ia.NAFION_LI)
        except (ValueError, RuntimeError, FloatingPointError):
            continue
        dt = time.process_time() - t0
        if r.success and np.isfinite(r.I) and r.I != 0.0:
            times.append(dt)
            I.append(r.I)
            keep.append(k)
    return np.array(times), np.array(I), np.array(keep, dtype=int)
