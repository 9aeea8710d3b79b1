"""Bench section ``kernels``: the compiled kernels of each fidelity on precomputed groups.

:func:`bare_driver` is a ``prange`` loop over the public point kernels of
:mod:`ipmc_asym.kernels` (:func:`~ipmc_asym.kernels.closed.closed_b1`,
:func:`~ipmc_asym.kernels.closed.layer_closed`, :func:`~ipmc_asym.kernels.closed.closed_finish`
stage by stage over blocks of ``ipmc_asym.integral.api.BLOCK`` points for the closed forms,
:func:`~ipmc_asym.kernels.quadrature.moment_quadrature` and
:func:`~ipmc_asym.kernels.exact.moment_exact` point by point), on the groups of
:func:`ipmc_asym.integral.api.groups_arrays`: the kernel cost per point with no API around it
(no input checks, no validity flags).  Also here: compile / cached-load times and start-up
time in fresh processes, and the BVP sample the errors are measured against.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time

import numba
import numpy as np

from ipmc_asym.base.registry import FIDELITIES
from ipmc_asym.integral.api import BLOCK, closed_model_id, groups_arrays
from ipmc_asym.kernels.closed import closed_b1, closed_finish, layer_closed
from ipmc_asym.kernels.exact import moment_exact
from ipmc_asym.kernels.jit import jit, jit_parallel, prange
from ipmc_asym.kernels.quadrature import moment_quadrature
from ipmc_asym.model.params import NAFION_LI, Strip
from ipmc_asym.model.permittivity import get_model

__all__ = ["bare_driver", "time_driver", "compile_times", "startup_time", "bvp_sample", "STARTUP_TARGET_S",
           "ROOT"]

#: the directory holding ``ipmc_asym`` and ``ipmc_asym_bench`` (PYTHONPATH of the subprocesses)
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

#: a quick estimate in a fresh process, Numba cache warm
STARTUP_TARGET_S = 1.5


@jit
def closed_block(lam, A2, A3, rho, model_id, order, I, err, B1, core):
    """The closed forms over a block of points, stage by stage (consecutive points are
    independent, so the processor overlaps their dependent chains of calls).  ``I``, ``err``,
    ``B1``, ``core``: outputs of the block's length, also the stage temporaries.  ``A2 = 0``
    gives ``I = 0``; an ``A2`` that is not a number > 0 gives NaN."""
    m = lam.size
    tmp = np.empty((5, m))
    em, yc, w0a, w1a, a2 = tmp[0], tmp[1], tmp[2], tmp[3], tmp[4]
    acc = 2 if order == 2 else 1
    for k in range(m):
        a2[k] = A2[k] if A2[k] > 0.0 else 1.0
        em[k], B1[k], yc[k] = closed_b1(a2[k], model_id)
    for k in range(m):
        I[k], err[k] = layer_closed(yc[k], model_id, acc)
    for k in range(m):
        w0a[k], w1a[k] = layer_closed(yc[k] - a2[k], model_id, acc)
    for k in range(m):
        if A2[k] > 0.0:
            I[k], err[k], B1[k], core[k] = closed_finish(lam[k], a2[k], A3, rho, model_id, order, em[k], B1[k],
                                                         yc[k], I[k], err[k], w0a[k], w1a[k])
        elif A2[k] == 0.0:
            I[k], err[k], B1[k], core[k] = 0.0, 0.0, 1.0, 2.0
        else:
            I[k] = err[k] = B1[k] = core[k] = np.nan


@jit_parallel
def ladder_driver(lam, A2, A3, rho, model_id, order, sign, I, err, B1, core):
    """``order`` 1 leading, 2 corrected (blocks), 0 quadrature, 3 exact (points), signed ``I``."""
    n = lam.size
    if order == 1 or order == 2:
        for b in prange((n + BLOCK - 1) // BLOCK):
            i0 = b * BLOCK
            i1 = min(n, i0 + BLOCK)
            closed_block(lam[i0:i1], A2[i0:i1], A3, rho, model_id, order, I[i0:i1], err[i0:i1], B1[i0:i1],
                         core[i0:i1])
            for i in range(i0, i1):
                I[i] = sign[i] * I[i]
    else:
        for i in prange(n):
            if A2[i] == 0.0:
                I[i], err[i], B1[i], core[i] = 0.0, 0.0, 1.0, 2.0
            elif order == 0:
                Ii, J1, J2, b1, c = moment_quadrature(lam[i], A2[i], A3, rho)
                I[i], err[i], B1[i], core[i] = sign[i] * Ii, 0.0, b1, c
            else:
                Ii, b1, ell, c, niter = moment_exact(lam[i], A2[i], A3, rho)
                I[i], err[i], B1[i], core[i] = sign[i] * Ii, (0.0 if niter >= 0 else np.inf), b1, c


@jit
def point_kernel(lam, A2, A3, rho, model_id, order):
    """``I`` of one point of a closed form (``order`` 1 or 2), the bare compiled point."""
    em, B1, Yc = closed_b1(A2, model_id)
    acc = 2 if order == 2 else 1
    W0c, W1c = layer_closed(Yc, model_id, acc)
    W0a, W1a = layer_closed(Yc - A2, model_id, acc)
    return closed_finish(lam, A2, A3, rho, model_id, order, em, B1, Yc, W0c, W1c, W0a, W1a)[0]


def bare_driver(fidelity, model, th, v):
    """The compiled kernels on precomputed groups: the kernel cost with no API around it.

    Returns
    -------
    call : callable
        Runs the driver once over all points.
    outs : list of ndarray, shape (n,)
        Its outputs ``I, error, B1, core`` (``error``: the kernels' own estimate, 0 where
        they give none; the API's validity bookkeeping is not part of the kernel cost).
    """
    perm = get_model(model)
    lam, A2, A3, rho, sign = groups_arrays(th, v, perm, NAFION_LI)
    lam, A2, sign = (np.ascontiguousarray(a, dtype=float) for a in (lam, A2, sign))
    outs = [np.empty(lam.size) for _ in range(4)]
    mid, order = closed_model_id(perm, fidelity), FIDELITIES[fidelity].kernel_code

    def call():
        ladder_driver(lam, A2, float(A3), float(rho), mid, order, sign, *outs)

    return call, outs


def time_driver(fidelity, model, th, v, threads, repeats):
    """Best-of-``repeats`` seconds per point of :func:`bare_driver` with ``threads`` threads,
    and the number of non-finite ``I``."""
    call, outs = bare_driver(fidelity, model, th, v)
    old = numba.get_num_threads()
    numba.set_num_threads(max(1, min(int(threads), numba.config.NUMBA_NUM_THREADS)))
    try:
        call()  # warm-up (compile or load from cache)
        best = np.inf
        for _ in range(repeats):
            t0 = time.perf_counter()
            call()
            best = min(best, time.perf_counter() - t0)
    finally:
        numba.set_num_threads(old)
    return best / outs[0].size, int(np.count_nonzero(~np.isfinite(outs[0])))


def subprocess_env(**extra) -> dict:
    """This environment with :data:`ROOT` first on ``PYTHONPATH`` (and ``extra`` set)."""
    env = dict(os.environ)
    env["PYTHONPATH"] = ROOT + (os.pathsep + env["PYTHONPATH"] if env.get("PYTHONPATH") else "")
    env.update(extra)
    return env


COMPILE_SNIPPET = """
import json, time
t0 = time.perf_counter()
from ipmc_asym.integral.api import moment
t1 = time.perf_counter()
moment(2e-4, 1.0, "constant", {fid!r})
t2 = time.perf_counter()
print(json.dumps({{"import": t1 - t0, "first_call": t2 - t1}}))
"""


def compile_times(fidelity_group: str):
    """(compile s, cached-load s) of the driver used by ``fidelity_group`` in fresh processes."""
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


def startup_time(repeats: int = 3) -> dict:
    """Wall time of ``ipmc-asym estimate --fidelity leading`` in a fresh process (cache warm).

    One untimed run first fills the cache; the best of ``repeats`` timed runs is reported,
    with the heavy modules that process imported (must not include SymPy, SciPy's
    ``integrate`` or matplotlib).
    """
    env = subprocess_env()
    code = ("import sys; from ipmc_asym.cli import main; rc = main(['estimate', '--fidelity', 'leading']); "
            "print('MODULES', ','.join(m for m in ('sympy', 'scipy.integrate', 'matplotlib') if m in sys.modules))")
    cmd = [sys.executable, "-c", code]
    subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=600)  # warm the cache
    best, heavy = float("inf"), ""
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
    """BVP solve times and ``I`` on the sample; points where it fails are dropped."""
    from ipmc_asym.bvp.solver import solve  # deferred: heavy import (scipy.integrate)

    times, I, keep = [], [], []
    for k, (t, u) in enumerate(zip(th, v)):
        t0 = time.perf_counter()
        try:
            r = solve(Strip(thickness=float(t), voltage=float(u)), model, NAFION_LI)
        except (ValueError, RuntimeError, FloatingPointError):
            continue
        dt = time.perf_counter() - t0
        if r.success and np.isfinite(r.I) and r.I != 0.0:
            times.append(dt)
            I.append(r.I)
            keep.append(k)
    return np.array(times), np.array(I), np.array(keep, dtype=int)
