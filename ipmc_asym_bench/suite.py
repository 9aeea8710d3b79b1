"""Speed/accuracy benchmark of the fidelity ladder (``ipmc-asym bench``): the runner.

For each permittivity model (constant, linear, affine) and each fidelity:

* time per point of ``ia.moment_integral`` (arrays in, ``I`` out) on ``N`` (default 10^6)
  points (a log grid, or random: thickness log-uniform in 10 um - 4 mm, voltage log-uniform
  in 1 mV - 10 V): single-threaded as CPU time (:func:`time.process_time`, least of the
  repeats) and on all Numba threads (at most 2 here) as wall time, the load average beside;
  the ``exact`` rung on :data:`EXACT_POINTS` points of the same sweep;
* first-call compile time (a subprocess with ``NUMBA_CACHE_DIR`` pointing to a fresh
  temporary directory) and cached-load time (a second subprocess with the same directory).
  ``leading`` and ``corrected`` share one compiled driver, hence one compile time;
* the CPU time of one BVP solve (``ia.solve_bvp_profile``), averaged over a small sample
  (``--bvp-points`` per model) of the same distribution;
* the relative error ``|I_f - I_bvp| / |I_bvp|`` of each fidelity (``ia.moment``) on that
  sample (max and median).

Targets (:data:`TARGETS`, single-threaded CPU time): leading <= 50 ns/point, corrected <= 200
ns/point, quadrature <= 5 us/point, exact <= 10 us/point; leading and corrected >= 1e6x,
quadrature >= 1e4x and exact >= 1e3x faster per point than the BVP.

Further sections (:data:`ipmc_asym_bench.sections.SECTIONS`, one module each) add their
figures.  :func:`run_bench` returns one JSON-ready dict; ``ipmc-asym bench --figure`` draws it.
Only names of ``ipmc_asym.__all__`` are used.
"""

from __future__ import annotations

import importlib

import numba
import numpy as np

import ipmc_asym as ia
from ipmc_asym_bench.kernels import bvp_sample, compile_seconds, startup_time, time_api
from ipmc_asym_bench.sections import MAX_BVP_POINTS, MAX_POINTS, SECTIONS
from ipmc_asym_bench.timing import load

__all__ = ["run_bench", "run_sections", "SECTIONS", "sample_points", "format_table", "TARGETS",
           "MODELS", "ERR_FLOOR", "quick_bench", "MAX_POINTS", "MAX_BVP_POINTS"]

MODELS = tuple(ia.MODELS)
FAST = ("leading", "corrected", "quadrature")
THICKNESS_RANGE = (10e-6, 4e-3)
VOLTAGE_RANGE = (1e-3, 10.0)

#: single-threaded CPU time per point (s) and minimum speed-up over one BVP solve (the goals;
#: ``exact``: the README's ~10 us a point, see ``ipmc_asym_bench.exact.TARGETS``)
TARGETS = {
    "leading": {"seconds_per_point": 50e-9, "speedup_vs_bvp": 1e6},
    "corrected": {"seconds_per_point": 200e-9, "speedup_vs_bvp": 1e6},
    "quadrature": {"seconds_per_point": 5e-6, "speedup_vs_bvp": 1e4},
    "exact": {"seconds_per_point": 10e-6, "speedup_vs_bvp": 1e3},
}

ERR_FLOOR = 1e-16  # relative errors below this are reported as this (log plots)
#: the ``exact`` rung (~10 us a point) is timed on this many points of the sweep
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
        Number of points (>= 1; the CLI caps it at :data:`MAX_POINTS`).
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


def run_sections(names=None, quick: bool = False) -> dict:
    """Run the registered sections ``names`` (default all); ``{name: result}``."""
    names = list(SECTIONS) if names is None else list(names)
    for name in names:  # every name checked before any work
        if name not in SECTIONS:
            raise ValueError(f"bench section must be one of {', '.join(SECTIONS) or '(none)'}; got {name!r}")
    out = {}
    for name in names:
        mod, fn = SECTIONS[name].split(":")
        out[name] = getattr(importlib.import_module(mod), fn)(quick=quick)
    return out


