"""``ipmc-asym step``: charging transient after a voltage step (reduced model or PNP solver)."""

from __future__ import annotations

import csv
import sys

import numpy as np

from ipmc_asym.base.registry import model_names
from ipmc_asym.base.units import fmt_length, parse_time
from ipmc_asym.cli import SUMMARIES
from ipmc_asym.cli.common import (
    add_strip_options,
    arg_type,
    count_type,
    diffusion_type,
    first_run_notice,
    fmt_num,
    material_from_args,
    strip_from_args,
)
from ipmc_asym.dynamics.circuit import STEP_FIDELITIES, step_response
from ipmc_asym.forward.model import CHECKS
from ipmc_asym.io.fileio import atomic_write, check_output_path
from ipmc_asym.io.jsonio import dumps

COLUMNS = ("t", "phi0", "sigma", "current_density", "M_A", "theta", "w")
#: per time point: the forward model's checks (forward.model.CHECKS), as in estimate and sweep
CHECK_COLUMNS = tuple(f"check_{c}" for c in CHECKS) + ("valid",)


def _duration(text):
    v = parse_time("--duration", text)
    if v <= 0:
        raise ValueError(f"--duration must be > 0 (e.g. 0.5s, 200ms); got {text!r}")
    return v


def _num(x, scale):
    """A withheld (NaN) value as n/a, like estimate."""
    return fmt_num(x * scale if np.isfinite(x) else None, ".4g")


def register(sub):
    p = sub.add_parser("step", help=SUMMARIES["step"])
    add_strip_options(p)
    p.add_argument("--duration", type=arg_type(_duration, "duration"), default=None,
                   help="end time (e.g. 0.2s, 50ms; default 5 tau)")
    p.add_argument("--fidelity", default="circuit", choices=STEP_FIDELITIES,
                   help="circuit (reduced nonlinear capacitor) or pnp (transient Nernst-Planck/Gauss)")
    p.add_argument("--model", default="constant", choices=list(model_names()), help="permittivity model")
    p.add_argument("--diffusion", type=diffusion_type(), default=None,
                   help="cation diffusion coefficient D (1e-10m2/s, 1e-6cm2/s; a bare number is m^2/s)")
    p.add_argument("--points", type=count_type("--points", 2), default=1000, help="output times (default 1000)")
    p.add_argument("--out", default=None, help="CSV file (columns t, phi0, sigma, current_density, M_A, theta, w, "
                                                "check_* and valid per time point)")
    p.add_argument("--json", action="store_true", help="print one JSON object")


def run(args):
    if args.out:
        check_output_path(args.out, "file")
    material = material_from_args(args)
    if args.diffusion is not None:
        material = material.with_(D=args.diffusion)
    strip = strip_from_args(args)
    first_run_notice()
    r = step_response(strip.voltage, args.duration, strip=strip, model=args.model, fidelity=args.fidelity,
                      material=material, points=args.points)
    cols = {"t": r.t, "phi0": r.phi0, "sigma": r.sigma, "current_density": r.current_density, "M_A": r.M_A,
            "theta": r.theta, "w": r.w}
    flags = {f"check_{c}": r.checks[c] for c in CHECKS}
    flags["valid"] = r.valid
    if args.out:
        with atomic_write(args.out) as fh:
            wr = csv.writer(fh)
            wr.writerow([f"# tau = {r.tau!r} s; thickness_total = {strip.thickness!r} m; model = {r.model}; "
                         f"fidelity = {r.fidelity}; SI units"])
            wr.writerow(COLUMNS + CHECK_COLUMNS)
            for i in range(r.t.size):
                wr.writerow([repr(float(cols[c][i])) for c in COLUMNS] + [str(bool(flags[c][i])) for c in CHECK_COLUMNS])
        sys.stderr.write(f"step: {r.t.size} rows -> {args.out}\n")
    head = {"tau": r.tau, "R": r.R, "C_d0": r.C_d0, "model": r.model, "fidelity": r.fidelity,
            "voltage": strip.voltage, "thickness_total": strip.thickness, "half_thickness_e": strip.e,
            "diffusion_coefficient": material.D, "seconds": r.seconds, "notes": r.notes, "message": r.message,
            "warnings": r.warnings}
    for w in r.warnings:  # the forward model's flags, one line each (also in --json's "warnings")
        sys.stderr.write(f"step: warning: {w}\n")
    if args.json:
        out = dict(head)
        out.update({c: cols[c] for c in COLUMNS})
        out.update({c: flags[c] for c in CHECK_COLUMNS})
        print(dumps(out, indent=1))
        return 0
    if not args.out:
        print(f"step {strip.voltage:g} V, total thickness 2e = {fmt_length(strip.thickness)}, model {r.model}, "
              f"fidelity {r.fidelity}: tau = {r.tau:.4g} s (R = {r.R:.4g} Ohm m^2, C_d(0) = {r.C_d0:.4g} F/m^2, "
              f"D = {material.D:.3g} m^2/s)")
        idx = np.unique(np.linspace(0, r.t.size - 1, min(r.t.size, 11)).astype(int))
        print(f"{'t [s]':>11s} {'sigma [C/m^2]':>14s} {'J [A/m^2]':>11s} {'M_A [N m]':>11s} {'theta':>9s} "
              f"{'w [mm]':>9s} valid")
        for i in idx:
            print(f"{r.t[i]:11.4g} {r.sigma[i]:14.6g} {r.current_density[i]:11.4g} {r.M_A[i]:11.4g} "
                  f"{_num(r.theta[i], 1.0):>9s} {_num(r.w[i], 1e3):>9s} {'yes' if r.valid[i] else 'no'}")
        for n in r.notes:
            print(f"note: {n}")
    return 0
