"""Speed/accuracy benchmark of the fidelity ladder (``ipmc-asym bench``): the runner.

For each permittivity model (constant, linear, affine) and each fidelity:

* time per point of the compiled kernels on ``N`` (default 10^6) points (a log grid, or
  random: thickness log-uniform in 10 um - 4 mm, voltage log-uniform in 1 mV - 10 V),
  single-threaded (``numba.set_num_threads(1)`` around the ``prange`` driver) and parallel
  (all Numba threads, at most 2 here).  The groups (``lambda``, ``A2``) are precomputed, so
  the figure is the kernel cost per point (:func:`ipmc_asym_bench.kernels.bare_driver`);
* first-call compile time (a subprocess with ``NUMBA_CACHE_DIR`` pointing to a fresh
  temporary directory) and cached-load time (a second subprocess with the same directory).
  ``leading`` and ``corrected`` share one compiled driver, hence one compile time;
* the wall time of one BVP solve, averaged over a small sample (``--bvp-points`` per model)
  of the same distribution;
* the relative error ``|I_f - I_bvp| / |I_bvp|`` of each fidelity (``moment()``) on that
  sample (max and median).

Targets (checked side by side in one run, single-threaded): leading <= 50 ns/point,
corrected <= 200 ns/point, quadrature <= 5 us/point; leading and corrected >= 1e6x and
quadrature >= 1e4x faster per point than the BVP.

Further sections (:data:`SECTIONS`, one module each) add their figures.  :func:`run_bench`
returns one JSON-ready dict; :func:`ipmc_asym.plotting.speed.plot_speed_accuracy` draws it.
Only the public API of ``ipmc_asym`` is used.
"""

from __future__ import annotations

import importlib
import time

import numba
import numpy as np

from ipmc_asym import moment_integral
from ipmc_asym.base.registry import model_names
from ipmc_asym.integral.api import moment
from ipmc_asym_bench.kernels import bvp_sample, startup_time, time_driver

__all__ = ["run_bench", "run_sections", "SECTIONS", "sample_points", "format_table", "TARGETS",
           "MODELS", "ERR_FLOOR", "quick_bench"]

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
#: the ``exact`` rung (~15 us a point) is timed through the API on this many points of the grid
EXACT_POINTS = 20_000


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


#: further bench sections: name -> "module:function" (imported only when run).  Each function
#: takes ``quick: bool`` and returns ``{"figures": [{"what", "value", "unit", "target", "pass",
#: "note"}, ...], ...}``: figures measured side by side in one run, as ratios where a target is
#: a ratio.  Adding a section is adding one line here.
SECTIONS: dict[str, str] = {
    # first: fresh-process wall times, measured before the dask section (after it, the same
    # sweep measured 3.6 s instead of 2.9 s: what the cluster leaves behind is not the sweep's)
    "commands": "ipmc_asym_bench.commands:section",  # sweep --out 10^6 rows, figures
    "exact_api": "ipmc_asym_bench.exact:section",
    "uq": "ipmc_asym_bench.uq:section",
    "distributed": "ipmc_asym_bench.distributed:section",
    "charge": "ipmc_asym_bench.charge:section",  # charge, step circuit/pnp
    "dynamics": "ipmc_asym_bench.dynamics:section",  # freq 1000 frequencies, 10^5-point sine drive
}


def run_sections(names=None, quick: bool = False) -> dict:
    """Run the registered sections ``names`` (default all); ``{name: result}``."""
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
    points = int(points)
    th, v = sample_points(points, seed, layout)
    ths, vs = sample_points(max(int(bvp_points), 1), seed + 1)
    threads = max(1, min(int(threads), numba.config.NUMBA_NUM_THREADS))
    comp = {}
    startup = startup_time() if compile_times else None
    if compile_times:
        closed = compile_times("leading")
        quad = compile_times("quadrature")
        comp = {
            "leading": {"compile_s": closed[0], "cached_load_s": closed[1], "shared_with": "corrected"},
            "corrected": {"compile_s": closed[0], "cached_load_s": closed[1], "shared_with": "leading"},
            "quadrature": {"compile_s": quad[0], "cached_load_s": quad[1]},
        }
    rows = []
    for model in MODELS:
        bt, bI, keep = bvp_sample(model, ths, vs)
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
            s1, bad = time_driver(fid, model, th, v, 1, repeats)
            s2, _ = time_driver(fid, model, th, v, threads, repeats)
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
        rows.append(_exact_row(model, th, v, sub_th, sub_v, bI, t_bvp, repeats))
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


def _exact_row(model, th, v, sub_th, sub_v, bI, t_bvp, repeats) -> dict:
    """The ``exact`` rung's row: the public API on :data:`EXACT_POINTS` points of the same grid
    (single-threaded, best of ``repeats``), its error against the BVP sample."""
    step = max(1, th.size // EXACT_POINTS)
    te, ve = th[::step], v[::step]
    old = numba.get_num_threads()
    numba.set_num_threads(1)
    try:
        moment_integral(te[:2], ve[:2], model, "exact")  # warm-up (compile or load from cache)
        best = np.inf
        for _ in range(max(1, repeats)):
            t0 = time.perf_counter()
            out = moment_integral(te, ve, model, "exact", on_invalid="nan")
            best = min(best, time.perf_counter() - t0)
    finally:
        numba.set_num_threads(old)
    s1 = best / te.size
    if bI.size:
        r = moment(sub_th, sub_v, model, "exact")
        rel = np.maximum(np.abs(r.I - bI) / np.abs(bI), ERR_FLOOR)
        emax, emed, est = float(rel.max()), float(np.median(rel)), float(np.max(r.error))
    else:
        emax = emed = est = None
    return {"model": model, "fidelity": "exact", "seconds_per_point_serial": s1,
            "seconds_per_point_parallel": None, "nonfinite": int(np.count_nonzero(~np.isfinite(out))),
            "bvp_sample": int(bI.size), "rel_error_max": emax, "rel_error_median": emed,
            "error_estimate_max": est, "speedup_vs_bvp": (t_bvp / s1) if t_bvp else None,
            "target_seconds_per_point": None, "target_speedup": None, "pass_time": None,
            "pass_speedup": None, "note": f"timed through moment_integral on {te.size} points"}


def quick_bench(points: int = 10**5, bvp_points: int = 3) -> dict:
    """A quick in-process measurement for the speed/accuracy figure of ``ipmc-asym figures``:
    no compile subprocesses, no further sections, one repeat."""
    return run_bench(points, bvp_points, repeats=1, compile_times=False, sections=[])


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
             f"log-uniform, {res['ranges'].get('layout', 'random')}), parallel = {res['threads']} threads, "
             f"BVP sample {res['bvp_points']}/model"]
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
