"""``ipmc-asym warmup``: compile every Numba kernel once, so that later runs load them from the cache.

Numba compiles a kernel the first time it is called after install (``cache=True``: the machine
code then lives in the cache directory, ``kernels.jit.CACHE_DIR``).  Each command compiles what
it needs on its first run; this command calls every compiled path once on a few points (each
rung of the ladder for the three models, the charge, the circuit and PNP transients, the
spectrum with the modal beam and the electrode line, a waveform drive (also through the line), a
sweep written to CSV), says how long each took, and marks the cache as warm.  ``--jobs N`` compiles the groups in N
processes side by side (Numba compiles in one thread; the cache files are written atomically).
"""

from __future__ import annotations

import contextlib
import os
import sys
import tempfile
import time

from ipmc_asym.cli import SUMMARIES
from ipmc_asym.cli.common import WARM_MARKER, _touch, count_type


def register(sub):
    p = sub.add_parser("warmup", help=SUMMARIES["warmup"],
                       description="Compile every Numba kernel once (a few minutes on a busy 2-core machine); "
                                   "later runs of every command load them from the cache.")
    p.add_argument("--jobs", type=count_type("--jobs", 1), default=1,
                   help=f"compile the groups in this many processes side by side (default 1, at most {MAX_JOBS})")
    p.add_argument("--json", action="store_true", help="print {step: seconds} as one JSON object")


#: cap on --jobs (each process holds its own copy of the compiler, ~300 MB)
MAX_JOBS = 8


def _steps():
    """(label, callable) of each compiled path, the longest to compile first."""
    import numpy as np  # deferred: heavy module, start-up (ipmc-asym --help lists warmup)

    import ipmc_asym as ia  # deferred: the whole public API (start-up of the other commands)

    th = np.geomspace(20e-6, 2e-3, 64)  # enough points to run the compiled drivers, not their interpreted twins
    models = ("constant", "linear", "affine")

    def closed():
        for m in models:
            for fid in ("leading", "corrected", "quadrature", "exact"):
                ia.moment_integral(th, 1.0, model=m, fidelity=fid, on_invalid="nan")

    def per_point():
        from ipmc_asym.forward.model import forward  # deferred: heavy module, start-up (and options no public function has)

        # C_moy per point (eq. (17) over a sweep of materials) and the moment with the pressure term
        for fid in ("corrected", "quadrature"):
            forward(0.02, 5e-3, th, 1.0, c_moy=np.full(th.size, 1100.0), fidelity=fid)
        forward(0.02, 5e-3, th, 1.0, pressure_term=True)

    def forward():
        ia.sweep({"thickness": th, "voltage": [0.5, 1.0]}, "constant", "quadrature")

    def charge():
        for m in models:
            for fid in ("leading", "quadrature", "exact"):
                ia.charge(th, 1.0, m, fid)
        ia.charge(1e-6, 20.0, "constant", "leading")  # overlapping layers: the closed forms' error against exact

    def transient():
        ia.step_response(1.0, points=50)
        ia.step_response(0.1, duration=0.05, points=20, fidelity="pnp")
        ia.step_response(0.1, duration=0.05, points=20, fidelity="pnp", model="linear")  # its own right-hand side

    def spectrum():
        f = np.geomspace(1.0, 1e3, 20)
        ia.frequency_response(f, beam="dynamic")
        ia.line_response(f, sheet_resistance=2.5)

    def drive():
        ia.drive_response("sine:0.5V@10Hz", 0.2, 400)
        ia.drive_response("step:0.5V", 0.05, 20, sheet_resistance=2.5)  # the electrode line

    def sweep_csv():
        from ipmc_asym.cli import main  # deferred: cli/__init__ imports this module

        # the command's own report (fits along the axis, warnings) is not the warmup's
        with tempfile.TemporaryDirectory() as d, open(os.devnull, "w") as null, \
                contextlib.redirect_stdout(null), contextlib.redirect_stderr(null):
            main(["sweep", "--vary", "thickness=100um:300um:2000", "--out", os.path.join(d, "w.csv"), "--no-progress"])

    # the longest first, so that --jobs balances them by taking the next group as a process frees
    # (measured cold, one process: the moment integral ~50 s, per point ~23 s, charge ~15 s, CSV ~12 s,
    # the rest ~2 s: they load what the first groups compiled)
    return [("moment integral: leading, corrected, quadrature, exact x 3 models", closed),
            ("moment with C_moy per point and the pressure term", per_point),
            ("electrode charge", charge),
            ("sweep written to CSV (compiled formatter)", sweep_csv),
            ("forward model and beam (a sweep)", forward),
            ("charging transient: circuit and PNP solver", transient),
            ("spectrum: modal beam and electrode line", spectrum),
            ("waveform drive: uniform strip and electrode line", drive)]


def _group(i):
    """Run step ``i`` of :func:`_steps` (in a worker process of ``--jobs``); its seconds."""
    from ipmc_asym.kernels.jit import compile_notice_given  # deferred: loads Numba

    compile_notice_given()  # the parent has said what compiles
    t0 = time.perf_counter()
    _steps()[i][1]()
    return time.perf_counter() - t0


def run(args):
    if args.jobs > MAX_JOBS:
        raise ValueError(f"--jobs must be an integer in [1, {MAX_JOBS}]; got {args.jobs}")
    from ipmc_asym.kernels.jit import CACHE_DIR, compile_notice_given  # deferred: loads Numba

    compile_notice_given()  # the line below says it
    steps = _steps()
    sys.stderr.write(f"ipmc-asym warmup: compiling the kernels of {len(steps)} groups into {CACHE_DIR} "
                     "(a few minutes on a busy machine; once per install)\n")
    took = {}
    start = time.perf_counter()
    if args.jobs == 1:
        for i, (label, fn) in enumerate(steps, 1):
            sys.stderr.write(f"  [{i}/{len(steps)}] {label} ...\n")
            sys.stderr.flush()
            t0 = time.perf_counter()
            fn()
            took[label] = time.perf_counter() - t0
    else:
        import multiprocessing  # deferred: only --jobs > 1 needs it
        from concurrent.futures import ProcessPoolExecutor  # deferred: only --jobs > 1 needs it

        # fresh interpreters (spawn): no fork of a process that has loaded Numba's compiler
        with ProcessPoolExecutor(args.jobs, mp_context=multiprocessing.get_context("spawn")) as pool:
            futures = [pool.submit(_group, i) for i in range(len(steps))]
            for i, fut in enumerate(futures):
                took[steps[i][0]] = fut.result()
                sys.stderr.write(f"  [{i + 1}/{len(steps)}] {steps[i][0]}: done\n")
                sys.stderr.flush()
    _touch(os.path.join(CACHE_DIR, WARM_MARKER))
    if args.json:
        from ipmc_asym.base.jsonio import dumps  # deferred: heavy module, start-up

        print(dumps({"cache_dir": CACHE_DIR, "seconds": took, "wall_seconds": time.perf_counter() - start,
                     "jobs": args.jobs}, indent=1))
        return 0
    for label, s in took.items():
        print(f"{s:8.1f} s  {label}")
    wall = time.perf_counter() - start
    print(f"{wall:8.1f} s  in all" + (f" ({args.jobs} processes side by side)" if args.jobs > 1 else "")
          + f"; the kernels are in {CACHE_DIR}")
    return 0
