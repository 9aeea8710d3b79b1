"""Speed/accuracy benchmark of the fidelity ladder (``ipmc-asym bench``).

For each permittivity model (constant, linear, affine) and each fidelity:

* time per point of the compiled sweep driver on ``N`` (default 10^6) random
  ``(thickness, voltage)`` points -- thickness log-uniform in 10 um - 4 mm, voltage
  log-uniform in 1 mV - 10 V -- single-threaded (``numba.set_num_threads(1)`` around the
  ``prange`` driver) and parallel (all Numba threads, at most 2 here).  The groups
  (``lambda``, ``A2``) are precomputed, so the figure is the kernel cost per point;
* first-call compile time (a subprocess with ``NUMBA_CACHE_DIR`` pointing to a fresh
  temporary directory) and cached-load time (a second subprocess with the same directory).
  ``leading`` and ``corrected`` share one compiled driver, hence one compile time;
* the wall time of one BVP solve, averaged over a small sample (``--bvp-points`` per model)
  of the same distribution;
* the relative error ``|I_f - I_bvp| / |I_bvp|`` of each fidelity on that sample (max and
  median).

Targets (checked side by side in one run, single-threaded): leading <= 50 ns/point,
corrected <= 200 ns/point, quadrature <= 5 us/point; leading and corrected >= 1e6x and
quadrature >= 1e4x faster per point than the BVP.

:func:`run_bench` returns one JSON-ready dict; :func:`ipmc_asym.plotting.speed.plot_speed_accuracy`
draws ``figures/speed_accuracy.png``.  Module-level imports are stdlib + numpy only.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

from ipmc_asym.base.registry import model_names

__all__ = ["run_bench", "bare_driver", "load_bench", "run_sections", "SECTIONS", "sample_points", "format_table", "TARGETS", "MODELS", "ERR_FLOOR"]

MODELS = model_names()
FAST = ("leading", "corrected", "quadrature")
THICKNESS_RANGE = (10e-6, 4e-3)
VOLTAGE_RANGE = (1e-3, 10.0)

#: single-threaded time per point (s) and minimum speed-up over one BVP solve
TARGETS = {
    "leading": {"seconds_per_point": 50e-9, "speedup_vs_bvp": 1e6},
    "corrected": {"seconds_per_point": 200e-9, "speedup_vs_bvp": 1e6},
    "quadrature": {"seconds_per_point": 5e-6, "speedup_vs_bvp": 1e4},
}

ERR_FLOOR = 1e-16  # relative errors below this are reported as this (log plots)


def sample_points(n: int, seed: int = 0, layout: str = "random"):
    """``n`` points, thickness (total, m) and voltage (V) log-uniform in the bench ranges.

    ``layout="grid"`` gives the points of a sweep instead: a log-spaced grid of about
    ``sqrt(n)`` thicknesses x ``n / sqrt(n)`` voltages, voltage varying fastest (what
    ``ipmc-asym sweep`` produces); ``"random"`` draws them independently (worst case for
    branch prediction, ~10-20 % slower per point for the closed forms).

    Parameters
    ----------
    n : int
        Number of points (>= 1).
    seed : int
        Seed of ``numpy.random.default_rng``.

    Returns
    -------
    thickness, voltage : ndarray, shape (n,)
    """
    n = int(n)
    if n < 1:
        raise ValueError(f"points must be an integer >= 1; got {n!r}")
    if layout == "grid":
        nt = max(1, int(round(np.sqrt(n))))
        nv = max(1, -(-n // nt))
        tt = np.logspace(*np.log10(THICKNESS_RANGE), nt)
        vv = np.logspace(*np.log10(VOLTAGE_RANGE), nv)
        T, V = np.meshgrid(tt, vv, indexing="ij")
        return T.reshape(-1)[:n].copy(), V.reshape(-1)[:n].copy()
    if layout != "random":
        raise ValueError(f"layout must be 'grid' or 'random'; got {layout!r}")
    rng = np.random.default_rng(seed)
    lo, hi = np.log(THICKNESS_RANGE)
    th = np.exp(rng.uniform(lo, hi, n))
    lo, hi = np.log(VOLTAGE_RANGE)
    v = np.exp(rng.uniform(lo, hi, n))
    return th, v


def bare_driver(fidelity, model, th, v):
    """The compiled sweep driver on precomputed groups: the kernel cost with no API around it.

    Returns
    -------
    call : callable
        Runs the driver once over all points.
    outs : list of ndarray, shape (n,)
        Its outputs ``I, error, B1, core``.
    """
    from ipmc_asym.integral.api import _ORDER, _sweep, closed_model_id, groups_arrays
    from ipmc_asym.model.params import NAFION_LI
    from ipmc_asym.model.permittivity import get_model

    perm = get_model(model)
    lam, A2, A3, rho, sign = groups_arrays(th, v, perm, NAFION_LI)
    lam, A2, sign = (np.ascontiguousarray(a, dtype=float) for a in (lam, A2, sign))
    outs = [np.empty(lam.size) for _ in range(4)]
    mid, order = closed_model_id(perm, fidelity), _ORDER[fidelity]

    def call():
        _sweep(lam, A2, A3, rho, mid, order, sign, *outs)

    return call, outs


def _time_driver(fidelity, model, th, v, threads, repeats):
    """Best-of-``repeats`` seconds per point of the sweep driver with ``threads`` threads."""
    import numba

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


_COMPILE_SNIPPET = """
import json, time
t0 = time.perf_counter()
from ipmc_asym.integral.api import moment
t1 = time.perf_counter()
moment(2e-4, 1.0, "constant", {fid!r})
t2 = time.perf_counter()
print(json.dumps({{"import": t1 - t0, "first_call": t2 - t1}}))
"""


def _compile_times(fidelity_group: str):
    """(compile s, cached-load s) of the driver used by ``fidelity_group`` in fresh processes."""
    root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    env = dict(os.environ)
    env["PYTHONPATH"] = root + (os.pathsep + env["PYTHONPATH"] if env.get("PYTHONPATH") else "")
    code = _COMPILE_SNIPPET.format(fid=fidelity_group)
    out = []
    with tempfile.TemporaryDirectory(prefix="ipmc_bench_cache_") as d:
        env["NUMBA_CACHE_DIR"] = d
        for _ in range(2):
            p = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True,
                               timeout=600)
            if p.returncode != 0:
                raise RuntimeError(f"bench: compile-time subprocess failed: {p.stderr.strip().splitlines()[-1:]}")
            out.append(json.loads(p.stdout.strip().splitlines()[-1])["first_call"])
    return out[0], out[1]


#: issue target: a quick estimate in a fresh process, Numba cache warm
STARTUP_TARGET_S = 1.5


def startup_time(repeats: int = 3) -> dict:
    """Wall time of ``ipmc-asym estimate --fidelity leading`` in a fresh process (cache warm).

    One untimed run first fills the cache; the best of ``repeats`` timed runs is reported,
    with the heavy modules that process imported (must not include SymPy, SciPy's
    ``integrate`` or matplotlib).
    """
    root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    env = dict(os.environ)
    env["PYTHONPATH"] = root + (os.pathsep + env["PYTHONPATH"] if env.get("PYTHONPATH") else "")
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


def _bvp_sample(model, th, v):
    """BVP solve times and ``I`` on the sample; points where it fails are dropped."""
    from ipmc_asym.bvp.solver import solve
    from ipmc_asym.model.params import NAFION_LI, Strip

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


#: further bench sections: name -> "module:function" (imported only when run).  Each function
#: takes ``quick: bool`` and returns ``{"figures": [{"what", "value", "unit", "target", "pass",
#: "note"}, ...], ...}``: figures measured side by side in one run, as ratios where a target is
#: a ratio.  Adding a section is adding one line here.
SECTIONS: dict[str, str] = {
    # first: fresh-process wall times, measured before the dask section (after it, the same
    # sweep measured 3.6 s instead of 2.9 s: what the cluster leaves behind is not the sweep's)
    "commands": "ipmc_asym.bench.commands:section",  # issue 10: sweep --out 10^6 rows, figures
    "exact_api": "ipmc_asym.bench.exact:section",
    "uq": "ipmc_asym.studies.uq:bench_section",
    "distributed": "ipmc_asym.bench.distributed:bench_section",
    "charge": "ipmc_asym.studies.charge_studies:bench_section",  # issue 11: charge, step circuit/pnp
}


def run_sections(names=None, quick: bool = False) -> dict:
    """Run the registered sections ``names`` (default all); ``{name: result}``."""
    import importlib

    names = list(SECTIONS) if names is None else list(names)
    out = {}
    for name in names:
        if name not in SECTIONS:
            raise ValueError(f"bench section must be one of {', '.join(SECTIONS) or '(none)'}; got {name!r}")
        mod, fn = SECTIONS[name].split(":")
        out[name] = getattr(importlib.import_module(mod), fn)(quick=quick)
    return out


def run_bench(points: int = 10**6, bvp_points: int = 5, repeats: int = 3, seed: int = 0,
              compile_times: bool = True, threads: int = 2, layout: str = "grid",
              sections=None, quick_sections: bool = False) -> dict:
    """Run the whole benchmark and return a JSON-ready dict.

    Parameters
    ----------
    points : int
        Sweep size ``N`` for the timings.
    bvp_points : int
        BVP sample size per model (drawn from the same distribution).
    repeats : int
        Timing repeats (best is kept).
    seed : int
    compile_times : bool
        Measure compile / cached-load times in subprocesses (a few seconds each).
    threads : int
        Threads of the parallel timing.
    layout : {"grid", "random"}
        Sweep points as a grid (default, what a sweep is) or drawn at random.

    Returns
    -------
    dict
        ``{"points", "bvp_points", "threads", "ranges", "targets", "compile": {fidelity:
        {"compile_s", "cached_load_s"}}, "results": [row, ...], "all_pass"}`` with one row per
        ``(model, fidelity)``: ``seconds_per_point_serial``, ``seconds_per_point_parallel``
        (None for bvp), ``nonfinite``, ``rel_error_max``, ``rel_error_median``,
        ``error_estimate_max`` (the fidelity's own estimate on the sample), ``speedup_vs_bvp``,
        ``target_seconds_per_point``, ``target_speedup``, ``pass_time``, ``pass_speedup``.
    """
    import numba

    from ipmc_asym.integral.api import moment

    points = int(points)
    th, v = sample_points(points, seed, layout)
    ths, vs = sample_points(max(int(bvp_points), 1), seed + 1)
    threads = max(1, min(int(threads), numba.config.NUMBA_NUM_THREADS))
    comp = {}
    startup = startup_time() if compile_times else None
    if compile_times:
        closed = _compile_times("leading")
        quad = _compile_times("quadrature")
        comp = {
            "leading": {"compile_s": closed[0], "cached_load_s": closed[1], "shared_with": "corrected"},
            "corrected": {"compile_s": closed[0], "cached_load_s": closed[1], "shared_with": "leading"},
            "quadrature": {"compile_s": quad[0], "cached_load_s": quad[1]},
        }
    rows = []
    for model in MODELS:
        bt, bI, keep = _bvp_sample(model, ths, vs)
        t_bvp = float(np.mean(bt)) if bt.size else None
        sub_th, sub_v = ths[keep], vs[keep]
        rows.append({
            "model": model, "fidelity": "bvp", "seconds_per_point_serial": t_bvp,
            "seconds_per_point_parallel": None, "nonfinite": 0, "bvp_sample": int(bt.size),
            "rel_error_max": 1e-9 if bt.size else None, "rel_error_median": 1e-9 if bt.size else None,
            "error_estimate_max": 1e-9, "speedup_vs_bvp": 1.0, "target_seconds_per_point": None,
            "target_speedup": None, "pass_time": None, "pass_speedup": None,
            "note": "BVP error is its stated estimate (solve_bvp tol 1e-10), not measured",
        })
        for fid in FAST:
            s1, bad = _time_driver(fid, model, th, v, 1, repeats)
            s2, _ = _time_driver(fid, model, th, v, threads, repeats)
            if bt.size:
                r = moment(sub_th, sub_v, model, fid)
                rel = np.maximum(np.abs(r.I - bI) / np.abs(bI), ERR_FLOOR)
                emax, emed, est = float(rel.max()), float(np.median(rel)), float(np.max(r.error))
            else:
                emax = emed = est = None
            tgt = TARGETS[fid]
            speed = (t_bvp / s1) if t_bvp else None
            rows.append({
                "model": model, "fidelity": fid, "seconds_per_point_serial": s1,
                "seconds_per_point_parallel": s2, "nonfinite": bad, "bvp_sample": int(bt.size),
                "rel_error_max": emax, "rel_error_median": emed, "error_estimate_max": est,
                "speedup_vs_bvp": speed, "target_seconds_per_point": tgt["seconds_per_point"],
                "target_speedup": tgt["speedup_vs_bvp"],
                "pass_time": bool(s1 <= tgt["seconds_per_point"]),
                "pass_speedup": None if speed is None else bool(speed >= tgt["speedup_vs_bvp"]),
            })
    checks = [r[k] for r in rows for k in ("pass_time", "pass_speedup") if r[k] is not None]
    extra = run_sections(sections, quick_sections)
    checks += [f["pass"] for sec in extra.values() for f in sec.get("figures", []) if f.get("pass") is not None]
    return {
        "points": points, "bvp_points": int(bvp_points), "threads": threads, "repeats": int(repeats),
        "ranges": {"thickness_m": list(THICKNESS_RANGE), "voltage_V": list(VOLTAGE_RANGE),
                   "distribution": "log-uniform", "layout": layout},
        "targets": TARGETS, "compile": comp, "startup": startup, "results": rows, "sections": extra,
        "all_pass": bool(all(checks) and (startup is None or startup["pass"])),
    }


def load_bench(path) -> dict:
    """A saved ``ipmc-asym bench --json`` result, checked; one-line ``ValueError`` otherwise."""
    try:
        with open(path, encoding="utf-8") as fh:
            res = json.load(fh)
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise ValueError(f"--bench {path!r}: cannot read a bench JSON file ({exc.__class__.__name__}: {exc})") from None
    if not isinstance(res, dict) or not isinstance(res.get("results"), list) or "points" not in res:
        raise ValueError(f"--bench {path!r}: not the output of `ipmc-asym bench --json` (no 'results' list)")
    return res


def _t(x):
    if x is None:
        return "n/a"
    for unit, f in (("s", 1.0), ("ms", 1e-3), ("us", 1e-6), ("ns", 1e-9)):
        if x >= f or unit == "ns":
            return f"{x / f:.3g} {unit}"
    return f"{x:g}"


def _pf(b):
    return "-" if b is None else ("pass" if b else "FAIL")


def format_table(res: dict) -> str:
    """Human-readable table of :func:`run_bench`'s result."""
    lines = [f"ipmc-asym bench: N = {res['points']} points (thickness 10 um - 4 mm, voltage 1 mV - 10 V, "
             f"log-uniform, {res['ranges'].get('layout', 'random')}), parallel = {res['threads']} threads, BVP sample {res['bvp_points']}/model"]
    hdr = (f"{'model':9s} {'fidelity':10s} {'t/pt serial':>12s} {'t/pt par':>10s} {'target':>9s} {'time':>5s} "
           f"{'x vs BVP':>9s} {'target':>7s} {'spd':>5s} {'err max':>9s} {'err med':>9s} {'estimate':>9s}")
    lines.append(hdr)
    for r in res["results"]:
        def e(x):
            return f"{x:9.2e}" if x is not None else f"{'n/a':>9s}"

        sp = r["speedup_vs_bvp"]
        ts = f"{r['target_speedup']:.0e}" if r["target_speedup"] else "-"
        lines.append(
            f"{r['model']:9s} {r['fidelity']:10s} {_t(r['seconds_per_point_serial']):>12s} "
            f"{_t(r['seconds_per_point_parallel']):>10s} {_t(r['target_seconds_per_point']):>9s} "
            f"{_pf(r['pass_time']):>5s} {(f'{sp:.2e}' if sp else 'n/a'):>9s} "
            f"{ts:>7s} "
            f"{_pf(r['pass_speedup']):>5s} {e(r['rel_error_max'])} {e(r['rel_error_median'])} "
            f"{e(r['error_estimate_max'])}"
        )
    if res["compile"]:
        lines.append("compile (fresh NUMBA_CACHE_DIR) / cached load, first call in a new process:")
        for f, c in res["compile"].items():
            lines.append(f"  {f:10s} compile {c['compile_s']:.2f} s   cached load {c['cached_load_s']:.3f} s"
                         + (f"   (same driver as {c['shared_with']})" if "shared_with" in c else ""))
    st = res.get("startup")
    if st:
        lines.append(f"start-up: `ipmc-asym estimate --fidelity leading` in a fresh process, cache warm: "
                     f"{st['estimate_leading_wall_s']:.2f} s (target {st['target_s']} s: "
                     f"{'pass' if st['pass'] else 'FAIL'}); heavy modules imported: "
                     f"{', '.join(st['heavy_modules_imported']) or 'none'}")
    for name, sec in res.get("sections", {}).items():
        lines.append(f"[{name}]")
        for f in sec.get("figures", []):
            tgt = f" (target {f['target']})" if f.get("target") is not None else ""
            ok = "" if f.get("pass") is None else f"  {_pf(f['pass'])}"
            unit = f" {f['unit']}" if f.get("unit") else ""
            note = f"  -- {f['note']}" if f.get("note") else ""
            val = f"{f['value']:.4g}" if isinstance(f.get("value"), (int, float)) else str(f.get("value"))
            lines.append(f"  {f['what']}: {val}{unit}{tgt}{ok}{note}")
    lines.append(f"all targets: {'pass' if res['all_pass'] else 'FAIL (see table)'}")
    return "\n".join(lines)