def run_bench(points: int = 10**6, bvp_points: int = 5, repeats: int = 3, seed: int = 0,
              compile_times: bool = True, threads: int = 2, layout: str = "grid",
              sections=None, quick_sections: bool = False, quick: bool = False) -> dict:
    """Run the whole benchmark and return a JSON-ready dict.

    Parameters
    ----------
    points : int
        Sweep size ``N`` for the timings (the CLI caps it at :data:`MAX_POINTS`).
    bvp_points : int
        BVP sample size per model (drawn from the same distribution; the CLI caps it at
        :data:`MAX_BVP_POINTS`).
    repeats : int
        Timing repeats (the least time is kept).
    seed : int
    compile_times : bool
        Measure compile / cached-load times in subprocesses (a few seconds each).
    threads : int
        Threads of the parallel timing.
    layout : {"grid", "random"}
        Sweep points as a grid (default, what a sweep is) or drawn at random.
    sections : list of str, optional
        Further sections to run (default all of :data:`SECTIONS`; ``[]`` none).
    quick_sections : bool
        The sections' smallest sizes.
    quick : bool
        The smallest sizes throughout (what the tests run): the sections' (``quick_sections``),
        one repeat, one compile measurement (the closed forms' driver), one start-up run and
        no untimed warm-up runs of the fresh-process figures (the Numba cache is normally warm).

    Returns
    -------
    dict
        ``{"points", "bvp_points", "threads", "ranges", "targets", "clock", "load", "compile":
        {fidelity: {"compile_s", "cached_load_s"}}, "results": [row, ...], "all_pass"}`` with one
        row per ``(model, fidelity)``: ``seconds_per_point_serial`` (CPU time, 1 thread),
        ``seconds_per_point_parallel`` (wall time, ``threads``; None for bvp and exact),
        ``nonfinite``, ``rel_error_max``, ``rel_error_median``, ``error_estimate_max`` (the
        fidelity's own estimate on the sample), ``speedup_vs_bvp``, ``target_seconds_per_point``,
        ``target_speedup``, ``pass_time``, ``pass_speedup``, ``load`` (1-minute load average
        when the row was measured).
    """
    points = int(points)
    bvp_points = int(bvp_points)
    if bvp_points < 1:
        raise ValueError(f"bvp_points must be an integer >= 1; got {bvp_points!r}")
    names = list(SECTIONS) if sections is None else list(sections)
    for name in names:  # refused before any work
        if name not in SECTIONS:
            raise ValueError(f"bench section must be one of {', '.join(SECTIONS)}; got {name!r}")
    if quick:
        repeats, quick_sections = 1, True
    th, v = sample_points(points, seed, layout)
    ths, vs = sample_points(bvp_points, seed + 1)
    threads = max(1, min(int(threads), numba.config.NUMBA_NUM_THREADS))
    load0 = load()
    comp = {}
    startup = startup_time(repeats=1 if quick else 3, warm=not quick) if compile_times else None
    if compile_times:
        closed = compile_seconds("leading")
        comp = {
            "leading": {"compile_s": closed[0], "cached_load_s": closed[1], "shared_with": "corrected"},
            "corrected": {"compile_s": closed[0], "cached_load_s": closed[1], "shared_with": "leading"},
        }
        if not quick:
            quad = compile_seconds("quadrature")
            comp["quadrature"] = {"compile_s": quad[0], "cached_load_s": quad[1]}
    step = max(1, th.size // EXACT_POINTS)
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
            "target_speedup": None, "pass_time": None, "pass_speedup": None, "load": load(),
            "note": "BVP error is its stated estimate (solve_bvp tol 1e-10), not measured; CPU time of one solve",
        })
        for fid in (*FAST, "exact"):
            tf, vf = (th, v) if fid != "exact" else (th[::step], v[::step])
            s1, bad = time_api(fid, model, tf, vf, 1, repeats)
            s2 = time_api(fid, model, tf, vf, threads, repeats)[0] if fid != "exact" else None
            if bt.size:
                r = ia.moment(sub_th, sub_v, model, fid)
                rel = np.maximum(np.abs(r.I - bI) / np.abs(bI), ERR_FLOOR)
                emax, emed, est = float(rel.max()), float(np.median(rel)), float(np.max(r.error))
            else:
                emax = emed = est = None
            tgt = TARGETS[fid]
            speed = (t_bvp / s1) if t_bvp else None
            row = {
                "model": model, "fidelity": fid, "seconds_per_point_serial": s1,
                "seconds_per_point_parallel": s2, "nonfinite": bad, "bvp_sample": int(bt.size),
                "rel_error_max": emax, "rel_error_median": emed, "error_estimate_max": est,
                "speedup_vs_bvp": speed, "target_seconds_per_point": tgt["seconds_per_point"],
                "target_speedup": tgt["speedup_vs_bvp"],
                "pass_time": bool(s1 <= tgt["seconds_per_point"]),
                "pass_speedup": None if speed is None else bool(speed >= tgt["speedup_vs_bvp"]),
                "load": load(),
            }
            if fid == "exact":
                row["note"] = f"timed on {tf.size} points of the sweep"
            rows.append(row)
    checks = [r[k] for r in rows for k in ("pass_time", "pass_speedup") if r[k] is not None]
    extra = run_sections(names, quick_sections)
    checks += [f["pass"] for sec in extra.values() for f in sec.get("figures", []) if f.get("pass") is not None]
    return {
        "points": points, "bvp_points": bvp_points, "threads": threads, "repeats": int(repeats),
        "ranges": {"thickness_m": list(THICKNESS_RANGE), "voltage_V": list(VOLTAGE_RANGE),
                   "distribution": "log-uniform", "layout": layout},
        "clock": "single-thread figures: CPU time (time.process_time), least of the repeats; parallel: wall time",
        "load": {"start": load0, "end": load()},
        "targets": TARGETS, "compile": comp, "startup": startup, "results": rows, "sections": extra,
        "all_pass": bool(all(checks) and (startup is None or startup["pass"])),
    }


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
    if res.get("clock"):
        ld = res.get("load") or {}
        lines.append(f"clock: {res['clock']}; load average {ld.get('start', float('nan')):.2f} at the start, "
                     f"{ld.get('end', float('nan')):.2f} at the end")
    hdr = (f"{'model':9s} {'fidelity':10s} {'t/pt serial':>12s} {'t/pt par':>10s} {'target':>9s} {'time':>5s} "
           f"{'x vs BVP':>9s} {'target':>7s} {'spd':>5s} {'err max':>9s} {'err med':>9s} {'estimate':>9s} {'load':>5s}")
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
            f"{e(r['error_estimate_max'])} {r.get('load', float('nan')):5.2f}"
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
