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
    material_from_args,
    strip_from_args,
    tol_type,
)
from ipmc_asym.dynamics.circuit import STEP_FIDELITIES, step_response
from ipmc_asym.io.fileio import atomic_write, check_output_path
from ipmc_asym.io.jsonio import dumps

COLUMNS = ("t", "phi0", "sigma", "current_density", "M_A", "theta", "w")


def _duration(text):
    v = parse_time("--duration", text)
    if v <= 0:
        raise ValueError(f"--duration must be > 0 (e.g. 0.5s, 200ms); got {text!r}")
    return v


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
    p.add_argument("--tol", type=tol_type, default=None,
                   help="relative accuracy required of sigma at every output time, e.g. 1e-3 or 0.1%% (in [1e-8, 0.5)): "
                        "the circuit's error is bounded against the PNP solver and the PNP is used where it fails; "
                        "default: no estimate for the circuit, 1e-6 for pnp")
    p.add_argument("--points", type=count_type("--points", 2), default=1000, help="output times (default 1000)")
    p.add_argument("--out", default=None,
                   help="CSV file (columns t, phi0, sigma, current_density, M_A, theta, w; with --tol also sigma_error)")
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
                      material=material, points=args.points, tol=args.tol)
    cols = {"t": r.t, "phi0": r.phi0, "sigma": r.sigma, "sigma_error": r.sigma_error,
            "current_density": r.current_density, "M_A": r.M_A,
            "theta": r.theta, "w": r.w}
    columns = COLUMNS + (("sigma_error",) if args.tol is not None else ())
    if args.out:
        with atomic_write(args.out) as fh:
            wr = csv.writer(fh)
            wr.writerow([f"# tau = {r.tau!r} s; thickness_total = {strip.thickness!r} m; model = {r.model}; "
                         f"fidelity = {r.fidelity}; SI units"])
            wr.writerow(columns)
            for i in range(r.t.size):
                wr.writerow([repr(float(cols[c][i])) for c in columns])
        sys.stderr.write(f"step: {r.t.size} rows -> {args.out}\n")
    head = {"tau": r.tau, "R": r.R, "C_d0": r.C_d0, "model": r.model, "fidelity": r.fidelity,
            "voltage": strip.voltage, "thickness_total": strip.thickness, "half_thickness_e": strip.e,
            "diffusion_coefficient": material.D, "seconds": r.seconds, "notes": r.notes, "message": r.message,
            "tol": args.tol, "valid_from": r.extra.get("valid_from")}
    if args.json:
        out = dict(head)
        out.update({c: cols[c] for c in columns})
        print(dumps(out, indent=1))
        return 0
    if not args.out:
        print(f"step {strip.voltage:g} V, total thickness 2e = {fmt_length(strip.thickness)}, model {r.model}, "
              f"fidelity {r.fidelity}: tau = {r.tau:.4g} s (R = {r.R:.4g} Ohm m^2, C_d(0) = {r.C_d0:.4g} F/m^2, "
              f"D = {material.D:.3g} m^2/s)")
        idx = np.unique(np.linspace(0, r.t.size - 1, min(r.t.size, 11)).astype(int))
        print(f"{'t [s]':>11s} {'sigma [C/m^2]':>14s} {'J [A/m^2]':>11s} {'M_A [N m]':>11s} {'theta':>9s} {'w [mm]':>9s}")
        for i in idx:
            print(f"{r.t[i]:11.4g} {r.sigma[i]:14.6g} {r.current_density[i]:11.4g} {r.M_A[i]:11.4g} "
                  f"{r.theta[i]:9.4g} {r.w[i] * 1e3:9.4g}")
        for n in r.notes:
            print(f"note: {n}")
    return 0
